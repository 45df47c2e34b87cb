"""optdesign.models.loop_path: the plant that follows the fin angle and the duty cycle's
history.

(a) a path of equal plants is the fixed plant (to 1e-9); (b) a rigid, backlash-free,
frictionless drive through a crank-slider's varying ratio against Lagrange's equation in
the fin's angle, written and integrated here; (c) without friction, damping and motor
torque, kinetic plus elastic energy is conserved over a free swing across the stroke
(hypothesis); (d) the duty cycle's deflection history and load; (e) refusals.
"""

from __future__ import annotations

import dataclasses
import math

import loop_drives
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from optdesign.errors import InputError
from optdesign.models import loop_simulation as ls
from optdesign.models.loop_path import DrivePath, LoadHistory, duty_history
from optdesign.models.loop_plant import CascadeLoop, DrivePlant, PositionLoop

B = math.radians(0.1)
GRID = np.linspace(-0.6, 0.6, 61)


def _constant_path(plant: DrivePlant) -> DrivePath:
    return DrivePath.from_plants([dataclasses.replace(plant, angle=a) for a in GRID])


# --- (a) a constant path is the fixed plant -----------------------------------------------
@pytest.mark.parametrize(
    "reference, loop",
    [
        (ls.StepReference(math.radians(1.0)), PositionLoop(kp=1500.0, kd=45.0, current_lag=1e-4)),
        (ls.SineReference(math.radians(0.5), 40.0), PositionLoop(kp=1500.0, kd=45.0, ki=2e3)),
        (
            ls.StepReference(math.radians(1.0)),
            CascadeLoop(25.0, 60.0, speed_integral_time=0.1, current_lag=1e-4),
        ),
    ],
    ids=["step, PD and lag", "sine, PID", "step, PI cascade"],
)
def test_a_path_of_equal_plants_responds_as_the_fixed_plant(reference, loop):
    """The gap, friction (stick and slip), the peak torque, the speed limit and the
    current loop, under a PID or the position/speed cascade: every event of the fixed
    plant, at the same times, and the samples to 1e-9 of their range."""
    plant = DrivePlant(
        **loop_drives.TWO_MASS,
        backlash=B,
        friction_torque=2.0,
        peak_torque=60.0,
        max_speed=200.0,
    )
    fixed = ls.simulate(plant, loop, reference, 0.3, samples=3001)
    path = ls.simulate(_constant_path(plant), loop, reference, 0.3, samples=3001)
    assert len(fixed.event_kinds) > 20 and path.event_kinds == fixed.event_kinds
    np.testing.assert_allclose(path.event_times, fixed.event_times, rtol=0, atol=1e-12)
    for name in ("fin_angle", "motor_angle", "motor_rate", "motor_torque", "chain_torque"):
        a, b = getattr(fixed, name), getattr(path, name)
        assert np.max(np.abs(a - b)) <= 1e-9 * np.ptp(a), name
    np.testing.assert_array_equal(path.contact, fixed.contact)


# --- (b) a varying ratio against Lagrange's equation --------------------------------------
# a crank-slider's nut position x(phi) (mm) and the motor's angle theta = 2 pi i x / p
R, L, N, BETA, I, P = 60.0, 110.0, 45.0, 0.4, 2.0, 5.0


def _nut(phi):
    u = phi + BETA
    return R * np.sin(u) + np.sqrt(L**2 - (R * np.cos(u) - N) ** 2)


def _g1(phi, h=1e-5):
    return 2 * np.pi * I / P * (_nut(phi + h) - _nut(phi - h)) / (2 * h)


def _g2(phi, h=1e-4):
    return 2 * np.pi * I / P * (_nut(phi + h) - 2 * _nut(phi) + _nut(phi - h)) / h**2


def test_a_stiff_path_follows_lagrange_s_equation_of_the_rigid_linkage():
    """Kinetic energy J_m theta'^2 / 2 + J_2 phi'^2 / 2 with theta = g(phi) (the nut's
    position of a crank-slider whose ratio falls from 144 to 67 across the stroke):
    (J_m g'^2 + J_2) phi'' + J_m g' g'' phi'^2 = g' T - k_h phi - c_f phi', T the PD law,
    integrated here with g' and g'' from differences of the nut's position. The path
    simulation with a chain of 1e11 N*mm/rad and no gap follows a 40 deg ramp to 1e-6 of
    it (9.4e-8 measured: the chain's deflection and the spline's error); the ratio held
    at one angle (no f'', no change of the inertia) misses by 4.8e5 times more."""
    ratio = _g1(GRID)
    assert ratio[0] / ratio[-1] > 2.1  # the ratio changes by a factor 2.15 on the stroke
    Jm, J2, kh, cf = 0.02, 10.0, 2e4, 20.0
    k = 1e11
    common = dict(motor_inertia=Jm, fin_inertia=J2, hinge_spring=kh, fin_damping=cf)
    path = DrivePath(
        angles=tuple(GRID),
        ratio=tuple(ratio),
        stiffness=(k,) * GRID.size,
        damping=(2 * 0.3 * math.sqrt(k * J2 * Jm * 90.0**2 / (J2 + Jm * 90.0**2)),) * GRID.size,
        backlash=(0.0,) * GRID.size,
        **common,
    )
    loop = PositionLoop(kp=2000.0, kd=60.0)
    start, end, T = -0.35, 0.35, 0.4
    ref = ls.SampledReference((0.0, 0.2), (start, end))
    sim = ls.simulate(
        path,
        loop,
        ref,
        T,
        samples=401,
        initial_motor_angle=start,
        initial_fin_angle=start,
        rtol=1e-9,
    )

    def lagrange(t, y):
        phi, w = y
        g1, g2 = _g1(phi), _g2(phi)
        torque = loop.kp * (ref(t) - phi) - loop.kd * w
        return [w, (g1 * torque - kh * phi - cf * w - Jm * g1 * g2 * w * w) / (Jm * g1**2 + J2)]

    exact = solve_ivp(lagrange, (0, T), [start, 0.0], t_eval=sim.times, rtol=1e-11, atol=1e-12)
    error = np.max(np.abs(sim.fin_angle - exact.y[0]))
    assert error < 1e-6 * (end - start)
    assert np.max(np.abs(sim.motor_rate - exact.y[1])) < 4e-6 * np.max(np.abs(exact.y[1]))
    # the ratio held at -14 deg's (no f'', nor the inertia's change) is far off
    held = ls.simulate(
        dataclasses.replace(path, ratio=(ratio[18],) * GRID.size),
        loop,
        ref,
        T,
        samples=401,
        initial_motor_angle=start,
        initial_fin_angle=start,
    )
    assert np.max(np.abs(held.fin_angle - exact.y[0])) > 1e4 * error


# --- (c) energy -------------------------------------------------------------------------
def _energy(path: DrivePath, sim) -> np.ndarray:
    """J_m (f' psi')^2 / 2 + J_2 phi'^2 / 2 + k (|psi - phi| - b)_+^2 / 2 + k_h phi^2 / 2."""
    out = []
    for psi, phi, w1, w2 in zip(
        sim.motor_angle, sim.fin_angle, sim.motor_rate, sim.fin_rate, strict=True
    ):
        f, _, k, _, _, b, _ = path.at(psi)
        p = max(abs(psi - phi) - b, 0.0)
        out.append(
            0.5 * path.motor_inertia * (f * w1) ** 2
            + 0.5 * path.fin_inertia * w2**2
            + 0.5 * k * p**2
            + 0.5 * path.hinge_spring * phi**2
        )
    return np.array(out)


@settings(max_examples=6, deadline=None)
@given(
    beta=st.floats(0.0, 0.4),
    stiffness_slope=st.floats(-0.5, 0.5),
    gap=st.one_of(st.just(0.0), st.floats(0.02, 0.3)),
    start=st.floats(-0.5, -0.2),
    offset=st.floats(-1.0, 1.0),
)
def test_kinetic_and_elastic_energy_are_conserved_in_a_free_swing(
    beta, stiffness_slope, gap, start, offset
):
    """No friction, no damping, no load, the motor's torque held below 1e-9 N*mm: the fin
    swings on its hinge spring from rest at ``start`` through the stroke's middle, through
    a crank-slider's ratio and a chain whose stiffness and gap change along the stroke.
    Kinetic plus elastic energy stays within 1e-6 of its start."""
    u = GRID + beta
    nut_rate = R * np.cos(u) + (R * np.cos(u) - N) * R * np.sin(u) / np.sqrt(
        L**2 - (R * np.cos(u) - N) ** 2
    )
    b = math.radians(gap) * (1.0 + 0.5 * np.sin(3 * GRID))
    path = DrivePath(
        angles=tuple(GRID),
        ratio=tuple(2 * np.pi * I / P * nut_rate),
        stiffness=tuple(1e7 * (1.0 + stiffness_slope * GRID)),
        damping=(0.0,) * GRID.size,
        backlash=tuple(b),
        motor_inertia=0.001,
        fin_inertia=10.0,
        hinge_spring=1e5,
        peak_torque=1e-9,
    )
    psi0 = start + offset * float(b[0])
    sim = ls.simulate(
        path,
        PositionLoop(kp=1.0),
        ls.StepReference(0.0),
        0.06,
        samples=601,
        initial_motor_angle=psi0,
        initial_fin_angle=start,
        rtol=1e-10,
        max_events=20_000,
    )
    assert np.max(sim.fin_angle) > 0.0  # across the middle of the stroke
    e = _energy(path, sim)
    assert np.max(np.abs(e - e[0])) < 1e-6 * e[0]


# --- (d) the duty cycle -----------------------------------------------------------------
def test_the_duty_history_holds_each_step_after_a_ramp_at_the_rate_taken_from_its_time():
    """Steps 0, 15 and -25 deg for 0.6, 0.3 and 0.1 of 5 s, at 120 deg/s: step 1 holds
    from 0.125 s after its window opens at 3 s; step 2's window opens at 4.5 s, its ramp
    of 40 deg takes 1/3 s; the second period begins with the 25 deg ramp back to 0 (5/24
    s). The load is -s M + k_h phi_k: the moment opposing the deflection, at 0 deg the
    move into it (from -25 deg, upwards: -150 N*m)."""
    deg = math.radians
    h = duty_history(
        [0.0, deg(15), deg(-25)],
        [150e3, 300e3, 450e3],
        [0.6, 0.3, 0.1],
        5.0,
        deg(120),
        2,
        hinge_spring=-5e5,
    )
    assert h.horizon == pytest.approx(10.0)
    starts = [(round(a, 9), round(b, 9), k) for a, b, k in h.holds]
    assert starts[:4] == [
        (0.0, 3.0, 0),
        (3.125, 4.5, 1),
        (4.833333333, 5.0, 2),
        (5.208333333, 8.0, 0),
    ]
    ref = h.reference
    assert ref(3.0) == 0.0 and ref(3.0625) == pytest.approx(deg(7.5))
    assert ref(4.5) == pytest.approx(deg(15)) and ref(4.6) == pytest.approx(deg(3))
    assert np.max(np.abs(np.diff(ref.angles) / np.diff(ref.times))) == pytest.approx(deg(120))
    assert h.load(1.0) == pytest.approx(-150e3)
    assert h.load(3.01) == pytest.approx(-300e3 - 5e5 * deg(15))
    assert h.load(4.9) == pytest.approx(450e3 + 5e5 * deg(25))
    assert h.load.breaks == pytest.approx((3.0, 4.5, 5.0, 8.0, 9.5))


# --- (e) refusals ---------------------------------------------------------------------------
def test_a_bad_path_a_reference_off_its_grid_and_a_load_without_a_path_are_refused():
    plant = DrivePlant(**loop_drives.TWO_MASS)
    path = _constant_path(plant)
    loop = PositionLoop(kp=1500.0, kd=45.0)
    with pytest.raises(InputError, match=r"path.angles"):
        dataclasses.replace(path, angles=tuple(GRID[::-1]))
    with pytest.raises(InputError, match=r"path.ratio.*positive"):
        dataclasses.replace(path, ratio=(0.0,) * GRID.size)
    with pytest.raises(InputError, match=r"path.backlash.*5"):
        dataclasses.replace(path, backlash=(0.1,) * GRID.size)
    with pytest.raises(InputError, match=r"path.stiffness.*one value per angle"):
        dataclasses.replace(path, stiffness=(1e7,))
    with pytest.raises(InputError, match=r"plant.motor_inertia.*varies"):
        DrivePath.from_plants([plant, dataclasses.replace(plant, motor_inertia=0.03, angle=1)])
    with pytest.raises(InputError, match=r"reference.*leaves the path's grid"):
        ls.simulate(path, loop, ls.StepReference(0.7), 0.1)
    with pytest.raises(InputError, match=r"initial_fin_angle.*leaves"):
        ls.simulate(path, loop, ls.StepReference(0.1), 0.1, initial_fin_angle=-0.65)
    with pytest.raises(InputError, match=r"load.*DrivePath"):
        ls.simulate(plant, loop, ls.StepReference(0.1), 0.1, load=LoadHistory((0.0,), (1.0,)))
    deg = math.radians
    args = ([0.0, deg(15), deg(-25)], [150e3, 300e3, 450e3], [0.6, 0.3, 0.1])
    with pytest.raises(InputError, match=r"period.*step 2.*lengthen the period"):
        duty_history(*args, 3.0, deg(120))
    with pytest.raises(InputError, match=r"periods.*600 s"):
        duty_history(*args, 5.0, deg(120), 121)
    with pytest.raises(InputError, match=r"periods.*whole number"):
        duty_history(*args, 5.0, deg(120), 0)
