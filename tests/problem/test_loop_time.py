"""optdesign/problem/loop_time.py and od.simulate: the time response of fin_actuator_loop's
optimum at 0 deg against its linear loop's static gain and the describing function's
limit cycle, the CSV's columns and units, and the refusals of bad arguments."""

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
from optdesign.models.loop_simulation import steady_oscillation

ROOT = Path(__file__).resolve().parents[2]


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
