"""Screw (seed 001), ISO 286 fits and Hertz flattening: printed checks and invariants."""

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.models import screw
from optdesign.models.fit_formulas import Fit, fit_clearance, tolerance_unit
from optdesign.models.hertz_line import pin_flattening, pin_flattening_first_order


def test_screw_efficiency_check_values():
    # physics.md 8: p = 5, d_m = 20, mu = 0.003 -> lambda = 4.550 deg, eta = 0.9634, eta' = 0.9621
    lam = screw.lead_angle(5.0, 20.0)
    phi_f = screw.friction_angle(0.003)
    assert np.degrees(lam) == pytest.approx(4.550, abs=5e-4)
    assert screw.efficiency_forward(lam, phi_f) == pytest.approx(0.9634, abs=5e-5)
    assert screw.efficiency_backdrive(lam, phi_f) == pytest.approx(0.9621, abs=5e-5)


@settings(max_examples=80, deadline=None)
@given(p=st.floats(1, 40), d_m=st.floats(8, 80), mu=st.floats(0.001, 0.05), K=st.floats(1e2, 1e6))
def test_stiffness_conversion_identities(p, d_m, mu, K):
    lam, phi_f = screw.lead_angle(p, d_m), screw.friction_angle(mu)
    eta = screw.efficiency_forward(lam, phi_f)
    Kt = screw.torsional_stiffness(K, d_m, p, lam, phi_f)
    # physics.md 4 note: K_theta = K (h/2pi)^2 / eta
    assert Kt == pytest.approx(K * (p / (2 * np.pi)) ** 2 / eta, rel=1e-10)
    assert screw.axial_stiffness(Kt, d_m, p, lam, phi_f) == pytest.approx(K, rel=1e-12)
    # torque for a load: M = P p / (2 pi eta), energy balance of the screw
    assert screw.drive_torque(1000.0, d_m, lam, phi_f) == pytest.approx(
        1000.0 * p / (2 * np.pi * eta), rel=1e-10
    )
    assert 0 < eta < 1


def test_series_stiffness():
    assert screw.series_stiffness(100.0, 100.0) == pytest.approx(50.0)
    assert screw.series_stiffness(300.0, 600.0, 200.0) == pytest.approx(100.0)
    with pytest.raises(ValueError):
        screw.series_stiffness()


def test_fit_formula_check_values():
    # physics.md 2.4: H7/g6 largest clearance 30.9 um at 10 mm, 39.2 um at 20 mm
    assert 1e3 * fit_clearance(10.0, "H7/g6", "max") == pytest.approx(30.9, abs=0.05)
    assert 1e3 * fit_clearance(20.0, "H7/g6", "max") == pytest.approx(39.2, abs=0.05)
    # and the ISO 286 tables to their step rounding (29 um for 6-10 mm, 41 um for 18-30 mm)
    assert 1e3 * fit_clearance(np.sqrt(6 * 10), "H7/g6", "max") == pytest.approx(29, abs=1.5)
    assert 1e3 * fit_clearance(np.sqrt(18 * 30), "H7/g6", "max") == pytest.approx(41, abs=1.5)
    # H7/h6: smallest clearance 0, largest IT7 + IT6 = 26 i
    assert fit_clearance(12.0, "H7/h6", "min") == 0.0
    assert 1e3 * fit_clearance(12.0, "H7/h6", "max") == pytest.approx(26 * tolerance_unit(12.0))
    # H7/f7 at 25 mm: min = 5.5 D^0.41 = 20.6 um (table 18-30 mm: 20), max = min + 32 i = 63.5
    # (table: 62)
    assert 1e3 * fit_clearance(25.0, "H7/f7", "min") == pytest.approx(5.5 * 25**0.41, rel=1e-12)
    assert 1e3 * fit_clearance(25.0, "H7/f7", "min") == pytest.approx(20, abs=1.0)
    assert 1e3 * fit_clearance(25.0, "H7/f7", "max") == pytest.approx(62, abs=2.0)


def test_fit_is_differentiable_in_casadi():
    D = ca.SX.sym("D")
    c = Fit.parse("H7/g6").clearance(D, "max")
    dc = ca.Function("dc", [D], [ca.jacobian(c, D)])
    h = 1e-5
    fd = (fit_clearance(12 + h, "H7/g6") - fit_clearance(12 - h, "H7/g6")) / (2 * h)
    assert float(dc(12.0)) == pytest.approx(fd, rel=1e-6)
    assert float(dc(12.0)) > 0


@pytest.mark.parametrize("bad", ["H7", "h7/g6", "H7/z6", "H4/g6", "Q7/g6", "H7/s6"])
def test_fit_parse_errors_name_the_field(bad):
    with pytest.raises(InputError, match=r"^fit"):
        Fit.parse(bad)


@settings(max_examples=60, deadline=None)
@given(D=st.floats(3, 60), F=st.floats(10, 5e4), L=st.floats(3, 90))
def test_flattening_first_order_is_a_lower_bound(D, F, L):
    exact = pin_flattening(D, F, L, 2.1e5, 0.3)
    first = pin_flattening_first_order(D, F, L, 2.1e5, 0.3)
    # Delta = b^2/(D/2 + sqrt(D^2/4 - b^2)) >= b^2/D, equal to first order
    assert exact >= first * (1 - 1e-12)
    b2 = first * D
    if b2 < 1e-3 * D**2:
        assert exact == pytest.approx(first, rel=2e-3)


def test_series_stiffness_needs_a_member():
    from optdesign.models.screw import series_stiffness

    with pytest.raises(ValueError, match=r"^series_stiffness needs at least one stiffness$"):
        series_stiffness()
    assert series_stiffness(3.0, 6.0) == pytest.approx(2.0)  # 1/(1/3 + 1/6)
