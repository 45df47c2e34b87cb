"""Sweeps whose points move several parameters together (``od.sweep(..., linked=...)``,
``optdesign sweep --with PATH=SWEPT``) and sweeps of the position loop's numbers: each
point's problem is the problem written with every moved value, the store knows the links,
and bad links are refused naming the field."""

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.cli import main
from optdesign.commands.sweep import parse_with
from optdesign.problem.parameters import at_values
from optdesign.studies.sweep_grid import point_settings, sweep_axes

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"
FORK = PROBLEMS / "fork_min_backlash.toml"
LOOP = PROBLEMS / "fin_actuator_loop.toml"
BANDWIDTH = "requirements.bandwidth_min"
R_UPPER = "variables.R.upper"
TRAVEL = "requirements.nut_travel_max"


def _loop_data(bandwidth: str) -> dict:
    data = tomllib.loads(LOOP.read_text())
    data["requirements"]["bandwidth_min"] = bandwidth
    data["loop"]["bandwidth"] = bandwidth
    return data


def test_a_linked_loop_bandwidth_is_the_problem_written_with_both():
    """The point of a sweep of the required bandwidth with the loop's placed bandwidth
    linked: the same loop rows at a design as the file that writes both at 12 Hz, and
    other rows than the point that moves the requirement alone (the gains follow)."""
    problem = od.load(LOOP)
    axes = sweep_axes(
        problem, {BANDWIDTH: ("6 Hz", "12 Hz", 4)}, linked={"loop.bandwidth": BANDWIDTH}
    )
    assert axes[0].linked == ("loop.bandwidth",) and axes[0].values == (6.0, 8.0, 10.0, 12.0)
    settings = point_settings(axes, [12.0])
    assert settings == {BANDWIDTH: 12.0, "loop.bandwidth": 12.0}
    moved = at_values(problem, settings)
    written = od.load(_loop_data("12 Hz"))
    alone = at_values(problem, {BANDWIDTH: 12.0})  # the gains still placed for 9 Hz
    # the shipped optimum (docs/loop.md): R, l, n, phi0 and the items d0, p, d
    design = {"R": 105.571, "l": 59.794, "n": 102.087, "phi0": 0.2292, "d0": 25.0, "p": 5.0}
    x = np.array([{**design, "d": 16.0}[v.name] for v in problem.free])
    rows = {
        name: [p.evaluate(x).constraints[name].values for p in (moved, written, alone)]
        for name in ("bandwidth", "phase_margin", "resonance_margin")
    }
    for name, (a, b, c) in rows.items():
        np.testing.assert_allclose(a, b, rtol=1e-12, err_msg=name)
        assert not np.allclose(a, c, rtol=1e-6), name  # the linked gains change every row
    assert problem.spec.loop.bandwidth == 9.0  # the base problem is left as it was


@pytest.mark.parametrize(
    ("vary", "linked", "field", "reason"),
    [
        (
            {BANDWIDTH: ("6 Hz", "12 Hz", 3)},
            {"loop.bandwidht": BANDWIDTH},
            "linked.loop.bandwidht",
            "unknown field of [loop] (did you mean 'bandwidth'?)",
        ),
        (
            {BANDWIDTH: ("6 Hz", "12 Hz", 3)},
            {"loop.bandwidth": "requirements.hinge_moment"},
            "linked.loop.bandwidth",
            "follows 'requirements.hinge_moment', which is not swept (swept: "
            "requirements.bandwidth_min)",
        ),
        (
            {BANDWIDTH: ("6 Hz", "12 Hz", 3)},
            {"loop.current_lag": BANDWIDTH},
            "linked.loop.current_lag",
            "a time cannot follow requirements.bandwidth_min (a frequency)",
        ),
        (
            {BANDWIDTH: ("6 Hz", "12 Hz", 3)},
            {BANDWIDTH: BANDWIDTH},
            "linked.requirements.bandwidth_min",
            "is swept itself",
        ),
        (
            {BANDWIDTH: ("6 Hz", "12 Hz", 3)},
            {"loop.angles": BANDWIDTH},
            "linked.loop.angles",
            "not a number (a int)",
        ),
        (
            {BANDWIDTH: ("6 Hz", "12 Hz", 3)},
            ["loop.bandwidth"],
            "linked",
            "give {path: swept path}",
        ),
        (  # the problem refuses an end of the range with the linked value
            {BANDWIDTH: ("0 Hz", "12 Hz", 3)},
            {"loop.bandwidth": BANDWIDTH},
            "vary.requirements.bandwidth_min",
            "0 Hz..12 Hz (with loop.bandwidth): fin_actuator_loop: requirements.bandwidth_min: "
            "must be positive",
        ),
        (  # a loop's number is swept like a requirement, and refused by [loop]'s rules
            {"loop.kp": ("1 N*m/rad", "2 N*m/rad", 3)},
            None,
            "vary.loop.kp",
            "loop.bandwidth: places kp and kd on the drive; do not give kp too",
        ),
    ],
)
def test_bad_links_are_refused_naming_the_field(vary, linked, field, reason):
    problem = od.load(LOOP)
    with pytest.raises(od.InputError) as err:
        sweep_axes(problem, vary, linked)
    assert err.value.field == field
    assert reason in err.value.reason


def test_the_with_text_of_the_command_line():
    assert parse_with(" loop.bandwidth = requirements.bandwidth_min") == (
        "loop.bandwidth",
        BANDWIDTH,
    )
    for text, reason in (
        ("loop.bandwidth", "write PATH=SWEPT_PATH"),
        ("=requirements.bandwidth_min", "write PATH=SWEPT_PATH"),
        ("loop..bandwidth=requirements.bandwidth_min", "an empty name between two dots"),
    ):
        with pytest.raises(od.InputError) as err:
            parse_with(text)
        assert err.value.field == "--with" and reason in err.value.reason


def test_a_linked_bound_moves_with_the_swept_one_and_the_store_knows_it(tmp_path, capsys):
    """The fork's nut travel limit moved with R's upper bound: the travel, 2 R tan 30 deg,
    reaches the limit before R does, so the travel binds at every point (R's bound
    alone binds at 80 mm), each point equals a cold solve of the problem with both
    moved, and a resume without the link is another sweep."""
    out = tmp_path / "s"
    vary = {R_UPPER: ("80 mm", "100 mm", 2)}
    sweep = od.sweep(FORK, vary, linked={TRAVEL: R_UPPER}, out=out)
    problem = od.load(FORK)
    for point in sweep.points:
        moved = at_values(problem, {R_UPPER: point.values[0], TRAVEL: point.values[0]})
        cold = od.solve(moved, ranges=False, diagnose=False)
        assert point.success and point.objective == pytest.approx(cold.objective, rel=1e-7)
        assert point.design["R"] == pytest.approx(point.values[0] / (2 * np.tan(np.pi / 6)))
        assert "nut_travel" in point.active and "R.upper" not in point.active
    assert "R.upper [mm] 80..100 (2 points; requirements.nut_travel_max with it)" in sweep.summary()
    figure = sweep.plot()  # the chart's x axis says what moved with R's upper bound
    labels = {ax.get_xlabel() for ax in figure.axes if ax.get_visible()}
    assert "R.upper [mm] (with requirements.nut_travel_max)" in labels
    doc = json.loads((out / "sweep.json").read_text())
    assert doc["axes"][0]["linked"] == [TRAVEL]
    lines = (out / "sweep.jsonl").read_text().splitlines()
    assert json.loads(lines[0])["identity"]["method"]["linked"] == {TRAVEL: R_UPPER}
    again = od.sweep(FORK, vary, linked={TRAVEL: R_UPPER}, out=out, resume=True)
    assert (out / "sweep.jsonl").read_text().splitlines() == lines  # nothing solved again
    assert [p.objective for p in again.points] == [p.objective for p in sweep.points]
    with pytest.raises(od.OptDesignError, match="method"):
        od.sweep(FORK, vary, out=out, resume=True)
    # the command line: --with, refused naming it before any work
    bad = tmp_path / "bad"
    argv = ["sweep", str(FORK), "--vary", "variables.R.upper=80..100mm:2"]
    assert main([*argv, "--with", "requirements.nut_travel_max=R.upper", "--out", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        "optdesign: error: --with.requirements.nut_travel_max: follows 'R.upper', which is "
        "not swept (swept: variables.R.upper)"
    )
    assert not bad.exists()
