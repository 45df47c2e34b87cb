"""optdesign/studies/pareto/catalogue_knowledge.py as a whole: which tasks of a catalogue
front share a memo and how its points are chained (loosest limit first), and which
neighbours' optima a point's search starts from, in which order."""

from pathlib import Path

import pytest

import optdesign as od
from optdesign.formulations.catalogue import bnb as catalogue_bnb
from optdesign.formulations.catalogue.discrete import discrete_variables
from optdesign.studies.pareto.catalogue_knowledge import (
    chain_points,
    front_knowledge,
    previous_holds,
)
from optdesign.studies.pareto.records import PointRecord

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"


def _tasks():
    anchors = [{"id": "anchor-backlash", "after": []}, {"id": "anchor-ripple", "after": []}]
    points = [
        {"id": "eps-1", "eps_frac": 0.25, "after": ["anchor-backlash"]},
        {"id": "eps-2", "eps_frac": 0.75, "after": ["anchor-backlash"]},
        {"id": "eps-3", "eps_frac": 0.5, "after": ["anchor-ripple"]},
    ]
    return anchors + points, points


def test_points_run_in_parallel_are_neither_chained_nor_given_a_memo():
    tasks, points = _tasks()
    before = [dict(t) for t in tasks]
    chain_points(tasks, points, sequential=False)
    assert tasks == before


def test_points_run_one_after_another_are_chained_from_the_loosest_limit():
    tasks, points = _tasks()
    chain_points(tasks, points, sequential=True)
    by_id = {t["id"]: t for t in tasks}
    assert all(t["memo"] is True for t in tasks)
    assert "previous" not in by_id["eps-2"]  # the loosest (0.75) starts the chain
    assert by_id["eps-2"]["after"] == ["anchor-backlash"]
    assert by_id["eps-3"]["previous"] == "eps-2"
    assert by_id["eps-3"]["after"] == ["anchor-ripple", "eps-2"]
    assert by_id["eps-1"]["previous"] == "eps-3"
    assert by_id["eps-1"]["after"] == ["anchor-backlash", "eps-3"]


def test_points_of_equal_limits_are_chained_in_their_given_order():
    points = [{"id": f"p{i}", "eps_frac": 0.5, "after": []} for i in range(3)]
    chain_points(list(points), points, sequential=True)
    assert [p.get("previous") for p in points] == [None, "p0", "p1"]


def _record(design, status="optimal", verified=True):
    return PointRecord(
        id="x", kind="anchor", target="t", status=status, verified=verified, design=design
    ).to_dict()


DEPS = {
    "anchor-backlash": _record({"d": 1.0}),
    "anchor-ripple": _record({"d": 2.0}),
    "eps-9": _record({"d": 3.0}),
}


def _point(frac, **kw):
    return {"eps_frac": frac, "eps_name": "backlash", "target": "ripple", **kw}


@pytest.mark.parametrize(
    "frac,expected",
    [
        (0.25, [1.0, 2.0]),  # near the backlash anchor: it comes first
        (0.5, [1.0, 2.0]),  # the middle still counts as near the limited objective's anchor
        (0.51, [2.0, 1.0]),
        (0.9, [2.0, 1.0]),
    ],
)
def test_a_point_starts_from_the_nearer_anchor_first(frac, expected):
    k = front_knowledge(_point(frac), DEPS)
    assert [d["d"] for d in k["incumbents"]] == expected
    assert k["memo"] is None


def test_a_chained_point_starts_from_the_previous_point_first():
    k = front_knowledge(_point(0.9, previous="eps-9"), DEPS)
    assert [d["d"] for d in k["incumbents"]] == [3.0, 2.0, 1.0]


def test_a_tie_break_starts_from_its_anchor_only_and_an_anchor_from_nothing():
    assert front_knowledge({"tie_of": "anchor-ripple"}, DEPS)["incumbents"] == [{"d": 2.0}]
    assert front_knowledge({}, DEPS)["incumbents"] == []


def test_failed_missing_or_empty_neighbours_give_no_start():
    deps = {
        "anchor-backlash": _record({"d": 1.0}, status="infeasible"),
        "anchor-ripple": _record({"d": 2.0}, verified=False),
        "eps-9": _record({}),
    }
    assert front_knowledge(_point(0.25, previous="eps-9"), deps)["incumbents"] == []
    assert front_knowledge(_point(0.25, previous="eps-8"), {})["incumbents"] == []
    feasible = {"anchor-ripple": _record({"d": 2.0}, status="feasible")}
    assert front_knowledge(_point(0.25), feasible)["incumbents"] == [{"d": 2.0}]


def test_tasks_with_a_memo_share_one_per_problem_starts_and_seed():
    problem = od.load(PROBLEMS / "cs_min_backlash_catalogue.toml")
    catalogue_bnb._MEMOS.clear()
    task = {"problem": problem, "starts": 2, "seed": 0, "memo": True}
    first = front_knowledge(task, {})["memo"]
    assert isinstance(first, catalogue_bnb.InfeasibleBoxes)
    assert front_knowledge(dict(task), {})["memo"] is first
    assert front_knowledge({**task, "seed": 1}, {})["memo"] is not first
    assert front_knowledge({**task, "starts": 3}, {})["memo"] is not first
    assert front_knowledge({**task, "memo": False}, {})["memo"] is None
    # The memo's box is the catalogue variables' full ranges, with their items.
    dvars = discrete_variables(problem)
    assert first.full == {v.name: (v.lower, v.upper) for v in dvars}
    assert first.items == {v.name: tuple(sorted(v.values)) for v in dvars}
    catalogue_bnb._MEMOS.clear()


def _looser_point(backlash: float, limit: float = 0.0403, status: str = "optimal") -> dict:
    return PointRecord(
        id="eps-2",
        kind="eps",
        target="motor_torque",
        status=status,
        verified=True,
        design={"d0": 25.0, "p": 5.0, "d": 6.0},
        objectives={"backlash": backlash, "motor_torque": 2189.9},
        eps={"backlash": limit},
        n_solves=28,
    ).to_dict()


def test_the_looser_points_optimum_inside_a_tighter_limit_is_that_points_optimum():
    """Point 0.0389 of fin_actuator's front: the design of point 0.0403, whose backlash
    is 0.0379, is its optimum too (the feasible set shrank around it): no search."""
    task = {"id": "eps-3", "kind": "eps", "previous": "eps-2"}
    rec = previous_holds(task, {"eps-2": _looser_point(0.0379)}, {"backlash": 0.0389})
    assert rec is not None and (rec.id, rec.kind) == ("eps-3", "eps")
    assert rec.eps == {"backlash": 0.0389} and rec.n_solves == 0
    assert rec.design == {"d0": 25.0, "p": 5.0, "d": 6.0}
    assert "the design of eps-2, inside this point's limits" in rec.message


@pytest.mark.parametrize(
    ("backlash", "limit", "status", "previous"),
    [
        (0.0389 * (1 - 1e-7), 0.0403, "optimal", "eps-2"),  # on the limit, within the tie
        (0.0395, 0.0403, "optimal", "eps-2"),  # beyond the tighter limit
        (0.0379, 0.0385, "optimal", "eps-2"),  # solved under a tighter limit than this one
        (0.0379, 0.0403, "infeasible", "eps-2"),  # no optimum
        (0.0379, 0.0403, "optimal", None),  # the points run in parallel: no neighbour
    ],
)
def test_the_looser_points_design_is_not_taken_without_room_or_an_optimum(
    backlash, limit, status, previous
):
    task = {"id": "eps-3", "kind": "eps", "previous": previous}
    deps = {"eps-2": _looser_point(backlash, limit, status)}
    assert previous_holds(task, deps, {"backlash": 0.0389}) is None
