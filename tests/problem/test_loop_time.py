"""optdesign/problem/loop_time.py and od.simulate: the time response of fin_actuator_loop's
optimum at 0 deg against its linear loop's static gain and the describing function's
limit cycle, the CSV's columns and units, and the refusals of bad arguments; over its
duty cycle with the plant following the fin, against the static balance of its loop at
each hold, the path plant's step against the fixed plant's, the CSV's hinge moment and
the duty run's refusals."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_refusal import command_line_refusal

import optdesign as od
from optdesign.models import loop_linear as ll
from optdesign.models.loop_backlash import limit_cycles
from optdesign.models.loop_run import steady_oscillation
from optdesign.problem.loop_time import design_path
from optdesign.problem.motor_drive import duty_torques

ROOT = Path(__file__).resolve().parents[2]
PROBLEM_FILE = ROOT / "problems" / "fin_actuator_loop.toml"


@pytest.fixture(scope="module")
def result():
    problem = od.load(ROOT / "problems" / "fin_actuator_loop.toml")
    return od.solve(problem, ranges=False, sensitivities=False)


def test_a_step_settles_at_the_static_gain_and_hunts_in_the_predicted_limit_cycle(result):
    """A 1 deg step at 0 deg: the fin settles about T(0) x 1 deg = 1.0198 deg (the
    unstable fin's hinge spring, no integral action) and hunts in the chain's gap. The
    describing function predicts 0.0357 deg at 156.1 Hz; simulated 0.0326 deg at 136.2 Hz
    (-8.8 % and -12.8 %, within the 10 % and 25 % the issue allows)."""
    sim = od.simulate(result, amplitude="1 deg", angle="0 deg", horizon="1 s", samples=20001)
    assert sim.angle == 0.0 and sim.index == 30
    r = sim.response
    pol = ll.loop_polynomials(r.plant, r.loop)
    t0 = np.polyval(pol.closed_numerator, 0.0) / np.polyval(pol.closed_denominator, 0.0)
    assert t0 == pytest.approx(1.0198, abs=1e-4)
    tail = np.degrees(r.fin_angle[r.times > 0.6])
    assert tail.mean() == pytest.approx(t0, rel=2e-3)
    amplitude, frequency = steady_oscillation(r, 0.6)
    (cycle,) = [c for c in limit_cycles(r.plant, r.loop).cycles if c.stable]
    assert math.degrees(cycle.fin_amplitude) == pytest.approx(0.0357, abs=5e-4)
    assert amplitude / cycle.fin_amplitude == pytest.approx(1.0, abs=0.10)
    assert frequency / cycle.frequency == pytest.approx(1.0, abs=0.25)


def test_the_csv_holds_every_quantity_in_the_units_its_header_names(result, tmp_path):
    path = tmp_path / "step.csv"
    sim = od.simulate(result, amplitude="0.5 deg", horizon="20 ms", samples=21, csv=path)
    lines = path.read_text().splitlines()
    assert lines[0] == (
        "time [s],reference [deg],fin_angle [deg],fin_rate [deg/s],"
        "motor_angle_at_fin [deg],motor_rate_at_fin [deg/s],motor_torque [N*m],"
        "chain_torque [N*m],contact [-1/0/+1]"
    )
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert data.shape == (21, 9)
    np.testing.assert_allclose(data[:, 0], np.linspace(0.0, 0.02, 21))
    np.testing.assert_allclose(data[:, 1], 0.5)
    np.testing.assert_allclose(data[:, 2], np.degrees(sim.response.fin_angle), rtol=1e-8)
    np.testing.assert_allclose(data[:, 6], sim.response.motor_torque * 1e-3, rtol=1e-8)


@pytest.mark.parametrize(
    "kwargs, field, reason",
    [
        ({"horizon": "1e9 s"}, "horizon", "600"),
        ({"angle": "40 deg"}, "angle", "outside the stroke"),
        ({"reference": "ramp"}, "reference", "expected one of step, sine"),
        ({"amplitude": "3 mm"}, "amplitude", "expected an angle"),
        ({"samples": 10**9}, "samples", ""),
    ],
)
def test_bad_simulation_arguments_are_refused_naming_them(result, kwargs, field, reason):
    with pytest.raises(od.OptDesignError) as err:
        od.simulate(result, **kwargs)
    assert field in str(err.value) and reason in str(err.value)


def test_a_result_without_a_loop_or_a_design_is_refused():
    plain = od.solve(od.load(ROOT / "problems" / "cs_min_backlash.toml"), ranges=False)
    with pytest.raises(od.OptDesignError, match=r"simulate: needs a \[loop\] section"):
        od.simulate(plain)
    with pytest.raises(od.OptDesignError, match="result"):
        od.simulate(object())


def test_the_command_line_simulates_a_result_json_into_a_csv_and_a_figure(result, tmp_path):
    """``optdesign simulate RESULT``: the design of a result.json of the shipped problem
    (its name), a 30 ms step at 0 deg: simulation.csv as od.simulate's, and a figure."""
    from optdesign.cli import main
    from optdesign.reports.result_json import result_json

    path = tmp_path / "result.json"
    path.write_text(result_json(result))
    out = tmp_path / "sim"
    argv = ["simulate", str(path), "--horizon", "30 ms", "--samples", "31", "--out", str(out)]
    assert main(argv) == 0
    assert (out / "simulation.png").stat().st_size > 10_000
    data = np.loadtxt(out / "simulation.csv", delimiter=",", skiprows=1)
    sim = od.simulate(result, horizon="30 ms", samples=31)
    np.testing.assert_allclose(data[:, 2], np.degrees(sim.response.fin_angle), rtol=1e-8)


def test_the_command_line_refuses_a_horizon_of_a_billion_seconds_before_any_solve(tmp_path):
    message = command_line_refusal(
        tomllib.loads((ROOT / "problems" / "fin_actuator_loop.toml").read_text()),
        tmp_path,
        False,
        ["simulate", "--horizon", "1e9 s"],
    )
    assert "horizon: must be in (0, 600] s" in message


# --- the duty cycle, the plant following the fin ------------------------------------------
@pytest.fixture(scope="module")
def duty(result):
    return od.simulate(result, "duty", period="5 s", samples=5001)


def test_the_fin_holds_each_duty_step_within_its_loops_static_band(result, duty):
    """0, 15 and -25 deg under 150, 300 and 450 N*m for 3, 1.5 and 0.5 s of 5 s at 120
    deg/s. At each hold's end the fin is at rest where its PD loop balances the step's
    moment: (f' kp + k_h) e = s M +- f' T_f (e = r - phi; the motor stuck in its
    friction band, f' at the fin). Measured e = 0.324, 0.672 and -0.985 deg: 4.5 % of the
    15 deg step and 3.9 % of the -25 deg one, the proportional loop's static error under
    load. The motor holds the chain's torque through the ratio, within its friction, in
    the step's direction, and below the duty cycle's sizing torque (which adds the
    screw's losses: the loop's plant is lossless but for the motor's friction)."""
    problem = result.problem_object
    path = design_path(problem, {**problem.fixed_values, **result.design})
    r, steps = duty.response, problem.spec.requirements.duty_cycle
    sizing = [float(np.ravel(t)[0]) for t in duty_torques(problem.quantities(result.design))]
    assert duty.plant == "path" and [k for _, _, k in duty.duty.holds] == [0, 1, 2]
    errors = []
    for (_, end, k), step in zip(duty.duty.holds, steps, strict=True):
        i = int(np.searchsorted(r.times, end)) - 1  # the last sample before the next step
        phi, e, T = r.fin_angle[i], r.reference[i] - r.fin_angle[i], r.motor_torque[i]
        assert r.reference[i] == pytest.approx(step.deflection, abs=1e-12)
        assert abs(r.fin_rate[i]) < 1e-4  # at rest
        f = path.at(phi)[0]
        stiffness = f * r.loop.kp + path.hinge_spring
        s = math.copysign(1.0, step.deflection) if step.deflection else 1.0
        band = f * path.friction_torque
        assert (s * step.hinge_moment - band) / stiffness <= e
        assert e <= (s * step.hinge_moment + band) / stiffness
        errors.append(math.degrees(e))
        # the chain carries the step's moment and the hinge spring's about the step
        moment = s * step.hinge_moment + path.hinge_spring * (phi - step.deflection)
        assert r.chain_torque[i] == pytest.approx(moment, rel=1e-4)
        assert r.hinge_moment[i] == pytest.approx(-moment, rel=1e-4)
        assert math.copysign(1.0, T) == s and abs(f * T - r.chain_torque[i]) <= band
        assert abs(T) < sizing[k]
    assert errors == pytest.approx([0.324, 0.672, -0.985], abs=2e-3)


def test_the_path_plants_step_at_mid_stroke_is_the_fixed_plants(result):
    """The plant following the fin about 0 deg, its angles the fin's own: the same 287
    events as the fixed plant of 0 deg over 0.3 s, and the fin's mean after 0.2 s within
    1e-4 deg of it (the ratio changes by 0.1 % over the hunting's 0.07 deg)."""
    fixed = od.simulate(result, angle="0 deg", horizon="0.3 s")
    path = od.simulate(result, angle="0 deg", horizon="0.3 s", plant="path")
    assert path.plant == "path" and path.angle == fixed.angle == 0.0
    a, b = fixed.response, path.response
    assert len(b.event_times) == len(a.event_times)
    tail = a.times > 0.2
    assert math.degrees(b.fin_angle[tail].mean()) == pytest.approx(
        math.degrees(a.fin_angle[tail].mean()), abs=1e-4
    )


def test_the_command_line_simulates_the_duty_cycle_into_a_csv_with_the_hinge_moment(
    result, duty, tmp_path
):
    from optdesign.cli import main
    from optdesign.reports.result_json import result_json

    path = tmp_path / "result.json"
    path.write_text(result_json(result))
    out = tmp_path / "sim"
    argv = ["simulate", str(path), "--reference", "duty", "--period", "5 s", "--out", str(out)]
    assert main([*argv, "--samples", "5001"]) == 0
    assert (out / "simulation.png").stat().st_size > 10_000
    lines = (out / "simulation.csv").read_text().splitlines()
    assert lines[0].endswith(",contact [-1/0/+1],hinge_moment [N*m]")
    data = np.loadtxt(out / "simulation.csv", delimiter=",", skiprows=1)
    assert data.shape == (5001, 10)
    np.testing.assert_allclose(data[:, 2], np.degrees(duty.response.fin_angle), rtol=1e-8)
    np.testing.assert_allclose(data[:, 9], duty.response.hinge_moment * 1e-3, rtol=1e-8)


@pytest.mark.parametrize(
    "kwargs, field, reason",
    [
        ({}, "period", "requirements.duty_period"),
        ({"period": "5 s", "periods": 0}, "periods", "whole number"),
        ({"period": "5 s", "periods": 121}, "periods", "600 s"),
        ({"period": "3 s"}, "period", "lengthen the period"),
        ({"period": "5 s", "plant": "angle"}, "plant", "sweeps the stroke"),
        ({"period": "5 s", "horizon": "1 s"}, "horizon", "periods"),
        ({"period": "-5 s"}, "period", "must be in (0, 600] s"),
        ({"period": "5 s", "angle": "10 deg"}, "angle", "steps' deflections"),
    ],
)
def test_bad_duty_arguments_are_refused_naming_them(result, kwargs, field, reason):
    with pytest.raises(od.OptDesignError) as err:
        od.simulate(result, "duty", **kwargs)
    assert field in str(err.value) and reason in str(err.value)


def test_a_problem_without_a_duty_cycle_is_refused_naming_it(result):
    data = tomllib.loads(PROBLEM_FILE.read_text())
    for name in ("duty_cycle", "life_min"):
        del data["requirements"][name]
    with pytest.raises(od.OptDesignError, match=r"requirements.duty_cycle: the duty reference"):
        od.simulate(od.load(data), "duty", design=result.design, period="5 s")
    with pytest.raises(od.OptDesignError, match="plant: expected one of angle, path"):
        od.simulate(result, plant="curved")


def test_the_command_line_refuses_a_duty_run_without_its_period_before_any_solve(tmp_path, capsys):
    from optdesign.cli import main

    data = tomllib.loads(PROBLEM_FILE.read_text())
    message = command_line_refusal(data, tmp_path, False, ["simulate", "--reference", "duty"])
    assert "period: give the duty cycle's length" in message
    with pytest.raises(SystemExit) as exit_:
        main(["simulate", str(PROBLEM_FILE), "--reference", "duty", "--periods", "0"])
    assert exit_.value.code == 2
    assert "argument --periods: 0 is outside 1..1000000" in capsys.readouterr().err
