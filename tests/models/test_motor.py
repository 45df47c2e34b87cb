"""optdesign.models.motor: the motor in the drive (issue 37).

Published checks (THK's selection example, a two-mass drive, a second-order loop's step),
the reflected inertia against the kinetic energy of a crank-slider's nut, the motor
torque against a Lagrange integration of the drive and against its power balance, the
efficiency against the project's screw torque, property tests of the invariants, and one
evaluation of every function on CasADi symbols.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from optdesign.errors import InputError
from optdesign.models import crank_slider as cs
from optdesign.models import loads
from optdesign.models import motor as mo

# A crank-slider drive (mm, rad): the nut rate dx/dphi runs from 41 to 25 mm/rad over
# phi in [-0.4, 0.4], a ratio f' that varies by a factor 1.6 along the stroke.
R, L, N, PHI0 = 40.0, 100.0, 10.0, 0.3
LEAD, GEAR = 5.0, 2.0


def _x(phi):
    return cs.nut_position(R, L, N, phi, PHI0)


def _chain():
    """theta(phi), f' and f'' of the crank-slider drive, exact (CasADi), mapped on grids."""
    phi = ca.SX.sym("phi")
    x = cs.nut_position(R, L, N, phi, PHI0)
    v = cs.nut_velocity(R, L, N, phi, PHI0)
    theta = GEAR * 2.0 * np.pi / LEAD * x
    f1 = mo.motor_ratio(v, LEAD, GEAR)
    f2 = mo.motor_ratio(ca.jacobian(v, phi), LEAD, GEAR)
    fun = ca.Function("chain", [phi], [theta, f1, f2])

    def evaluate(values):
        values = np.atleast_1d(np.asarray(values, dtype=float))
        out = fun.map(values.size)(values.reshape(1, -1))
        return tuple(np.asarray(o).ravel() for o in out)

    return evaluate


CHAIN = _chain()


# --- THK's motor selection (published) ------------------------------------------------------
def test_thk_high_speed_transfer_example():
    """THK Ball Screw General Catalog, "Examples of Selecting a Ball Screw", high-speed
    transfer equipment (horizontal use), sections "Studying the Rotational Torque" and
    "Studying the Driving Motor" ([THK-EX]; read through a public repository's
    transcription of the bondy.dk mirror, not from the page itself).

    Given: table + work 60 + 20 kg, Vmax = 1 m/s, t1 = t3 = 0.15 s, WTF2040-2 (lead
    40 mm), direct coupling, screw shaft inertia 1.23e-3 kg*cm^2/mm x 1200 mm =
    1.48e-4 kg*m^2, rotor 1e-3 kg*m^2, axial load at uniform motion Fa = 17 N, eta = 0.9.
    Printed: T1 = Fa Ph / (2 pi eta) = 120 N*mm; J = m (Ph/2pi)^2 + J_S = 3.39e-3 kg*m^2;
    alpha = 2 pi Nm / (60 t1) = 1050 rad/s^2 (the exact 1047.2 rounded); acceleration
    torque T2 = (J + J_M) alpha = 4.61 N*m; maximum torque during acceleration Tk = T1 + T2
    = 4.73 N*m (4730 N*mm, "the instantaneous maximum torque must be at least 4730 N*mm");
    during uniform motion Tt = T1 = 0.12 N*m; during deceleration Tg = T1 - T2 =
    -4.49 N*m; stopped Ts = 0; over 0.15 / 0.85 / 0.15 / 2.6 s the effective torque
    Trms = 1305 N*mm; the rotor inertia must be at least J / 10 = 3.39e-4 kg*m^2.

    Every printed number reproduces to its last printed digit with THK's own chain: J
    carried on rounded to 3.39e-3 kg*m^2 and alpha = 1050. With the unrounded J
    (3.3903e-3) Trms is 1305.5 N*mm; with the exact alpha (1047.2 rad/s^2) 1302 N*mm.
    """
    lead = 40.0
    ratio = 2.0 * np.pi / lead  # motor rad per mm of table travel (the "fin" is the table)
    J_screw = 1.23e-3 * 1200.0 * mo.KG_CM2  # kg*cm^2/mm x mm, in t*mm^2
    assert J_screw / mo.KG_M2 == pytest.approx(1.48e-4, abs=0.005e-4)
    J_load = mo.translating_mass_inertia(80.0 * mo.KG, lead) + 1.48e-4 * mo.KG_M2
    assert J_load / mo.KG_M2 == pytest.approx(3.39e-3, abs=0.005e-3)
    assert mo.min_rotor_inertia(J_load) / mo.KG_M2 == pytest.approx(3.39e-4, abs=0.005e-4)
    J_exact = mo.motor_side_inertia(1e-3 * mo.KG_M2, 1.48e-4 * mo.KG_M2, 80.0 * mo.KG, lead)
    assert J_exact == pytest.approx(J_load + 1e-3 * mo.KG_M2, rel=1e-12)
    J_m = (3.39e-3 + 1e-3) * mo.KG_M2  # THK's J + J_M, as printed

    # the motor's speed and acceleration: 1 m/s on a 40 mm lead is 1500 min^-1
    omega = mo.motor_rate(ratio, 1000.0)
    assert omega / mo.RPM == pytest.approx(1500.0, rel=1e-12)
    assert round(omega / 0.15, -1) == 1050.0  # THK prints 1050 for 1047.2

    T1 = mo.torque_at_motor(17.0, ratio, efficiency=0.9)
    assert T1 == pytest.approx(120.0, abs=0.5)
    alpha = 1050.0
    x_ddot = alpha / ratio  # the table's acceleration that gives THK's alpha
    T2 = J_m * alpha
    assert T2 / mo.N_M == pytest.approx(4.61, abs=0.005)

    def torque(accel):
        return mo.motor_torque(J_m, ratio, 0.0, 1000.0, accel, 17.0, efficiency=0.9)

    Tk, Tt, Tg = torque(x_ddot), torque(0.0), torque(-x_ddot)
    assert Tk / mo.N_M == pytest.approx(4.73, abs=0.005)
    assert Tt / mo.N_M == pytest.approx(0.12, abs=0.005)
    assert Tg / mo.N_M == pytest.approx(-4.49, abs=0.005)
    assert mo.phase_torques(J_m, alpha, T1, ("accel", "run", "decel", "stop")) == pytest.approx(
        [Tk, Tt, Tg, 0.0], rel=1e-12
    )
    torques, durations = [Tk, Tt, Tg, 0.0], [0.15, 0.85, 0.15, 2.6]
    assert mo.rms_torque(torques, durations) == pytest.approx(1305.0, abs=0.5)
    assert mo.peak_torque(torques) == pytest.approx(4730.0, abs=5.0)
    # unrounded: J 3.3903e-3 gives 1305.5 N*mm; the exact alpha 1302 N*mm
    unrounded = mo.phase_torques(J_exact, alpha, T1, ("accel", "run", "decel", "stop"))
    assert mo.rms_torque(unrounded, durations) == pytest.approx(1305.5, abs=0.05)
    exact = mo.phase_torques(J_m, omega / 0.15, T1, ("accel", "run", "decel", "stop"))
    assert mo.rms_torque(exact, durations) == pytest.approx(1302.0, abs=0.5)


def test_thk_vertical_conveyance_example():
    """The same chapter's vertical conveyance system ([THK-EX], same transcription):
    50 kg on a BLK1510-5.6 (lead 10 mm), screw 3.9e-4 kg*cm^2/mm x 800 mm, rotor
    5e-5 kg*m^2, 0.3 m/s in 0.2 s. Printed: J = 1.58e-4 kg*m^2, alpha = 942 rad/s^2, and
    over its seven phases (1100 / 900 / 700 N*mm up, 630 / 830 / 1030 down, 0.2 / 1.8 /
    0.2 s each, then 658 N*mm holding for 7.6 s) Trms = 743 N*mm. Reproduced. Its printed
    acceleration torque, 200 N*mm, is (J + J_M) alpha = 196 N*mm rounded to two figures.
    """
    J_screw = 3.9e-4 * 800.0 * mo.KG_CM2
    J = mo.translating_mass_inertia(50.0 * mo.KG, 10.0) + J_screw
    assert J / mo.KG_M2 == pytest.approx(1.58e-4, abs=0.005e-4)
    omega = mo.motor_rate(2.0 * np.pi / 10.0, 300.0)
    assert omega / 0.2 == pytest.approx(942.0, abs=0.5)
    assert (J + 5e-5 * mo.KG_M2) * 942.0 == pytest.approx(196.0, abs=0.5)
    torques = [1100.0, 900.0, 700.0, 630.0, 830.0, 1030.0, 658.0]
    durations = [0.2, 1.8, 0.2, 0.2, 1.8, 0.2, 7.6]
    assert mo.rms_torque(torques, durations) == pytest.approx(743.0, abs=0.5)
    assert mo.peak_torque(torques) == 1100.0


# --- frequencies (published) -----------------------------------------------------------------
def test_two_mass_drive_frequencies():
    """J1 = 0.002 kg*m^2 (motor), J2 = 0.018 kg*m^2 (load), k = 2000 N*m/rad:
    anti-resonance sqrt(k/J2) = 53.1 Hz, resonance sqrt(k (J1+J2)/(J1 J2)) = 167.8 Hz."""
    J1, J2, k = 0.002 * mo.KG_M2, 0.018 * mo.KG_M2, 2000.0 * mo.N_M
    assert mo.hertz(mo.anti_resonance(J2, k)) == pytest.approx(53.1, abs=0.05)
    assert mo.hertz(mo.resonance(J1, J2, k)) == pytest.approx(167.8, abs=0.05)
    # independent: the eigenvalues of the undamped two-mass system M q'' + K q = 0
    w2 = np.linalg.eigvals(np.linalg.solve(np.diag([J1, J2]), [[k, -k], [-k, k]]))
    assert np.sqrt(max(w2)) == pytest.approx(mo.resonance(J1, J2, k), rel=1e-12)
    assert min(abs(w2)) < 1e-9  # the rigid-body mode
    # the notch: motor speed over motor torque vanishes where J2 s^2 + k = 0
    s = 1j * mo.anti_resonance(J2, k)
    assert abs(J2 * s**2 + k) < 1e-6 * k


def test_locked_motor_frequency_of_the_fin():
    J_fin, k_chain = 50.0, 4.0e6  # t*mm^2, N*mm/rad
    w2 = mo.locked_frequency_squared(k_chain, J_fin)
    assert mo.frequency_from_squared(w2) == pytest.approx(math.sqrt(8e4), rel=1e-12)
    unstable = mo.locked_frequency_squared(k_chain, J_fin, hinge_spring=-1.0e6)
    assert mo.frequency_from_squared(unstable) == pytest.approx(math.sqrt(6e4), rel=1e-12)
    diverging = mo.locked_frequency_squared(k_chain, J_fin, hinge_spring=-5.0e6)
    assert diverging == pytest.approx(-2e4) and mo.frequency_from_squared(diverging) == 0.0
    # on the solver path omega^2 is smooth through zero: its derivative in the spring is 1/J
    k = ca.SX.sym("k")
    grad = ca.Function("g", [k], [ca.gradient(mo.locked_frequency_squared(k_chain, J_fin, k), k)])
    assert float(grad(-4.0e6)) == pytest.approx(1.0 / J_fin)


# --- a closed loop's step (published) ---------------------------------------------------------
def test_second_order_step_check():
    """Damping 0.7 and a 5 % rise time of 72 ms to a 0.5 deg step: natural frequency
    40.28 rad/s, peak rate 9.24 deg/s, peak acceleration 811.15 deg/s^2.

    The "5 % rise time" is the first time the response reaches 95 % of the step (for
    zeta = 0.7 also the 5 % settling time, the overshoot being 4.6 %): wn t = 2.89982, wn
    = 40.2753 rad/s, printed 40.28. The printed peak rate and acceleration follow from wn
    t = 2.9 rounded (wn = 40.2778): 0.5 x 40.2778 x exp(-0.7 acos 0.7 / sqrt(0.51)) =
    9.2350 -> 9.24 and 0.5 x 40.2778^2 = 811.15. From the unrounded wn they are 9.2345
    (9.23) and 811.05 deg/s^2: 0.06 % and 0.012 % below the printed ones.
    """
    wn = mo.natural_frequency_for_rise_time(0.7, 0.072)
    assert wn == pytest.approx(40.28, abs=0.005)
    assert wn * 0.072 == pytest.approx(2.89982, abs=1e-5)
    printed_wn = 2.9 / 0.072
    assert mo.step_peak_rate(printed_wn, 0.7, 0.5) == pytest.approx(9.24, abs=0.005)
    assert mo.step_peak_acceleration(printed_wn, 0.7, 0.5) == pytest.approx(811.15, abs=0.005)
    assert mo.step_peak_rate(wn, 0.7, 0.5) == pytest.approx(9.2345, abs=5e-5)
    assert mo.step_peak_acceleration(wn, 0.7, 0.5) == pytest.approx(811.05, abs=0.005)


@pytest.mark.parametrize("zeta", [0.2, 0.5, 0.7, 0.9])
def test_step_closed_forms_against_an_integrated_response(zeta):
    wn, step = 40.0, 0.5

    def rhs(_t, y):
        return [y[1], wn**2 * (step - y[0]) - 2.0 * zeta * wn * y[1]]

    t = np.linspace(0.0, 0.5, 200_001)
    sol = solve_ivp(rhs, (0.0, 0.5), [0.0, 0.0], t_eval=t, rtol=1e-12, atol=1e-14)
    y, rate = sol.y
    accel = np.array([rhs(0.0, yk)[1] for yk in sol.y.T])
    assert y == pytest.approx(step * mo.step_response(t, wn, zeta), abs=1e-9)
    k = int(np.argmax(rate))
    assert rate[k] == pytest.approx(mo.step_peak_rate(wn, zeta, step), rel=1e-8)
    assert t[k] == pytest.approx(mo.step_peak_rate_time(wn, zeta), abs=2 * t[1])
    assert np.max(np.abs(accel)) == pytest.approx(mo.step_peak_acceleration(wn, zeta, step))
    assert np.argmax(np.abs(accel)) == 0
    rise = mo.natural_frequency_for_rise_time(zeta, 0.05, level=0.9)
    first = np.argmax(step * mo.step_response(t, rise, zeta) >= 0.9 * step)
    assert 0.05 <= t[first] <= 0.05 + 1.01 * t[1]


# --- the reflected inertia against kinetic energy ----------------------------------------
def test_reflected_inertia_equals_the_kinetic_energy_of_the_crank_slider_nut():
    """The nut (mass m) of a crank-slider drive moving along a fin history: its kinetic
    energy 1/2 m x_dot^2, with x_dot a time difference of the nut position x(phi(t)),
    equals 1/2 J_fin phi_dot^2 with J_fin = inertia_at_fin(m (lead/2 pi)^2, f') and
    1/2 J_motor theta_dot^2 through the gear."""
    m_nut, h = 0.5 * mo.KG, 1e-6
    t = np.linspace(0.0, 0.8, 41)[1:-1]

    def phi(s):
        return 0.05 + 0.3 * np.sin(7.0 * s)

    phi_dot = 0.3 * 7.0 * np.cos(7.0 * t)
    x_dot = (_x(phi(t + h)) - _x(phi(t - h))) / (2 * h)
    kinetic = 0.5 * m_nut * x_dot**2
    _, f1, _ = CHAIN(phi(t))
    J_screw_side = mo.translating_mass_inertia(m_nut, LEAD)
    J_at_motor = mo.reflected_inertia(J_screw_side, GEAR)
    J_fin = mo.inertia_at_fin(J_at_motor, f1)
    assert 0.5 * J_fin * phi_dot**2 == pytest.approx(kinetic, rel=1e-8)
    assert 0.5 * J_at_motor * (f1 * phi_dot) ** 2 == pytest.approx(kinetic, rel=1e-8)
    # equivalently m (dx/dphi)^2 at the fin, from a difference of positions in phi
    dx = (_x(phi(t) + h) - _x(phi(t) - h)) / (2 * h)
    assert J_fin == pytest.approx(m_nut * dx**2, rel=1e-8)
    # and the fin seen at the motor with the chain: J_at_motor + J_out / f'^2
    J_total = mo.inertia_at_motor(J_at_motor, 50.0, f1)
    assert mo.inertia_at_fin(J_total, f1) == pytest.approx(J_fin + 50.0, rel=1e-12)


# --- the motor torque against the dynamics ---------------------------------------------------
J_M = mo.motor_side_inertia(0.0659e-4 * mo.KG_M2, 0.02, 0.5 * mo.KG, LEAD, GEAR)
J_FIN, DAMPING, SPRING, HINGE = 50.0, 500.0, -2.0e5, 2.0e4  # t*mm^2, N*mm*s, N*mm/rad, N*mm


def test_motor_torque_against_a_lagrange_integration():
    """Integrate the drive's own equation of motion under a given motor torque T(t):
    with M(phi) = J_m f'(phi)^2 + J_fin (f' from a finite difference of the nut
    position), Lagrange gives M phi_ddot + 1/2 M'(phi) phi_dot^2 = T f' - c phi_dot -
    k phi - M_h. Along the integrated motion, motor_torque must return T(t). (A stable
    hinge spring: open loop, an unstable fin would leave the stroke.)"""
    spring = 4.0e5

    def f1_fd(phi, h=1e-6):
        return GEAR * 2 * np.pi / LEAD * (_x(phi + h) - _x(phi - h)) / (2 * h)

    def mass(phi):
        return J_M * f1_fd(phi) ** 2 + J_FIN

    def torque(t):
        return 230.0 + 150.0 * np.sin(20.0 * t)

    def rhs(t, y):
        phi, rate = y
        h = 1e-3
        dmass = (mass(phi + h) - mass(phi - h)) / (2 * h)
        force = torque(t) * f1_fd(phi) - DAMPING * rate - spring * phi - HINGE
        return [rate, (force - 0.5 * dmass * rate**2) / mass(phi)]

    t = np.linspace(0.0, 0.4, 81)
    sol = solve_ivp(rhs, (0.0, 0.4), [0.1, 0.0], t_eval=t, rtol=1e-11, atol=1e-12)
    phi, phi_dot = sol.y
    assert np.ptp(phi) > 0.1 and np.max(np.abs(phi)) < 0.4  # a real swing, in the stroke
    phi_ddot = np.array([rhs(tk, yk)[1] for tk, yk in zip(t, sol.y.T, strict=True)])
    _, f1, f2 = CHAIN(phi)
    M_out = mo.output_torque(J_FIN, phi_ddot, DAMPING, phi_dot, spring, phi, HINGE)
    T = mo.motor_torque(J_M, f1, f2, phi_dot, phi_ddot, M_out)
    assert T == pytest.approx(torque(t), abs=1e-6 * 230.0)
    # without the ratio's rate the torque is wrong where the fin moves fast: by 16 N*mm
    T_no_rate = mo.motor_torque(J_M, f1, 0.0 * f2, phi_dot, phi_ddot, M_out)
    assert np.max(np.abs(T_no_rate - torque(t))) > 10.0


def test_motor_torque_against_the_power_balance_of_a_prescribed_motion():
    """theta(t) = f(phi(t)) sampled from the nut position alone: the motor's power
    T theta_dot equals the rate of the kinetic energy 1/2 J_m theta_dot^2 +
    1/2 J_fin phi_dot^2 plus the power into damping, spring and hinge moment."""
    dt = 1e-4
    t = np.arange(0.0, 0.5 + dt / 2, dt)
    phi = 0.15 + 0.2 * np.sin(8.0 * t)
    phi_dot = 1.6 * np.cos(8.0 * t)
    phi_ddot = -12.8 * np.sin(8.0 * t)
    theta = GEAR * 2 * np.pi / LEAD * _x(phi)
    theta_dot = np.gradient(theta, dt)
    kinetic = 0.5 * J_M * theta_dot**2 + 0.5 * J_FIN * phi_dot**2
    power_out = np.gradient(kinetic, dt) + DAMPING * phi_dot**2 + (SPRING * phi + HINGE) * phi_dot
    _, f1, f2 = CHAIN(phi)
    M_out = mo.output_torque(J_FIN, phi_ddot, DAMPING, phi_dot, SPRING, phi, HINGE)
    T = mo.motor_torque(J_M, f1, f2, phi_dot, phi_ddot, M_out)
    inner = slice(2, -2)
    scale = np.max(np.abs(power_out))
    assert (T * theta_dot)[inner] == pytest.approx(power_out[inner], abs=1e-5 * scale)
    assert theta_dot[inner] == pytest.approx(mo.motor_rate(f1, phi_dot)[inner], rel=1e-6)


def test_the_motor_accelerates_at_a_constant_fin_rate():
    dt, rate = 1e-4, 2.0
    t = np.arange(0.0, 0.3, dt)
    phi = -0.3 + rate * t
    theta = GEAR * 2 * np.pi / LEAD * _x(phi)
    theta_ddot = np.gradient(np.gradient(theta, dt), dt)
    _, f1, f2 = CHAIN(phi)
    expected = mo.motor_acceleration(f1, f2, rate, 0.0)
    assert np.max(expected) < -120.0  # rad/s^2: the falling ratio decelerates the motor
    assert theta_ddot[2:-2] == pytest.approx(expected[2:-2], rel=1e-4)


def test_efficiency_against_the_screw_torque_and_back_driving():
    """Static: the torque through the chain equals the project's screw torque
    (optdesign.models.loads) for the nut force M / (dx/dphi). Back-driven where the
    output returns power; driving at rest and where the motor does the work."""
    phi = np.array([-0.3, 0.0, 0.3])
    M, eta, eta_back = 3.0e4, 0.8, 0.7
    _, f1, _ = CHAIN(phi)
    dx = cs.nut_velocity(R, L, N, phi, PHI0)
    screw = loads.motor_torque(M / dx, LEAD, GEAR, eta_screw=eta)
    assert mo.torque_at_motor(M, f1, eta) == pytest.approx(screw, rel=1e-12)
    back = loads.backdriven_motor_torque(M / dx, LEAD, GEAR, eta_screw_back=eta_back)
    rates = np.array([-1.0, 0.0, 1.0])  # M > 0 against phi_dot < 0: the air drives the fin
    got = mo.torque_at_motor(M, f1, eta, back_efficiency=eta_back, phi_dot=rates)
    assert got == pytest.approx([back[0], screw[1], screw[2]], rel=1e-12)
    # driving-only is the larger magnitude for either sign of the output torque
    assert abs(mo.torque_at_motor(-M, f1[0], eta)) > abs(
        mo.torque_at_motor(-M, f1[0], eta, back_efficiency=eta_back, phi_dot=1.0)
    )
    # the motor torque then adds its friction, signed with the motion
    T = mo.motor_torque(J_M, f1, 0.0, 0.0, 0.0, M, eta, friction=120.0)
    assert T == pytest.approx(screw + 120.0, rel=1e-12)


def test_speed_and_torque_margins():
    _, f1, _ = CHAIN(np.array([-0.4, 0.4]))
    speed = mo.motor_rate(f1, 3.0)  # 3 rad/s at the fin
    assert speed == pytest.approx([309.49, 189.79], abs=0.01)  # rad/s
    top = 3000.0 * mo.RPM  # 314.16 rad/s
    margin = mo.speed_margin(speed, top)
    assert margin[0] == pytest.approx(1.0 - 309.49 / 314.159, abs=1e-4) and margin[0] > 0
    assert mo.speed_margin(-400.0, top) < 0
    assert mo.torque_margin(1305.0, 1910.0) == pytest.approx(1.0 - 1305.0 / 1910.0)


# --- invariants ----------------------------------------------------------------------------
positive = st.floats(1e-3, 1e3, allow_nan=False, allow_infinity=False)


@given(J=positive, ratio=positive, c=st.floats(0.1, 10.0))
def test_reflected_inertia_is_positive_and_scales_with_the_ratio_squared(J, ratio, c):
    J_in = mo.reflected_inertia(J, ratio)
    assert J_in > 0
    assert mo.reflected_inertia(J, c * ratio) == pytest.approx(J_in / c**2, rel=1e-12)
    assert mo.inertia_at_output(J_in, ratio) == pytest.approx(J, rel=1e-12)
    total = mo.inertia_at_motor(J, J, ratio)
    assert mo.inertia_at_fin(total, ratio) == pytest.approx(J * ratio**2 + J, rel=1e-12)


@given(
    phases=st.lists(
        st.tuples(st.floats(-1e4, 1e4, allow_nan=False), st.floats(1e-3, 10.0)),
        min_size=1,
        max_size=8,
    )
)
def test_rms_lies_between_the_mean_magnitude_and_the_peak(phases):
    torques = [T for T, _ in phases]
    durations = [t for _, t in phases]
    rms = mo.rms_torque(torques, durations)
    mean_abs = sum(abs(T) * t for T, t in phases) / sum(durations)
    assert mean_abs <= rms * (1 + 1e-12) + 1e-12
    assert rms <= mo.peak_torque(torques) * (1 + 1e-12) + 1e-12
    assert mo.rms_torque([2.0 * T for T in torques], durations) == pytest.approx(2.0 * rms)
    assert mo.rms_torque(torques, [3.0 * t for t in durations]) == pytest.approx(rms)


def test_rms_and_peak_over_arrays_of_designs():
    torques = np.array([[3.0, -4.0, 0.0], [1.0, 1.0, 1.0]])  # two designs x three phases
    rms = mo.rms_torque(torques, np.array([1.0, 1.0, 2.0]))
    assert rms == pytest.approx([math.sqrt(25.0 / 4.0), 1.0])
    assert mo.peak_torque(list(torques.T)) == pytest.approx([4.0, 1.0])


# --- CasADi symbols ------------------------------------------------------------------------
def test_every_function_evaluates_on_casadi_symbols():
    x = ca.SX.sym("x", 6)
    J, r, r2, w, a, z = (x[i] for i in range(6))
    exprs = {
        "reflected": mo.reflected_inertia(J, r),
        "at_output": mo.inertia_at_output(J, r),
        "translating": mo.translating_mass_inertia(J, r),
        "side": mo.motor_side_inertia(J, 0.5 * J, J, r, 2.0),
        "ratio": mo.motor_ratio(r, 5.0, 2.0),
        "at_motor": mo.inertia_at_motor(J, 3.0 * J, r),
        "min_rotor": mo.min_rotor_inertia(J),
        "torque": mo.motor_torque(J, r, r2, w, a, mo.output_torque(J, a, 2.0, w, 3.0, a, 4.0)),
        "back": mo.torque_at_motor(w - a, r, 0.9, back_efficiency=0.8, phi_dot=w),
        "rms": mo.rms_torque(x[:3], [0.1, 0.2, 0.3]),
        "peak": mo.peak_torque(x[:3]),
        "speed": mo.speed_margin(mo.motor_rate(r, w), 600.0),
        "anti": mo.anti_resonance(J, r),
        "res": mo.resonance(J, a, r),
        "locked": mo.frequency_from_squared(mo.locked_frequency_squared(r, J, -a)),
        "step": mo.step_response(w, a, z),
        "rate": mo.step_peak_rate(a, z, 0.5),
        "accel": mo.step_peak_acceleration(a, z, 0.5),
    }
    fun = ca.Function("f", [x], list(exprs.values()))
    values = np.array([2.0, 30.0, 0.7, 1.5, 40.0, 0.6])
    got = [float(v) for v in fun(values)]
    J, r, r2, w, a, z = values
    expected = {
        "reflected": mo.reflected_inertia(J, r),
        "at_output": mo.inertia_at_output(J, r),
        "translating": mo.translating_mass_inertia(J, r),
        "side": mo.motor_side_inertia(J, 0.5 * J, J, r, 2.0),
        "ratio": mo.motor_ratio(r, 5.0, 2.0),
        "at_motor": mo.inertia_at_motor(J, 3.0 * J, r),
        "min_rotor": mo.min_rotor_inertia(J),
        "torque": mo.motor_torque(J, r, r2, w, a, mo.output_torque(J, a, 2.0, w, 3.0, a, 4.0)),
        "back": mo.torque_at_motor(w - a, r, 0.9, back_efficiency=0.8, phi_dot=w),
        "rms": mo.rms_torque(values[:3], [0.1, 0.2, 0.3]),
        "peak": mo.peak_torque(list(values[:3])),
        "speed": mo.speed_margin(mo.motor_rate(r, w), 600.0),
        "anti": mo.anti_resonance(J, r),
        "res": mo.resonance(J, a, r),
        "locked": mo.frequency_from_squared(mo.locked_frequency_squared(r, J, -a)),
        "step": mo.step_response(w, a, z),
        "rate": mo.step_peak_rate(a, z, 0.5),
        "accel": mo.step_peak_acceleration(a, z, 0.5),
    }
    assert got == pytest.approx([float(v) for v in expected.values()], rel=1e-12)
    assert expected["back"] == pytest.approx((w - a) * 0.8 / r)  # back-driven: w - a < 0


# --- refusals ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda: mo.torque_at_motor(1.0, 2.0, efficiency=1.2), "efficiency"),
        (lambda: mo.torque_at_motor(1.0, 2.0, efficiency=0.0), "efficiency"),
        (lambda: mo.torque_at_motor(1.0, 2.0, back_efficiency=0.5), "phi_dot"),
        (lambda: mo.torque_at_motor(1.0, 2.0, back_efficiency=1.5, phi_dot=1.0), "back_efficiency"),
        (lambda: mo.natural_frequency_for_rise_time(1.0, 0.1), "zeta"),
        (lambda: mo.natural_frequency_for_rise_time(0.7, 0.1, level=1.0), "level"),
        (lambda: mo.natural_frequency_for_rise_time(0.7, -0.1), "t_rise"),
        (lambda: mo.step_peak_rate(10.0, 0.0, 1.0), "zeta"),
        (lambda: mo.rms_torque([1.0, 2.0], [1.0, -1.0]), "durations[1]"),
        (lambda: mo.rms_torque([1.0, 2.0], [0.0, 0.0]), "durations"),
        (lambda: mo.rms_torque([1.0, 2.0], [1.0]), "durations"),
        (lambda: mo.peak_torque([]), "torques"),
        (lambda: mo.min_rotor_inertia(1.0, 0.0), "max_ratio"),
        (lambda: mo.phase_torques(1.0, 1.0, 1.0, ("accel", "coast")), "phases"),
    ],
)
def test_impossible_inputs_are_refused_naming_the_field(call, field):
    with pytest.raises(InputError) as err:
        call()
    assert err.value.field == field
