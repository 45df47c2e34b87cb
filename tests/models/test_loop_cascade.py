"""The position/speed cascade (optdesign.models.loop_plant.CascadeLoop) in the linear
loop, the harmonic balance and the simulation.

(a) L(jw), T(jw), the bandwidth and the margins against the cascade built a second time
with python-control's ``tf``, ``feedback`` and ``series`` from the same two-mass plant,
the way an engineer closes it: the speed loop first, then the position loop around it;
(b) a P speed loop equals the PD loop on the motor (kp = Kv Kpos, kd = Kv) in the
response and in a simulation; (c) the simulated step of the backlash-free loop equals
python-control's step response of its linear loop; (d) the limit cycle of a cascade
that hunts against the describing function; (e) bad gains refused naming them.
"""

from __future__ import annotations

import math

import casadi as ca
import loop_drives
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.models import loop_backlash as lb
from optdesign.models import loop_linear as ll
from optdesign.models import loop_simulation as ls
from optdesign.models.loop_plant import CascadeLoop, DrivePlant, PositionLoop
from optdesign.models.loop_run import steady_oscillation

ct = pytest.importorskip("control")

TWO_MASS = DrivePlant(**loop_drives.TWO_MASS)
# J = J_m f'^2 + J_2 = 82 t*mm^2: a speed gain Kv puts the rigid speed loop's crossover at
# f' Kv / J (60 Kv / 82 rad/s: 44 rad/s for Kv = 60)
CASCADES = [
    CascadeLoop(position_gain=20.0, speed_gain=60.0, current_lag=2e-4, feedback="motor"),
    CascadeLoop(20.0, 60.0, speed_integral_time=0.1, current_lag=2e-4, feedback="motor"),
    CascadeLoop(15.0, 100.0, speed_integral_time=0.05, current_lag=2e-4, feedback="fin"),
    CascadeLoop(30.0, 80.0, speed_integral_time=0.2, current_lag=0.0, feedback="fin"),
]


def _ids(c: CascadeLoop) -> str:
    return f"{c.feedback}-Ti{c.speed_integral_time:g}"


def _python_control_cascade(plant: DrivePlant, c: CascadeLoop):
    """(L, T) of the cascade from python-control's block algebra, written from the
    equations (not the module): phi / u = f' (c s + k) / Delta, psi / u = f' D_2 / Delta,
    the speed loop u = G C_v (w_ref - s psi), C_v = Kv (1 + 1 / (Ti s)), G the current
    loop, and the position loop w_ref = Kpos (r - y)."""
    s = ct.tf("s")
    J1, J2, f = plant.motor_inertia_at_fin, plant.fin_inertia, plant.ratio
    k, cc = plant.stiffness, plant.damping
    d1 = J1 * s**2 + cc * s + k
    d2 = J2 * s**2 + (cc + plant.fin_damping) * s + k + plant.hinge_spring
    delta = d1 * d2 - (cc * s + k) ** 2
    p_phi = f * (cc * s + k) / delta
    p_psi = f * d2 / delta
    p_y = p_phi if c.feedback == "fin" else p_psi
    cv = (
        c.speed_gain * (1 + 1 / (c.speed_integral_time * s))
        if c.speed_integral_time
        else c.speed_gain * (s / s)
    )
    g = 1 / (c.current_lag * s + 1)
    # the speed loop closed: w_ref -> u
    speed_loop = ct.feedback(ct.series(cv, g), s * p_psi)
    # the position loop around it: r -> y, and the fin's angle
    to_y = ct.series(c.position_gain, speed_loop, p_y)
    closed_y = ct.feedback(to_y, 1)
    T = ct.series(closed_y, p_phi / p_y) if c.feedback == "motor" else closed_y
    # broken at the torque command: u -> -(controller's torque at r = 0)
    L = ct.series(g, cv, ct.parallel(c.position_gain * p_y, s * p_psi))
    return L, T


@pytest.mark.parametrize("cascade", CASCADES, ids=_ids)
def test_cascade_response_equals_python_controls_block_algebra(cascade):
    L_ref, T_ref = _python_control_cascade(TWO_MASS, cascade)
    w = np.geomspace(1.0, 1e5, 61)
    L, T = ll.frequency_response(TWO_MASS, cascade, w)
    assert np.max(np.abs(L - L_ref(1j * w)) / np.abs(L)) < 1e-8
    assert np.max(np.abs(T - T_ref(1j * w)) / np.abs(T)) < 1e-8
    pol = ll.loop_polynomials(TWO_MASS, cascade)
    assert np.allclose(ct.tf(pol.open_numerator, pol.open_denominator)(1j * w), L, rtol=1e-9)
    assert np.allclose(ct.tf(pol.closed_numerator, pol.closed_denominator)(1j * w), T, rtol=1e-9)


@pytest.mark.parametrize("cascade", CASCADES, ids=_ids)
def test_cascade_bandwidth_and_margins_equal_python_controls(cascade):
    pol = ll.loop_polynomials(TWO_MASS, cascade)
    L_ref, T_ref = _python_control_cascade(TWO_MASS, cascade)
    # python-control's bandwidth and margins read a state space / polynomial form; its
    # own block algebra's (not minimal) is reduced first
    T_min = ct.minreal(T_ref, tol=1e-9, verbose=False)
    assert ll.bandwidth(TWO_MASS, cascade) == pytest.approx(
        ct.bandwidth(T_min, dbdrop=-10.0 * math.log10(2.0)), rel=1e-6
    )
    gm, pm, sm, wpc, wgc, wsm = ct.stability_margins(ct.minreal(L_ref, tol=1e-9, verbose=False))
    got = ll.margins(TWO_MASS, cascade)
    assert got.phase_margin == pytest.approx(pm, rel=1e-6)
    assert got.gain_crossover == pytest.approx(wgc, rel=1e-6)
    assert got.stability_margin == pytest.approx(sm, rel=1e-6)
    assert got.stability_margin_frequency == pytest.approx(wsm, rel=1e-4)
    if math.isfinite(gm) and gm < 1e9:
        assert got.gain_margin == pytest.approx(gm, rel=1e-6)
        assert got.phase_crossover == pytest.approx(wpc, rel=1e-6)
    # the poles: the characteristic polynomial's roots are T's
    assert ll.is_stable(TWO_MASS, cascade) == bool(np.all(np.real(T_min.poles()) < 0))
    assert len(ll.closed_loop_poles(TWO_MASS, cascade)) == len(pol.closed_denominator) - 1


def test_cascade_response_on_casadi_symbols_equals_the_numbers():
    # fin position, motor speed: the two channels apart
    c = CASCADES[2]
    J = ca.SX.sym("J")
    args = {**ll.plant_arguments(TWO_MASS, c), "motor_inertia": J}
    r = ll.loop_response(**args, omega=300.0)
    fn = ca.Function("f", [J], [r.open_re, r.open_im, r.closed_re, r.closed_im])
    got = [float(v) for v in fn(TWO_MASS.motor_inertia)]
    L, T = ll.frequency_response(TWO_MASS, c, np.array([300.0]))
    assert got == pytest.approx([L[0].real, L[0].imag, T[0].real, T[0].imag], rel=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    kpos=st.floats(2.0, 200.0),
    kv=st.floats(5.0, 500.0),
    ti=st.sampled_from([0.0, 0.005, 0.05, 0.5]),
    lag=st.sampled_from([0.0, 1e-4, 1e-3]),
    feedback=st.sampled_from(["fin", "motor"]),
)
def test_the_dead_zones_loop_closed_at_unit_gain_is_the_cascades_linear_loop(
    kpos, kv, ti, lag, feedback
):
    # 1 + L_d = 0 with the gap closed (N = 1) is the characteristic equation of the
    # linear loop: the same roots, from two ways of writing the controller's two angles
    loop = CascadeLoop(kpos, kv, ti, lag, feedback)
    num, den = lb.deflection_loop(TWO_MASS, loop)
    lur_e = np.polyadd(num, den)
    char = ll.loop_polynomials(TWO_MASS, loop).closed_denominator
    assert len(lur_e) == len(char)
    ours = list(ll.scaled_roots(lur_e))
    for root in ll.scaled_roots(char):  # each root matched to its nearest, then removed
        k = int(np.argmin([abs(o - root) for o in ours]))
        assert abs(ours.pop(k) - root) < 1e-6 * abs(root)


# --- (b) a P speed loop is the PD loop on the motor -------------------------------------------
def test_a_p_speed_cascade_is_the_pd_loop_on_the_motors_speed():
    kv, kpos = 60.0, 20.0
    pd = PositionLoop(kp=kv * kpos, kd=kv, current_lag=2e-4, feedback="motor")
    cascade = CascadeLoop(kpos, kv, current_lag=2e-4, feedback="motor")
    w = np.geomspace(1.0, 1e5, 41)
    for a, b in zip(
        ll.frequency_response(TWO_MASS, cascade, w),
        ll.frequency_response(TWO_MASS, pd, w),
        strict=True,
    ):
        assert np.max(np.abs(a - b) / np.abs(b)) < 1e-12
    assert ll.bandwidth(TWO_MASS, cascade) == pytest.approx(ll.bandwidth(TWO_MASS, pd), rel=1e-12)
    # with the gap, friction and the limits: the same run
    plant = DrivePlant(
        **loop_drives.TWO_MASS, backlash=math.radians(0.05), friction_torque=5.0, peak_torque=300.0
    )
    step = ls.StepReference(math.radians(2.0))
    a = ls.simulate(plant, cascade, step, 0.2, samples=401)
    b = ls.simulate(plant, pd, step, 0.2, samples=401)
    assert np.max(np.abs(a.fin_angle - b.fin_angle)) <= 1e-12 * math.radians(2.0)
    assert np.max(np.abs(a.motor_torque - b.motor_torque)) <= 1e-12 * 300.0
    assert a.event_kinds == b.event_kinds


# --- (c) the time response of the linear loop ---------------------------------------------
def _state_space_cascade(plant: DrivePlant, c: CascadeLoop):
    """r -> phi as a state space in the motor coordinate, written from the equations:
    states [theta, phi, theta', phi', T_m, z_v],

        J_m theta'' = T_m - tau / f',  J_2 phi'' = tau - k_h phi - c_f phi',
        tau = k (theta / f' - phi) + c (theta' / f' - phi'),
        e_v = Kpos (r - y) - theta' / f',  z_v' = e_v,
        tau_i T_m' = Kv (e_v + z_v / Ti) - T_m.
    """
    Jm, f, J2 = plant.motor_inertia, plant.ratio, plant.fin_inertia
    k, cc, kh, cf = plant.stiffness, plant.damping, plant.hinge_spring, plant.fin_damping
    kv, kpos, ti, lag = c.speed_gain, c.position_gain, c.speed_integral_time, c.current_lag
    tau = np.array([k / f, -k, cc / f, -cc, 0.0, 0.0])
    y = np.array([1.0 / f, 0, 0, 0, 0, 0]) if c.feedback == "motor" else np.eye(6)[1]
    e_v = -kpos * y - np.eye(6)[2] / f  # and + Kpos r
    A = np.zeros((6, 6))
    A[0, 2] = A[1, 3] = 1.0
    A[2] = -tau / (f * Jm) + np.eye(6)[4] / Jm
    A[3] = (tau - kh * np.eye(6)[1] - cf * np.eye(6)[3]) / J2
    A[4] = (kv * (e_v + np.eye(6)[5] / ti) - np.eye(6)[4]) / lag
    A[5] = e_v
    B = np.zeros((6, 1))
    B[4, 0] = kv * kpos / lag
    B[5, 0] = kpos
    return ct.ss(A, B, np.eye(6)[1:2], np.zeros((1, 1)))


@pytest.mark.parametrize("cascade", [CASCADES[1], CASCADES[2]], ids=_ids)
def test_backlash_free_cascade_step_equals_an_independent_state_space(cascade):
    step = math.radians(1.0)
    sim = ls.simulate(TWO_MASS, cascade, ls.StepReference(step), 0.5, samples=501, rtol=1e-9)
    closed = _state_space_cascade(TWO_MASS, cascade)
    # the state space is the loop of (a): its frequency response is T
    w = np.geomspace(1.0, 1e4, 9)
    assert np.allclose(closed(1j * w), ll.frequency_response(TWO_MASS, cascade, w)[1], rtol=1e-8)
    # the simulation starts the current loop's state at the command (its convention for
    # every controller): Kv Kpos r at t = 0
    x0 = np.zeros(6)
    x0[4] = cascade.speed_gain * cascade.position_gain * step
    forced = ct.forced_response(closed, T=sim.times, U=np.full(sim.times.size, step), X0=x0)
    ref = np.ravel(forced.outputs)
    assert np.max(np.abs(sim.fin_angle - ref)) < 1e-5 * step
    # the speed loop's integrator takes the measured angle to the reference: the fin's
    # (fin feedback), or the motor's (motor feedback; the hinge spring then deflects the
    # chain: T(0) = k / (k + k_h))
    static = 1.0 if cascade.feedback == "fin" else 1e7 / (1e7 + 2e4)
    T0 = ll.frequency_response(TWO_MASS, cascade, np.array([1e-6]))[1][0]
    assert abs(T0) == pytest.approx(static, rel=1e-9)


# --- (d) the limit cycle of a hunting cascade --------------------------------------------------
HUNTING = {
    # the fin measured across the gap, the speed integrator on the motor: the classical
    # hunter. Measured against the describing function (docs/loop.md): fin amplitude
    # +1.3 % and +1.8 %, frequency -6.5 % and -5.0 %
    "free fin": ({**loop_drives.TWO_MASS, "hinge_spring": 0.0}, (40.0, 60.0, 0.02)),
    "air spring": (loop_drives.TWO_MASS, (40.0, 60.0, 0.02)),
}


@pytest.mark.parametrize("name", list(HUNTING))
def test_hunting_cascade_cycle_matches_the_harmonic_balance(name):
    params, (kpos, kv, ti) = HUNTING[name]
    plant = DrivePlant(**params, backlash=math.radians(0.1))
    loop = CascadeLoop(kpos, kv, ti, current_lag=2e-4, feedback="fin")
    assert ll.is_stable(plant, loop)  # the gap closed, the loop is stable: the gap hunts
    predicted = max(
        (c for c in lb.limit_cycles(plant, loop).cycles if c.stable), key=lambda c: c.fin_amplitude
    )
    horizon = 3.0
    sim = ls.simulate(
        plant,
        loop,
        ls.StepReference(0.0),
        horizon,
        samples=int(horizon * 2e4) + 1,
        initial_fin_angle=predicted.fin_amplitude,
    )
    amplitude, frequency = steady_oscillation(sim, horizon - 0.5)
    assert amplitude == pytest.approx(predicted.fin_amplitude, rel=0.10)
    assert frequency == pytest.approx(predicted.frequency, rel=0.25)
    # settled: the last half second's cycle is the one before it
    earlier, _ = steady_oscillation(sim, horizon - 1.5)
    assert earlier == pytest.approx(amplitude, rel=0.02)


# --- (e) refusals ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(position_gain=0.0, speed_gain=60.0), "loop.position_gain"),
        (dict(position_gain=20.0, speed_gain=-1.0), "loop.speed_gain"),
        (
            dict(position_gain=20.0, speed_gain=60.0, speed_integral_time=-0.1),
            "loop.speed_integral_time",
        ),
        (dict(position_gain=math.inf, speed_gain=60.0), "loop.position_gain"),
        (dict(position_gain=20.0, speed_gain=60.0, feedback="encoder"), "loop.feedback"),
    ],
)
def test_bad_cascade_gains_are_refused_naming_them(kwargs, field):
    with pytest.raises(InputError) as err:
        CascadeLoop(**kwargs)
    assert err.value.field == field


def test_the_cascades_rational_form_is_its_gains_products():
    c = CascadeLoop(position_gain=20.0, speed_gain=60.0, speed_integral_time=0.1)
    # kp = Kv Kpos, ki = Kv Kpos / Ti, kd = Kv, speed_ki = Kv / Ti on the motor's speed
    assert (c.kp, c.ki, c.kd, c.speed_ki) == pytest.approx((1200.0, 12000.0, 60.0, 600.0))
    assert c.speed_feedback == "motor"
    assert CascadeLoop(20.0, 60.0).ki == 0.0 == CascadeLoop(20.0, 60.0).speed_ki
