"""optdesign.models.loop_simulation (issue 38).

(a) a rigid, backlash-free drive under PD control against the closed-form step of its
second-order loop; (b) the limit cycle the chain's clearance sustains against the
harmonic balance of loop_backlash (amplitude within 10 %, frequency within 25 %);
(c) invariants: the contact never pulls and carries nothing in the gap, the mechanical
energy balance closes, friction, saturation and the speed limit hold; (d) bad input is
refused naming the field and its limit.
"""

from __future__ import annotations

import math

import loop_drives
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.models import loop_backlash as lb
from optdesign.models import loop_linear as ll
from optdesign.models import loop_simulation as ls
from optdesign.models.loop_plant import DrivePlant, PositionLoop
from optdesign.models.loop_run import steady_oscillation
from optdesign.models.motor import step_response

B = math.radians(0.1)
TWO_MASS = loop_drives.TWO_MASS


# --- (a) the rigid loop -------------------------------------------------------------------
def test_rigid_backlash_free_step_is_the_second_order_closed_form():
    # a chain 100 times stiffer than the two-mass one (its mode near 1.1e4 rad/s, 330
    # times the loop's): PD on the fin, no lag, no hinge spring
    plant = DrivePlant(motor_inertia=0.02, ratio=60.0, fin_inertia=10.0, stiffness=1e9, damping=3e3)
    loop = PositionLoop(kp=1500.0, kd=40.0)
    wn = ll.rigid_natural_frequency(plant, loop)  # sqrt(60 * 1500 / 82) = 33.13 rad/s
    zeta = 60.0 * 40.0 / 82.0 / (2.0 * wn)  # 0.4417
    step = 0.1
    sim = ls.simulate(plant, loop, ls.StepReference(step), 0.3, samples=301)
    closed = step * step_response(sim.times, wn, zeta)
    assert np.max(np.abs(sim.fin_angle - closed)) < 1e-4 * step
    # the motor's torque is the PD law on the fin: kp e - kd phi'
    assert sim.motor_torque[0] == pytest.approx(1500.0 * step)
    assert sim.event_times == ()
    assert np.all(sim.contact[1:] != 0)


# --- (b) the limit cycle against harmonic balance -----------------------------------------
CYCLING = {
    # fin feedback, a chain resonance near 1070 rad/s: settles within 0.2 s
    "two-mass": (TWO_MASS, dict(kp=1500.0, kd=45.0, current_lag=1e-4, feedback="fin"), 0.5),
    # a chain 3 times stiffer: the cycle near 1750 rad/s, settling in about 1 s
    "stiff chain": (
        {**TWO_MASS, "stiffness": 3e7},
        dict(kp=1500.0, kd=60.0, current_lag=1e-4, feedback="fin"),
        1.0,
    ),
}


@pytest.mark.parametrize("name", list(CYCLING))
def test_simulated_limit_cycle_matches_the_harmonic_balance(name):
    params, gains, horizon = CYCLING[name]
    plant, loop = DrivePlant(**params, backlash=B), PositionLoop(**gains)
    predicted = max(
        (c for c in lb.limit_cycles(plant, loop).cycles if c.stable), key=lambda c: c.fin_amplitude
    )
    # started at the predicted amplitude (the cycle is weakly attracting)
    sim = ls.simulate(
        plant,
        loop,
        ls.StepReference(0.0),
        horizon,
        samples=int(horizon * 2e4) + 1,
        initial_fin_angle=predicted.fin_amplitude,
    )
    amplitude, frequency = steady_oscillation(sim, horizon - 0.2)
    assert amplitude == pytest.approx(predicted.fin_amplitude, rel=0.10)
    assert frequency == pytest.approx(predicted.frequency, rel=0.25)
    # four contact changes a period at most (close, unload, open, ... on each flank)
    kinds = np.array(sim.event_kinds)
    late = np.array(sim.event_times) > horizon - 0.2
    closes = np.count_nonzero(late & (kinds == "closes"))
    assert closes == pytest.approx(2 * 0.2 * frequency / (2 * math.pi), abs=2)


# --- (c) invariants -------------------------------------------------------------------------
def _energy_terms(sim: ls.LoopSimulation):
    p = sim.plant
    J1 = p.motor_inertia_at_fin
    energy = (
        0.5 * J1 * sim.motor_rate**2
        + 0.5 * p.fin_inertia * sim.fin_rate**2
        + 0.5 * p.hinge_spring * sim.fin_angle**2
    )
    friction = np.where(
        sim.motor_rate != 0, p.ratio * p.friction_torque * np.abs(sim.motor_rate), 0.0
    )
    power = (
        p.ratio * sim.motor_torque * sim.motor_rate
        - friction
        - p.fin_damping * sim.fin_rate**2
        - sim.chain_torque * (sim.motor_rate - sim.fin_rate)
    )
    return energy, power


@settings(max_examples=12, deadline=None)
@given(
    b_deg=st.floats(0.01, 0.5),
    damping=st.floats(0.0, 3000.0),
    kd=st.floats(20.0, 90.0),
    feedback=st.sampled_from(["fin", "motor"]),
    step_deg=st.floats(0.05, 5.0),
    sign=st.sampled_from([-1.0, 1.0]),
)
def test_contact_never_pulls_and_the_energy_balance_closes(
    b_deg, damping, kd, feedback, step_deg, sign
):
    # steps of 0.05 deg and more: the tolerances follow the reference's and the gap's scale
    plant = DrivePlant(**{**TWO_MASS, "damping": damping}, backlash=math.radians(b_deg))
    loop = PositionLoop(kp=1500.0, kd=kd, current_lag=1e-4, feedback=feedback)
    sim = ls.simulate(
        plant, loop, ls.StepReference(sign * math.radians(step_deg)), 0.15, samples=30001
    )
    d = sim.motor_angle - sim.fin_angle
    # never pulling: the torque has the sign of the deflection, nothing inside the gap
    assert np.all(sim.chain_torque * np.sign(d) >= -1e-9 * (1 + np.abs(sim.chain_torque)))
    inside = np.abs(d) < plant.backlash * (1 - 1e-6)
    assert np.all(sim.chain_torque[inside] == 0.0)
    assert np.all(sim.contact[inside] == 0)
    # the contact torque is at most the spring's and damper's: k (|d| - b) + c |d'|
    bound = plant.stiffness * np.maximum(np.abs(d) - plant.backlash, 0) + damping * np.abs(
        sim.motor_rate - sim.fin_rate
    )
    assert np.all(np.abs(sim.chain_torque) <= bound * (1 + 1e-9) + 1e-9)
    # energy: kinetic + hinge's at the end = at the start + the work put in (trapezoid)
    energy, power = _energy_terms(sim)
    work = np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(sim.times))
    scale = np.max(np.abs(energy)) + np.sum(np.abs(power[:-1]) * np.diff(sim.times))
    assert energy[-1] - energy[0] == pytest.approx(work, abs=2e-3 * scale)


def test_friction_sticks_the_motor_within_its_band():
    # motor feedback, PD: the motor stops where |f' T - tau| <= f' T_f
    plant = DrivePlant(**TWO_MASS, backlash=B, friction_torque=40.0)
    loop = PositionLoop(kp=2000.0, kd=60.0, current_lag=2e-4, feedback="motor")
    sim = ls.simulate(plant, loop, ls.StepReference(math.radians(3.0)), 1.0, samples=2001)
    assert "stops" in sim.event_kinds
    assert sim.motor_rate[-1] == 0.0
    held = plant.ratio * sim.motor_torque[-1] - sim.chain_torque[-1]
    assert abs(held) <= plant.ratio * plant.friction_torque * (1 + 1e-9)
    # stuck: the motor's angle does not move over the last tenth of the run
    late = sim.times > 0.9
    assert np.ptp(sim.motor_angle[late]) == 0.0


def test_a_delayed_step_frees_a_stuck_motor_once():
    # no current lag: the command jumps with the reference at 0.05 s, from inside the
    # friction band to far beyond it; the motor slips there, once
    plant = DrivePlant(**TWO_MASS, backlash=4.1e-4, friction_torque=20.0)
    loop = PositionLoop(kp=2000.0, kd=35.0, ki=3000.0, feedback="fin")
    sim = ls.simulate(plant, loop, ls.StepReference(-0.07, time=0.05), 0.3, samples=301)
    assert sim.event_times[0] == 0.05 and sim.event_kinds[0] == "slips"
    assert sim.event_times.count(0.05) == 1
    assert np.all(sim.motor_rate[sim.times < 0.05] == 0.0)
    assert sim.motor_rate[sim.times > 0.05][0] < 0.0


def test_saturation_and_speed_limit_bound_the_motor():
    plant = DrivePlant(
        **TWO_MASS, backlash=B, friction_torque=30.0, peak_torque=250.0, max_speed=150.0
    )
    loop = PositionLoop(kp=2000.0, kd=60.0, ki=8000.0, current_lag=2e-4, feedback="motor")
    sim = ls.simulate(plant, loop, ls.StepReference(math.radians(10.0)), 1.0, samples=4001)
    # the torque-speed curve's corner: the speed settles in the last 1 % below the limit
    top = np.max(np.abs(sim.motor_rate)) * plant.ratio
    assert 150.0 * (1 - ls.SPEED_BAND) < top <= 150.0
    assert np.max(np.abs(sim.motor_torque)) <= 250.0 + 1e-9
    assert "speed limit" in sim.event_kinds and "speed released" in sim.event_kinds
    # in the corner the torque is the command's, scaled down linearly to none at the top
    speed = sim.motor_rate * plant.ratio
    corner = speed > 150.0 * (1 - ls.SPEED_BAND) + 1e-6
    assert np.all(sim.motor_torque[corner] <= 250.0 * (150.0 - speed[corner]) / 1.5 + 1e-9)
    # the linear loop would need 10 deg * kp = 349 N*mm at once: the command saturates
    assert np.max(sim.motor_torque) == pytest.approx(250.0)


def test_above_the_speed_limit_the_motor_only_brakes():
    # an undamped chain rings and drives the motor past its limit: there the motor
    # applies no torque in the direction of motion
    plant = DrivePlant(
        motor_inertia=0.0251,
        ratio=63.47,
        fin_inertia=3.204,
        stiffness=1.438e7,
        hinge_spring=1.324e4,
        max_speed=150.0,
    )
    loop = PositionLoop(kp=1634.7, kd=20.26, ki=3000.0, feedback="motor")
    sim = ls.simulate(plant, loop, ls.SineReference(math.radians(3.0), 30.0), 0.3, samples=30001)
    speed = sim.motor_rate * plant.ratio
    above = np.abs(speed) > 150.0 * (1 + 1e-9)
    assert np.count_nonzero(above) > 10
    assert np.all(sim.motor_torque[above] * np.sign(speed[above]) <= 0.0)


def test_sampled_reference_reproduces_the_sine():
    plant = DrivePlant(**TWO_MASS, backlash=B)
    loop = PositionLoop(kp=2000.0, kd=60.0, current_lag=2e-4, feedback="motor")
    sine = ls.SineReference(math.radians(2.0), 20.0)
    t = np.linspace(0.0, 0.4, 8001)
    sampled = ls.SampledReference(tuple(t), tuple(sine(x) for x in t))
    a = ls.simulate(plant, loop, sine, 0.4, samples=401)
    b = ls.simulate(plant, loop, sampled, 0.4, samples=401)
    assert np.max(np.abs(a.fin_angle - b.fin_angle)) < 1e-3 * math.radians(2.0)
    assert np.max(np.abs(a.reference - b.reference)) < 1e-5
    # the loop tracks: |T(j20)| of the linear loop within the gap's play
    _, T = ll.frequency_response(plant, loop, 20.0)
    late = a.times > 0.25
    assert np.max(np.abs(a.fin_angle[late])) == pytest.approx(abs(T) * math.radians(2.0), abs=2 * B)


# --- (d) refusals ---------------------------------------------------------------------------
def test_bad_input_is_refused_naming_the_field_and_its_limit():
    plant, loop = DrivePlant(**TWO_MASS, backlash=B), PositionLoop(kp=1500.0)
    step = ls.StepReference(0.1)
    with pytest.raises(InputError, match=r"horizon.*600") as err:
        ls.simulate(plant, loop, step, 1e9)
    assert err.value.field == "horizon"
    with pytest.raises(InputError, match=r"samples.*1000000"):
        ls.simulate(plant, loop, step, 1.0, samples=10**9)
    with pytest.raises(InputError, match=r"reference.amplitude.*pi"):
        ls.StepReference(math.inf)
    with pytest.raises(InputError, match=r"reference.amplitude"):
        ls.SineReference(math.nan, 10.0)
    with pytest.raises(InputError, match=r"reference.frequency"):
        ls.SineReference(0.1, -1.0)
    with pytest.raises(InputError, match=r"reference.times"):
        ls.SampledReference((0.0, 0.0), (0.0, 0.1))
    with pytest.raises(InputError, match=r"reference.angles"):
        ls.SampledReference((0.0, 1.0), (0.0, 10.0))
    with pytest.raises(InputError, match="reference"):
        ls.simulate(plant, loop, 0.1, 1.0)
    with pytest.raises(InputError, match="initial_fin_angle"):
        ls.simulate(plant, loop, step, 1.0, initial_fin_angle=math.nan)
    with pytest.raises(InputError, match="rtol"):
        ls.simulate(plant, loop, step, 1.0, rtol=0.5)
    with pytest.raises(InputError, match=r"max_events.*200000"):
        ls.simulate(plant, loop, step, 1.0, max_events=10**7)


def test_a_run_with_more_events_than_allowed_is_refused():
    plant = DrivePlant(**TWO_MASS, backlash=B)
    loop = PositionLoop(kp=1500.0, kd=45.0, current_lag=1e-4, feedback="fin")
    with pytest.raises(InputError, match="max_events"):
        ls.simulate(plant, loop, ls.StepReference(0.0), 0.5, initial_fin_angle=0.005, max_events=20)
