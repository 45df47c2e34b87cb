"""Ties between catalogue combinations are decided by value, then by the items.

A catalogue optimum where one variable does not change the objective (the fin actuator's
screw diameter when the pin decides the backlash) has tied combinations. Which one is
reported must not depend on the order the search meets them in (the warm bounds, a
front's or sweep's first incumbent, the number of workers): the smallest items, in the
declared order of the catalogue variables, win a tie.

The same fake node solvers check the diagnosis's depth-first search (``first_feasible``):
a relaxation sitting on items does not settle its box, whose other combinations may work.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pytest

from optdesign.formulations.catalogue.bnb import (
    box_cannot_win,
    branch_and_bound_warm,
    combination_key,
    wins,
)
from optdesign.formulations.catalogue.search import enumerate_catalogue
from optdesign.solvers.result import MultistartInfo, Result

A_ITEMS = (1.0, 2.0, 3.0)
B_ITEMS = (1.0, 2.0, 3.0, 4.0)


@dataclass
class _Var:
    name: str
    values: tuple[float, ...]
    discrete: bool = True

    @property
    def lower(self) -> float:
        return self.values[0]

    @property
    def upper(self) -> float:
        return self.values[-1]


@dataclass
class _Problem:
    free: list[_Var]


def _infeasible() -> Result:
    """A fake node solve with no design."""
    return Result(
        status="infeasible",
        objective=float("nan"),
        design={},
        solver="fake",
        formulation="nlp",
        wall_time_s=0.0,
    )


class TiedNodes:
    """A node solver whose objective, (a - 2)^2 + 1, ignores b; each relaxation sits at
    the top of b's range, so the search meets the largest b first."""

    def __init__(self):
        self.problem = _Problem([_Var("a", A_ITEMS), _Var("b", B_ITEMS)])
        self.names = ["a", "b"]
        self.starts = 1
        self.boxes: list[dict] = []

    def solve(
        self, box, x_hint=None, warm=False, prunes=None, fallback=True, floor=None, relaxed=False
    ):
        self.boxes.append(dict(box))
        lo_a, hi_a = box.get("a", (A_ITEMS[0], A_ITEMS[-1]))
        _, hi_b = box.get("b", (B_ITEMS[0], B_ITEMS[-1]))
        a = min(max(2.0, lo_a), hi_a)
        return Result(
            status="optimal",
            objective=(a - 2.0) ** 2 + 1.0,
            design={"a": a, "b": hi_b},
            solver="fake",
            formulation="nlp",
            wall_time_s=0.0,
        )

    def x_of(self, result):
        return np.array([result.design[n] for n in self.names])


def _search(candidates=()):
    ns = TiedNodes()
    best, stats = branch_and_bound_warm(ns, ns.solve({}), candidates)
    return best, stats


def test_the_search_counts_each_node_it_solves():
    """``details.catalogue.nodes``: every node solve (root, children, leaves, the first
    incumbent's candidates)."""
    for candidates in ((), [{"a": 2.0, "b": 4.0}, {"a": 3.0, "b": 1.0}]):
        ns = TiedNodes()
        _, stats = branch_and_bound_warm(ns, ns.solve({}), candidates)
        assert stats["nodes"] == len(ns.boxes)
        assert stats["seeded"] == len(candidates)


def test_the_smallest_tied_items_win_whatever_the_search_meets_first():
    best, stats = _search()
    assert best.objective == pytest.approx(1.0)
    # b ties at every item: b = 1 is reported, although the search met b = 4 first
    assert (best.design["a"], best.design["b"]) == (2.0, 1.0)
    assert stats["leaves"] >= 2


@pytest.mark.parametrize(
    "candidates",
    [
        [{"a": 2.0, "b": 4.0}],
        [{"a": 2.0, "b": 3.0}, {"a": 2.0, "b": 2.0}],
        [{"a": 3.0, "b": 1.0}, {"a": 2.0, "b": 4.0}],
        [{"a": 2.0, "b": 1.0}],
    ],
)
def test_a_first_incumbent_changes_the_work_not_the_tie(candidates):
    best, _ = _search(candidates)
    assert (best.design["a"], best.design["b"]) == (2.0, 1.0)


def test_enumeration_decides_the_tie_the_same_way():
    best, table = enumerate_catalogue(TiedNodes())
    assert len(table) == len(A_ITEMS) * len(B_ITEMS)
    assert (best.design["a"], best.design["b"]) == (2.0, 1.0)


def test_wins_is_value_first_then_items():
    small, large = (2.0, 1.0), (2.0, 4.0)
    assert wins(1.0, large, None, None)
    # better beyond the tolerance wins whatever the items
    assert wins(1.0, large, 1.001, small)
    assert not wins(1.001, small, 1.0, large)
    # within the tolerance (1e-6 relative) the smaller items win, either way round
    assert wins(1.0 + 5e-7, small, 1.0, large)
    assert wins(1.0 - 5e-7, small, 1.0, large)
    assert not wins(1.0 - 5e-7, large, 1.0, small)
    assert not wins(1.0, small, 1.0, small)


def test_a_tied_box_is_pruned_only_when_it_holds_no_smaller_combination():
    names = ["a", "b"]
    best_key = combination_key({"b": 3.0, "a": 2.0}, names)
    assert best_key == (2.0, 3.0)
    holds_smaller = {"a": (2.0, 3.0), "b": (1.0, 4.0)}
    holds_none = {"a": (2.0, 3.0), "b": (3.0, 4.0)}
    assert not box_cannot_win(1.0, holds_smaller, names, 1.0, best_key)
    assert box_cannot_win(1.0, holds_none, names, 1.0, best_key)
    # worse beyond the tolerance: pruned whatever it holds
    assert box_cannot_win(1.01, holds_smaller, names, 1.0, best_key)
    # better beyond the tolerance: never pruned
    assert not box_cannot_win(0.99, holds_none, names, 1.0, best_key)


class TrapNodes(TiedNodes):
    """The relaxation of every wide box sits on (2, top of b), but the combination
    (2, 4) is infeasible with its own items (its box's data were the most favourable)."""

    def solve(
        self, box, x_hint=None, warm=False, prunes=None, fallback=True, floor=None, relaxed=False
    ):
        result = super().solve(box, x_hint, warm, prunes, fallback, floor)
        fixed = all(box.get(n, (0, 1))[0] == box.get(n, (0, 1))[1] for n in self.names)
        if fixed and (box["a"][0], box["b"][0]) == (2.0, 4.0):
            return _infeasible()
        return result


def test_first_feasible_searches_the_rest_of_a_box_whose_relaxation_sat_on_items():
    from optdesign.formulations.catalogue.bnb import first_feasible

    ns = TrapNodes()
    found = first_feasible(ns)
    # the leaf (2, 4) fails; the rest of its box still holds feasible combinations
    assert found is not None and found.success
    assert (found.design["a"], found.design["b"]) == (2.0, 3.0)
    assert {"a": (2.0, 2.0), "b": (4.0, 4.0)} in ns.boxes  # the failed leaf was tried


class CountedNodes(TiedNodes):
    """The tied node solver, recording how each box was solved."""

    def __init__(self):
        super().__init__()
        self.calls: list[tuple[dict, bool]] = []

    def solve(
        self, box, x_hint=None, warm=False, prunes=None, fallback=True, floor=None, relaxed=False
    ):
        self.calls.append((dict(box), warm and x_hint is not None and not fallback))
        return super().solve(box, x_hint, warm, prunes, fallback, floor)


def test_a_combination_met_again_is_solved_from_the_new_start_only():
    """The root sits on (2, 4), a leaf; the box a = 2 it splits off sits on (2, 4) again:
    that combination gets its full multistart once, then only the new start (which does
    not beat it), and the answer is the same."""
    ns = CountedNodes()
    best, _ = branch_and_bound_warm(ns, ns.solve({}), ())
    assert (best.design["a"], best.design["b"]) == (2.0, 1.0)
    leaf = {"a": (2.0, 2.0), "b": (4.0, 4.0)}
    how = [one_start for box, one_start in ns.calls if box == leaf]
    assert how == [False, True]
    full = [tuple(sorted(box.items())) for box, one_start in ns.calls if not one_start]
    fixed = [b for b in full if all(lo == hi for _, (lo, hi) in b)]
    assert len(fixed) == len(set(fixed))  # no combination's multistart twice


class NearItemNodes(TiedNodes):
    """One catalogue variable that matters, b in (1, 2, 3, 4), with the relaxation at
    b = 3.9 (off its items, nearest 4); a has a single item. The optimum is b = 4."""

    def __init__(self):
        super().__init__()
        self.problem = _Problem([_Var("a", (1.0,)), _Var("b", B_ITEMS)])

    def solve(
        self, box, x_hint=None, warm=False, prunes=None, fallback=True, floor=None, relaxed=False
    ):
        self.boxes.append(dict(box))
        lo, hi = box.get("b", (B_ITEMS[0], B_ITEMS[-1]))
        b = min(max(3.9, lo), hi)
        return Result(
            status="optimal",
            objective=(b - 3.9) ** 2 + 1.0,
            design={"a": 1.0, "b": b},
            solver="fake",
            formulation="nlp",
            wall_time_s=0.0,
        )


def test_a_branch_child_that_is_one_combination_is_solved_not_taken_for_a_leaf():
    """Branching b around 3.9 gives the child b = 4 alone, the combination nearest the
    relaxation: it is a leaf still to solve (an earlier search skipped it as "the leaf
    just solved", reporting b = 3)."""
    ns = NearItemNodes()
    best, _ = branch_and_bound_warm(ns, ns.solve({}), ())
    assert best.design["b"] == 4.0 and best.objective == pytest.approx(1.01)
    assert {"a": (1.0, 1.0), "b": (4.0, 4.0)} in ns.boxes


class WarmTrapNodes(TiedNodes):
    """b in (1, 2, 3, 4), the relaxation at b = 2.5, f = (b - 2.5)^2 (b = 2 and 3 tie):
    a warm start in the box b <= 2 lands on a local optimum 10 worse, unless its value
    would prune the node, in which case the full multistart runs (as NodeSolver does) and
    finds the true one."""

    def __init__(self):
        super().__init__()
        self.problem = _Problem([_Var("a", (1.0,)), _Var("b", B_ITEMS)])
        self.starts = 4

    def solve(
        self, box, x_hint=None, warm=False, prunes=None, fallback=True, floor=None, relaxed=False
    ):
        self.boxes.append(dict(box))
        lo, hi = box.get("b", (B_ITEMS[0], B_ITEMS[-1]))
        b = min(max(2.5, lo), hi)
        value, starts = (b - 2.5) ** 2, 4
        if warm and x_hint is not None:
            starts = 1
            if hi <= 2.0 and (prunes is None or not prunes(value + 10.0)):
                value += 10.0  # the poor local optimum of one start
        result = Result(
            status="optimal",
            objective=value,
            design={"a": 1.0, "b": b},
            solver="fake",
            formulation="nlp",
            wall_time_s=0.0,
        )
        result.multistart = MultistartInfo(starts, starts, 1, 1e-6)
        return result


def test_a_node_kept_on_a_one_start_bound_is_solved_again_before_it_is_pruned():
    """The box b <= 2 enters the heap on a poor one-start value; when the incumbent
    (b = 3) would prune it, its full multistart finds b = 2 ties, the box can still win on
    its smaller items, and it goes back on the heap: b = 2 is reported."""
    ns = WarmTrapNodes()
    best, _ = branch_and_bound_warm(ns, ns.solve({}), ())
    assert best.design["b"] == 2.0 and best.objective == pytest.approx(0.25)
    low = {"b": (1.0, 2.0)}
    assert [box for box in ns.boxes if box.get("b") == low["b"]] == [
        {"a": (1.0, 1.0), **low},
        {"a": (1.0, 1.0), **low},
    ]  # its one warm start, then its full multistart


def test_a_value_only_search_prunes_the_ties_and_gives_the_same_value():
    """``ties=False`` (the first stage of a lexicographic anchor): the value is the same,
    the ties the item rule would have visited are pruned, and the design is the tied
    combination the search met first (the top of b, where each relaxation sits)."""
    decided = CountedNodes()
    best, _ = branch_and_bound_warm(decided, decided.solve({}), ())
    value_only = CountedNodes()
    first, _ = branch_and_bound_warm(value_only, value_only.solve({}), (), ties=False)
    assert first.objective == best.objective == pytest.approx(1.0)
    assert (first.design["a"], first.design["b"]) == (2.0, 4.0)
    assert (best.design["a"], best.design["b"]) == (2.0, 1.0)
    assert len(value_only.calls) < len(decided.calls)
    # no box holding only combinations tied with the incumbent was solved after it
    assert {"a": (2.0, 2.0), "b": (1.0, 1.0)} not in [box for box, _ in value_only.calls]


def test_a_value_only_search_keeps_a_strictly_better_candidate_not_a_tie():
    ns = CountedNodes()
    found, stats = branch_and_bound_warm(
        ns, ns.solve({}), [{"a": 2.0, "b": 2.0}, {"a": 3.0, "b": 1.0}], ties=False
    )
    # the candidate (2, 2) ties with every b: the first met of the tie is kept, and the
    # worse candidate (3, 1) never replaces it
    assert (found.design["a"], found.design["b"]) == (2.0, 2.0)
    assert stats["seeded"] == 2


def test_pseudo_costs_branch_on_what_moved_the_bounds_once_each_variable_has_a_history():
    from optdesign.formulations.catalogue.bnb import PseudoCosts

    def _result(value, design=None, status="optimal"):
        return Result(status=status, objective=value, design=design or {}, formulation="nlp")

    problem = _Problem([_Var("a", A_ITEMS), _Var("b", B_ITEMS)])
    box = {"a": (1.0, 3.0), "b": (1.0, 4.0)}
    res = _result(1.0, {"a": 1.5, "b": 2.5})
    a, b = problem.free
    costs = PseudoCosts()
    # a child 10 % up and an infeasible one; a child 1 % up and one at the parent's value
    assert costs.gain(1.0, _result(1.1)) == pytest.approx(0.1)
    assert costs.gain(1.0, _result(float("nan"), status="infeasible")) == 1.0
    costs.record("a", [0.1, 1.0])
    # b has no history yet: the search's own choice stands
    assert costs.choose(problem.free, box, res, b) is b
    costs.record("b", [0.01, 0.0])
    assert costs.choose(problem.free, box, res, b) is a  # 0.1 x 1 against 0.01 x 1e-6
    assert costs.choose(problem.free, box, res, None) is None  # a leaf stays a leaf
    # a variable on an item is not a candidate, whatever its history
    on_b = _result(1.0, {"a": 1.5, "b": 2.0})
    assert costs.choose(problem.free, box, on_b, a) is a


class WarmThenInfeasibleNodes(WarmTrapNodes):
    """As WarmTrapNodes, but the box b <= 2 has no feasible design: its one warm start
    stopped on a poor point, its full multistart finds none."""

    def solve(
        self, box, x_hint=None, warm=False, prunes=None, fallback=True, floor=None, relaxed=False
    ):
        result = super().solve(box, x_hint, warm, prunes, fallback, floor)
        if box.get("b", (1.0, 4.0))[1] <= 2.0 and not warm:
            return _infeasible()
        return result


def test_a_node_kept_on_a_one_start_bound_and_found_infeasible_is_counted():
    ns = WarmThenInfeasibleNodes()
    best, stats = branch_and_bound_warm(ns, ns.solve({}), ())
    assert best.design["b"] == 3.0
    low = [box for box in ns.boxes if box.get("b") == (1.0, 2.0)]
    assert len(low) == 2  # its warm start, then the full multistart that finds no design
    assert stats["infeasible"] == 1


def test_a_tie_in_distance_from_the_items_branches_on_the_first_declared_variable():

    from optdesign.formulations.catalogue.bnb import on_items

    a = SimpleNamespace(name="a", values=(1.0, 2.0))
    b = SimpleNamespace(name="b", values=(10.0, 20.0))
    box = {"a": (1.0, 2.0), "b": (10.0, 20.0)}
    res = SimpleNamespace(design={"a": 1.5, "b": 15.0})  # both halfway: the same distance
    worst, items = on_items([a, b], box, res)
    assert worst is a and items == {"a": 1.0, "b": 10.0}
    on = SimpleNamespace(design={"a": 2.0, "b": 10.0})
    assert on_items([a, b], box, on)[0] is None
