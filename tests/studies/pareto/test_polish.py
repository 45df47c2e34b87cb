"""optdesign.studies.pareto.polish: where a front's points are solved again - the seams
between points not started one from the other, the points a seen design beats, the
neighbours of a point that improved - worked out by hand on made-up records."""

from __future__ import annotations

from optdesign.studies.pareto.polish import best_seen, round_tasks, seams
from optdesign.studies.pareto.records import PointRecord


def _rec(id_, a, b, warm=None, retried="", status="optimal", eps=None):
    return PointRecord(
        id=id_,
        kind="eps",
        target="b",
        status=status,
        verified=True if status == "optimal" else None,
        objectives={"a": a, "b": b},
        x=[a, b],
        eps=dict(eps if eps is not None else {"a": a}),
        warm=warm,
        retried=retried,
    )


def _chain():
    """Five points: 0-1 from anchor A's side, 4-3-2 from B's side (they meet between 1
    and 2); point 3 was re-solved cold."""
    ids = [f"p{i}" for i in range(5)]
    recs = [
        _rec("p0", 1.0, 9.0, warm="anchor-a"),
        _rec("p1", 2.0, 7.0, warm="p0"),
        _rec("p2", 3.0, 6.0, warm="p3"),
        _rec("p3", 4.0, 4.0, warm="p4", retried="jump in design space"),
        _rec("p4", 5.0, 3.0, warm="anchor-b"),
    ]
    return recs, ids


def test_seams_are_neighbours_not_started_one_from_the_other():
    recs, ids = _chain()
    # 1|2: the chains meet; 3|4: point 3 came from cold starts (2|3 is no seam: point 2
    # was started from point 3's design, so the two lie on one branch)
    assert seams(recs, ids) == [1, 3]


def test_a_seen_design_that_meets_the_bound_and_beats_the_point_is_found():
    point = _rec("p", 3.0, 6.0, eps={"a": 3.0})
    worse = _rec("w", 2.0, 6.5)
    better = _rec("s", 2.9, 5.0)
    best = _rec("t", 3.0 * (1 + 1e-7), 4.5)  # on the bound, within a tie
    outside = _rec("o", 3.5, 1.0)  # better but beyond the point's bound
    failed = _rec("f", 1.0, 1.0, status="failed")
    assert best_seen(point, [worse, better, best, outside, failed], "b", point.eps) is best
    assert best_seen(point, [worse, outside, failed], "b", point.eps) is None
    tie = _rec("e", 2.0, 6.0 * (1 - 1e-8))  # a tie is no improvement
    assert best_seen(point, [tie], "b", point.eps) is None


def test_round_one_solves_the_seams_both_ways_and_the_beaten_points():
    recs, ids = _chain()
    seen = [*recs, _rec("anchor-x", 2.5, 5.5)]  # beats p2 (a 2.5 <= 3, b 5.5 < 6) only
    tasks = round_tasks(recs, ids, seen, [r.id for r in seen], None, 1, "eps", {"k": 1})
    by_point = {t["point"]: t["sources"] for t in tasks}
    assert by_point == {
        "p1": ["p2"],
        "p2": ["anchor-x", "p1"],
        "p3": ["p4"],
        "p4": ["p3"],
    }
    t = next(t for t in tasks if t["point"] == "p2")
    assert t["id"] == "eps-0002-polish1" and t["kind"] == "polish" and t["index"] == 2
    assert t["after"] == sorted({"p2", "anchor-x", "p1"}) and t["k"] == 1


def test_later_rounds_spread_an_improvement_to_its_neighbours_only():
    recs, ids = _chain()
    ids[2] = "p2-polish1"
    tasks = round_tasks(recs, ids, recs, [r.id for r in recs], {2}, 2, "eps", {})
    assert {t["point"]: t["sources"] for t in tasks} == {
        "p1": ["p2-polish1"],
        "p3": ["p2-polish1"],
    }
    assert [t["id"] for t in tasks] == ["eps-0001-polish2", "eps-0003-polish2"]
    assert round_tasks(recs, ids, recs, [r.id for r in recs], set(), 3, "eps", {}) == []
