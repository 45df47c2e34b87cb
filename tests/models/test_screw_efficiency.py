"""Screw efficiency by kind (ball, sliding Tr/Acme, roller), forward and back-driving."""

import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.models import roller_screw as rs
from optdesign.models import screw
from optdesign.models.screw_efficiency import (
    is_back_drivable,
    screw_efficiency,
    self_locking_margin,
    sliding_friction_angle,
)


def test_ball_screw_printed_values():
    # physics.md 8: p = 5, d_m = 20, mu = 0.003 -> lambda 4.550 deg, eta 0.9634, eta' 0.9621
    assert np.degrees(screw.lead_angle(5.0, 20.0)) == pytest.approx(4.550, abs=5e-4)
    assert screw_efficiency("ball", 5.0, 20.0, 0.003) == pytest.approx(0.9634, abs=5e-5)
    assert screw_efficiency("ball", 5.0, 20.0, 0.003, "back") == pytest.approx(0.9621, abs=5e-5)


def test_trapezoidal_textbook_example():
    # Bhandari, Design of Machine Elements, Example 6.6 (FOSSEE Scilab companion 764,
    # EX6.6): Tr 52 x 8 single start, d_m = 52 - 8/2 = 48 mm, mu = 0.15, 15 deg flanks,
    # collar 100/60 mm with mu_c = 0.12 (uniform wear), W = 2 kN -> efficiency 12.937099 %.
    W, lead = 2000.0, 8.0
    T_collar = 0.12 * W * (100.0 + 60.0) / 4.0
    eta = screw_efficiency("trapezoidal", lead, 48.0, 0.15, normal_section=False)
    T_thread = W * lead / (2 * np.pi * eta)
    overall = W * lead / (2 * np.pi * (T_thread + T_collar))
    assert 100 * overall == pytest.approx(12.937099, abs=2e-6)
    # thread alone: tan(lam)(1 - mu' tan lam)/(tan lam + mu'), mu' = 0.15 / cos 15 deg
    t, mu_ = lead / (np.pi * 48.0), 0.15 / np.cos(np.radians(15.0))
    assert eta == pytest.approx(t * (1 - mu_ * t) / (t + mu_), rel=1e-12)
    # normal-section flank angle: mu' changes by cos(lambda), the efficiency by 7e-5
    exact = screw_efficiency("trapezoidal", lead, 48.0, 0.15)
    assert exact == pytest.approx(eta, abs=1e-4) and exact != eta
    # a Tr screw this steep still self-locks (lambda = 3.04 deg < phi' = 8.83 deg)
    assert not is_back_drivable("trapezoidal", lead, 48.0, 0.15)
    assert np.degrees(self_locking_margin("trapezoidal", lead, 48.0, 0.15)) == pytest.approx(
        np.degrees(
            np.arctan(0.15 / np.cos(np.arctan(np.tan(np.radians(15)) * np.cos(np.arctan(t)))))
        )
        - np.degrees(np.arctan(t)),
        rel=1e-12,
    )


def test_square_thread_is_the_ball_formula():
    # alpha = 0: sliding friction angle = atan(mu), the same formula as the ball screw
    for direction in ("forward", "back"):
        sq = screw_efficiency("sliding", 10.0, 30.0, 0.05, direction, flank_angle=0.0)
        ball = screw_efficiency("ball", 10.0, 30.0, 0.05, direction)
        assert sq == pytest.approx(ball, rel=1e-14)
    assert sliding_friction_angle(0.1, np.radians(15.0)) == pytest.approx(
        np.arctan(0.1 / np.cos(np.radians(15.0)))
    )
    # Acme flanks (14.5 deg) lose slightly less than Tr (15 deg)
    assert screw_efficiency("acme", 5.0, 20.0, 0.1) > screw_efficiency(
        "trapezoidal", 5.0, 20.0, 0.1
    )


@pytest.mark.parametrize("kind", ["ball", "sliding", "roller"])
def test_frictionless_efficiency_is_one(kind):
    for direction in ("forward", "back"):
        eta = screw_efficiency(kind, 5.0, 20.0, 0.0, direction, f_k=0.0, f_r=0.0)
        assert eta == pytest.approx(1.0, abs=1e-12)
    # and tends to 1 as the friction vanishes
    small = screw_efficiency(kind, 5.0, 20.0, 1e-7, f_k=1e-7, f_r=1e-7)
    assert 1 - 1e-5 < small < 1


def test_roller_back_driving_reduces_to_the_ball_form():
    # beta = 90 deg, f_k = 0: only the rolling-friction angle rho acts, as mu does in a
    # ball screw: eta = tan a / tan(a + rho), eta' = tan(a - rho) / tan a
    a, r_RP, f_r = np.radians(8.0), 10.0, 0.05
    rho = np.arctan(f_r / r_RP)
    assert rs.efficiency(a, np.pi / 2, 20.0, r_RP, 0.0, f_r) == pytest.approx(
        np.tan(a) / np.tan(a + rho), rel=1e-12
    )
    assert rs.efficiency_backdrive(a, np.pi / 2, 20.0, r_RP, 0.0, f_r) == pytest.approx(
        np.tan(a - rho) / np.tan(a), rel=1e-12
    )
    # seed 003's numbers at 10/45 deg: eta = 0.974796. Eq. 14 models sliding friction as a
    # force f_k N along the tangent, not as a friction angle: that term alone gives
    # eta = 1 - x forward and 1/(1 + x) back, so the two differ at second order in the
    # loss and the back-driving value lies 2.2e-4 *above* eta here.
    eta = rs.efficiency(np.radians(10.0), np.radians(45.0), 40.0, 10.0, 0.055, 0.01)
    back = rs.efficiency_backdrive(np.radians(10.0), np.radians(45.0), 40.0, 10.0, 0.055, 0.01)
    assert eta == pytest.approx(0.974796, abs=1e-6)
    assert back == pytest.approx(0.975016, abs=1e-6)
    assert 0 < back - eta < 1.1 * (1 - eta) ** 2


@settings(max_examples=200, deadline=None)
@given(
    kind=st.sampled_from(["ball", "sliding"]),
    p=st.floats(0.5, 200.0),
    d_m=st.floats(6.0, 80.0),
    mu=st.floats(0.001, 0.3),
)
def test_back_driving_below_forward_iff_lead_angle_below_45_deg(kind, p, d_m, mu):
    # eta / eta' = tan^2 lam / (tan(lam + phi) tan(lam - phi)) >= 1  <=>  tan^4 lam <= 1
    lam = screw.lead_angle(p, d_m)
    fwd = screw_efficiency(kind, p, d_m, mu, "forward")
    back = screw_efficiency(kind, p, d_m, mu, "back")
    assert fwd <= 1.0
    if lam < np.radians(44.9):
        assert back < fwd
    elif lam > np.radians(45.1) and back > 0:
        assert back > fwd


@settings(max_examples=150, deadline=None)
@given(
    a=st.floats(2.0, 40.0),
    beta=st.floats(20.0, 90.0),
    f_k=st.floats(0.0, 0.15),
    f_r=st.floats(0.0, 0.05),
)
def test_roller_back_driving_within_second_order_of_forward(a, beta, f_k, f_r):
    args = (np.radians(a), np.radians(beta), 20.0, 10.0, f_k, f_r)
    fwd, back = rs.efficiency(*args), rs.efficiency_backdrive(*args)
    assert back <= 1.0 + 1e-12 and fwd <= 1.0 + 1e-12
    assert abs(back - fwd) <= 1.5 * (1 - min(fwd, back)) ** 2 + 1e-12


@settings(max_examples=150, deadline=None)
@given(
    kind=st.sampled_from(["ball", "sliding"]),
    p=st.floats(0.5, 40.0),
    d_m=st.floats(6.0, 80.0),
    mu=st.floats(0.0, 0.3),
)
def test_self_locking_iff_lead_angle_below_friction_angle(kind, p, d_m, mu):
    margin = self_locking_margin(kind, p, d_m, mu)
    back = screw_efficiency(kind, p, d_m, mu, "back")
    if abs(margin) > 1e-9:
        assert (back > 0) == (margin < 0) == bool(is_back_drivable(kind, p, d_m, mu))


def test_casadi_matches_numpy_and_derivative_matches_finite_difference():
    p, d_m, mu = ca.SX.sym("p"), ca.SX.sym("d_m"), ca.SX.sym("mu")
    for kind in ("ball", "trapezoidal", "roller"):
        for direction in ("forward", "back"):
            e = screw_efficiency(kind, p, d_m, mu, direction)
            f = ca.Function("e", [p, d_m, mu], [e, ca.gradient(e, p)])
            x = (6.0, 24.0, 0.01 if kind == "ball" else 0.1)
            val, dval = (float(v) for v in f(*x))
            assert val == pytest.approx(float(screw_efficiency(kind, *x, direction)), rel=1e-13)
            h = 1e-6
            fd = (
                screw_efficiency(kind, x[0] + h, *x[1:], direction)
                - screw_efficiency(kind, x[0] - h, *x[1:], direction)
            ) / (2 * h)
            assert dval == pytest.approx(fd, rel=1e-6)
            assert dval > 0  # a steeper lead loses less to friction (below the optimum)
    with pytest.raises(InputError, match=r"^p"):
        is_back_drivable("ball", p, 20.0)


def test_bad_inputs_name_the_field():
    with pytest.raises(InputError, match=r"^kind"):
        screw_efficiency("worm", 5.0, 20.0)
    with pytest.raises(InputError, match=r"^direction"):
        screw_efficiency("ball", 5.0, 20.0, direction="up")
    with pytest.raises(InputError, match=r"^mu"):
        screw_efficiency("ball", 5.0, 20.0, -0.1)
    with pytest.raises(InputError, match=r"^d_m"):
        screw_efficiency("ball", 5.0, 0.0)


def test_ball_and_sliding_defaults_by_hand():
    from optdesign.models.screw_efficiency import (
        equivalent_friction_angle,
        is_back_drivable,
        screw_efficiency,
        self_locking_margin,
    )

    # ball screw, mu = 0.003 by default: lam = atan(5 / (20 pi)) = 0.0794101 rad,
    # eta = tan(lam) / tan(lam + atan 0.003) = 0.963440
    lam = math.atan(5.0 / (20.0 * math.pi))
    eta = math.tan(lam) / math.tan(lam + math.atan(0.003))
    assert eta == pytest.approx(0.963440, abs=1e-6)
    assert float(screw_efficiency("ball", 5.0, 20.0)) == pytest.approx(eta, rel=1e-12)
    # trapezoidal = sliding with Tr's 15 deg flank, mu = 0.1 by default; acme 14.5 deg
    for kind, flank in (("trapezoidal", 15.0), ("acme", 14.5), ("sliding", 15.0)):
        alpha_n = math.atan(math.tan(math.radians(flank)) * math.cos(lam))
        phi = math.atan(0.1 / math.cos(alpha_n))
        assert float(equivalent_friction_angle(kind, 5.0, 20.0)) == pytest.approx(phi), kind
        # without the normal section the axial flank angle is used
        phi_axial = math.atan(0.1 / math.cos(math.radians(flank)))
        assert float(
            equivalent_friction_angle(kind, 5.0, 20.0, normal_section=False)
        ) == pytest.approx(phi_axial), kind
        assert float(self_locking_margin(kind, 5.0, 20.0, normal_section=False)) == pytest.approx(
            phi_axial - lam
        ), kind
    # a Tr 20x4 (p = 4, d_m = 18) self-locks at mu = 0.1; a 5/20 ball screw does not
    assert not is_back_drivable("trapezoidal", 4.0, 18.0)
    assert is_back_drivable("ball", 5.0, 20.0)
    # exactly at the locking limit (eta' = 0) the screw is not back-drivable: mu = tan(lam)
    lam_b = math.atan(5.0 / (20.0 * math.pi))
    assert not is_back_drivable("ball", 5.0, 20.0, mu=math.tan(lam_b) * (1 + 1e-12))
    # keyword arguments reach the friction angle: a 45 deg flank raises it
    assert not is_back_drivable("sliding", 5.0, 20.0, 0.07, flank_angle=math.radians(45))
    assert is_back_drivable("sliding", 5.0, 20.0, 0.07)


def test_screw_efficiency_errors_name_the_field():
    import casadi as ca

    from optdesign.errors import InputError
    from optdesign.models.screw_efficiency import (
        equivalent_friction_angle,
        is_back_drivable,
        screw_efficiency,
    )

    with pytest.raises(InputError, match=r"^kind: 'nut' not in \("):
        screw_efficiency("nut", 5.0, 20.0)
    with pytest.raises(InputError, match=r"^direction: 'up' not in \("):
        screw_efficiency("ball", 5.0, 20.0, direction="up")
    with pytest.raises(InputError, match=r"^p: must be positive"):
        screw_efficiency("ball", 0.0, 20.0)
    with pytest.raises(InputError, match=r"^d_m: must be positive"):
        screw_efficiency("ball", 5.0, -1.0)
    with pytest.raises(InputError, match=r"^mu: must be >= 0"):
        equivalent_friction_angle("ball", 5.0, 20.0, -0.01)
    with pytest.raises(InputError, match=r"^mu: must be >= 0"):
        equivalent_friction_angle("sliding", 5.0, 20.0, -0.01)
    with pytest.raises(
        InputError, match=r"^kind: a roller screw has no single friction angle; use screw_eff"
    ):
        equivalent_friction_angle("roller", 5.0, 20.0)
    for args in (
        (ca.SX.sym("p"), 20.0, 0.1),
        (5.0, ca.SX.sym("d"), 0.1),
        (5.0, 20.0, ca.SX.sym("mu")),
    ):
        with pytest.raises(InputError, match=r"^p: is_back_drivable needs numbers"):
            is_back_drivable("sliding", *args)


def test_back_drivable_exactly_at_the_locking_limit_is_not():
    from optdesign.models.screw_efficiency import is_back_drivable

    # mu = tan(lambda) exactly (the same expression): lambda - phi = 0, eta' = 0: locked
    mu = 5.0 / (math.pi * 20.0)
    assert not is_back_drivable("ball", 5.0, 20.0, mu)
