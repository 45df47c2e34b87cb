"""Kinematics checked against independent computations: CasADi derivatives vs finite
differences of the position equations, loop closure, virtual work, symmetry."""

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from optdesign.errors import AssemblyError, InputError
from optdesign.mechanisms import CrankSlider, Joint, PinJoint, ShiftingFork
from optdesign.models import crank_slider as cs_model
from optdesign.models import crank_slider as model


@st.composite
def crank_designs(draw):
    """Random crank-slider designs that assemble over +-30 deg (margin >= 5 % of l^2)."""
    R = draw(st.floats(30, 120))
    l = draw(st.floats(40, 200))
    n = draw(st.floats(0, 150))
    phi0 = draw(st.floats(-0.6, 0.6))
    p = draw(st.floats(2, 10))
    mech = CrankSlider(R=R, l=l, n=n, p=p, i_a=2.0, phi0=phi0)
    phi = np.radians(np.linspace(-30, 30, 61))
    margin = mech.assembly_margin(phi)
    from hypothesis import assume

    assume(np.min(margin) > 0.05 * l**2)
    assume(np.min(np.abs(mech.nut_velocity(phi))) > 1.0)
    return mech


def test_casadi_derivative_matches_central_difference():
    R, l, n, phi0 = 90.0, 80.0, 50.0, 0.1
    phi = ca.SX.sym("phi")
    m_expr = cs_model.nut_position(R, l, n, phi, phi0)
    dm = ca.Function("dm", [phi], [ca.jacobian(m_expr, phi)])
    h = 1e-6
    for p in np.radians(np.linspace(-30, 30, 13)):
        fd = (
            cs_model.nut_position(R, l, n, p + h, phi0)
            - cs_model.nut_position(R, l, n, p - h, phi0)
        ) / (2 * h)
        assert float(dm(p)) == pytest.approx(fd, rel=1e-7)
        # the hand-written derivative used by the ratio agrees with both
        assert cs_model.nut_velocity(R, l, n, p, phi0) == pytest.approx(float(dm(p)), rel=1e-12)


def test_symbolic_and_numeric_paths_agree():
    x = ca.SX.sym("x", 4)  # R, l, n, phi0
    phi = np.radians(np.linspace(-30, 30, 7))
    mech = CrankSlider(R=x[0], l=x[1], n=x[2], p=5.0, i_a=2.0, phi0=x[3])
    f = ca.Function("i", [x], [mech.ratio(phi)])
    val = np.array(f([90, 80, 50, 0.2])).ravel()
    ref = CrankSlider(R=90, l=80, n=50, p=5.0, i_a=2.0, phi0=0.2).ratio(phi)
    np.testing.assert_allclose(val, ref, rtol=1e-13)


@settings(max_examples=60, deadline=None)
@given(crank_designs())
def test_loop_closure_and_virtual_work(mech):
    phi = np.radians(np.linspace(-30, 30, 61))
    (bx, by), (cx, cy) = mech.pin_positions(phi)
    np.testing.assert_allclose(np.hypot(cx - bx, cy - by), mech.l, rtol=1e-12)
    # virtual work: F_a dm = M_h dphi with dm from a central difference of positions
    M_h = 500e3
    h = 1e-6
    dm = mech.nut_position(phi + h) - mech.nut_position(phi - h)
    np.testing.assert_allclose(mech.nut_force(phi, M_h) * dm, M_h * 2 * h, rtol=1e-5)
    # the rod force projected on the screw axis carries the nut force
    s = mech.rod_run(phi)
    np.testing.assert_allclose(
        mech.rod_force(phi, M_h) * s / mech.l, mech.nut_force(phi, M_h), rtol=1e-10
    )


@settings(max_examples=40, deadline=None)
@given(crank_designs())
def test_transmission_angle_from_pin_positions(mech):
    phi = np.radians(np.linspace(-30, 30, 31))
    (bx, by), (cx, cy) = mech.pin_positions(phi)
    bo = np.stack([-bx, -by])
    bc = np.stack([cx - bx, cy - by])
    cosang = np.sum(bo * bc, axis=0) / (np.linalg.norm(bo, axis=0) * np.linalg.norm(bc, axis=0))
    np.testing.assert_allclose(mech.transmission_angle(phi), np.arccos(cosang), atol=1e-9)
    # signed inclination of the rod to the screw axis: atan2(u, s) with u = yB - yC, s = xB - xC
    np.testing.assert_allclose(mech.rod_inclination(phi), np.arctan2(by - cy, bx - cx), atol=1e-12)


def test_fork_symmetric_crank_slider_not():
    phi = np.radians(np.linspace(-30, 30, 61))
    fork = ShiftingFork(R=90, p=5, i_a=2)
    np.testing.assert_allclose(fork.ratio(phi), fork.ratio(-phi), rtol=1e-14)
    mech = CrankSlider(R=90, l=80, n=50, p=5, i_a=2)
    assert np.max(np.abs(mech.ratio(phi) - mech.ratio(-phi))) > 10


def test_fork_derivative_matches_finite_difference():
    fork = ShiftingFork(R=75.0, p=4.0, i_a=2.0)
    phi = np.radians(np.linspace(-30, 30, 13))
    h = 1e-6
    fd = (fork.nut_position(phi + h) - fork.nut_position(phi - h)) / (2 * h)
    np.testing.assert_allclose(fork.nut_velocity(phi), fd, rtol=1e-8)
    # virtual work for the pin: F_n * (pin lever arm) = M_h
    M_h = 500e3
    np.testing.assert_allclose(fork.pin_normal_force(phi, M_h) * 75.0 / np.cos(phi), M_h)


def test_finite_step_ratio_converges_to_derivative():
    mech = CrankSlider(R=90, l=80, n=50, p=5, i_a=2)
    phi = np.radians(np.linspace(-30, 30, 61))
    errs = [np.max(np.abs(mech.ratio_finite_step(phi, h) - mech.ratio(phi))) for h in (1e-2, 1e-3)]
    assert errs[1] < errs[0] / 8  # first-order forward difference: error ~ step


def test_numpy_population_broadcasts():
    R = np.array([[80.0], [90.0], [100.0]])
    mech = CrankSlider(R=R, l=80.0, n=50.0, p=5.0, i_a=2.0)
    phi = np.radians(np.linspace(-30, 30, 61))
    i = mech.ratio(phi)
    assert i.shape == (3, 61)
    np.testing.assert_allclose(i[1], CrankSlider(R=90, l=80, n=50, p=5, i_a=2).ratio(phi))
    assert mech.ripple(phi).shape == (3,)


def _output_angle(R, l, n, phi0, m_target, guess):
    """Solve the loop closure for phi at a fixed nut position (independent of the models'
    derivative formulas)."""

    def f(phi):
        a = phi0 + phi
        return (R * np.sin(a) - m_target) ** 2 + (R * np.cos(a) - n) ** 2 - l**2

    return brentq(f, guess - 0.05, guess + 0.05, xtol=1e-15)


@pytest.mark.parametrize("phi_deg", [-30, -12, 0, 17, 30])
def test_rod_length_sensitivity_by_reassembly(phi_deg):
    R, l, n, phi0 = 90.0, 80.0, 50.0, 0.0
    phi = np.radians(phi_deg)
    mech = CrankSlider(R=R, l=l, n=n, p=5, i_a=2, phi0=phi0)
    m0 = mech.nut_position(phi)
    delta = 1e-4
    phi_plus = _output_angle(R, l + delta, n, phi0, m0, phi)
    phi_minus = _output_angle(R, l - delta, n, phi0, m0, phi)
    fd = (phi_plus - phi_minus) / (2 * delta)
    assert abs(fd) == pytest.approx(abs(mech.sensitivity_rod_length(phi)), rel=1e-6)
    # lateral clearance of the nut slide: move the nut line by dn
    fd_n = (
        _output_angle(R, l, n + delta, phi0, m0, phi)
        - _output_angle(R, l, n - delta, phi0, m0, phi)
    ) / (2 * delta)
    assert abs(fd_n) == pytest.approx(mech.sensitivity_lateral(phi), rel=1e-6, abs=1e-12)


def test_backlash_chain_crank_slider():
    mech = CrankSlider(R=90, l=80, n=50, p=5, i_a=2)
    phi = np.radians(np.linspace(-30, 30, 61))
    pin = PinJoint(10, 15, "H7/g6")
    joints = [j for j in mech.joints(phi, 500e3, pin) if j.pin is not None]
    b = mech.backlash(phi, joints)
    # both rod pins carry the same force and the same clearance: equal shares
    np.testing.assert_allclose(b.per_joint["D rod pin (arm)"], b.per_joint["E rod pin (nut)"])
    np.testing.assert_allclose(b.worst_case, 2 * b.per_joint["D rod pin (arm)"])
    np.testing.assert_allclose(b.rss, np.sqrt(2) * b.per_joint["D rod pin (arm)"])
    # by hand at phi = 0: clearance (fit + 2 Delta) / (d|BC|/dphi), in degrees
    F = mech.rod_force(0.0, 500e3)
    c = pin.clearance(F)
    expected = np.degrees(c / model.rod_length_rate(90, 80, 50, 0.0))
    assert b.per_joint["D rod pin (arm)"][30] == pytest.approx(expected, rel=1e-12)
    # an angular clearance at O adds directly
    b2 = mech.backlash(phi, [Joint("O", "O", angular=True, clearance=np.radians(0.01))])
    np.testing.assert_allclose(b2.worst_case, 0.01)


def test_assembly_error_names_angle_and_margin():
    mech = CrankSlider(R=90, l=45, n=10, p=5, i_a=2)  # rod too short at -30 deg (u = 67.9 > l)
    with pytest.raises(AssemblyError, match=r"deflection -30\.000 deg.*margin") as exc:
        mech.check_assembly(np.radians(np.linspace(-30, 30, 61)))
    assert exc.value.margin < 0
    # the message ends with the design it was checked at (the mechanism's description)
    assert str(exc.value).endswith(f"; {mech.describe()}") and "R=90" in mech.describe()
    CrankSlider(R=90, l=80, n=50, p=5, i_a=2).check_assembly(np.radians(np.linspace(-30, 30, 61)))


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"R": -90}, "R"),
        ({"l": 0}, "l"),
        ({"p": 0}, "p"),
        ({"n": float("nan")}, "n"),
        ({"i_a": -1}, "i_a"),
    ],
)
def test_non_physical_inputs_name_the_field(kwargs, field):
    args = {"R": 90, "l": 80, "n": 50, "p": 5, "i_a": 2} | kwargs
    with pytest.raises(InputError) as exc:
        CrankSlider(**args)
    assert exc.value.field == field
