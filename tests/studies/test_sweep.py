"""Issue 24: parametric sweeps (od.sweep, optdesign sweep) - every point's global search,
then polish rounds from the neighbours - the store and its resume, infeasible points,
the design chart, and the refusals of bad input."""

import json
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.cli import main
from optdesign.commands.sweep import parse_vary
from optdesign.formulations.nlp.solve import solve_nlp
from optdesign.problem.parameters import at_values
from optdesign.problem.request import SolveRequest
from optdesign.runtime.run_options import RunOptions
from optdesign.studies.sweep import run_sweep
from optdesign.studies.sweep_grid import grid_order, neighbour, sweep_axes
from optdesign.studies.sweep_point import grid_neighbours, polish_choice

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"
FORK = PROBLEMS / "fork_min_backlash.toml"
CRANK = PROBLEMS / "cs_min_backlash.toml"
HINGE = "requirements.hinge_moment"


def _records(store: Path) -> dict[str, dict]:
    """The records of a sweep's store by id, without their timings."""
    out = {}
    for line in store.read_text().splitlines()[1:]:
        rec = json.loads(line)
        rec.pop("time_s")
        out[rec["id"]] = rec
    return out


@pytest.fixture(scope="module")
def fork_sweep(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep")
    vary = {HINGE: ("200 N*m", "1000 N*m", 5)}
    return od.sweep(FORK, vary, out=out, sensitivities=True), out


def test_every_point_equals_a_cold_global_search(fork_sweep):
    sweep, _ = fork_sweep
    problem = od.load(FORK)
    assert [p.values[0] for p in sweep.points] == pytest.approx([200e3, 400e3, 600e3, 800e3, 1e6])
    for p in sweep.points:
        alone = solve_nlp(at_values(problem, {HINGE: p.values[0]}))
        assert p.success and alone.success
        assert p.objective == pytest.approx(alone.objective, rel=1e-6)
    # every point had its own global search, and no polish round improved on one
    assert all(p.checked for p in sweep.points)
    assert [p.found_by for p in sweep.points] == ["global search"] * 5
    assert sweep.points[0].active == ["d.lower", "nut_travel"]  # a light load: the smallest pin
    assert sweep.points[1].active == ["nut_travel", "pin_bearing_pressure"]
    assert [p.active_change for p in sweep.points] == [False, True, False, False, False]
    assert not any(p.jump for p in sweep.points)
    # a point's solves: its search's starts, then one warm start per neighbour (round 1)
    records = _records(sweep.store)
    for k, p in enumerate(sweep.points):
        search = records[f"p{k:04d}"]["solves"]
        assert search >= 3 and p.solves == search + (1 if k in (0, 4) else 2)
    # the backlash grows with the load (the pin grows with it)
    objectives = [p.objective for p in sweep.points]
    assert objectives == sorted(objectives)
    # each point carries its sensitivities: +1 % hinge moment costs about 0.24 % at 500 N*m
    assert 0.1 < sweep.points[2].sensitivities[HINGE] < 0.4


@pytest.fixture(scope="module")
def crank_sweeps(tmp_path_factory):
    """A shipped problem swept by one worker and by two."""
    out = tmp_path_factory.mktemp("crank")
    vary = {HINGE: ("400 N*m", "600 N*m", 3)}
    return [od.sweep(CRANK, vary, out=out / f"w{n}", workers=n) for n in (1, 2)]


def test_a_sweep_of_a_shipped_problem_equals_a_cold_solve_at_every_point(crank_sweeps):
    sweep, _ = crank_sweeps
    problem = od.load(CRANK)
    assert [p.values[0] for p in sweep.points] == pytest.approx([400e3, 500e3, 600e3])
    for p in sweep.points:
        cold = od.solve(at_values(problem, {HINGE: p.values[0]}), ranges=False)
        assert p.success and cold.success
        assert p.objective == pytest.approx(cold.objective, rel=1e-6)
        assert p.checked


def test_one_and_two_workers_give_the_same_records(crank_sweeps):
    one, two = crank_sweeps
    assert _records(two.store) == _records(one.store)
    assert [(p.objective, p.design, p.jump, p.found_by, p.solves) for p in two.points] == [
        (p.objective, p.design, p.jump, p.found_by, p.solves) for p in one.points
    ]


def test_frame_csv_and_chart_in_the_users_units(fork_sweep):
    sweep, _ = fork_sweep
    frame = sweep.to_frame()
    assert list(frame.columns[:6]) == [
        "point",
        "hinge_moment [N*m]",
        "backlash [deg]",
        "R [mm]",
        "p [mm]",
        "d [mm]",
    ]
    assert frame["hinge_moment [N*m]"].tolist() == pytest.approx([200, 400, 600, 800, 1000])
    assert frame.attrs["units"]["backlash [deg]"] == "deg"
    fig = sweep.plot()
    labels = [ax.get_ylabel() for ax in fig.axes if ax.get_visible()]
    assert labels == ["backlash [deg]", "R [mm]", "p [mm]", "d [mm]"]
    # the binding-set change is marked on every panel (a dotted line at 400 N*m)
    first = fig.axes[0]
    assert any(line.get_xdata()[0] == 400 for line in first.lines if line.get_linestyle() == ":")
    text = sweep.summary()
    assert "binding set changes at:" in text and "point 1: nut_travel;pin_bearing_pressure" in text


def test_resume_reuses_the_stored_points(fork_sweep):
    sweep, out = fork_sweep
    store = out / "sweep.jsonl"
    lines = store.read_text().splitlines()
    vary = {HINGE: ("200 N*m", "1000 N*m", 5)}
    # check_every is accepted and ignored (every point has its search): not in the identity
    again = od.sweep(FORK, vary, out=out, check_every=3, resume=True, sensitivities=True)
    assert store.read_text().splitlines() == lines  # nothing solved again
    assert [p.objective for p in again.points] == [p.objective for p in sweep.points]
    assert [p.solves for p in again.points] == [p.solves for p in sweep.points]
    # another range is another run: refused, naming what changed
    with pytest.raises(od.OptDesignError, match="method"):
        od.sweep(FORK, {HINGE: ("200 N*m", "900 N*m", 5)}, out=out, resume=True)
    # and a new run does not silently replace the stored one
    with pytest.raises(od.OptDesignError, match="resume=True"):
        od.sweep(FORK, {HINGE: ("200 N*m", "900 N*m", 5)}, out=out)


@pytest.mark.slow  # a sweep with an infeasible point and its diagnosis: 4-10 s
def test_an_infeasible_point_says_what_fails(tmp_path):
    sweep = od.sweep(CRANK, {HINGE: ("10 kN*m", "15 kN*m", 2)}, out=tmp_path)
    ok, bad = sweep.points
    assert ok.success and ok.active == ["d.upper", "nut_travel"]
    assert not bad.success  # the best design found violates the requirements
    # it says what fails there: what a cold solve of the point finds violated
    cold = od.solve(at_values(od.load(CRANK), {HINGE: 15e6}), ranges=False, diagnose=False)
    assert not cold.success and cold.violated
    assert all(any(r.name in v for v in bad.violated) for r in cold.violated)
    text = sweep.summary()
    assert "infeasible points (what fails at the best design found):" in text
    row = next(line for line in text.splitlines() if line.startswith("1 "))
    assert row.split()[:4] == ["1", "15000", "-", "-"] and bad.status in row
    y = sweep.plot().axes[0].lines[0].get_ydata()
    assert np.isnan(y[1]) and np.isfinite(y[0])  # nothing drawn where nothing is feasible


def test_two_parameters_snake_through_the_grid(tmp_path):
    sweep = od.sweep(
        FORK,
        {HINGE: ("400 N*m", "600 N*m", 2), "variables.R.upper": ("90 mm", "110 mm", 2)},
        out=tmp_path,
    )
    assert len(sweep.points) == 4 and all(p.success for p in sweep.points)
    # R's upper bound of 90 mm binds (the free optimum has R = 95.3 mm), 110 mm does not
    assert "R.upper" in sweep.points[0].active and "R.upper" not in sweep.points[2].active
    assert sweep.points[0].objective > sweep.points[2].objective
    assert grid_order(sweep.axes) == [(0, 0), (1, 0), (0, 1), (1, 1)]
    # a jump is judged against the chain's predecessor: along the row, a row's first
    # point against the row before's first point
    assert [neighbour(i) for i in grid_order(sweep.axes)] == [None, (0, 0), (0, 0), (0, 1)]
    # a polish round starts from the neighbours along the first parameter, then the rows
    assert grid_neighbours((1, 1), (3, 3)) == [
        ("from the previous point", (0, 1)),
        ("from the next point", (2, 1)),
        ("from the previous row", (1, 0)),
        ("from the next row", (1, 2)),
    ]
    assert grid_neighbours((0, 0), (2, 2)) == [
        ("from the next point", (1, 0)),
        ("from the next row", (0, 1)),
    ]
    assert sweep.plot().axes[0].get_xlabel() == "hinge_moment [N*m]"
    # two workers run the points side by side: the same records, whatever the timing
    vary = {HINGE: ("400 N*m", "600 N*m", 2), "variables.R.upper": ("90 mm", "110 mm", 2)}
    again = od.sweep(FORK, vary, out=tmp_path / "w2", workers=2)
    assert _records(again.store) == _records(sweep.store)


@pytest.mark.parametrize(
    ("vary", "field", "reason"),
    [
        (
            {"requirements.hinge_momnet": ("1 N*m", "2 N*m", 3)},
            "vary",
            "did you mean 'hinge_moment'",
        ),
        ({HINGE: ("200 mm", "2 N*m", 3)}, "vary.requirements.hinge_moment start", "a length"),
        ({HINGE: ("200", "1000 N*m", 3)}, "vary.requirements.hinge_moment start", "no unit"),
        ({HINGE: ("2 N*m", "2 N*m", 3)}, "vary.requirements.hinge_moment", "an empty range"),
        ({HINGE: ("1 N*m", "2 N*m", 1)}, "vary.requirements.hinge_moment", "outside 2..1000"),
        ({HINGE: ("1 N*m", "2 N*m", 2.5)}, "vary.requirements.hinge_moment", "an integer"),
        ({HINGE: ("1 N*m", "2 N*m")}, "vary.requirements.hinge_moment", "(start, stop, count)"),
        ({"variables.d": ("1 mm", "2 mm", 3)}, "vary", "sweep variables.d.lower or d.upper"),
        ({"requirements.fit": (1, 2, 3)}, "vary", "not a number"),
        ({}, "vary", "give {parameter path"),
        (
            {
                HINGE: ("1 N*m", "2 N*m", 2),
                "variables.R.upper": ("90 mm", "91 mm", 2),
                "variables.p.upper": ("9 mm", "10 mm", 2),
            },
            "vary",
            "at most 2",
        ),
        ({"variables.R.lower": ("100 mm", "130 mm", 2)}, "vary.variables.R.lower", "not below"),
        ({"motion.rise_time": ("90 ms", "40 ms", 3)}, "vary", "no [motion] section"),
        ({"motor.peak_torque": ("5 N*m", "6 N*m", 3)}, "vary", "give requirements.NAME, motion"),
    ],
)
def test_bad_sweeps_are_refused_naming_the_field(vary, field, reason):
    problem = od.load(FORK)
    with pytest.raises(od.InputError) as err:
        sweep_axes(problem, vary)
    assert err.value.field == field
    assert reason in err.value.reason


def test_api_arguments_are_checked_before_any_work():
    with pytest.raises(od.InputError, match="resume: give the out folder"):
        od.sweep(FORK, {HINGE: ("1 N*m", "2 N*m", 2)}, resume=True)
    with pytest.raises(od.InputError, match="starts: 0 is outside"):
        od.sweep(FORK, {HINGE: ("1 N*m", "2 N*m", 2)}, starts=0)
    with pytest.raises(od.InputError, match="objective"):
        od.sweep(FORK, {HINGE: ("1 N*m", "2 N*m", 2)}, objective="nope")


def test_vary_text_of_the_command_line():
    assert parse_vary("requirements.hinge_moment=200..1000N*m:20") == (
        HINGE,
        ("200 N*m", "1000 N*m", 20),
    )
    assert parse_vary("requirements.mean_ratio.min=180..220:5") == (
        "requirements.mean_ratio.min",
        ("180", "220", 5),
    )
    assert parse_vary("variables.R.upper=0.09 m..0.11 m:3")[1] == ("0.09 m", "0.11 m", 3)
    with pytest.raises(od.InputError, match=r"--vary: requirements.hinge_moment: '200:3'"):
        parse_vary("requirements.hinge_moment=200:3")


def test_a_path_with_an_empty_name_is_refused_naming_vary_and_where(tmp_path, capsys):
    """A trailing dot (an AttributeError before), two dots in a row and a path below a
    plain value: refused naming the argument, through od.sweep and the command line."""
    with pytest.raises(od.InputError) as err:
        od.sweep(FORK, {HINGE + ".": ("200 N*m", "300 N*m", 3)})
    assert str(err.value).startswith(
        "vary: 'requirements.hinge_moment.': an empty name after its last dot; give "
        "requirements.NAME, motion.NAME, load.NAME, loop.NAME or variables.NAME[.lower|.upper]"
    )
    problem = od.load(FORK)
    with pytest.raises(od.InputError) as err:
        sweep_axes(problem, {"requirements..hinge_moment": ("200 N*m", "300 N*m", 3)})
    assert str(err.value).startswith(
        "vary: 'requirements..hinge_moment': an empty name between two dots (after requirements)"
    )
    with pytest.raises(od.InputError) as err:
        sweep_axes(problem, {HINGE + ".min": ("200 N*m", "300 N*m", 3)})
    assert str(err.value).startswith(
        "vary: requirements.hinge_moment.min: requirements.hinge_moment is a value, not a table"
    )
    out = tmp_path / "o"
    code = main(["sweep", str(FORK), "--vary", HINGE + ".=200:300:3", "--out", str(out)])
    err_text = capsys.readouterr().err
    assert code == 2
    assert err_text.startswith(
        "optdesign: error: --vary: 'requirements.hinge_moment.': an empty name after its last dot"
    )
    assert len(err_text.strip().splitlines()) == 1 and not out.exists()


def test_a_count_in_another_scripts_digits_is_refused_naming_the_digit():
    with pytest.raises(od.InputError) as err:
        parse_vary("requirements.hinge_moment=200..300N*m:\u0663")
    assert str(err.value).startswith(
        "--vary: requirements.hinge_moment: count '\u0663' has the digit '\u0663' (U+0663 "
        "ARABIC-INDIC DIGIT THREE): write numbers with the digits 0-9"
    )


def test_cli_writes_the_table_chart_and_json(tmp_path, capsys):
    out = tmp_path / "o"
    args = [
        "sweep",
        str(FORK),
        "--vary",
        "requirements.mean_ratio.min=180..220:3",
        "--out",
        str(out),
        "--no-progress",
    ]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "sweep     mean_ratio.min 180..220 (3 points)" in text
    assert {p.name for p in out.iterdir()} >= {
        "sweep.csv",
        "sweep.json",
        "sweep.png",
        "sweep.html",
        "sweep.jsonl",
    }
    header = (out / "sweep.csv").read_text().splitlines()[0]
    assert header.startswith("point,mean_ratio.min,backlash [deg],R [mm],p [mm],d [mm],status")
    assert main([*args, "--resume", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["axes"][0] == {
        "path": "requirements.mean_ratio.min",
        "unit": "",
        "values": [180.0, 200.0, 220.0],
    }
    assert [p["status"] for p in doc["points"]] == ["optimal"] * 3
    assert main(["sweep", str(FORK), "--vary", "requirements.hinge_moment=1..2mm:3"]) == 2
    assert "--vary.requirements.hinge_moment start: '1 mm' is a length" in capsys.readouterr().err


def test_one_nlp_for_loads_and_limits_its_own_for_the_rest(tmp_path):
    from optdesign.studies.sweep_solver import sweep_mode

    problem = od.load(FORK)
    assert sweep_mode(problem, [HINGE], [(2e5, 1e6)]) == "shared"  # a parameter of the NLP
    assert sweep_mode(problem, ["requirements.nut_travel_max"], [(100.0, 120.0)]) == "shared"
    # the stroke moves the grid, a bound the variables' scaling: each point its own NLP
    assert sweep_mode(problem, ["requirements.deflection.max"], [(0.4, 0.6)]) == "rebuild"
    assert sweep_mode(problem, ["variables.R.upper"], [(90.0, 110.0)]) == "rebuild"
    # the hinge moment also sets the pin's load in the contact model: not a limit
    assert (
        sweep_mode(
            problem,
            ["requirements.hinge_moment", "requirements.nut_travel_max"],
            [(2e5, 1e6), (100.0, 120.0)],
        )
        == "shared"
    )
    sweep = od.sweep(
        problem, {"requirements.nut_travel_max": ("100 mm", "120 mm", 3)}, out=tmp_path
    )
    for p in sweep.points:
        alone = solve_nlp(at_values(problem, {"requirements.nut_travel_max": p.values[0]}))
        assert p.objective == pytest.approx(alone.objective, rel=1e-6)
        assert "nut_travel" in p.active


def test_a_catalogue_problem_is_swept_point_by_point_and_item_changes_marked(tmp_path):
    problem = od.load(PROBLEMS / "cs_min_backlash_catalogue.toml")
    sweep = od.sweep(problem, {HINGE: ("400 N*m", "600 N*m", 2)}, starts=1, out=tmp_path)
    assert not sweep.continuation and "no continuation" in sweep.notes[0]
    first, second = sweep.points
    # the pin steps up two catalogue sizes (ISO 2338: 6 -> 10 mm, as enumeration finds:
    # d = 8 mm gives 0.0390417 deg at 600 N*m); the binding set is the same
    assert (first.design["d"], second.design["d"]) == (6.0, 10.0)
    assert second.objective == pytest.approx(0.0378044, rel=1e-5)
    assert first.active == second.active == ["nut_travel"]
    assert (first.active_change, second.active_change) == (False, True)
    at_600 = od.solve(at_values(problem, {HINGE: 600e3}), starts=1, ranges=False)
    assert second.objective == pytest.approx(at_600.objective, rel=1e-9)


def test_a_worse_warm_start_is_caught_as_a_jump(tmp_path, monkeypatch):
    # The warm starts made to end 1 % above the optimum (as if continuation followed a
    # local optimum): every point's own search has the better one, the polish keeps it,
    # and the points a warm start from the point before would have got wrong are jumps.
    import dataclasses

    from optdesign.studies.sweep_solver import SweepSolver

    original = SweepSolver.warm

    def worse(self, point, x0):
        r = original(self, point, x0)
        return dataclasses.replace(r, objective=r.objective * 1.01)

    monkeypatch.setattr(SweepSolver, "warm", worse)
    sweep = od.sweep(FORK, {HINGE: ("400 N*m", "600 N*m", 3)}, out=tmp_path)
    assert [p.jump for p in sweep.points] == [False, True, True]  # the first has no neighbour
    assert [p.found_by for p in sweep.points] == ["global search"] * 3
    assert all(p.checked for p in sweep.points)
    problem = od.load(FORK)
    for p in sweep.points:
        alone = solve_nlp(at_values(problem, {HINGE: p.values[0]}))
        assert p.objective == pytest.approx(alone.objective, rel=1e-9)
    assert "jumps (a warm start from the point before would have stayed on a worse branch)" in (
        sweep.summary()
    )


def test_the_polish_rule_decides_by_value_then_by_order():
    ok = {"success": True, "max_violation": 0.0}
    current = {**ok, "objective": 1.0}
    # a tie (within the tolerance) keeps the point's own value
    assert polish_choice(current, [{**ok, "objective": 1.0 - 1e-9}]) is None
    # the better wins; of two equal ones the first in the neighbours' order
    cands = [{**ok, "objective": 1.2}, {**ok, "objective": 0.9}, {**ok, "objective": 0.9}]
    assert polish_choice(current, cands) == 1
    assert polish_choice(current, [{**ok, "objective": 0.9}, {**ok, "objective": 0.8}]) == 1
    # a feasible design beats any infeasible one; two infeasible: the smaller violation
    bad = {"success": False, "objective": 0.1, "max_violation": 0.5}
    assert polish_choice(current, [bad]) is None
    assert polish_choice(bad, [{**bad, "max_violation": 0.4}, current]) == 1
    assert polish_choice(bad, [{**bad, "max_violation": 0.4}]) == 0


def _two_branches(monkeypatch, good_at: float) -> None:
    """A made-up second branch: every point's own search lands on it (R shifted by
    1000 mm, the backlash 2 % higher) except the point at ``good_at`` N*mm; a warm start
    from a design on it stays on it, from any other design finds the true optimum."""
    import dataclasses

    from optdesign.studies.sweep_solver import SweepSolver

    search, warm = SweepSolver.search, SweepSolver.warm

    def worse(r):
        design = {**r.design, "R": r.design["R"] + 1000.0}
        return dataclasses.replace(r, objective=r.objective * 1.02, design=design)

    def fake_search(self, point, starts, seed, agree=None):
        r = search(self, point, starts, seed, agree)
        return r if point.spec.requirements.hinge_moment == good_at else worse(r)

    def fake_warm(self, point, x0):
        k = [v.name for v in point.free].index("R")
        if x0[k] < 500.0:
            return warm(self, point, x0)
        x0 = x0.copy()
        x0[k] -= 1000.0
        return worse(warm(self, point, x0))

    monkeypatch.setattr(SweepSolver, "search", fake_search)
    monkeypatch.setattr(SweepSolver, "warm", fake_warm)


@pytest.mark.parametrize(
    ("good", "found"), [(0, "from the previous point"), (4, "from the next point")]
)
def test_a_better_branch_spreads_through_the_polish_rounds(tmp_path, monkeypatch, good, found):
    values = [400e3, 450e3, 500e3, 550e3, 600e3]
    _two_branches(monkeypatch, values[good])
    sweep = od.sweep(FORK, {HINGE: ("400 N*m", "600 N*m", 5)}, out=tmp_path)
    problem = od.load(FORK)
    for p in sweep.points:  # every point lifted onto the true optimum
        alone = solve_nlp(at_values(problem, {HINGE: p.values[0]}))
        assert p.objective == pytest.approx(alone.objective, rel=1e-6)
        assert p.design["R"] < 500.0
    assert [p.found_by for p in sweep.points] == [
        "global search" if k == good else found for k in range(5)
    ]
    assert [p.jump for p in sweep.points] == [k != good for k in range(5)]
    # one point a round: the better branch moves one step along the sweep each time
    records = _records(sweep.store)
    lifted = {rec["index"]: rec["round"] for rec in records.values() if rec.get("improved")}
    assert lifted == {k: abs(k - good) for k in range(5) if k != good}
    # each round's points: those next to a point lifted in the round before; the last
    # round lifts nothing and ends the polish (5 rounds: the cap, not reached)
    rounds = sorted({rec["round"] for rec in records.values()})
    assert rounds == [0, 1, 2, 3, 4, 5] and not sweep.notes
    # a point's solves: its search, one per neighbour in round 1, then one more from
    # each neighbour in the round after that neighbour was lifted
    for k, p in enumerate(sweep.points):
        search = records[f"p{k:04d}"]["solves"]
        beside = [j for j in (k - 1, k + 1) if 0 <= j < 5]
        assert p.solves == search + len(beside) + sum(j in lifted for j in beside)


@pytest.mark.parametrize("workers", [1, 2])
def test_a_killed_sweep_resumes_to_the_same_records(tmp_path, monkeypatch, workers):
    # Killed in the middle of its polish rounds, the sweep resumes from its store: the
    # records stored are not computed again and the answer is the uninterrupted one's.
    _two_branches(monkeypatch, 400e3)
    problem = od.load(FORK)
    vary = {HINGE: ("400 N*m", "600 N*m", 5)}
    request = SolveRequest.for_problem(problem, ranges=False, sensitivities=False)
    whole = run_sweep(problem, vary, request, run=RunOptions(out=tmp_path / "whole"))

    seen = []

    def kill(record):
        seen.append(record["id"])
        if len(seen) == 8:  # round 0 done, round 1 under way
            raise KeyboardInterrupt

    out = tmp_path / "killed"
    with pytest.raises(KeyboardInterrupt):
        run_sweep(problem, vary, request, run=RunOptions(out=out, on_record=kill, workers=workers))
    stored = (out / "sweep.jsonl").read_text().splitlines()
    assert len(stored) == 1 + 8
    again = []
    resume = RunOptions(out=out, resume=True, on_record=again.append, workers=workers)
    resumed = run_sweep(problem, vary, request, run=resume)
    assert not set(seen) & {r["id"] for r in again}  # nothing stored was solved again
    assert (out / "sweep.jsonl").read_text().splitlines()[: len(stored)] == stored
    assert _records(resumed.store) == _records(whole.store)
    assert [(p.objective, p.found_by, p.jump) for p in resumed.points] == [
        (p.objective, p.found_by, p.jump) for p in whole.points
    ]


def test_the_points_are_solved_with_the_one_request_od_sweep_builds(tmp_path, monkeypatch):
    # od.sweep checks its arguments and builds one SolveRequest; a point its formulation
    # solves (a catalogue problem: no continuation) receives it as it is, the file's
    # seed filled in, no ranges, an infeasible point diagnosed.
    import optdesign.studies.solve as solve_module
    from optdesign.problem.request import SolveRequest

    seen = []
    original = solve_module.solve

    def spy(problem, request):
        seen.append(request)
        return original(problem, request)

    monkeypatch.setattr(solve_module, "solve", spy)
    problem = od.load(PROBLEMS / "cs_min_backlash_catalogue.toml")
    sweep = od.sweep(problem, {HINGE: ("400 N*m", "600 N*m", 2)}, starts=1, out=tmp_path)
    assert problem.spec.solver.seed is not None
    want = SolveRequest(
        "backlash",
        starts=1,
        seed=problem.spec.solver.seed,
        ranges=False,
        diagnose=True,
        sensitivities=False,
    )
    assert seen == [want, want]
    assert [p.success for p in sweep.points] == [True, True]


@pytest.mark.parametrize("check_every", [0, 10_001, 2.5, True])
def test_check_every_still_checked_by_od_sweep_naming_it(check_every, tmp_path):
    with pytest.raises(od.InputError) as info:
        od.sweep(FORK, {HINGE: ("200 N*m", "300 N*m", 2)}, check_every=check_every, out=tmp_path)
    assert info.value.field == "check_every"
    assert not (tmp_path / "sweep.jsonl").exists()


def test_sweep_csv_neutralises_text_a_spreadsheet_would_run(monkeypatch):
    """optdesign.reports.sweep_text.sweep_csv: a text cell starting like a formula (a user's
    text in ``what_fails``) is written with a leading quote, as front.csv writes it; a
    negative number stays a number."""
    import csv
    import io

    import optdesign.reports.sweep_text as report

    rows = [[1.5, "infeasible", '=HYPERLINK("x")', -2.0], [2.5, "optimal", "", 3.0]]
    monkeypatch.setattr(
        report, "sweep_rows", lambda sweep: (["m", "status", "what_fails", "R"], rows)
    )
    table = list(csv.reader(io.StringIO(report.sweep_csv(object()))))
    assert table[1] == ["1.5", "infeasible", '\'=HYPERLINK("x")', "-2"]
    assert table[2] == ["2.5", "optimal", "", "3"]


def test_a_grid_beyond_its_cap_is_refused_naming_vary_and_the_product(tmp_path, capsys):
    """optdesign.studies.sweep_grid.sweep_axes: the product of the axes' counts is at most
    MAX_GRID (a 1000 x 1000 grid was accepted: about a day of global searches); od.sweep
    and the command line refuse it before any work."""
    from optdesign.studies.sweep_grid import MAX_GRID

    assert MAX_GRID == 2500
    R = "variables.R.upper"
    out = tmp_path / "o"
    with pytest.raises(od.InputError) as err:
        od.sweep(
            FORK, {HINGE: ("200 N*m", "1000 N*m", 1000), R: ("90 mm", "110 mm", 1000)}, out=out
        )
    assert err.value.field == "vary"
    assert str(err.value).startswith(
        "vary: 1000 x 1000 = 1000000 points; a sweep's grid has at most 2500"
    )
    argv = ["sweep", str(FORK), "--vary", f"{HINGE}=200..1000N*m:51"]
    assert main([*argv, "--vary", f"{R}=90..110mm:50", "--out", str(out)]) == 2
    assert capsys.readouterr().err.startswith(
        "optdesign: error: --vary: 51 x 50 = 2550 points; a sweep's grid has at most 2500"
    )
    assert not out.exists()
    # the cap itself is a sweep: 50 x 50
    axes = sweep_axes(
        od.load(FORK), {HINGE: ("200 N*m", "1000 N*m", 50), R: ("90 mm", "110 mm", 50)}
    )
    assert [len(a.values) for a in axes] == [50, 50]


def test_a_scheduler_that_is_no_address_is_refused_before_any_work(tmp_path, capsys):
    """optdesign.argument_checks.scheduler: od.sweep's scheduler and --scheduler are an
    address SCHEME://HOST:PORT (a garbage one ended as an internal error)."""
    out = tmp_path / "o"
    with pytest.raises(od.InputError) as err:
        od.sweep(FORK, {HINGE: ("200 N*m", "300 N*m", 2)}, scheduler="not a url", out=out)
    assert err.value.field == "scheduler"
    assert str(err.value).startswith(
        "scheduler: 'not a url' is not a scheduler's address: no port 1..65535 "
        "(write SCHEME://HOST:PORT, e.g. tcp://127.0.0.1:8786)"
    )
    argv = ["sweep", str(FORK), "--vary", f"{HINGE}=200..300N*m:2", "--out", str(out)]
    with pytest.raises(SystemExit) as caught:
        main([*argv, "--scheduler", "tcp://my host:8786"])
    assert caught.value.code == 2
    last = capsys.readouterr().err.splitlines()[-1]
    assert last.startswith(
        "optdesign sweep: error: argument --scheduler: 'tcp://my host:8786' is not a "
        "scheduler's address: 'my host' is not a host name"
    )
    assert not out.exists()


def test_a_sweep_given_out_writes_the_files_the_command_writes(tmp_path):
    """optdesign.api.sweep with ``out``: sweep.csv, sweep.json, sweep.png and sweep.html
    beside the store, as ``optdesign sweep`` writes them; the CSV has a row per point."""
    import csv

    swept = od.sweep(
        PROBLEMS / "cs_min_ripple.toml",
        {"requirements.hinge_moment": ("200 N*m", "300 N*m", 2)},
        out=tmp_path / "s",
    )
    names = {p.name for p in (tmp_path / "s").iterdir()}
    assert {"sweep.csv", "sweep.json", "sweep.png", "sweep.html", "sweep.jsonl"} <= names
    with (tmp_path / "s" / "sweep.csv").open(newline="") as fh:
        assert len(list(csv.DictReader(fh))) == len(swept.points) == 2


def _motor_data(rise_time: str) -> dict:
    import tomllib

    data = tomllib.loads(CRANK.read_text())
    data["motor"] = {"rotor_inertia": "0.5 kg*cm^2", "peak_torque": "5 N*m",
                     "rated_torque": "1.5 N*m", "max_speed": "6000 rpm"}  # fmt: skip
    data["load"] = {"inertia": "0.2 kg*m^2", "nut_mass": "0.5 kg"}
    data["motion"] = {"step": "3 deg", "rise_time": rise_time, "rate": "90 deg/s"}
    return data


def test_a_moved_rise_time_is_the_problem_written_with_it():
    """at_values (what a sweep's point solves) on [motion]: the same motor torque at a
    design as the problem loaded from a file that writes that rise time."""
    problem = od.load(_motor_data("72 ms"))
    x = problem.lower() + 0.4 * (problem.upper() - problem.lower())
    moved = at_values(problem, {"motion.rise_time": 0.05 / 3600})  # 50 ms, internal hours
    written = od.load(_motor_data("50 ms"))
    torque = [p.evaluate(x).objectives["motor_peak_torque"] for p in (problem, moved, written)]
    assert torque[1] == pytest.approx(torque[2], rel=1e-12)
    assert torque[1] > 1.1 * torque[0]  # a faster step asks more torque (of the rotor, the fin)
    assert problem.spec.motion.rise_time == pytest.approx(0.072 / 3600)  # the original kept


def test_the_motion_is_swept_like_a_requirement(tmp_path):
    sweep = od.sweep(
        od.load(_motor_data("72 ms")), {"motion.rise_time": ("90 ms", "60 ms", 2)}, out=tmp_path
    )
    assert [p.success for p in sweep.points] == [True, True]
    assert sweep.axes[0].label == "rise_time [ms]" and sweep.axes[0].shown == (90.0, 60.0)
