"""optdesign.models.describing_function and optdesign.models.harmonic_balance (issue 38).

Against python-control (a test-only dependency; skipped without it): its backlash and
saturation describing functions, and its harmonic balance of the example loop
8/(s^3 + 2 s^2 + 2 s + 1) with a unit saturation. Against closed forms: that loop's phase
crossover sqrt(2) rad/s with L = -8/3 (so N = 3/8), a conditionally stable loop whose
cycle is unstable by Routh's test. Loeb's verdict against the closed-loop roots of the
loop with N frozen just above and below the cycle's amplitude. Property tests of the
bounds N obeys, and refusals naming the argument.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.models import describing_function as df
from optdesign.models import harmonic_balance as hb
from optdesign.models.describing_function import Backlash, Saturation

# python-control's example loop (its describing_function_response docstring)
EXAMPLE = ([8.0], [1.0, 2.0, 2.0, 1.0])


def _control():
    ct = pytest.importorskip("control")
    if not hasattr(ct, "describing_function_response"):
        pytest.skip("python-control < 0.10 has no describing_function_response")
    return ct


def _pc_cycles(ct, num, den, nonlinearity, amplitudes, omega):
    """python-control's intersections (its refinement is scipy's minimize)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        response = ct.describing_function_response(
            ct.tf(num, den), nonlinearity, amplitudes, omega=omega
        )
    return sorted((float(a), float(w)) for a, w in response.intersections)


# --- the describing functions against python-control -------------------------------------
@pytest.mark.parametrize("b", [0.3, 1e-3, 2.0])
def test_backlash_equals_python_controls_with_its_total_width(b):
    ct = _control()
    theirs = ct.friction_backlash_nonlinearity(2 * b)  # python-control: total width
    for A in [0.2 * b, b, b * (1 + 1e-7), 1.1 * b, 1.5 * b, 2 * b, 3 * b, 10 * b, 1e4 * b]:
        assert abs(df.backlash_df(A, b) - theirs.describing_function(A)) <= 1e-9, A


def test_backlash_at_python_controls_width_is_half_minus_j_over_pi():
    ct = _control()
    b_pc = 0.8  # python-control's b (total width); ours is its half, 0.4
    assert ct.friction_backlash_nonlinearity(b_pc).describing_function(b_pc) == pytest.approx(
        0.5 - 1j / math.pi, abs=1e-15
    )
    assert df.backlash_df(b_pc, b_pc / 2) == pytest.approx(0.5 - 1j / math.pi, abs=1e-15)
    assert Backlash(b_pc / 2).describing_function(b_pc) == pytest.approx(0.5 - 0.3183098861837907j)


def test_saturation_equals_python_controls():
    ct = _control()
    for c in [1.0, 0.05, 7.0]:
        theirs = ct.saturation_nonlinearity(c)
        for A in [0.0, 0.5 * c, c, c * (1 + 1e-7), 1.3 * c, 3 * c, 1e3 * c]:
            assert abs(df.saturation_df(A, c) - theirs.describing_function(A)) <= 1e-9, (c, A)


def test_describing_functions_on_arrays_keep_the_shape():
    A = np.array([[0.1, 0.5], [0.6, 2.0]])
    n = df.backlash_df(A, 0.25)
    assert n.shape == (2, 2) and n[0, 0] == 0 and n[0, 1] == pytest.approx(0.5 - 1j / math.pi)
    s = df.saturation_df(A, 0.5)
    assert s.shape == (2, 2) and s[0, 0] == 1.0 and s[0, 1] == 1.0
    assert s[1, 1] == pytest.approx(2 / math.pi * (math.asin(0.25) + 0.25 * math.sqrt(1 - 0.0625)))


# --- harmonic balance --------------------------------------------------------------------
def test_python_controls_example_cycle_exactly():
    """L(jw) = 8 / ((1 - 2w^2) + j(2w - w^3)): real at w = sqrt(2), L = 8/(1 - 4) = -8/3,
    so N(A) = 3/8, A = 3.3440 (python-control's docstring prints 3.3438 from its
    minimiser). Stable: -1/N moves left, out of the Nyquist curve, as A grows."""
    out = hb.harmonic_balance(hb.polynomial_loop(*EXAMPLE), Saturation(1.0))
    (cycle,) = out.cycles
    assert cycle.frequency == pytest.approx(math.sqrt(2), rel=1e-12)
    assert cycle.loop_response == pytest.approx(-8 / 3, rel=1e-12)
    assert cycle.describing_function == pytest.approx(3 / 8, rel=1e-12)
    assert df.saturation_df(cycle.amplitude, 1.0) == pytest.approx(3 / 8, rel=1e-13)
    assert cycle.amplitude == pytest.approx(3.343998730, rel=1e-9)
    assert round(cycle.amplitude, 2) == 3.34
    assert cycle.stability == "stable" and cycle.loeb > 0
    # |d(3j sqrt 2)| = |-35 - 48 sqrt(2) j| = sqrt(5833): the third harmonic's gain 3/sqrt(5833)
    assert cycle.third_harmonic_gain == pytest.approx(3 / math.sqrt(5833), rel=1e-12)
    assert cycle.filter_hypothesis_holds and not out.none and out.reason == ""


def test_python_controls_example_against_its_describing_function_response():
    ct = _control()
    theirs = _pc_cycles(
        ct,
        *EXAMPLE,
        ct.saturation_nonlinearity(1),
        np.linspace(1, 4, 10),
        np.geomspace(0.1, 10, 2000),
    )
    ours = hb.harmonic_balance(hb.polynomial_loop(*EXAMPLE), Saturation(1.0)).cycles
    assert len(theirs) == len(ours) == 1
    assert ours[0].amplitude == pytest.approx(theirs[0][0], rel=1e-3)
    assert ours[0].frequency == pytest.approx(theirs[0][1], rel=1e-4)


def test_saturation_scales_the_amplitude_only():
    (unit,) = hb.harmonic_balance(hb.polynomial_loop(*EXAMPLE), Saturation(1.0)).cycles
    (scaled,) = hb.harmonic_balance(hb.polynomial_loop(*EXAMPLE), Saturation(0.02)).cycles
    assert scaled.amplitude == pytest.approx(0.02 * unit.amplitude, rel=1e-12)
    assert scaled.frequency == pytest.approx(unit.frequency, rel=1e-12)


def test_conditionally_stable_loop_has_an_unstable_cycle():
    """L = (s + 1)^2 / s^3: L(jw) = (j(1 - w^2) - 2w) / w^3 is real at w = 1, L = -2, so
    N = 1/2. The closed loop s^3 + N (s^2 + 2 s + 1) is stable for N > 1/2 (Routh:
    2 N^2 > N) and unstable below: a larger amplitude (smaller N) grows, the cycle is
    unstable."""
    (cycle,) = hb.harmonic_balance(
        hb.polynomial_loop([1, 2, 1], [1, 0, 0, 0]), Saturation(1.0)
    ).cycles
    assert cycle.frequency == pytest.approx(1.0, rel=1e-12)
    assert cycle.describing_function == pytest.approx(0.5, rel=1e-12)
    assert cycle.amplitude == pytest.approx(df.saturation_amplitude(0.5, 1.0), rel=1e-12)
    assert 2.4 < cycle.amplitude < 2.5
    assert cycle.stability == "unstable" and cycle.loeb < 0
    # |L(3j)| / |L(j)| = (10/27) / 2
    assert cycle.third_harmonic_gain == pytest.approx(5 / 27, rel=1e-12)
    assert not cycle.filter_hypothesis_holds


INTEGRAL = {K: ([K, 0.5 * K], [1.0, 1.0, 0.0, 0.0]) for K in (0.2, 0.5, 1.0, 2.0)}


@pytest.mark.parametrize("K", sorted(INTEGRAL))
def test_backlash_in_an_integral_loop_against_python_control(K):
    """L = K (s + 0.5) / (s^2 (s + 1)), a PI-like loop, and a backlash of half-width 0.1:
    one stable cycle, as python-control finds it."""
    ct = _control()
    num, den = INTEGRAL[K]
    theirs = _pc_cycles(
        ct,
        num,
        den,
        ct.friction_backlash_nonlinearity(0.2),
        np.geomspace(0.1001, 100, 400),
        np.geomspace(1e-3, 1e3, 3000),
    )
    ours = hb.harmonic_balance(hb.polynomial_loop(num, den), Backlash(0.1)).cycles
    assert len(ours) == len(theirs) == 1
    assert ours[0].amplitude == pytest.approx(theirs[0][0], rel=1e-4)
    assert ours[0].frequency == pytest.approx(theirs[0][1], rel=1e-4)
    assert abs(1 + ours[0].describing_function * ours[0].loop_response) < 1e-10
    assert ours[0].stability == "stable"


TYPE_ONE = ([10.0], [0.1, 1.1, 1.0, 0.0])  # 10 / (s (s + 1) (0.1 s + 1)): gain margin 1.1


@pytest.mark.parametrize("K, count", [(2.5, 0), (3.5, 2), (10.0, 2)])
def test_backlash_in_a_type_one_loop_against_python_control(K, count):
    """K / (s (s + 1) (0.1 s + 1)) with a backlash of half-width 0.01. The Nyquist curve
    ends right of -1/N at both ends (it crosses the real axis at -K/11, and -1/N runs
    left faster than the loop's asymptote Re L = -1.1 K as both fall to -j inf), so the
    curves cross an even number of times: none at K = 2.5, else a small unstable cycle
    just outside the gap and a larger stable one, which grows without bound as K -> 11
    (the linear loop's own limit)."""
    ct = _control()
    num, den = [K], TYPE_ONE[1]
    ours = hb.harmonic_balance(hb.polynomial_loop(num, den), Backlash(0.01))
    theirs = _pc_cycles(
        ct,
        num,
        den,
        ct.friction_backlash_nonlinearity(0.02),
        0.01 * (1 + np.geomspace(1e-6, 1e3, 800)),
        np.geomspace(1e-2, 1e2, 2500),
    )
    assert len(ours.cycles) == len(theirs) == count
    for c, (a, w) in zip(ours.cycles, theirs, strict=True):
        # python-control's minimiser stops at about 1e-5 where the curves cross at a
        # shallow angle (K = 10); ours is a root to 1e-10
        assert c.amplitude == pytest.approx(a, rel=1e-4)
        assert c.frequency == pytest.approx(w, rel=1e-4)
        assert abs(1 + c.describing_function * c.loop_response) < 1e-10
    if count:
        assert [c.stability for c in ours.cycles] == ["unstable", "stable"]
        assert ours.cycles[0].amplitude < 1.12 * 0.01 < ours.cycles[1].amplitude
    else:
        assert "does not meet -1/N(A)" in ours.reason
    if K == 10.0:
        assert 40 < ours.cycles[1].amplitude / 0.01 < 45


def _closed_loop_root(num, den, N, omega):
    """The root of den(s) + N num(s) nearest j omega (N complex, frozen)."""
    n = np.zeros(len(den), dtype=complex)
    n[len(den) - len(num) :] = num
    roots = np.roots(np.asarray(den, dtype=complex) + N * n)
    return roots[np.argmin(np.abs(roots - 1j * omega))]


@pytest.mark.parametrize(
    "case",
    [
        (EXAMPLE, Saturation(1.0)),
        (([1, 2, 1], [1, 0, 0, 0]), Saturation(1.0)),
        (INTEGRAL[1.0], Backlash(0.1)),
        (TYPE_ONE, Backlash(0.01)),
    ],
    ids=["example", "conditional", "integral", "type-one"],
)
def test_loeb_verdict_agrees_with_the_roots_of_the_frozen_loop(case):
    """A cycle is stable when a larger amplitude puts the closed loop's root near jw in
    the left half-plane (it decays) and a smaller one in the right: the roots of
    den + N(A (1 +- 1e-6)) num, computed without derivatives."""
    (num, den), nl = case
    cycles = hb.harmonic_balance(hb.polynomial_loop(num, den), nl).cycles
    assert cycles
    for c in cycles:
        above = _closed_loop_root(
            num, den, nl.describing_function(c.amplitude * (1 + 1e-6)), c.frequency
        )
        below = _closed_loop_root(
            num, den, nl.describing_function(c.amplitude * (1 - 1e-6)), c.frequency
        )
        assert abs(above - 1j * c.frequency) < 1e-2 * c.frequency
        assert (above.real < 0 < below.real) == c.stable
        assert (above.real > 0 > below.real) == (c.stability == "unstable")


def test_a_callable_loop_finds_the_same_cycle():
    poly = hb.polynomial_loop(*EXAMPLE)
    call = hb.callable_loop(
        lambda w: 8 / ((1j * w) ** 3 + 2 * (1j * w) ** 2 + 2j * w + 1), (0.01, 100)
    )
    (a,) = hb.harmonic_balance(poly, Saturation(1.0)).cycles
    (b,) = hb.harmonic_balance(call, Saturation(1.0)).cycles
    assert b.amplitude == pytest.approx(a.amplitude, rel=1e-10)
    assert b.frequency == pytest.approx(a.frequency, rel=1e-10)
    assert b.loeb == pytest.approx(a.loeb, rel=1e-6)


def test_none_and_why():
    low_gain = hb.harmonic_balance(hb.polynomial_loop([0.5], [1, 3, 3, 1]), Saturation(1.0))
    # 0.5 / (s + 1)^3 crosses -180 deg at w = sqrt(3) with L = -1/16: never reached
    assert low_gain.none and "below 1" in low_gain.reason and "-0.0625" in low_gain.reason
    no_crossover = hb.harmonic_balance(hb.polynomial_loop([5], [1, 1]), Saturation(1.0))
    assert no_crossover.none and "never crosses -180 deg" in no_crossover.reason
    # 1 / (s + 1)^2 keeps Re L > -1/8: the curve -1/N (Re <= -1) is never met
    lag = hb.harmonic_balance(hb.polynomial_loop([1], [1, 2, 1]), Backlash(0.1))
    assert lag.none and "does not meet -1/N(A)" in lag.reason


def test_default_frequency_range_spans_the_corners():
    assert hb.polynomial_loop([1], [0.1, 1.1, 1, 0]).omega_range == pytest.approx((0.01, 1000.0))
    assert hb.polynomial_loop([2], [1, 0, 0]).omega_range == (0.01, 100.0)


# --- properties --------------------------------------------------------------------------
positive = st.floats(1e-6, 1e6)
ratio = st.floats(0.0, 1e6)


@given(b=positive, x=ratio)
def test_backlash_gain_is_at_most_one_and_lags(b, x):
    n = df.backlash_df(x * b, b)
    assert abs(n) <= 1.0 + 1e-15 and n.imag <= 0.0
    # N -> 1 as A -> inf: |1 - N| <= (4/pi) b/A (the bound is the limit of |Im N| A/b)
    if x > 1:
        assert abs(1 - n) <= 4 / math.pi / x * (1 + 1e-12)
    else:
        assert n == 0


@given(c=positive, x=ratio)
def test_saturation_gain_is_at_most_one_and_falls_as_four_over_pi_a(c, x):
    n = df.saturation_df(x * c, c)
    assert 0.0 < n <= 1.0 and isinstance(n, float)
    if x <= 1:
        assert n == 1.0
    if x > 1e3:  # 4/(pi x) (1 + O(1/x^2)): a square wave's fundamental
        assert n * x == pytest.approx(4 / math.pi, rel=1e-6)


@given(b=positive, x1=st.floats(0.0, 50.0), x2=st.floats(0.0, 50.0))
def test_backlash_is_continuous_with_lipschitz_constant_four_over_pi_b(b, x1, x2):
    """|dN/dA| <= 4/(pi b), across A = b too (N and its slope vanish there)."""
    gap = abs(df.backlash_df(x1 * b, b) - df.backlash_df(x2 * b, b))
    assert gap <= 4 / (math.pi * b) * abs(x1 - x2) * b * (1 + 1e-9) + 1e-15


@given(c=positive, x1=st.floats(0.0, 50.0), x2=st.floats(0.0, 50.0))
def test_saturation_is_continuous_with_its_lipschitz_constant(c, x1, x2):
    """|dN/dA| <= (4/pi) max u^2 sqrt(1 - u^2) / c = 8/(3 sqrt(3) pi c), at u^2 = 2/3."""
    gap = abs(df.saturation_df(x1 * c, c) - df.saturation_df(x2 * c, c))
    assert gap <= 8 / (3 * math.sqrt(3) * math.pi) * abs(x1 - x2) * (1 + 1e-9) + 1e-15


@given(x=st.floats(1.001, 1e3))
def test_derivatives_equal_central_differences(x):
    h = 1e-6 * x
    for f, d in [
        (df.backlash_df, df.backlash_df_derivative),
        (df.saturation_df, df.saturation_df_derivative),
    ]:
        fd = (f(x + h, 1.0) - f(x - h, 1.0)) / (2 * h)
        assert abs(d(x, 1.0) - fd) <= 1e-6 * abs(fd) + 1e-9


@given(N=st.floats(1e-4, 0.9999), c=positive)
def test_saturation_amplitude_inverts_the_describing_function(N, c):
    A = df.saturation_amplitude(N, c)
    assert A > c and df.saturation_df(A, c) == pytest.approx(N, rel=1e-12)


# --- refusals ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "call, field",
    [
        (lambda: df.backlash_df(-1.0, 0.1), "A"),
        (lambda: df.backlash_df(math.inf, 0.1), "A"),
        (lambda: df.backlash_df([1.0, math.nan], 0.1), "A"),
        (lambda: df.backlash_df(1.0, -0.1), "b"),
        (lambda: df.saturation_df(1.0, 0.0), "c"),
        (lambda: df.saturation_df_derivative(-2.0, 1.0), "A"),
        (lambda: df.saturation_amplitude(1.5, 1.0), "N"),
        (lambda: Backlash(-0.1), "half_width"),
        (lambda: Saturation(math.nan), "limit"),
        (lambda: hb.polynomial_loop([1, 0, 0], [1, 1]), "numerator"),
        (lambda: hb.polynomial_loop([1], [0, 0]), "denominator"),
        (lambda: hb.polynomial_loop([1], [1, math.inf]), "denominator"),
        (lambda: hb.polynomial_loop([1], [1, 1], omega_range=(1, 0.1)), "omega_range"),
        (lambda: hb.callable_loop(lambda w: 1 / (1j * w + 1), (0.0, 1.0)), "omega_range"),
        (lambda: hb.callable_loop("L", (0.1, 1.0)), "response"),
        (lambda: hb.harmonic_balance(hb.polynomial_loop(*EXAMPLE), "saturation"), "nonlinearity"),
        (
            lambda: hb.harmonic_balance(hb.polynomial_loop(*EXAMPLE), Saturation(1.0), points=10),
            "points",
        ),
        (lambda: hb.harmonic_balance(EXAMPLE, Saturation(1.0)), "loop"),
    ],
)
def test_bad_input_is_refused_naming_the_argument(call, field):
    with pytest.raises(InputError) as err:
        call()
    assert err.value.field == field
