"""The cascade of ``[loop] structure = "cascade"``: its gains placed from a bandwidth
against the PD placement of the same drive, fixed gains read in internal units, the
loop's rows of problems/fin_actuator_cascade.toml against the cascade's own frequency
response (NumPy and solver paths), its optimum, ``od.simulate`` with it, and every wrong
field refused with its name and reason (API, command line in both output modes)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from cli_refusal import command_line_refusal

import optdesign as od
from optdesign.errors import InputError
from optdesign.models import loop_linear as ll
from optdesign.models.loop_plant import CascadeLoop, PositionLoop
from optdesign.models.loop_references import StepReference
from optdesign.models.loop_simulation import simulate
from optdesign.problem.loop import (
    bandwidth_factor,
    drive_plants_of,
    loop_angles,
    loop_gains,
    position_loop,
)
from optdesign.problem.loop_time import design_plant

ROOT = Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "problems"

#: fin_actuator_motor's optimum (tests/problem/test_loop_requirements.py): 10 mm pins.
MOTOR_OPTIMUM = {"R": 105.5714658, "l": 59.7942416, "n": 102.0869895, "phi0": 0.2292040,
                 "d0": 25.0, "p": 5.0, "d": 10.0}  # fmt: skip


def _with_loop(**loop) -> dict:
    data = tomllib.loads((PROBLEMS / "fin_actuator_motor.toml").read_text())
    data["loop"] = loop
    return data


def _x(problem, values=MOTOR_OPTIMUM):
    return np.array([values[v.name] for v in problem.free])


def _quantities(problem, values=MOTOR_OPTIMUM):
    return problem.quantities(problem.design_dict(_x(problem, values)))


@pytest.fixture(scope="module")
def problem():
    return od.load(PROBLEMS / "fin_actuator_cascade.toml")


# --- the gains -----------------------------------------------------------------------------
def test_a_cascade_placed_from_a_bandwidth_is_the_pd_placement_on_the_motors_speed():
    """Kv = kd and Kv Kpos = kp of the PD placed for the same 9 Hz and damping ratio: the
    P speed loop equal to that PD with its derivative on the motor's speed; on the rigid
    drive at the mean ratio, (c_fin + f' Kv) / J = 2 zeta w_n and Kpos = (J w_n^2 - k_h) /
    (2 zeta w_n J - c_fin)."""
    pd = position_loop(_quantities(od.load(_with_loop(bandwidth="9 Hz", current_lag="0.5 ms"))))
    cascade_problem = od.load(
        _with_loop(
            structure="cascade",
            bandwidth="9 Hz",
            speed_integral_time="50 ms",
            current_lag="0.5 ms",
        )
    )
    q = _quantities(cascade_problem)
    cascade = position_loop(q)
    assert isinstance(pd, PositionLoop) and isinstance(cascade, CascadeLoop)
    assert cascade.speed_gain == pytest.approx(pd.kd, rel=1e-12)
    assert cascade.speed_gain * cascade.position_gain == pytest.approx(pd.kp, rel=1e-12)
    assert cascade.speed_integral_time == pytest.approx(0.05, rel=1e-12)
    assert cascade.feedback == "fin" and cascade.speed_feedback == "motor"
    f = float(np.mean(np.asarray(q.ratio)))
    J = float(np.mean(np.asarray(q.motor_side_inertia))) * f**2 + 500.0
    wn = 2 * math.pi * 9.0 / bandwidth_factor(0.7)
    # c_fin = 5 N*m*s/rad, k_h = -500 N*m/rad
    assert (5e3 + f * cascade.speed_gain) / J == pytest.approx(2 * 0.7 * wn, rel=1e-12)
    assert cascade.position_gain == pytest.approx(
        (J * wn**2 + 5e5) / (2 * 0.7 * wn * J - 5e3), rel=1e-12
    )
    # the rule in numbers: the speed loop's crossover 77.8 rad/s, 1.89 times Kpos = 41.1 /s
    assert f * cascade.speed_gain / J == pytest.approx(77.76, abs=0.01)
    assert cascade.position_gain == pytest.approx(41.10, abs=0.01)


def test_fixed_cascade_gains_pass_through_in_internal_units():
    problem = od.load(
        _with_loop(
            structure="cascade",
            position_gain="25 1/s",
            speed_gain="3 N*m*s/rad",
            speed_integral_time="20 ms",
            feedback="motor",
        )
    )
    gains = loop_gains(_quantities(problem))
    # kp = Kv Kpos = 3e3 * 25, ki = kp / Ti, kd = Kv, speed_ki = Kv / Ti on the motor
    assert (gains.kp, gains.kd, gains.ki, gains.speed_ki) == pytest.approx(
        (7.5e4, 3e3, 7.5e4 / 0.02, 3e3 / 0.02), rel=1e-12
    )
    assert gains.speed_on == "motor" and gains.feedback == "motor"
    loop = position_loop(_quantities(problem))
    assert (loop.position_gain, loop.speed_gain) == pytest.approx((25.0, 3e3), rel=1e-12)
    # without speed_integral_time, a P speed loop
    p_loop = position_loop(
        _quantities(
            od.load(
                _with_loop(structure="cascade", position_gain="25 1/s", speed_gain="3 N*m*s/rad")
            )
        )
    )
    assert p_loop.speed_integral_time == 0.0 and p_loop.ki == 0.0 == p_loop.speed_ki


# --- the rows of the shipped cascade -----------------------------------------------------
def test_the_cascades_rows_are_its_own_frequency_response(problem):
    """At each of the seven loop angles: the bandwidth row is |T(j w_b)|^2 / |T(0)|^2 of
    the cascade's response, the resonance row |L(j w_r)|, the phase-margin row at most
    the least |1 + L| on its frequencies; the solver's rows evaluate to the same numbers."""
    x = _x(problem)
    q = _quantities(problem)
    plants, loop = drive_plants_of(q, loop_angles(problem))[0]
    assert isinstance(loop, CascadeLoop)
    ev = problem.evaluate(x)
    bandwidth = np.asarray(ev.constraints["bandwidth"].values)
    resonance = np.asarray(ev.constraints["resonance_margin"].values)
    w_r = np.sqrt(np.asarray(q.two_mass_frequency_squared).ravel()[loop_angles(problem)])
    for row_b, row_r, plant, wr in zip(bandwidth, resonance, plants, w_r, strict=True):
        _, T = ll.frequency_response(plant, loop, 2 * math.pi * 9.0)
        pol = ll.loop_polynomials(plant, loop)
        t0 = np.polyval(pol.closed_numerator, 0.0) / np.polyval(pol.closed_denominator, 0.0)
        assert t0 == pytest.approx(1.0, rel=1e-12)  # the speed integrator: type 1 on the fin
        assert row_b == pytest.approx(abs(T) ** 2, rel=1e-7)
        L, _ = ll.frequency_response(plant, loop, wr)
        assert row_r == pytest.approx(abs(L), rel=1e-9)
        assert 11.5 < ll.bandwidth(plant, loop) / (2 * math.pi) < 11.7
    names = ["R", "l", "n", "phi0"]
    X = ca.SX.sym("x", len(names))
    design = problem.design_dict(x)
    design.update({name: X[k] for k, name in enumerate(names)})
    symbolic = {b.name: b.expr for b in problem.expressions(design, guarded=True).constraints}
    at = [MOTOR_OPTIMUM[name] for name in names]
    for name in ("bandwidth", "phase_margin", "resonance_margin"):
        f = ca.Function("f", [X], [symbolic[name]])
        np.testing.assert_allclose(
            np.asarray(f(at)).ravel(), np.asarray(ev.constraints[name].values), rtol=1e-9
        )


def test_fin_actuator_cascade_keeps_the_10_mm_pins(problem):
    """The motor-speed loop's gain at the drive's own mode is 0.031-0.037 at the loop's
    angles (a resonance margin of 26.7 or more; 26.5 at +14 deg over the whole grid),
    against the fin PD's 2.80 on the same design: the 10 mm pins pass, and the optimum is fin_actuator_motor's, backlash 0.0377566 deg, with every loop
    requirement met: least bandwidth 11.58 Hz, largest limit cycle 0.0231 deg."""
    result = od.solve(problem, ranges=False, sensitivities=False)
    assert result.status == "optimal" and result.verified
    assert result.design["d"] == 10 and result.design["d0"] == 25.0
    assert result.objective == pytest.approx(0.0377566, rel=1e-6)
    assert 1.0 / result.objectives["bandwidth_period"] == pytest.approx(11.58, abs=0.01)
    assert result.objectives["limit_cycle_amplitude"] == pytest.approx(0.0231, abs=1e-4)
    assert 1.0 / result.objectives["resonance_gain"] == pytest.approx(26.5, abs=0.1)
    # od.simulate runs the cascade: a 1 deg step at 0 deg comes to rest at the reference
    # (the speed integrator on the fin's error; friction quenches the cycle the describing
    # function predicts, docs/loop.md)
    sim = od.simulate(result, amplitude="1 deg", angle="0 deg", horizon="1 s", samples=2001)
    r = sim.response
    assert isinstance(r.loop, CascadeLoop)
    tail = np.degrees(r.fin_angle[r.times > 0.8])
    assert tail.mean() == pytest.approx(1.0, abs=2e-3)
    assert np.ptp(tail) < 1e-3
    # held longer, the speed integrator winds up against the motor's friction at rest and
    # the motor sticks and slips ever faster (the hybrid friction has no dwell): the run
    # is refused at its event limit saying so, not returned as a number
    at = design_plant(problem, result.design, "0 deg")
    with pytest.raises(InputError, match=r"^max_events: .*the motor sticks and slips ever"):
        simulate(at.plant, at.loop, StepReference(math.radians(1.0)), 2.0, 101, max_events=300)


# --- refusals ---------------------------------------------------------------------------
KV = "0.3 N*m*s/rad"
REFUSED = [
    ({"structure": "cascade"}, "position_gain: needed"),
    ({"structure": "cascade", "position_gain": "20 1/s"}, "speed_gain: needed"),
    (
        {"structure": "cascade", "position_gain": "-5 1/s", "speed_gain": KV},
        "position_gain: must be positive, got -5 1/s",
    ),
    (
        {"structure": "cascade", "position_gain": "20 1/s", "speed_gain": "-0.3 N*m*s/rad"},
        "speed_gain: must be positive, got -0.3 N*m*s/rad",
    ),
    (
        {
            "structure": "cascade",
            "position_gain": "20 1/s",
            "speed_gain": KV,
            "speed_integral_time": "-10 ms",
        },
        "speed_integral_time: cannot be negative, got -0.01 s",
    ),
    (
        {"structure": "cascade", "position_gain": "20 1/s", "speed_gain": KV, "kp": "2 N*m/rad"},
        "kp: a PID gain",
    ),
    (
        {
            "structure": "cascade",
            "position_gain": "20 1/s",
            "speed_gain": KV,
            "ki": "2 N*m/(rad*s)",
        },
        "ki: a PID gain",
    ),
    ({"kp": "2 N*m/rad", "speed_gain": KV}, 'speed_gain: a gain of structure = "cascade"'),
    (
        {"structure": "cascade", "bandwidth": "9 Hz", "speed_gain": KV},
        "do not give speed_gain too",
    ),
    (
        {"structure": "cascade", "position_gain": "20 rad/s", "speed_gain": KV},
        "expected a rate",
    ),
    ({"structure": "ladder", "kp": "2 N*m/rad"}, "structure"),
]


def _refused_data(value: dict) -> dict:
    return _with_loop(**value)


@pytest.mark.parametrize("value, reason", REFUSED)
def test_a_wrong_cascade_field_is_refused_naming_it_through_the_api(value, reason):
    with pytest.raises(od.OptDesignError) as err:
        od.load(_refused_data(value))
    assert "loop." in str(err.value) and reason in str(err.value)


@pytest.mark.parametrize("json_mode", [False, True], ids=["text", "json"])
@pytest.mark.parametrize("value, reason", [REFUSED[0], REFUSED[2], REFUSED[5], REFUSED[7]])
def test_a_wrong_cascade_field_is_refused_naming_it_on_the_command_line(
    value, reason, json_mode, tmp_path
):
    message = command_line_refusal(_refused_data(value), tmp_path, json_mode)
    assert "loop" in message and reason in message


def test_an_unstable_cascade_is_refused_showing_its_own_gains():
    data = _with_loop(
        structure="cascade",
        position_gain="5000 1/s",
        speed_gain="0.01 N*m*s/rad",
        speed_integral_time="1 ms",
    )
    with pytest.raises(od.OptDesignError) as err:
        od.load(data)
    message = str(err.value)
    assert "is unstable at every one of its 7 angles" in message
    assert "cascade: position_gain = 5000 1/s, speed_gain = 0.01 N*m*s/rad" in message
    assert "speed_integral_time = 1 ms; kp = Kv Kpos = 50 N*m/rad" in message
