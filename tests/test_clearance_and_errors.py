"""Clearance chains against brute-force re-assembly, and errors that name the field."""

import numpy as np
import pytest
from scipy.optimize import brentq

from optdesign.errors import AssemblyError, InputError
from optdesign.mechanisms import CrankSlider, Joint, PinJoint, ShiftingFork
from optdesign.models import crank_slider as model


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


def test_fork_slot_backlash():
    fork = ShiftingFork(R=90, p=5, i_a=2)
    phi = np.radians(np.linspace(-30, 30, 61))
    pin = PinJoint(12, 18, "H7/g6")
    b = fork.backlash(phi, [j for j in fork.joints(phi, 500e3, pin) if j.pin is not None])
    F = 500e3 * np.cos(phi) / 90
    np.testing.assert_allclose(
        b.worst_case, np.degrees(pin.clearance(F) * np.cos(phi) / 90), rtol=1e-12
    )
    # worst at 0 deg where the pin is nearest and the load largest
    assert np.argmax(b.worst_case) == 30


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


@pytest.mark.parametrize("nu", [0.0, 0.5, -0.1, 0.7])
def test_poisson_ratio_out_of_range(nu):
    with pytest.raises(InputError, match=r"pin\.nu"):
        PinJoint(10, 15, nu=nu)


def test_fork_zero_lead_rejected():
    with pytest.raises(InputError, match=r"^p:"):
        ShiftingFork(R=90, p=0.0, i_a=2)
