"""optdesign/mechanisms/fork.py as a whole, against the plain geometry of a pin on a line
at distance R in a slot of the arm (not the model's formulas): the nut position and its
rate, the slot's assembly margin and refusal at a right angle, the pin's normal force by
statics, the clearance chain's sensitivities by small rotations, size, drawings and the
benchmark's declarations."""

import math

import numpy as np
import pytest
from independent_physics import (
    _fd,
    _fork_pin_x,
)

from optdesign.errors import AssemblyError, InputError
from optdesign.mechanisms import PinJoint, ShiftingFork
from optdesign.models import fork as fork_model
from optdesign.models.loads import (
    fork_pin_normal_force,
)

R, PHI0 = 60.0, 0.1
PHI = np.radians(np.linspace(-30.0, 30.0, 7))


def fork(**kw):
    return ShiftingFork(**{"R": R, "phi0": PHI0, "p": 5.0, **kw})


def _pin_x(phi):
    """Where the arm's line (angle a from the pin line's normal) meets the pin's line."""
    a = PHI0 + phi
    return R * math.sin(a) / math.cos(a)


def test_the_nut_position_and_rate_are_the_lines_intersection_and_its_derivative():
    f = fork()
    assert np.allclose(f.nut_position(PHI), [_pin_x(p) for p in PHI], rtol=1e-12)
    h = 1e-6
    fd = [(_pin_x(p + h) - _pin_x(p - h)) / (2 * h) for p in PHI]
    assert np.allclose(f.nut_velocity(PHI), fd, rtol=1e-7)
    assert np.allclose(f.ratio(PHI), 2 * np.pi * np.array(fd) / 5.0, rtol=1e-7)


def test_the_slot_assembles_short_of_a_right_angle_only():
    f = fork(phi0=0.0)
    margin = f.assembly_margin(np.radians([-60.0, 0.0, 89.0]))
    assert np.allclose(margin, np.cos(np.radians([-60.0, 0.0, 89.0])) * R**2)
    with pytest.raises(AssemblyError) as err:
        f.check_assembly(np.radians([0.0, 45.0, 91.0, 95.0]))
    assert err.value.angle_deg == pytest.approx(91.0)
    assert err.value.margin == pytest.approx(math.cos(math.radians(91.0)) * R**2)
    # with a neutral angle the arm's angle is phi0 + phi: right at phi = 90 deg - phi0
    tilted = fork(phi0=math.radians(20.0))
    angles = np.radians([-85.0, 60.0, 69.0, 71.0])
    assert np.allclose(tilted.assembly_margin(angles), np.cos(math.radians(20.0) + angles) * R**2)
    with pytest.raises(AssemblyError) as err:
        tilted.check_assembly(angles)
    assert err.value.angle_deg == pytest.approx(71.0)


def test_the_pins_normal_force_holds_the_hinge_moment():
    """Statics: the slot pushes the pin normal to the arm at distance R / cos(a) from O."""
    f = fork()
    M_h = 4.0e5
    for phi in PHI:
        a = PHI0 + phi
        lever = R / math.cos(a)
        assert float(f.pin_normal_force(phi, M_h)) == pytest.approx(M_h / lever, rel=1e-12)
    assert np.allclose(f.pin_force(PHI, M_h), f.pin_normal_force(PHI, M_h))


def test_the_chain_is_the_screw_bearings_nut_shaft_and_the_pin_in_its_slot():
    f = fork()
    pin = PinJoint(8.0, 10.0)
    chain = f.joints(PHI, 4.0e5, pin)
    assert [(j.name, j.key, j.angular) for j in chain] == [
        ("A screw bearings", "A", False),
        ("B screw/nut", "B", False),
        ("O output shaft", "O", True),
        ("C pin in slot", "", False),
    ]
    a = PHI0 + PHI
    # an axial clearance dx turns the arm by dx / (dx/dphi); a slot-normal one by
    # dn / (R / cos a), the pin's distance from O
    assert np.allclose(chain[0].sensitivity, np.cos(a) ** 2 / R, rtol=1e-12)
    assert np.allclose(chain[1].sensitivity, np.cos(a) ** 2 / R, rtol=1e-12)
    assert np.allclose(chain[3].sensitivity, np.cos(a) / R, rtol=1e-12)
    assert np.allclose(chain[3].force, 4.0e5 * np.cos(a) / R, rtol=1e-12)
    assert chain[3].pin is pin
    assert f.joints(PHI, 4.0e5)[3].pin is None


def test_a_small_slot_clearance_turns_the_arm_as_the_sensitivity_says():
    """Independent check: move the pin by dn normal to the arm, find the new arm angle."""
    f = fork()
    dn = 1e-6
    for phi in PHI:
        a = PHI0 + phi
        x = _pin_x(phi)
        # the pin moved normal to the arm's line: (cos a, -sin a) in the (x, y) frame
        px, py = x + dn * math.cos(a), R - dn * math.sin(a)
        turned = math.atan2(px, py) - a
        assert float(f.sensitivity_slot_normal(phi)) == pytest.approx(turned / dn, rel=1e-5)


def test_size_positions_and_sketch():
    f = fork()
    assert float(f.size()) == R
    arm_end, pin = f.pin_positions(PHI)
    assert np.allclose(arm_end[0], R * np.tan(PHI0 + PHI)) and np.allclose(arm_end[1], R)
    assert np.allclose(pin[0], f.nut_position(PHI)) and np.allclose(pin[1], R)
    sk = f.sketch(0.2)
    x = _pin_x(0.2)
    assert sk.links == [[(0.0, 0.0), (pytest.approx(x), R)]]
    assert sk.pivots == [(0.0, 0.0)] and sk.slider == (pytest.approx(x), R)
    assert sk.axis == ((pytest.approx(-0.3 * R), R), (pytest.approx(x + 0.3 * R), R))
    left = f.sketch(-0.5)
    xl = _pin_x(-0.5)
    assert left.axis == ((pytest.approx(xl - 0.3 * R), R), (pytest.approx(0.3 * R), R))


def test_the_declarations_and_the_benchmarks_template():
    table = ShiftingFork.variable_table()
    assert list(table) == ["R", "phi0", "p", "i_a"]
    assert table["R"].positive is True and table["R"].dimension == "length"
    assert table["phi0"].positive is False and table["phi0"].default == 0.0
    assert table["phi0"].dimension == "angle"
    assert ShiftingFork(R=1.0, p=1.0).phi0 == 0.0
    assert ShiftingFork.pin_shear_planes == 1
    assert ShiftingFork.bench_template() == (
        {"R": {"lower": "30 mm", "upper": "120 mm"}, "p": None},
        {},
    )
    assert ShiftingFork.bench_families == {
        "fork_backlash": ("backlash",),
        "fork_size": ("size",),
        "fork_torque": ("motor_torque",),
        "fork_front": ("backlash", "size"),
    }
    assert (ShiftingFork.name, ShiftingFork.title) == ("fork", "shifting fork")


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


def test_fork_zero_lead_rejected():
    with pytest.raises(InputError, match=r"^p:"):
        ShiftingFork(R=90, p=0.0, i_a=2)


@pytest.mark.parametrize("phi0", [0.25, -0.4])
@pytest.mark.parametrize("phi", [-0.3, 0.0, 0.35])
def test_fork_ratio_with_a_neutral_angle_from_finite_differences(phi0, phi):
    R, p, i_a = 70.0, 4.0, 2.0
    v = _fd(lambda f: _fork_pin_x(R, phi0 + f), phi)  # dx/dphi, mm/rad
    # motor angle per output angle: 2 pi i_a / p motor radians per mm of nut travel
    expected = 2 * math.pi * i_a * v / p
    mech = ShiftingFork(R=R, phi0=phi0, p=p, i_a=i_a)
    assert float(mech.ratio(phi)) == pytest.approx(expected, rel=1e-7)
    assert float(fork_model.ratio(R, p, i_a, phi, phi0)) == pytest.approx(expected, rel=1e-7)
    assert float(mech.nut_position(phi)) == pytest.approx(_fork_pin_x(R, phi0 + phi), rel=1e-12)
    # the output rotation per slot-normal clearance: the pin's lever arm is R / cos a
    assert float(mech.sensitivity_slot_normal(phi)) == pytest.approx(
        math.cos(phi0 + phi) / R, rel=1e-12
    )
    # axial sensitivity is the inverse of the finite-difference nut velocity
    assert float(mech.sensitivity_axial(phi)) == pytest.approx(1.0 / v, rel=1e-7)


def test_fork_neutral_angle_written_out():
    # R = 50 mm, phi0 = 20 deg, phi = 10 deg: a = 30 deg, cos^2 a = 3/4,
    # ds/dphi = 50 / 0.75 = 66.667 mm/rad; i = 2 pi * 2 * 66.667 / 5 = 167.552.
    mech = ShiftingFork(R=50.0, phi0=math.radians(20), p=5.0, i_a=2.0)
    assert float(mech.ratio(math.radians(10))) == pytest.approx(167.5516, rel=1e-6)
    # the pin's normal force M cos a / R: 500 N*m -> 5e5 * 0.866025 / 50 = 8660.25 N
    assert float(mech.pin_force(math.radians(10), 5e5)) == pytest.approx(8660.254, rel=1e-6)
    assert float(fork_pin_normal_force(5e5, 50.0, 0.1, 0.2)) == pytest.approx(
        5e5 * 0.9553365 / 50.0, rel=1e-6
    )


def test_motor_torque_by_virtual_work_through_the_fork():
    # Power balance: T_m * dtheta_m = M_h * dphi with dtheta_m = i * dphi, so T_m = M_h / i,
    # i from the finite-difference ratio of the geometry (no call into the load model).
    R, phi0, p, i_a, M_h = 80.0, 0.15, 5.0, 2.0, 5e5
    mech = ShiftingFork(R=R, phi0=phi0, p=p, i_a=i_a)
    for phi in (-0.4, 0.1, 0.4):
        i = 2 * math.pi * i_a * _fd(lambda f: _fork_pin_x(R, phi0 + f), phi) / p
        assert float(mech.motor_torque(phi, M_h)) == pytest.approx(M_h / i, rel=1e-7)
        # and with a screw efficiency the motor supplies 1/eta times more
        assert float(mech.motor_torque(phi, M_h, 0.8)) == pytest.approx(M_h / i / 0.8, rel=1e-7)


# --- the fork mechanism: its clearance chain, drawing and bench variables ------------------
def test_fork_joints_are_the_papers_chain_with_phi0():
    # seed 000 Fig. 9: A screw bearings, B screw/nut (axial, 1/(dx/dphi)), O the output
    # shaft (angular), C the pin in the slot (cos a / R, loaded by M cos a / R).
    from optdesign.mechanisms.fork import ShiftingFork

    R, phi0, phi, M = 60.0, 0.2, 0.3, 4e5
    mech = ShiftingFork(R=R, phi0=phi0, p=5.0, i_a=2.0)
    h = 1e-6
    v = (_fork_pin_x(R, phi0 + phi + h) - _fork_pin_x(R, phi0 + phi - h)) / (2 * h)
    joints = mech.joints(phi, M)
    assert [(j.name, j.key, j.angular) for j in joints] == [
        ("A screw bearings", "A", False),
        ("B screw/nut", "B", False),
        ("O output shaft", "O", True),
        ("C pin in slot", "", False),
    ]
    for j in joints[:2]:
        assert float(j.sensitivity) == pytest.approx(1 / v, rel=1e-7)
    a = phi0 + phi  # 0.5 rad: cos a = 0.8775826
    assert float(joints[3].sensitivity) == pytest.approx(0.8775826 / R, rel=1e-6)
    assert float(joints[3].force) == pytest.approx(M * 0.8775826 / R, rel=1e-6)
    assert math.cos(a) == pytest.approx(0.8775826, rel=1e-7)


def test_fork_drawing_and_margin():
    from optdesign.mechanisms.fork import ShiftingFork

    R, phi0, phi = 50.0, 0.1, 0.3
    mech = ShiftingFork(R=R, phi0=phi0, p=5.0, i_a=2.0)
    x = _fork_pin_x(R, phi0 + phi)  # 50 tan 0.4 = 21.1396 mm
    assert x == pytest.approx(21.13966, rel=1e-6)
    end, pin = mech.pin_positions(phi)
    assert [float(v) for v in end] == pytest.approx([x, R])
    assert [float(v) for v in pin] == pytest.approx([x, R])
    sk = mech.sketch(phi)
    assert sk.links == [[(0.0, 0.0), pytest.approx((x, R))]]
    assert sk.pivots == [(0.0, 0.0)] and sk.slider == pytest.approx((x, R))
    # the screw axis drawn from 0.3 R before the nearer end to 0.3 R past the farther one
    assert sk.axis[0] == pytest.approx((-0.3 * R, R)) and sk.axis[1] == pytest.approx(
        (x + 0.3 * R, R)
    )
    sk_neg = mech.sketch(-0.6)  # a = -0.5: the pin left of the axis
    xn = _fork_pin_x(R, -0.5)
    assert sk_neg.axis[0] == pytest.approx((xn - 0.3 * R, R))
    assert sk_neg.axis[1] == pytest.approx((0.3 * R, R))
    # the slot holds the pin while cos a > 0: margin cos(a) R^2
    assert float(mech.assembly_margin(phi)) == pytest.approx(math.cos(0.4) * 2500.0)
    assert float(mech.assembly_margin(1.6)) < 0  # a = 1.7 rad: past perpendicular


def test_fork_bench_template_and_size():
    from optdesign.mechanisms.fork import ShiftingFork

    variables, requirements = ShiftingFork.bench_template()
    assert variables == {"R": {"lower": "30 mm", "upper": "120 mm"}, "p": None}
    assert requirements == {}
    assert ShiftingFork(R=42.0, p=5.0, i_a=2.0).size() == 42.0
    assert ShiftingFork.pin_shear_planes == 1  # one pin in one slot: single shear
    assert ShiftingFork.variables["phi0"].default == 0.0


def test_fork_pin_positions_on_a_grid_through_zero():
    import numpy as np

    from optdesign.mechanisms.fork import ShiftingFork

    mech = ShiftingFork(R=40.0, p=5.0, i_a=2.0)
    phi = np.array([-0.2, 0.0, 0.2])
    with np.errstate(all="raise"):  # no 0/0 anywhere on the grid
        end, pin = mech.pin_positions(phi)
    assert np.asarray(pin[1]) == pytest.approx([40.0, 40.0, 40.0])
    assert np.asarray(end[1]) == pytest.approx([40.0, 40.0, 40.0])
    assert np.asarray(pin[0]) == pytest.approx(40.0 * np.tan(phi))
