"""Hertz point contact: closed forms (physics.md 9), Timoshenko's m/n, Hamrock-Brewe."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.models.hertz_point import (
    curvature_difference_closed_form,
    curvature_difference_from_k2,
    curvature_sum_difference,
    curvature_sum_difference_aligned,
    eccentricity_from_curvature_difference,
    effective_modulus,
    hamrock_brewe,
    hertz_from_curvatures,
    hertz_point_contact,
    hertz_point_contact_aligned,
    timoshenko_m_n,
)

E_STEEL = effective_modulus(2.06e5, 0.3)


@pytest.mark.parametrize("R, P", [(10.0, 1000.0), (3.0, 50.0), (25.0, 2e4)])
def test_sphere_on_flat_closed_form(R, P):
    c = hertz_point_contact(1 / R, 1 / R, 0.0, 0.0, 0.3, P, E_STEEL)
    a = (3 * P * R / (4 * E_STEEL)) ** (1 / 3)
    assert c.eccentricity == 0.0
    assert c.a == pytest.approx(a, rel=1e-12)
    assert c.b == pytest.approx(a, rel=1e-12)
    assert c.p_max == pytest.approx(3 * P / (2 * math.pi * a**2), rel=1e-12)
    assert c.approach == pytest.approx(a**2 / R, rel=1e-12)


def test_effective_modulus_steel():
    # 1/E* = 2 (1 - 0.09)/2.06e5
    assert effective_modulus(2.06e5, 0.3) == pytest.approx(2.06e5 / (2 * 0.91), rel=1e-15)


@pytest.mark.parametrize("R, P", [(10.0, 1000.0), (4.0, 300.0)])
def test_crossed_equal_cylinders_equal_sphere_on_flat(R, P):
    x = hertz_point_contact(1 / R, 0.0, 1 / R, 0.0, math.pi / 2, P, E_STEEL)
    s = hertz_point_contact(1 / R, 1 / R, 0.0, 0.0, 0.0, P, E_STEEL)
    for name in ("a", "b", "approach", "p_max"):
        assert getattr(x, name) == pytest.approx(getattr(s, name), rel=1e-6)
    assert x.eccentricity < 1e-7


@pytest.mark.parametrize(
    "theta, m_ref, n_ref", [(30, 2.731, 0.493), (60, 1.486, 0.717), (90, 1.0, 1.0)]
)
def test_timoshenko_m_n(theta, m_ref, n_ref):
    m_, n_ = timoshenko_m_n(math.radians(theta))
    assert round(m_, 3) == m_ref
    assert round(n_, 3) == n_ref


@pytest.mark.parametrize("e", [0.05, 0.3, 0.7, 0.95, 0.999])
def test_johnson_gap_coefficients_recovered(e):
    """Johnson eq. 3.64: A, B from the solved ellipse must equal the input gap."""
    A, B = 0.01, 0.01 / (1 - e**2) ** 0.8  # any A < B
    c = hertz_from_curvatures(2 * (A + B), (B - A) / (A + B), 700.0, E_STEEL)
    p0, a, b = c.p_max, c.a, c.b
    ee = c.eccentricity**2
    A_back = p0 * b * (c.K - c.E) / (E_STEEL * ee * a**2)
    B_back = p0 * b * ((a / b) ** 2 * c.E - c.K) / (E_STEEL * ee * a**2)
    assert A_back == pytest.approx(A, rel=1e-9)
    assert B_back == pytest.approx(B, rel=1e-9)
    assert c.approach == pytest.approx(p0 * b * c.K / E_STEEL, rel=1e-15)


@pytest.mark.parametrize("e", [0.01, 0.1, 0.22, 0.25, 0.6, 0.99, 0.99999])
def test_eccentricity_round_trip_and_series(e):
    F = curvature_difference_from_k2(1 - e * e)
    assert eccentricity_from_curvature_difference(F) == pytest.approx(e, rel=1e-8)
    if e > 0.05:
        assert F == pytest.approx(curvature_difference_closed_form(e), rel=1e-10)


def test_small_eccentricity_limit():
    # F = 3 e^2 / 8 + O(e^4) near the circle
    e = 1e-3
    assert curvature_difference_from_k2(1 - e * e) == pytest.approx(3 * e * e / 8, rel=1e-5)


def test_hamrock_brewe_within_known_error():
    """kappa fit within 3.5 % for Ry/Rx in [1, 30] (exactly 3.39 % at 1); E, K within 3 %."""
    for ratio in np.geomspace(1.0, 100.0, 25):
        A, B = 0.5 / ratio, 0.5
        exact = hertz_from_curvatures(2 * (A + B), (B - A) / (A + B), 1.0, 1.0)
        kappa, E, K = hamrock_brewe(1.0, ratio)
        if ratio <= 30.0:
            assert abs(kappa / exact.kappa - 1) < 0.035
        assert abs(E / exact.E - 1) < 0.03
        assert abs(K / exact.K - 1) < 0.03
    kappa1, _, _ = hamrock_brewe(2.0, 2.0)
    assert kappa1 == pytest.approx(1.0339)


def test_bad_inputs_name_the_field():
    with pytest.raises(InputError) as ei:
        hertz_from_curvatures(0.1, 0.2, -5.0, E_STEEL)
    assert ei.value.field == "Q"
    with pytest.raises(InputError) as ei:
        hertz_from_curvatures(-0.1, 0.2, 5.0, E_STEEL)
    assert ei.value.field == "sum_rho"
    with pytest.raises(InputError):
        eccentricity_from_curvature_difference(1.0)
    with pytest.raises(InputError) as ei:
        effective_modulus(2e5, 0.6)
    assert ei.value.field == "nu1"


curv = st.floats(-0.05, 0.3)
ang = st.floats(0.0, math.pi)


@settings(max_examples=60, deadline=None)
@given(curv, curv, curv, curv, ang)
def test_properties(r11, r12, r21, r22, omega):
    if r11 + r12 + r21 + r22 < 1e-3:
        return
    s, F = curvature_sum_difference(r11, r12, r21, r22, omega)
    if not F < 0.999:
        return
    c = hertz_point_contact(r11, r12, r21, r22, omega, 500.0, E_STEEL)
    assert 0.0 <= c.eccentricity < 1.0
    assert c.a >= c.b > 0
    # body order does not matter
    s2, F2 = curvature_sum_difference(r21, r22, r11, r12, omega)
    assert s2 == pytest.approx(s) and F2 == pytest.approx(F, abs=1e-12)
    # relabelling body 2's planes and turning omega by 90 deg changes nothing
    _, F3 = curvature_sum_difference(r11, r12, r22, r21, omega + math.pi / 2)
    assert F3 == pytest.approx(F, abs=1e-12)
    # omega = 0 is the simple formula
    _, F0 = curvature_sum_difference(r11, r12, r21, r22, 0.0)
    _, Fa = curvature_sum_difference_aligned(r11, r12, r21, r22)
    assert F0 == pytest.approx(Fa, abs=1e-12)
    if Fa < 0.999:
        ca_ = hertz_point_contact_aligned(r11, r12, r21, r22, 500.0, E_STEEL)
        c0 = hertz_point_contact(r11, r12, r21, r22, 0.0, 500.0, E_STEEL)
        assert ca_.a == pytest.approx(c0.a, rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.floats(1e-6, 0.9999))
def test_curvature_difference_increases_with_eccentricity(F):
    e = eccentricity_from_curvature_difference(F)
    e2 = eccentricity_from_curvature_difference(min(F * 1.01, 0.99995))
    assert 0 < e <= e2 < 1
