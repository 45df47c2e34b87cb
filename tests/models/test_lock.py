"""Motor-shaft locks (seed 002, physics.md 5) and their coupling to the mechanism."""

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.mechanisms import CrankSlider
from optdesign.models import lock, screw
from optdesign.models.loads import backdriven_motor_torque


def test_friction_radius_uniform_pressure_and_wear():
    # (2/3)(40^3 - 30^3)/(40^2 - 30^2) = (2/3)(37000/700) = 35.238 mm; wear: 35 mm
    assert lock.friction_radius(30.0, 40.0) == pytest.approx(35.2381, abs=1e-4)
    assert lock.friction_radius(30.0, 40.0, "uniform_wear") == pytest.approx(35.0)


def test_pin_lock_is_035_M_over_R_and_925_percent_of_plate():
    M = 1234.0
    f_a = lock.pin_lock_force(M, 40.0)
    assert f_a == pytest.approx(0.35 * M / 40.0, rel=1e-12)
    F = lock.friction_plate_force(M, 30.0, 40.0, 0.3)
    # Acceptance: the paper's 9.25 % to 0.01 percentage point.
    assert 100 * f_a / F == pytest.approx(9.25, abs=0.01)


def test_guide_reactions_sum_to_one_and_a_half_F1():
    F2, F3 = lock.pin_guide_reactions(1.0, 4.0)
    assert (F2, F3) == pytest.approx((1.25, 0.25))
    # Force balance of the pin: F2 - F3 = F1.
    assert F2 - F3 == pytest.approx(1.0)


def test_rolling_reconstruction_values():
    M, R = 1000.0, 40.0
    F = lock.friction_plate_force(M, 30.0, 40.0, 0.3)
    guide = lock.pin_lock_force_rolling(M, R, bearing="guide")
    tip = lock.pin_lock_force_rolling(M, R, bearing="tip")
    # 0.1 + 1.25 (0.01 cos 0.5deg + 0.1 sin 0.5deg) + 0.025 + 0.1 = 0.238590 M/R
    assert guide * R / M == pytest.approx(0.2385903, abs=1e-6)
    assert 100 * guide / F == pytest.approx(6.3056, abs=1e-3)  # paper prints 6.32
    assert tip * R / M == pytest.approx(0.2608723, abs=1e-6)
    # Without friction anywhere only the return spring is left.
    bare = lock.pin_lock_force_rolling(M, R, mu_h=0.0, mu_g=0.0)
    assert bare == pytest.approx(0.1 * M / R)


def test_bad_inputs_name_the_field():
    with pytest.raises(InputError, match="r2"):
        lock.friction_radius(40.0, 30.0)
    with pytest.raises(InputError, match="law"):
        lock.friction_radius(30.0, 40.0, "parabolic")
    with pytest.raises(InputError, match="bearing"):
        lock.pin_lock_force_rolling(1.0, 40.0, bearing="elsewhere")
    with pytest.raises(InputError, match="R"):
        lock.pin_lock_force(1.0, -1.0)


@settings(max_examples=60, deadline=None)
@given(
    M=st.floats(1.0, 1e6), dM=st.floats(1e-3, 1e5), R=st.floats(5.0, 100.0), mu=st.floats(0.05, 0.6)
)
def test_lock_forces_increase_with_moment(M, dM, R, mu):
    for design in (
        lock.FrictionPlateLock(0.5 * R, R, mu),
        lock.PinLock(R),
        lock.PinLock(R, bearing="guide"),
        lock.PinLock(R, bearing="tip"),
    ):
        assert design.force(M + dM) > design.force(M) > 0


def test_motor_shaft_moment_follows_the_ratio():
    mech = CrankSlider(R=90.0, l=80.0, n=50.0, p=5.0, i_a=2.0)
    phi = np.radians(np.linspace(-30, 30, 121))
    M_h, eta_b = 5e5, 0.96
    load = lock.motor_shaft_lock_load(mech, phi, M_h, eta_b, 1.0, lock.PinLock(40.0))
    # Virtual work: T = M_h eta' / i(phi) (i = motor radians per output radian).
    assert np.asarray(load.moment) == pytest.approx(
        M_h * eta_b / np.asarray(mech.ratio(phi)), rel=1e-10
    )
    assert float(load.moment_max) == pytest.approx(M_h * eta_b / np.min(mech.ratio(phi)))
    assert float(load.force) == pytest.approx(0.35 * float(load.moment_max) / 40.0)
    # A self-locking screw passes nothing to the motor shaft.
    locked = lock.motor_shaft_lock_load(mech, phi, M_h, -0.2, 1.0, lock.PinLock(40.0))
    assert float(locked.force) == 0.0


def test_lock_force_casadi_matches_numpy():
    # The same formulas as a CasADi expression in (R_arm, l, r) and numerically.
    Rs, ls, rs = ca.SX.sym("R"), ca.SX.sym("l"), ca.SX.sym("r")
    phi = np.radians(np.linspace(-30, 30, 61))
    eta_b = screw.efficiency_backdrive(screw.lead_angle(5.0, 20.0), screw.friction_angle(0.003))
    sym = lock.motor_shaft_lock_load(
        CrankSlider(R=Rs, l=ls, n=50.0, p=5.0, i_a=2.0),
        ca.DM(phi),
        5e5,
        eta_b,
        1.0,
        lock.PinLock(rs, bearing="guide"),
    )
    f = ca.Function("f", [Rs, ls, rs], [sym.force])
    num = lock.motor_shaft_lock_load(
        CrankSlider(R=90.0, l=80.0, n=50.0, p=5.0, i_a=2.0),
        phi,
        5e5,
        eta_b,
        1.0,
        lock.PinLock(40.0, bearing="guide"),
    )
    assert float(f(90.0, 80.0, 40.0)) == pytest.approx(float(num.force), rel=1e-12)
    # and the NumPy path agrees with loads.backdriven_motor_torque directly
    F_a = np.abs(CrankSlider(R=90.0, l=80.0, n=50.0, p=5.0, i_a=2.0).nut_force(phi, 5e5))
    assert np.asarray(num.moment) == pytest.approx(backdriven_motor_torque(F_a, 5.0, 2.0, eta_b))
