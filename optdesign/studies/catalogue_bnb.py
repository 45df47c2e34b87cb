"""Branch and bound over catalogue items that reuses what it knows.

The search of :mod:`optdesign.studies.catalogue` (best first, over NLP relaxations of
sub-boxes of the catalogue variables) with three savings:

- **warm nodes**: a child box is solved from its parent's optimum alone; the rest of the
  node multistart (and its retries) runs only when that start fails or when its value
  would prune the node (:meth:`NodeSolver.solve` with ``warm=True``). The relaxation at
  the root and every leaf (a combination of items: the values reported) keep the full
  multistart;
- **a first incumbent**: combinations known to be good (a front's anchors and previous
  point: the neighbours' discrete optima) are solved first, each as a leaf from the
  neighbour's design alone (one start: a feasible value bounds the optimum from above
  whatever start found it); the best feasible one prunes every node whose bound is
  worse than it beyond the tie tolerance, and is reported (after the full multistart)
  only when the search finds no leaf as good;
- **infeasible boxes implied** (:class:`InfeasibleBoxes`): a box proved infeasible under
  some epsilon limits proves every sub-box infeasible under limits at least as tight,
  with no NLP; the points of one catalogue front share these proofs.

What is proved and what is heuristic. Proved: the reported bound is the root
relaxation's optimum (multistart, as before) and lies below the discrete optimum; every
item combination reported is feasible by the independent check; a box implied
infeasible is a sub-box of one whose NLP had no feasible start, under tighter limits
(the NLP's feasible set only shrinks). Heuristic, as before: the node NLPs are non-convex
and solved locally, so a node's bound is the best local optimum its starts found. A node
is pruned, or called infeasible, only on the same starts as the cold search (the warm
start plus the multistart and its retries); what the warm start changes is the bound of
a node it does not prune (one start instead of several), which steers the order of the
search and the branching variable, not which node may be discarded. A first incumbent
prunes only nodes that cannot hold a combination tied with it, and a combination the
search finds keeps a tie with it: it is reported only when the search finds nothing as
good, so it does not decide between tied combinations. Which of two tied combinations
(within the pruning tolerance) the search finds first still depends on its order, which
the warm bounds steer.
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from optdesign.formulations.discrete import (
    ON_ITEM_TOL,
    branch,
    discrete_variables,
    items_within,
    nearest_item,
)
from optdesign.solvers.multistart import improves
from optdesign.solvers.result import Result
from optdesign.tolerances import OBJECTIVE_TIE_TOL

Box = Mapping[str, tuple[float, float]]

#: Relative tolerance of pruning (a node within it of the incumbent cannot improve it).
PRUNE_TOL = OBJECTIVE_TIE_TOL


def cannot_improve(bound: float, incumbent: float) -> bool:
    """Whether a node whose relaxation gives ``bound`` can be pruned: it cannot beat the
    incumbent's objective by more than ``PRUNE_TOL`` (relative)."""
    return bound >= incumbent - PRUNE_TOL * abs(incumbent)


def fixed_box(values: Mapping[str, float]) -> dict[str, tuple[float, float]]:
    """The box of one item combination (each variable fixed to its item)."""
    return {k: (v, v) for k, v in values.items()}


class InfeasibleBoxes:
    """Boxes of catalogue variables proved infeasible, with the epsilon limits of the
    proof.

    A box ``B`` proved infeasible under limits ``E`` (objective name -> upper limit)
    proves every box inside ``B`` infeasible under limits that hold each of ``E``'s at
    least as tight: the NLP's feasible set of the smaller box under the tighter limits
    lies in the first one's.
    """

    def __init__(self, full: Box):
        self.full = dict(full)
        self._proofs: list[tuple[dict[str, tuple[float, float]], dict[str, float]]] = []

    def __len__(self) -> int:
        return len(self._proofs)

    def add_infeasible(self, box: Box, eps: Mapping[str, float]) -> None:
        self._proofs.append(({**self.full, **box}, dict(eps)))

    def known_infeasible(self, box: Box, eps: Mapping[str, float]) -> bool:
        """Whether a stored proof covers ``box`` under limits ``eps``."""
        box = {**self.full, **box}
        for wide, limits in self._proofs:
            inside = all(
                wide[k][0] - _tol(wide[k][0]) <= lo and hi <= wide[k][1] + _tol(wide[k][1])
                for k, (lo, hi) in box.items()
                if k in wide
            )
            tighter = all(k in eps and eps[k] <= v for k, v in limits.items())
            if inside and tighter:
                return True
        return False


def _tol(v: float) -> float:
    return 1e-12 * max(1.0, abs(v))


#: Memos of this process, one per (problem, node-solver settings): the points of a
#: catalogue front solved one after another share their proofs.
_MEMOS: dict[tuple, InfeasibleBoxes] = {}
_MEMO_MAX = 8


def shared_memo(key: tuple, full: Box) -> InfeasibleBoxes:
    """The memo of ``key`` in this process (made on first use)."""
    if key not in _MEMOS:
        while len(_MEMOS) >= _MEMO_MAX:
            _MEMOS.pop(next(iter(_MEMOS)))
        _MEMOS[key] = InfeasibleBoxes(full)
    return _MEMOS[key]


def _on_items(ns, dvars, box: Box, res: Result) -> tuple[Any, dict[str, float]]:
    """The catalogue variable farthest (relatively) from an item in its range (None when
    every one sits on an item) and the nearest items."""
    worst, worst_d, items = None, ON_ITEM_TOL, {}
    for v in dvars:
        allowed = tuple(items_within(v.values, *box[v.name]))
        item, dist = nearest_item(res.design[v.name], allowed)
        items[v.name] = item
        if dist > worst_d:
            worst, worst_d = v, dist
    return worst, items


def first_incumbent(
    ns, candidates: Sequence[Mapping[str, float]], stats: dict
) -> tuple[Result | None, dict | None]:
    """The best feasible of ``candidates`` (item combinations), each solved as a leaf
    from the candidate's design alone (one start: its value only bounds the optimum from
    above); a tie keeps the earlier candidate."""
    dvars = discrete_variables(ns.problem)
    best, best_items, seen = None, None, set()
    for cand in candidates:
        try:
            items = {v.name: float(cand[v.name]) for v in dvars}
        except (KeyError, TypeError, ValueError):
            continue
        items = {v.name: nearest_item(items[v.name], v.values)[0] for v in dvars}
        key = tuple(items.values())
        if key in seen:
            continue
        seen.add(key)
        x0 = _x_of_design(ns, cand)
        if x0 is None:
            continue
        r = ns.solve(fixed_box(items), x0, warm=True, fallback=False)
        stats["nodes"] += 1
        stats["seeded"] += 1
        if r.success and (best is None or improves(r.objective, best.objective, _prune_tol())):
            best, best_items = r, items
    return best, best_items


def _x_of_design(ns, design: Mapping[str, float]):
    """The design vector of a candidate (a start), or None when it lacks a variable."""
    if not all(n in design for n in ns.names):
        return None
    return np.array([float(design[n]) for n in ns.names])


def _prune_tol() -> float:
    return PRUNE_TOL


def branch_and_bound_warm(
    ns, root: Result, candidates: Sequence[Mapping[str, float]] = ()
) -> tuple[Result | None, dict]:
    """Best-first branch and bound from the relaxation ``root`` with warm child nodes and
    the best of ``candidates`` (item combinations) as its first incumbent."""
    dvars = discrete_variables(ns.problem)
    full = {v.name: (v.lower, v.upper) for v in dvars}
    counter = itertools.count()
    heap: list = []
    stats = {"nodes": 1, "pruned": 0, "infeasible": 0, "leaves": 0, "seeded": 0}
    incumbent: Result | None = None  # the best leaf the search itself found
    seed: Result | None = None  # the best candidate's leaf
    seed_items: dict | None = None
    if root.success:
        seed, seed_items = first_incumbent(ns, candidates, stats)
        heapq.heappush(heap, (root.objective, next(counter), full, root, None))

    def prunes(bound: float) -> bool:
        # the search's own incumbent prunes ties too (the leaf found first is kept), as
        # before; a candidate prunes only what is worse beyond the tie tolerance, so that
        # the search still reaches the combination it would report without the candidate
        if incumbent is not None and cannot_improve(bound, incumbent.objective):
            return True
        return seed is not None and bound > seed.objective + _prune_tol() * abs(seed.objective)

    while heap:
        bound, _, box, res, warm_from = heapq.heappop(heap)
        if prunes(bound):
            if warm_from is not None:
                # a bound from the warm start alone: pruned only on the full multistart
                res = ns.solve(box, warm_from)
                stats["nodes"] += 1
                if not res.success:
                    stats["infeasible"] += 1
                    continue
                if not prunes(res.objective):
                    heapq.heappush(heap, (res.objective, next(counter), box, res, None))
                    continue
            stats["pruned"] += 1
            continue
        x = ns.x_of(res)
        worst, items = _on_items(ns, dvars, box, res)
        sides: list[tuple[Any, list[float]]] = []
        if worst is None:  # every catalogue variable sits on an item: a leaf
            one_combination = all(box[v.name][0] == box[v.name][1] for v in dvars)
            if one_combination:
                leaf = res  # already solved with every catalogue variable fixed
            else:
                leaf = ns.solve(fixed_box(items), x)
                stats["nodes"] += 1
            stats["leaves"] += 1
            if leaf.success and (
                incumbent is None or improves(leaf.objective, incumbent.objective, _prune_tol())
            ):
                incumbent = leaf  # a tie keeps the incumbent found first
            if one_combination or prunes(bound):
                continue
            # The node's relaxation sits on items, but its item data (fit ratios, screw
            # ratings) are the most favourable over the box's items, not those of the
            # items it sits on: the box's other combinations may still beat this leaf.
            # Split the first wide variable at its item: below it, at it, above it.
            var = next(v for v in dvars if box[v.name][0] != box[v.name][1])
            allowed = items_within(var.values, *box[var.name])
            at = items[var.name]
            sides = [(var, [a for a in allowed if a < at]), (var, [at])]
            sides.append((var, [a for a in allowed if a > at]))
        else:
            allowed = items_within(worst.values, *box[worst.name])
            sides = [(worst, side) for side in branch(res.design[worst.name], allowed)]
        for var, side in sides:
            if not side:
                continue
            child = dict(box)
            child[var.name] = (side[0], side[-1])
            if child == fixed_box(items):
                continue  # the leaf just solved
            fixed = all(child[v.name][0] == child[v.name][1] for v in dvars)
            # a box of one combination is a leaf: its value is reported, full multistart
            r = ns.solve(child, x) if fixed else ns.solve(child, x, warm=True, prunes=prunes)
            stats["nodes"] += 1
            if not r.success:
                stats["infeasible"] += 1
                continue
            if prunes(r.objective):
                stats["pruned"] += 1
                continue
            warm_only = not fixed and r.multistart is not None and r.multistart.n_starts < ns.starts
            entry = (r.objective, next(counter), child, r, x if warm_only else None)
            heapq.heappush(heap, entry)
    if seed is not None and (
        incumbent is None or improves(seed.objective, incumbent.objective, _prune_tol())
    ):
        # no leaf of the search ties with the candidate: it is the optimum, and as a
        # reported leaf it gets the full multistart (its own start first)
        full = ns.solve(fixed_box(seed_items), ns.x_of(seed))
        stats["nodes"] += 1
        incumbent = full if full.success and full.objective <= seed.objective else seed
    return incumbent, stats
