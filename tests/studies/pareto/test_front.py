"""optdesign/studies/pareto/front.py as a whole, on made-up points (no solve): which
points a front keeps and why the others are rejected, its order, matrix and metrics,
front.json's point and front records, the common hypervolume of several fronts, the
anchors' values and the count of retried points."""

import math

import numpy as np
import pytest

from optdesign.studies.pareto.front import (
    Front,
    FrontPoint,
    anchors_of,
    common_hypervolumes,
    make_front,
)
from optdesign.studies.pareto.metrics import front_metrics, hypervolume, reference_point
from optdesign.studies.pareto.records import PointRecord

OBJ = ["ripple", "backlash"]


def _pt(i, a, b, status="optimal", verified=True, retried="", **kw):
    objectives = {"ripple": a, "backlash": b} if b is not None else {"ripple": a}
    return FrontPoint(
        id=f"p{i}",
        kind="eps",
        target="backlash",
        status=status,
        verified=verified,
        objectives=objectives,
        design={"R": float(i)},
        retried=retried,
        **kw,
    )


def _points():
    return [
        _pt(0, 0.3, 1.0),
        _pt(1, 0.1, 3.0),
        _pt(2, 0.2, 2.0),
        _pt(3, 0.25, 2.5),  # dominated by p2
        _pt(4, 0.05, 0.5, status="infeasible"),
        _pt(5, 0.05, 0.5, verified=False),
        _pt(6, 0.15, None),  # no backlash
        _pt(7, 0.2, 2.0),  # the same point as p2: a duplicate
        _pt(8, 0.01, 0.1, status="feasible"),  # feasible counts as a success
    ]


def test_a_front_keeps_the_verified_non_dominated_points_sorted_and_says_why_not():
    points = _points()
    front = make_front(points, OBJ, "m", 1.5, problem="P", store="s", n_solves=9)
    assert [p.id for p in front.points] == ["p8"]
    # without the feasible point, the others
    front = make_front(_points()[:8], OBJ, "m", 1.5, problem="P", store="s", n_solves=9)
    assert [p.id for p in front.points] == ["p1", "p2", "p0"]
    assert {p.id: p.rejected for p in front.rejected} == {
        "p3": "dominated or duplicate",
        "p4": "failed",
        "p5": "failed",
        "p6": "missing objective",
        "p7": "dominated or duplicate",
    }
    assert [p.id for p in front.rejected] == ["p4", "p5", "p6", "p3", "p7"]
    assert all(p.rejected == "" for p in front.points)
    assert front.F.tolist() == [[0.1, 3.0], [0.2, 2.0], [0.3, 1.0]]
    assert (front.method, front.wall_time_s, front.store, front.n_solves) == ("m", 1.5, "s", 9)
    assert front.problem_object == "P"
    metrics = front_metrics(front.F)
    assert front.metrics["hypervolume"] == pytest.approx(metrics["hypervolume"])
    assert front.metrics["n_failed"] == 2
    assert front.metrics["n_points"] == 3


def test_a_point_another_front_rejected_is_on_this_one_without_a_reason():
    points = _points()
    make_front(points, OBJ, "m")  # p8 dominates every other point here
    assert points[1].rejected == "dominated or duplicate"
    front = make_front(points[:8], OBJ, "m")
    assert [(p.id, p.rejected) for p in front.points] == [("p1", ""), ("p2", ""), ("p0", "")]


def test_ties_on_the_first_objective_are_ordered_by_the_second():
    front = make_front([_pt(0, 0.1, 2.0), _pt(1, 0.2, 1.0), _pt(2, 0.1, 2.0 + 1e-3)], OBJ, "m")
    # (0.1, 2.001) is dominated by (0.1, 2.0): gone; the rest by ripple then backlash
    assert [p.id for p in front.points] == ["p0", "p1"]
    three = make_front(
        [_pt(0, 0.1, 2.0), _pt(1, 0.1, 1.0)], ["ripple", "backlash"], "m"
    )  # (0.1, 1) dominates (0.1, 2)
    assert [p.id for p in three.points] == ["p1"]


def test_an_empty_or_all_failed_front_has_an_empty_matrix_and_zero_metrics():
    front = make_front([_pt(0, 0.1, 1.0, status="failed")], OBJ, "m")
    assert front.points == [] and front.F.shape == (0, 2)
    assert front.metrics == {
        "n_points": 0,
        "n_nondominated": 0,
        "hypervolume": 0.0,
        "n_failed": 1,
    }
    assert make_front([], OBJ, "m").F.shape == (0, 2)


def test_the_retried_count_covers_the_front_and_its_rejected_points():
    front = make_front(
        [
            _pt(0, 0.1, 3.0, retried="failed"),
            _pt(1, 0.2, 2.0),
            _pt(2, 0.3, 3.0, retried="worse than a neighbour"),
        ],
        OBJ,
        "m",
    )
    assert [p.id for p in front.rejected] == ["p2"]
    assert front.n_retried == 2


def test_a_point_from_a_record_takes_its_values_and_the_weights_as_eps():
    rec = PointRecord(
        id="w1",
        kind="weights",
        target="ripple",
        status="optimal",
        verified=True,
        objectives={"ripple": 0.1, "backlash": 2.0},
        design={"R": 40.0},
        weights={"ripple": 0.3, "backlash": 0.7},
        active=["stroke"],
        n_solves=3,
    )
    point = FrontPoint.from_record(rec, "weighted_sum")
    assert (point.method, point.id, point.rejected) == ("weighted_sum", "w1", "")
    assert point.eps == {"ripple": 0.3, "backlash": 0.7}
    assert point.raw is None and point.n_solves == 3
    rec.objectives["ripple"] = 9.0
    rec.design["R"] = 9.0
    rec.active.append("x")
    assert point.objectives["ripple"] == 0.1 and point.design["R"] == 40.0
    assert point.active == ["stroke"]
    with_eps = FrontPoint.from_record(
        PointRecord(id="e", kind="eps", target="b", status="optimal", eps={"a": 1.0}), "m"
    )
    assert with_eps.eps == {"a": 1.0}


def test_the_json_of_a_point_and_of_a_front():
    point = _pt(0, 0.1, math.nan, message="ok", retried="failed")
    point.method, point.n_solves, point.wall_time_s = "m", 4, 2.5
    d = point.to_dict()
    assert d == {
        "objectives": {"ripple": 0.1, "backlash": None},
        "design": {"R": 0.0},
        "status": "optimal",
        "active": [],
        "method": "m",
        "verified": True,
        "eps": {},
        "id": "p0",
        "rejected": "",
        "n_solves": 4,
        "wall_time_s": 2.5,
        "message": "ok",
        "retried": "failed",
    }
    front = make_front([_pt(0, 0.1, 1.0), _pt(1, 0.2, 2.0)], OBJ, "m", 3.0, notes=["n"])
    fd = front.to_dict()
    assert list(fd) == [
        "method",
        "objectives",
        "metrics",
        "wall_time_s",
        "anchors",
        "store",
        "n_solves",
        "settings",
        "notes",
        "points",
        "rejected",
    ]
    assert [p["id"] for p in fd["points"]] == ["p0"]
    assert [p["id"] for p in fd["rejected"]] == ["p1"]
    assert fd["notes"] == ["n"] and fd["wall_time_s"] == 3.0


def test_common_hypervolumes_use_one_reference_point_for_every_front():
    a = make_front([_pt(0, 0.1, 3.0), _pt(1, 0.3, 1.0)], OBJ, "a")
    b = make_front([_pt(0, 0.2, 2.0), _pt(1, 0.4, 0.5)], OBJ, "b")
    empty = make_front([], OBJ, "e")
    common_hypervolumes([a, b, empty])
    ref = reference_point(np.vstack([a.F, b.F]))
    assert a.metrics["common_reference_point"] == pytest.approx(ref.tolist())
    assert b.metrics["common_reference_point"] == pytest.approx(ref.tolist())
    assert a.metrics["hypervolume_common"] == pytest.approx(hypervolume(a.F, ref))
    assert b.metrics["hypervolume_common"] == pytest.approx(hypervolume(b.F, ref))
    assert empty.metrics["hypervolume_common"] == 0.0
    only_empty = make_front([], OBJ, "e")
    common_hypervolumes([only_empty])
    assert "hypervolume_common" not in only_empty.metrics


def test_the_anchors_values_are_copied_per_anchor():
    rec = PointRecord(id="a", kind="anchor", target="t", status="optimal", objectives={"x": 1.0})
    out = anchors_of({"x": rec})
    assert out == {"x": {"x": 1.0}}
    rec.objectives["x"] = 2.0
    assert out["x"]["x"] == 1.0
    assert Front(OBJ, "m", []).anchors == {}


def test_common_hypervolumes_of_two_fronts_against_their_shared_reference_point():
    """Two fronts measured against the reference point of both together: each front's
    common hypervolume is its hypervolume against that point (the larger front's is
    larger), not against its own."""
    from optdesign.studies.pareto.front import Front, FrontPoint, common_hypervolumes
    from optdesign.studies.pareto.metrics import hypervolume, reference_point

    def front(F):
        points = [
            FrontPoint(
                id=f"p{k}",
                kind="eps",
                status="optimal",
                verified=True,
                target="a",
                objectives={"a": a, "b": b},
            )
            for k, (a, b) in enumerate(F)
        ]
        return Front(["a", "b"], "m", points)

    small, large = front([[1.0, 2.0], [2.0, 1.0]]), front([[0.5, 3.0], [3.0, 0.5], [1.0, 1.0]])
    common_hypervolumes([small, large])
    ref = reference_point(np.vstack([small.F, large.F]))
    for f in (small, large):
        assert f.metrics["common_reference_point"] == pytest.approx(ref.tolist())
        assert f.metrics["hypervolume_common"] == pytest.approx(hypervolume(f.F, ref))
    assert small.metrics["hypervolume_common"] != pytest.approx(hypervolume(small.F))
    assert large.metrics["hypervolume_common"] > small.metrics["hypervolume_common"]


def test_a_front_without_points_names_what_its_least_violating_design_violates():
    """``Front.no_point_text``: the command line's line for an infeasible front names the
    requirements that the least violating of its rejected designs violates."""
    from pathlib import Path

    import optdesign as od
    from optdesign.formulations.diagnosis import violated_text

    problem = od.load(Path(__file__).resolve().parents[3] / "problems" / "cs_min_backlash.toml")
    mid = problem.design_dict(problem.midpoint())
    low = {**mid, **{v.name: v.lower for v in problem.free}}
    X = np.array([[d[v.name] for v in problem.free] for d in (low, mid)])
    worst = np.asarray(problem.evaluate(X).violation, dtype=float)
    assert worst[0] != worst[1]  # one design violates less than the other
    least = X[int(np.argmin(worst))]
    rejected = []
    for k, design in enumerate((low, mid)):
        rejected.append(_pt(k, 0.1, 1.0, status="infeasible"))
        rejected[-1].design = design
    front = make_front(rejected, OBJ, "epsilon", problem=problem)
    text = front.no_point_text(problem)
    assert text == (
        "epsilon: no feasible design among 2 designs; the least violating one: "
        + (violated_text(problem, least) or "none")
    )
    assert make_front([], OBJ, "nsga2").no_point_text(problem) == "nsga2: no feasible design"
