"""optdesign/studies/pareto/chains.py as a whole, on made-up records (no solve): the
anchors' tasks, the anchor's failure message in each of its forms, the two chains of a
two-objective front driven as the runner drives them (frame, first and last points,
successors, claims, a fixed split, uniform and explicit limits), and the rows of a
three-objective front."""

import math
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.problem.load import load
from optdesign.studies.pareto.chains import (
    NoFeasibleAnchor,
    TwoChains,
    anchor_message,
    anchor_tasks,
    check_anchor,
    ideal_reached,
    three_objective_tasks,
)
from optdesign.studies.pareto.records import PointRecord
from optdesign.studies.pareto.tasks import ANCHOR_SLACK

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"


def _rec(id_, a, b, status="optimal", **kw):
    return PointRecord(
        id=id_,
        kind="anchor",
        target="x",
        status=status,
        verified=True,
        objectives={"A": a, "B": b},
        **kw,
    ).to_dict()


# --- anchors ---------------------------------------------------------------------------------


def test_anchor_tasks_multistarts_first_then_tie_breaks_in_rotated_order():
    tasks = anchor_tasks({"problem": "P"}, ["A", "B", "C"], 5, 7, 2)
    assert [(t["id"], t["kind"]) for t in tasks] == [
        ("anchor-A-ms", "anchor-multistart"),
        ("anchor-B-ms", "anchor-multistart"),
        ("anchor-C-ms", "anchor-multistart"),
        ("anchor-A", "anchor"),
        ("anchor-B", "anchor"),
        ("anchor-C", "anchor"),
    ]
    assert [t["order"] for t in tasks[:3]] == [["A", "B", "C"], ["B", "C", "A"], ["C", "A", "B"]]
    assert [t["order"] for t in tasks[3:]] == [["A", "B", "C"], ["B", "C", "A"], ["C", "A", "B"]]
    for t in tasks[:3]:
        assert (t["starts"], t["seed"], t["agree"], t["problem"]) == (5, 7, 2, "P")
        assert "after" not in t
    for t, name in zip(tasks[3:], "ABC", strict=True):
        assert t["multistart"] == f"anchor-{name}-ms" and t["after"] == [f"anchor-{name}-ms"]
        assert "starts" not in t and t["problem"] == "P"


@pytest.fixture(scope="module")
def problem():
    return od.load(PROBLEMS / "cs_min_backlash.toml")


def test_the_anchor_message_without_a_problem_or_design_lists_the_records_violations(problem):
    rec = PointRecord.from_dict(
        _rec("a", 1, 2, status="infeasible", violated=["stroke", "ripple_max"])
    )
    head = "anchor A: no feasible design found (status infeasible)"
    assert anchor_message("A", rec) == f"{head}; violated: stroke, ripple_max"
    rec.violated = []
    assert anchor_message("A", rec) == f"{head}; violated: none reported"
    # a design without every free variable cannot be evaluated: the record's list
    rec.violated = ["stroke"]
    rec.design = {"R": 50.0}
    assert anchor_message("A", rec, problem) == f"{head}; violated: stroke"


def test_the_anchor_message_names_what_the_best_point_violates(problem):
    from optdesign.formulations.diagnosis import violated_text

    x = problem.lower().astype(float).copy()
    design = problem.design_dict(x)
    shown = violated_text(problem, x)
    assert shown  # the corner of the bounds violates something
    rec = PointRecord.from_dict(_rec("a", 1, 2, status="infeasible", design=design))
    assert anchor_message("A", rec, problem) == (
        "anchor A: no feasible design found (status infeasible); at the best point found: "
        f"{shown}; od.solve (optdesign solve) gives the smallest relaxation of each"
    )


def test_the_anchor_message_when_nothing_is_violated_suggests_more_starts(problem):
    result = od.solve(problem, starts=1, ranges=False)
    design = dict(result.design)
    rec = PointRecord.from_dict(_rec("a", 1, 2, status="failed", design=design, message="maxiter"))
    assert anchor_message("A", rec, problem) == (
        "anchor A: no feasible design found (status failed): no requirement is violated at "
        "the best point found (the solver stopped: maxiter); more starts (starts=) may find one"
    )
    rec.message = ""
    assert "(the solver stopped: failed)" in anchor_message("A", rec, problem)


def test_check_anchor_passes_a_success_and_raises_naming_the_objective():
    check_anchor(PointRecord.from_dict(_rec("a", 1, 2)), "A")
    check_anchor(PointRecord.from_dict(_rec("a", 1, 2, status="feasible")), "A")
    bad = PointRecord.from_dict(_rec("a", 1, 2, status="infeasible"))
    with pytest.raises(NoFeasibleAnchor) as err:
        check_anchor(bad, "B")
    assert err.value.objective == "B" and err.value.record is bad
    assert str(err.value).startswith("anchor B: no feasible design found (status infeasible)")
    unverified = PointRecord.from_dict({**_rec("a", 1, 2), "verified": False})
    with pytest.raises(NoFeasibleAnchor):
        check_anchor(unverified, "A")


# --- two chains ----------------------------------------------------------------------------------

# anchor A minimises A: (A, B) = (1, 10); anchor B's multistart (10.5, 2), its tie-break (10, 2)
DONE_A = {"anchor-A": _rec("anchor-A", 1.0, 10.0)}
MS_B = {"anchor-B-ms": _rec("anchor-B-ms", 10.5, 2.0)}
TIE_B = {"anchor-B": _rec("anchor-B", 10.0, 2.0)}
LO = 1.0 * (1 + ANCHOR_SLACK) + 1e-12


def _chains(n=5, spacing="arc", eps_values=None, split=None):
    return TwoChains(["A", "B"], n, "front", {"problem": None, "x": 1}, spacing, eps_values, split)


def test_the_arc_frame_rests_on_anchor_a_and_bs_multistart_and_starts_chain_a():
    ch = _chains()
    assert ch({"id": "anchor-A"}, {}, DONE_A) == []  # B's multistart not in yet
    new = ch({"id": "anchor-B-ms"}, {}, {**DONE_A, **MS_B})
    assert [t["id"] for t in new] == ["front-0000"]
    first = new[0]
    assert first["eps"] == {"A": LO}
    assert (first["kind"], first["target"], first["warm"], first["after"]) == (
        "eps",
        "B",
        "anchor-A",
        ["anchor-A"],
    )
    assert (first["index"], first["dir"], first["x"]) == (0, 1, 1)
    assert ch.frame == {
        "a0": 1.0,
        "b0": 10.0,
        "ra": 10.5 - 1.0,
        "rb": 10.0 - 2.0,
        "a_lo": LO,
        "a_hi": 10.5,
    }
    assert ch.claimed == {0}


def test_chain_b_starts_at_bs_tie_break_with_its_exact_limit_and_the_chains_meet():
    ch = _chains()
    done = {**DONE_A, **MS_B}
    ch({"id": "anchor-B-ms"}, {}, done)
    done.update(TIE_B)
    new = ch({"id": "anchor-B"}, {}, done)
    assert [t["id"] for t in new] == ["front-0004"]
    assert new[0]["eps"] == {"A": 10.0} and new[0]["dir"] == -1 and new[0]["warm"] == "anchor-B"
    assert ch({"id": "anchor-B"}, {}, done) == []  # claimed once
    up = ch(ch.tasks[0], {}, done)
    assert [t["id"] for t in up] == ["front-0001"]
    mid = up[0]
    assert (mid["eps_name"], mid["arc"], mid["warm"], mid["after"]) == (
        "A",
        0.5,
        "front-0000",
        ["front-0000"],
    )
    assert mid["fallback_eps"] == pytest.approx(LO + (10.5 - LO) * 1 / 4)
    assert mid["frame"] is ch.frame and "eps" not in mid
    down = ch(ch.tasks[1], {}, done)
    assert [(t["id"], t["dir"], t["arc"]) for t in down] == [("front-0003", -1, 1.5)]
    # the chains meet at 2: whichever asks first gets it, the other adds nothing
    assert [t["id"] for t in ch(up[0], {}, done)] == ["front-0002"]
    assert ch(down[0], {}, done) == []
    assert ch.claimed == {0, 1, 2, 3, 4}


def test_the_ascending_chain_never_takes_the_last_point_and_strangers_add_nothing():
    ch = _chains(n=3)
    done = {**DONE_A, **MS_B}
    ch({"id": "anchor-B-ms"}, {}, done)
    one = ch(ch.tasks[0], {}, done)
    assert [t["id"] for t in one] == ["front-0001"]
    assert ch(one[0], {}, done) == []  # j = 2 = n - 1 belongs to chain B
    other = {"id": "other-0000", "kind": "eps", "index": 0, "dir": 1}
    assert ch(other, {}, done) == []
    anchor = {"id": "front-0000", "kind": "anchor", "index": 0, "dir": 1}
    assert ch(anchor, {}, done) == []


def test_a_fixed_split_waits_for_both_tie_breaks_and_gives_each_chain_its_side():
    ch = _chains(n=6, split=3)
    done = {**DONE_A, **MS_B}
    assert ch({"id": "anchor-B-ms"}, {}, done) == []  # the frame needs B's tie-break
    done.update(TIE_B)
    new = ch({"id": "anchor-B"}, {}, done)
    assert [t["id"] for t in new] == ["front-0000", "front-0005"]
    assert ch.frame["ra"] == pytest.approx(10.0 - 1.0) and ch.frame["a_hi"] == 10.0
    t1 = ch(new[0], {}, done)[0]
    t2 = ch(t1, {}, done)[0]
    assert [t1["index"], t2["index"]] == [1, 2]
    assert ch(t2, {}, done) == []  # 3 is chain B's
    t4 = ch(new[1], {}, done)[0]
    t3 = ch(t4, {}, done)[0]
    assert [t4["index"], t3["index"]] == [4, 3]
    assert ch(t3, {}, done) == []  # 2 is chain A's (claimed anyway)


def test_uniform_limits_are_evenly_spaced_between_the_ends_of_the_front():
    ch = _chains(n=4, spacing="uniform")
    done = {**DONE_A, **MS_B}
    assert ch({"id": "anchor-B-ms"}, {}, done) == []
    done.update(TIE_B)
    first, last = ch({"id": "anchor-B"}, {}, done)
    assert ch.eps_values == pytest.approx(list(np.linspace(LO, 10.0, 4)))
    assert first["eps"] == {"A": pytest.approx(LO)} and last["eps"] == {"A": pytest.approx(10.0)}
    nxt = ch(first, {}, done)[0]
    assert nxt["eps"] == {"A": pytest.approx(LO + (10.0 - LO) / 3)}
    assert "arc" not in nxt


def test_explicit_limits_are_taken_as_given():
    ch = _chains(n=3, eps_values=[2, 5.5, 9])
    assert ch.eps_values == [2.0, 5.5, 9.0]
    done = {**DONE_A, **MS_B, **TIE_B}
    first, last = ch({"id": "anchor-B"}, {}, done)
    assert first["eps"] == {"A": 2.0} and last["eps"] == {"A": 9.0}
    assert ch(first, {}, done)[0]["eps"] == {"A": 5.5}


def test_a_failed_anchor_stops_the_chains_naming_it():
    ch = _chains()
    bad_a = {"anchor-A": _rec("anchor-A", 1.0, 10.0, status="infeasible")}
    with pytest.raises(NoFeasibleAnchor) as err:
        ch({"id": "anchor-B-ms"}, {}, {**bad_a, **MS_B})
    assert err.value.objective == "A"
    ch = _chains()
    bad_ms = {"anchor-B-ms": _rec("anchor-B-ms", 10.5, 2.0, status="infeasible")}
    with pytest.raises(NoFeasibleAnchor) as err:
        ch({"id": "anchor-B-ms"}, {}, {**DONE_A, **bad_ms})
    assert err.value.objective == "B"
    ch = _chains()
    done = {**DONE_A, **MS_B}
    ch({"id": "anchor-B-ms"}, {}, done)
    with pytest.raises(NoFeasibleAnchor):
        ch({"id": "anchor-B"}, {}, {**done, "anchor-B": _rec("anchor-B", 1, 1, status="failed")})


def test_a_degenerate_frame_keeps_positive_ranges():
    ch = _chains()
    same = {"anchor-B-ms": _rec("anchor-B-ms", 1.0, 10.0)}
    ch({"id": "anchor-B-ms"}, {}, {**DONE_A, **same})
    assert ch.frame["ra"] == 1e-300 and ch.frame["rb"] == 1e-300
    assert ch.frame["a_hi"] == LO  # never below the first limit
    # anchor A has B's least value too: point 0 is the whole front, nothing else is added
    assert ch.single and [t["id"] for t in ch.tasks] == ["front-0000"]
    done = {**DONE_A, **same, "anchor-B": _rec("anchor-B", 1.0, 10.0)}
    assert ch({"id": "anchor-B"}, {}, done) == [] and ch(ch.tasks[0], {}, done) == []


@pytest.mark.parametrize(
    ("b_of_a", "single"),
    [(10.0 * (1 + 0.9e-6), True), (10.0 * (1 + 1.1e-6), False), (9.0, True)],
)
def test_a_front_is_one_design_when_anchor_a_has_the_least_b_to_the_tie_tolerance(b_of_a, single):
    """Anchor A (least A, then least B) with B's least value (10, from B's optimum) to a
    relative 1e-6 dominates every design in both objectives."""
    assert ideal_reached(PointRecord.from_dict(_rec("anchor-A", 1.0, b_of_a)),
                         PointRecord.from_dict(_rec("anchor-B-ms", 2.0, 10.0)), "B") is single  # fmt: skip


def test_a_front_whose_anchors_coincide_is_one_point_with_a_note_saying_why():
    """The pivoting screw's backlash optimum has its least ripple too. Swept, its 30
    points were copies of one design that differed in the 8th digit (three of them kept
    as non-dominated with sqpmethod as the sweep's primary); it is one point, not swept."""
    problem = od.load(PROBLEMS / "pivot_min_backlash.toml")
    front = od.pareto(problem, ["backlash", "ripple"], points=6, workers=1, files=False)
    assert len(front.points) == 1 and front.rejected == []
    (note,) = [n for n in front.notes if "one design" in n]
    assert note.startswith("backlash's optimum also has the least ripple")
    point, anchor = front.points[0], front.anchors["backlash"]
    assert point.objectives["backlash"] == pytest.approx(anchor["backlash"], rel=1e-6)
    assert point.objectives["ripple"] == pytest.approx(anchor["ripple"], rel=1e-6)


# --- three objectives ------------------------------------------------------------------------------


def test_three_objective_rows_heads_then_chains_from_the_tightest_limit():
    values = {"A": (1.0, 8.0, 5.0), "B": (4.0, 2.0, 6.0), "C": (7.0, 5.0, 1.0)}
    anchors = {
        k: PointRecord(
            id=k.lower(),
            kind="anchor",
            target=k,
            status="optimal",
            objectives=dict(zip("ABC", v, strict=True)),
        )
        for k, v in values.items()
    }
    tasks = three_objective_tasks(anchors, ["A", "B", "C"], 5, "f", {"p": 1})
    n_side = 3  # ceil(sqrt(5))
    assert len(tasks) == n_side * (n_side + 1)
    lo_a = 1.0 * (1 + ANCHOR_SLACK) + 1e-12
    rows = np.linspace(lo_a, 7.0, n_side)
    heads = [t for t in tasks if t.get("head")]
    assert [h["id"] for h in heads] == ["f-000-head", "f-001-head", "f-002-head"]
    assert [h["warm"] for h in heads] == ["anchor-A", "f-000-head", "f-001-head"]
    for r, h in enumerate(heads):
        assert h["eps"] == {"A": pytest.approx(rows[r]), "C": math.inf}
        assert (h["target"], h["index"], h["kind"], h["p"]) == ("B", r * 4, "eps", 1)
        assert h["after"] == [h["warm"]]
    row1 = [t for t in tasks if t["id"].startswith("f-001-") and not t.get("head")]
    assert [t["id"] for t in row1] == ["f-001-000", "f-001-001", "f-001-002"]
    assert [t["frac"] for t in row1] == [0.0, 0.5, 1.0]
    assert [t["index"] for t in row1] == [5, 6, 7]
    assert [t["warm"] for t in row1] == ["f-001-head", "f-001-000", "f-001-001"]
    assert row1[0]["after"] == ["f-001-head"]
    assert row1[1]["after"] == ["f-001-000", "f-001-head"]
    for t in row1:
        assert t["eps_row"] == {"A": pytest.approx(rows[1])}
        assert (t["target"], t["b_name"], t["b_hi"], t["row_head"]) == ("C", "B", 8.0, "f-001-head")
        assert t["jump"] is None
    # at least a 2 x 2 grid
    assert len(three_objective_tasks(anchors, ["A", "B", "C"], 1, "g", {})) == 2 * 3


ROOT = Path(__file__).resolve().parents[3]


def test_three_objective_tasks_are_indexed_row_by_row():
    """The index of a three-objective front's tasks is their row-major order (each row's
    head, then its points): the front lists its points, and seeds their retry starts,
    by it."""
    from optdesign.studies.pareto.chains import three_objective_tasks
    from optdesign.studies.pareto.records import PointRecord

    names = ["size", "backlash", "ripple"]
    anchors = {
        k: PointRecord(
            id=f"anchor-{k}",
            kind="anchor",
            status="optimal",
            verified=True,
            target=k,
            objectives=values,
        )
        for k, values in (
            ("size", {"size": 1.0, "backlash": 3.0, "ripple": 3.0}),
            ("backlash", {"size": 3.0, "backlash": 1.0, "ripple": 2.0}),
            ("ripple", {"size": 2.0, "backlash": 2.0, "ripple": 1.0}),
        )
    }
    tasks = three_objective_tasks(anchors, names, 9, "t", {})
    assert [t["index"] for t in tasks] == list(range(len(tasks))) and len(tasks) == 12
    assert [t["id"] for t in tasks[:5]] == [
        "t-000-head",
        "t-000-000",
        "t-000-001",
        "t-000-002",
        "t-001-head",
    ]


def test_a_failed_tie_break_of_the_far_anchor_names_what_its_point_violates(tmp_path):
    """The two-chain sweep checks anchor B's tie-break before the last point: a failed
    one raises NoFeasibleAnchor naming, in the file's units, what its best point violates
    (the problem reaches the check)."""
    import json

    from optdesign.formulations.diagnosis import violated_text
    from optdesign.studies.pareto.chains import NoFeasibleAnchor, TwoChains

    fork = load(ROOT / "problems" / "fork_min_backlash.toml")
    od.pareto(fork, ["size", "backlash"], 3, out=tmp_path, starts=1)
    lines = (tmp_path / "epsilon.jsonl").read_text().splitlines()[1:]
    done = {r["id"]: r for r in map(json.loads, lines)}
    chains = TwoChains(["size", "backlash"], 3, "epsilon", {"problem": fork}, "arc", None)
    first = {k: done[k] for k in ("anchor-size", "anchor-backlash-ms")}
    assert chains({"id": "anchor-backlash-ms"}, {}, first)  # the frame and point 0
    failed = dict(done["anchor-backlash"], status="failed", verified=False)
    # its best point: the anchor's design with every free variable at its lower bound
    failed["design"] = {**failed["design"], **{v.name: v.lower for v in fork.free}}
    failed["x"] = [v.lower for v in fork.free]
    shown = violated_text(fork, np.array(failed["x"]))
    assert shown  # that point violates something
    with pytest.raises(NoFeasibleAnchor) as caught:
        chains({"id": "anchor-backlash"}, {}, {**first, "anchor-backlash": failed})
    assert "anchor backlash: no feasible design found (status failed)" in str(caught.value)
    assert f"at the best point found: {shown}" in str(caught.value)


def test_an_anchor_message_without_the_problem_lists_the_records_violations():
    """Without the problem the message of a failed anchor falls back on the record's own
    list of violated rows, whatever design it holds."""
    from optdesign.studies.pareto.chains import anchor_message
    from optdesign.studies.pareto.records import PointRecord

    rec = PointRecord(
        id="anchor-size", kind="anchor", status="failed", verified=False, target="size", design={"R": 50.0},
        violated=["nut_travel", "mean_ratio"],
    )  # fmt: skip
    assert anchor_message("size", rec) == (
        "anchor size: no feasible design found (status failed); violated: nut_travel, mean_ratio"
    )
    rec.violated = []
    assert anchor_message("size", rec).endswith("violated: none reported")
