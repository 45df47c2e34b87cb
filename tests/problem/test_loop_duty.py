"""od.simulate(..., "duty") and ``optdesign simulate --reference duty``: fin_actuator_loop's
optimum over its duty cycle with the plant following the fin, against the static balance
of its loop at each hold; the step of the path plant against the fixed plant's; the CSV's
hinge moment; the refusals."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_refusal import command_line_refusal

import optdesign as od
from optdesign.problem.loop_time import design_path
from optdesign.problem.motor_drive import duty_torques

ROOT = Path(__file__).resolve().parents[2]
FILE = ROOT / "problems" / "fin_actuator_loop.toml"


@pytest.fixture(scope="module")
def result():
    return od.solve(od.load(FILE), ranges=False, sensitivities=False)


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
    data = tomllib.loads(FILE.read_text())
    for name in ("duty_cycle", "life_min"):
        del data["requirements"][name]
    with pytest.raises(od.OptDesignError, match=r"requirements.duty_cycle: the duty reference"):
        od.simulate(od.load(data), "duty", design=result.design, period="5 s")
    with pytest.raises(od.OptDesignError, match="plant: expected one of angle, path"):
        od.simulate(result, plant="curved")


def test_the_command_line_refuses_a_duty_run_without_its_period_before_any_solve(tmp_path, capsys):
    from optdesign.cli import main

    data = tomllib.loads(FILE.read_text())
    message = command_line_refusal(data, tmp_path, False, ["simulate", "--reference", "duty"])
    assert "period: give the duty cycle's length" in message
    with pytest.raises(SystemExit) as exit_:
        main(["simulate", str(FILE), "--reference", "duty", "--periods", "0"])
    assert exit_.value.code == 2
    assert "argument --periods: 0 is outside 1..1000000" in capsys.readouterr().err
