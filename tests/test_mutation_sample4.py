"""Tests written from the fourth mutation sample's survivors (issue 21, mutmut, SEED=23)
in studies/pareto, storage, units, reports and studies/relaxation.

Each test names the behaviour it pins, not the mutant it was written from (the mutants
and their verdicts go to the fourth sample's table in docs/testing.md). Every test was
checked to fail on its mutant (``MUTANT_UNDER_TEST=<name> pytest`` in a copy of the
run's ``mutants/``) and to pass on the code.
"""

from __future__ import annotations

import copy
import csv
import json
import shutil
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import pytest

import optdesign as od
from optdesign import units
from optdesign.errors import InputError, ProblemError
from optdesign.problem import problem_from_dict
from optdesign.reports.display_units import requirement_echo
from optdesign.storage import StoreError
from optdesign.studies.catalogue import solve_catalogue
from optdesign.studies.pareto import (
    NSGA2,
    EpsilonConstraint,
    FrontMethod,
    PointRecord,
    compute_front,
    make_method,
)
from optdesign.studies.pareto.catalogue_front import catalogue_task
from optdesign.studies.pareto.io import write_front_csv
from optdesign.studies.pareto.tasks import ANCHOR_SLACK, arc_eps, row_eps

ROOT = Path(__file__).resolve().parents[1]


def _small_catalogue():
    """cs_min_backlash_catalogue cut to 2 leads x 2 pins on an 11-point grid: a catalogue
    front of it takes about 20 NLP solves."""
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "8 mm"]}
    data["requirements"]["deflection"]["points"] = 11
    return problem_from_dict(data)


@pytest.fixture(scope="module")
def small_catalogue():
    return _small_catalogue()


# --- the front-method template ----------------------------------------------------------
@dataclass
class _NoSettings(FrontMethod):
    """A plug-in front method that declares neither ``starts`` nor ``seed``."""

    name: str = "plain"


def test_a_front_method_without_starts_or_seed_takes_the_problem_files():
    problem = od.load(ROOT / "problems" / "fork_min_backlash.toml")
    solver = problem.spec.solver
    # the file sets no starts: the global search's cap, chosen from the dimension
    assert solver.starts is None
    assert _NoSettings().starts_and_seed(problem) == (12 * len(problem.free), solver.seed)


def test_nsga2_is_a_front_method_of_a_catalogue_problem():
    """NSGA-II searches catalogue variables as item indices: it is not refused on a
    catalogue problem, and every point it gives is a catalogue design."""
    problem = od.load(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
    assert make_method(problem, "nsga2", 7, pop_size=8) == NSGA2(pop_size=8)
    front = od.pareto(
        problem, ["backlash", "motor_torque"], method="nsga2", pop_size=8, generations=3, seed=1
    )
    # a population of 8 over 3 generations may find no feasible design (it depends on
    # the releases' random streams): every design it gave, on the front or not, is read
    assert front.method == "nsga2"
    leads = {2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0}
    designs = [point.design for point in [*front.points, *front.rejected] if point.design]
    assert designs and all(design["p"] in leads for design in designs)
    assert all(point.verified for point in front.points)


def test_a_method_object_with_settings_beside_it_is_refused_naming_them():
    """Settings go into a method object, not beside it: the library front refuses them,
    naming each, before any work."""
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    method = EpsilonConstraint(points=3)
    with pytest.raises(ProblemError, match=r"options \['seed', 'starts'\] go into the method"):
        make_method(problem, method, 7, starts=2, seed=1)
    with pytest.raises(ProblemError, match=r"options \['starts'\] go into the method object"):
        compute_front(problem, ["backlash", "size"], 3, method, starts=2)
    assert make_method(problem, method, 7) is method


def test_a_catalogue_front_of_three_objectives_is_refused_saying_it_takes_two():
    problem = od.load(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
    with pytest.raises(InputError) as caught:
        od.pareto(problem, ["backlash", "motor_torque", "size"], 3)
    assert caught.value.field == "objectives"
    assert str(caught.value) == "objectives: a catalogue front takes two objectives"


# --- catalogue fronts: the shared memo ----------------------------------------------------
def test_a_catalogue_front_task_without_a_shared_memo_finds_the_searchs_optimum(
    small_catalogue,
):
    """A parallel catalogue front's tasks carry no memo (each worker runs one alone): such
    a task is the plain catalogue search."""
    problem = small_catalogue
    task = {
        "problem": problem,
        "starts": 1,
        "seed": 3,
        "id": "anchor-backlash-ms",
        "kind": "anchor-multistart",
        "target": "backlash",
    }
    rec = PointRecord.from_dict(catalogue_task(task, {}))
    alone = solve_catalogue(problem, starts=1, seed=3, objective="backlash")
    assert rec.success and alone.success
    assert rec.objectives["backlash"] == pytest.approx(alone.objective, rel=1e-6)


def test_a_sequential_catalogue_fronts_inner_point_reuses_the_proofs_before_it(
    small_catalogue, tmp_path
):
    """Run one after another, a catalogue front's points share one memo of boxes proved
    infeasible: the inner point takes fewer NLP solves than the same search (same limit,
    same first incumbents) without it, for the same answer."""
    problem = small_catalogue
    od.pareto(problem, ["backlash", "motor_torque"], points=3, starts=1, out=tmp_path)
    lines = (tmp_path / "epsilon-catalogue.jsonl").read_text().splitlines()[1:]
    recs = {r["id"]: PointRecord.from_dict(r) for r in map(json.loads, lines)}
    inner = recs["epsilon-catalogue-0001"]
    # the first incumbents the point was given: the looser point before it, then the anchors
    before = ("epsilon-catalogue-0002", "anchor-backlash", "anchor-motor_torque")
    alone = solve_catalogue(
        problem,
        starts=1,
        seed=problem.spec.solver.seed,
        objective="motor_torque",
        eps=inner.eps,
        incumbents=[dict(recs[k].design) for k in before],
    )
    assert inner.success and alone.success
    assert inner.objectives["motor_torque"] == pytest.approx(alone.objective, rel=1e-6)
    assert inner.n_solves < alone.details.catalogue.nlp_solves


# --- resuming a stored front ------------------------------------------------------------
@pytest.fixture(scope="module")
def weighted_run(tmp_path_factory):
    """A finished 3-point weighted-sum front of cs_min_backlash (its output folder)."""
    out = tmp_path_factory.mktemp("weighted")
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    front = od.pareto(problem, ["backlash", "size"], 3, method="weighted_sum", starts=1, out=out)
    assert len(front.points) >= 2
    return problem, out, front


def _resume_weighted(problem, out, points=3, starts=1):
    return od.pareto(
        problem,
        ["backlash", "size"],
        points,
        method="weighted_sum",
        starts=starts,
        out=out,
        resume=True,
    )


def test_resuming_a_weighted_sum_front_with_other_settings_names_the_setting(
    weighted_run, tmp_path
):
    problem, finished, _ = weighted_run
    out = shutil.copytree(finished, tmp_path / "out")
    with pytest.raises(
        StoreError, match=r"method's settings changed \(method.n: stored 3, now 4\)"
    ):
        _resume_weighted(problem, out, points=4)
    with pytest.raises(StoreError, match=r"\(method.starts: stored 1, now 2\)"):
        _resume_weighted(problem, out, starts=2)


@pytest.mark.parametrize("status", [None, "failed"])
def test_a_stored_record_whose_verified_flag_is_not_a_boolean_refuses_the_resume(
    weighted_run, tmp_path, status
):
    """A record's ``verified`` is true, false or null; anything else refuses the resume,
    a failed record's too (a failed record is otherwise not checked further)."""
    problem, finished, _ = weighted_run
    out = shutil.copytree(finished, tmp_path / "out")
    store = out / "weighted_sum.jsonl"
    lines = [json.loads(x) for x in store.read_text().splitlines()]
    k = next(k for k, r in enumerate(lines) if k and r.get("verified") is True)
    lines[k]["verified"] = "yes"
    if status is not None:
        lines[k]["status"] = status
    store.write_text("".join(json.dumps(x) + "\n" for x in lines))
    with pytest.raises(StoreError, match=f"line {k + 1}: record") as caught:
        _resume_weighted(problem, out)
    assert "field 'verified' is not true, false or null" in str(caught.value)


# --- the input echo of a report -------------------------------------------------------
def test_a_bare_zero_angle_is_echoed_in_the_one_angle_unit_the_file_wrote():
    """A bare 0 has no unit of its own: a file that wrote every angle in rad sees it in
    rad too, one that wrote them in degrees in deg."""
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash.toml").read_text())
    req = data["requirements"]
    req["deflection"] = {"min": 0, "max": "0.5 rad", "points": 11}
    req["transmission_angle"] = {"min": "0.7 rad", "max": "2.4 rad"}
    req["rod_inclination_max"] = "0.5 rad"
    echo = dict(requirement_echo(problem_from_dict(data)))
    assert echo["deflection"] == "{min = 0 rad, max = 0.5 rad, points = 11}"
    req["deflection"] = {"min": 0, "max": "30 deg", "points": 11}
    req["transmission_angle"] = {"min": "40 deg", "max": "140 deg"}
    req["rod_inclination_max"] = "30 deg"
    data["variables"]["phi0"] = {"lower": "-30 deg", "upper": "30 deg"}
    echo = dict(requirement_echo(problem_from_dict(data)))
    assert echo["deflection"] == "{min = 0 deg, max = 30 deg, points = 11}"


# --- units ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("written", "suggested"),
    [
        ("999999999999999 s", '"999999999999999 mm"'),
        ("1e15 s", '"1000000000000000.0 mm"'),
        ("-1e15 s", '"-1000000000000000.0 mm"'),
        ("2.5 s", '"2.5 mm"'),
    ],
)
def test_a_wrong_dimension_suggests_the_number_whole_below_1e15_and_as_a_float_from_it(
    written, suggested
):
    with pytest.raises(InputError) as caught:
        units.to_internal(written, "length", "f")
    assert str(caught.value) == (
        f"f: {written!r} is a time, expected a length (write e.g. {suggested})"
    )


# --- what a stored front holds ----------------------------------------------------------
def _stored(out: Path, name: str) -> dict[str, dict]:
    lines = (out / f"{name}.jsonl").read_text().splitlines()[1:]
    return {r["id"]: r for r in map(json.loads, lines)}


def test_a_weighted_sum_fronts_points_are_stored_as_weighted_sum_records(weighted_run):
    _, out, _ = weighted_run
    records = _stored(out, "weighted_sum")
    points = [r for r in records.values() if r["id"].startswith("ws-")]
    assert len(points) == 3
    assert {r["kind"] for r in points} == {"weighted_sum"}
    assert {r["kind"] for k, r in records.items() if k.startswith("anchor-")} == {
        "anchor-multistart",
        "anchor",
    }


def test_an_anchors_tie_break_minimises_its_second_objective_within_its_first(weighted_run):
    """The anchor of backlash holds backlash at its optimum (plus the anchors' slack) and
    then minimises size: no design the front found within that backlash is smaller."""
    _, out, _ = weighted_run
    records = _stored(out, "weighted_sum")
    anchor, first = records["anchor-backlash"], records["anchor-backlash-ms"]
    assert anchor["order"] == ["backlash", "size"]
    # the bound, to the solver's feasibility tolerance
    bound = (first["objectives"]["backlash"] * (1 + ANCHOR_SLACK) + 1e-12) * (1 + 1e-6)
    assert anchor["objectives"]["backlash"] <= bound
    within = [r for r in records.values() if r["objectives"]["backlash"] <= bound]
    assert len(within) >= 3  # the first stage and a weighted point too
    assert all(anchor["objectives"]["size"] <= r["objectives"]["size"] for r in within)


def test_front_csv_lists_the_rejected_points_off_the_front(weighted_run, tmp_path):
    """front.csv holds every point, the rejected ones (dominated, failed) marked off it."""
    problem, _, front = weighted_run
    front = copy.deepcopy(front)
    front.rejected = [replace(front.points[0], id="r-0", rejected="dominated")]
    path = write_front_csv(front, problem, tmp_path / "front.csv")
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["id"] for r in rows] == [*(p.id for p in front.points), "r-0"]
    assert [r["on_front"] for r in rows] == ["True"] * len(front.points) + ["False"]


def test_an_epsilon_front_solves_the_limits_it_is_given(tmp_path):
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    method = EpsilonConstraint(eps_values=[0.05, 0.1, 0.15], starts=1)
    front = od.pareto(problem, ["backlash", "size"], method=method, out=tmp_path)
    records = _stored(tmp_path, "epsilon")
    assert [records[f"epsilon-{i:04d}"]["eps"] for i in range(3)] == [
        {"backlash": 0.05},
        {"backlash": 0.1},
        {"backlash": 0.15},
    ]
    # each limit is active at its point: backlash on it, to the solver's tolerance
    got = sorted(p.objectives["backlash"] for p in front.points)
    assert got == pytest.approx([0.05, 0.1, 0.15], rel=1e-6)


def test_a_three_objective_grid_point_lies_at_its_fraction_between_the_row_head_and_b_max():
    head = PointRecord(
        id="row-head",
        kind="eps",
        status="optimal",
        verified=True,
        target="size",
        objectives={"backlash": 1.0, "size": 2.0, "ripple": 0.1},
    )
    task = {"b_name": "size", "b_hi": 10.0, "frac": 0.25, "eps_row": {"backlash": 1.5}}
    lo = 2.0 * (1 + ANCHOR_SLACK) + 1e-12
    assert row_eps(task, head) == {"backlash": 1.5, "size": pytest.approx(lo + 0.25 * (10 - lo))}
    # a failed head gives no lower end: the point sits at B_max
    failed = replace(head, status="failed", verified=None)
    assert row_eps(task, failed) == {"backlash": 1.5, "size": 10.0}


def test_an_arc_step_from_a_neighbour_without_a_slope_takes_the_frames_slope():
    """The next limit of an arc-spaced sweep is a Newton step along the front's arc; a
    neighbour whose multiplier gave no slope steps with the frame's mean slope rb / ra."""
    frame = {"a0": 0.0, "b0": 1.0, "ra": 1.0, "rb": 2.0, "a_lo": 0.0, "a_hi": 1.0}
    task = {"frame": frame, "eps_name": "a", "target": "b", "arc": 1.0, "fallback_eps": 0.9}
    nb = PointRecord(
        id="p",
        kind="eps",
        status="optimal",
        verified=True,
        target="b",
        objectives={"a": 0.2, "b": 1.6},
        eps={"a": 0.2},
    )
    # s1 = 0.2 / 1 + (1 - 1.6) / 2 = -0.1; slope 2 / 1 = 2; ds/da = 1 + 2 / 2 = 2
    assert arc_eps(task, nb) == {"a": pytest.approx(0.2 + 1.1 / 2)}
    # the neighbour's own slope -6: ds/da = 1 + 6 / 2 = 4
    assert arc_eps(task, replace(nb, slope=-6.0)) == {"a": pytest.approx(0.2 + 1.1 / 4)}
    # no neighbour's design: the task's fallback limit
    assert arc_eps(task, None) == {"a": 0.9}


def test_a_point_far_from_its_neighbours_design_is_retried_saying_so():
    """An epsilon point whose design lies more than a fifth of the box from its warm
    neighbour's is re-solved from cold starts, and its record says why."""
    from optdesign.studies.pareto.tasks import front_task

    problem = od.load(ROOT / "problems" / "fork_min_backlash.toml")
    common = {"problem": problem, "objectives": ["backlash", "size"], "solver": "ipopt"}
    first = {**common, "id": "p-0", "kind": "eps", "target": "backlash", "index": 0}
    solo = front_task({**first, "eps": {"size": 1e9}}, {})
    assert solo["retried"] == ""
    # a neighbour no better (so not the "worse" retry) at the far corner of the box
    neighbour = {**solo, "id": "p-1", "objectives": {**solo["objectives"]}}
    neighbour["objectives"]["backlash"] *= 1.1
    neighbour["eps"], neighbour["x"] = {"size": 5e8}, [float(v) for v in problem.lower()]
    task = {**first, "eps": {"size": 1e9}, "warm": "p-1", "retry_starts": 1, "seed": 3}
    rec = front_task(task, {"p-1": neighbour})
    assert rec["retried"] == "jump in design space"
