"""Branch and bound over catalogue items that reuses what it knows.

The search of :mod:`optdesign.formulations.catalogue.search` (best first, over NLP relaxations of
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
  with no NLP; the points of one catalogue front share these proofs, and the values and
  optima of their nodes (:mod:`~optdesign.formulations.catalogue.node_bounds`): a node
  whose bound from a search under looser limits cannot beat the incumbent is pruned with
  no NLP (:func:`earlier_bound`).

What is proved and what is heuristic. Proved: the reported bound is the root
relaxation's optimum (multistart, as before) and lies below the discrete optimum; every
item combination reported is feasible by the independent check; a box implied
infeasible is a sub-box of one whose NLP had no feasible start, under tighter limits
(the NLP's feasible set only shrinks). Heuristic, as before: the node NLPs are non-convex
and solved locally, so a node's bound is the best local optimum its starts found. A node
is pruned, or called infeasible, only on the same starts as the cold search (the warm
start plus the multistart, and its retries unless two starts or more all ended with the
back-end's verdict of local infeasibility: :meth:`NodeSolver.verdicts_decide`); a
combination met again as a leaf is solved from the new start, and with the full
multistart again only when that start beats its stored value. What the warm start
changes is the bound of a node it does not prune (one start instead of several), which
steers the order of the search and the branching variable, not which node may be
discarded. A first incumbent
prunes only what the search itself would prune, so it changes the work, not the answer.

Ties are decided by value, then by the items: of two combinations whose objectives tie
(within :data:`PRUNE_TOL`), the one with the smaller items in the order the catalogue
variables are declared (lexicographic, :func:`combination_key`) is reported, whatever
order the search meets them in. A node whose bound ties with the incumbent is pruned only
when its box holds no combination smaller than the incumbent's, so the answer does not
depend on the warm bounds, the first incumbent or the number of workers. (Enumeration
visits the combinations in that order and keeps the first of a tie: the same rule.)
The variable split at a node is the one farthest from an item until every candidate has
been split before; then the one whose splits raised the bound most (:class:`PseudoCosts`).
A variable whose item data only the rows read (a motor under a backlash objective) is
split last, at the first item the node's design meets; the sides that lose a tie with
that leaf go on the node's value
(:mod:`~optdesign.formulations.catalogue.objective_free`: where a box is split and when a
side is solved change, not what may be pruned).
A search that only needs the optimal value (``ties=False``: the first stage of a front's
lexicographic anchor, whose tie-break picks the design) prunes a tie whatever its items.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Mapping, Sequence
from functools import partial
from typing import Any

import numpy as np

from optdesign.formulations.catalogue.branching import PseudoCosts as PseudoCosts
from optdesign.formulations.catalogue.branching import first_feasible as first_feasible
from optdesign.formulations.catalogue.branching import fixed_box as fixed_box
from optdesign.formulations.catalogue.branching import item_distances as item_distances
from optdesign.formulations.catalogue.branching import on_items as on_items
from optdesign.formulations.catalogue.branching import side_boxes
from optdesign.formulations.catalogue.branching import split_at_items as split_at_items
from optdesign.formulations.catalogue.discrete import (
    branch,
    discrete_variables,
    items_within,
    nearest_item,
)
from optdesign.formulations.catalogue.node_bounds import NodeBounds
from optdesign.formulations.catalogue.node_bounds import inside as _inside
from optdesign.formulations.catalogue.objective_free import (
    first_items_met,
    split_first,
    split_last_variables,
)
from optdesign.solvers.multistart import improves
from optdesign.solvers.result import Result
from optdesign.tolerances import OBJECTIVE_TIE_TOL

#: The key of a node result's ``details`` set when the node was solved on the thinned
#: grid (a relaxation of the node: its value bounds the box's, its design may miss a row):
#: the thinned grid's number of angles.
RELAXED = "relaxed_grid"

Box = Mapping[str, tuple[float, float]]

#: Split last the catalogue variables whose item data only the rows read (neither the
#: objective nor any row reads their value), at the first item a node's design meets (:mod:`~optdesign.formulations.catalogue.objective_free`).
SPLIT_LAST = True

#: Relative tolerance of pruning (a node within it of the incumbent cannot improve it).
PRUNE_TOL = OBJECTIVE_TIE_TOL


def cannot_improve(bound: float, incumbent: float) -> bool:
    """Whether a node whose relaxation gives ``bound`` can be pruned: it cannot beat the
    incumbent's objective by more than ``PRUNE_TOL`` (relative)."""
    return bound >= incumbent - PRUNE_TOL * abs(incumbent)


def trusted(result: Result, starts: int) -> bool:
    """Whether a node's value may serve its children as a floor (see
    :meth:`~optdesign.formulations.catalogue.node_solver.NodeSolver.solve`): it comes from the node
    solver's full multistart of ``starts``, or it was settled at its own trusted floor."""
    ms = result.multistart
    return ms is not None and (ms.n_starts >= starts or ms.stopped_early)


def trusted_value(result: Result, starts: int) -> float | None:
    """The node's value when it may serve as a floor (:func:`trusted`), else None."""
    return result.objective if result.success and trusted(result, starts) else None


def combination_key(values: Mapping[str, float], names: Sequence[str]) -> tuple[float, ...]:
    """The order of item combinations that decides a tie: the items of ``names`` (the
    catalogue variables, in their declared order), compared lexicographically."""
    return tuple(float(values[n]) for n in names)


def box_key(box: Box, names: Sequence[str]) -> tuple[float, ...]:
    """The smallest :func:`combination_key` of a box's combinations (its lower ends)."""
    return tuple(float(box[n][0]) for n in names)


def wins(
    value: float, key: tuple[float, ...], best: float | None, best_key: tuple[float, ...] | None
) -> bool:
    """Whether a combination of objective ``value`` and items ``key`` replaces the best
    so far: a better value beyond the tie tolerance, or a tie with smaller items."""
    if best is None or best_key is None:
        return True
    if improves(value, best, PRUNE_TOL):
        return True
    return not improves(best, value, PRUNE_TOL) and key < best_key


def box_cannot_win(
    bound: float, box: Box, names: Sequence[str], best: float, best_key: tuple[float, ...]
) -> bool:
    """Whether a node (relaxation ``bound`` over ``box``) can be pruned against the best
    combination so far: its bound is worse beyond the tie tolerance, or ties and the box
    holds no combination with smaller items."""
    if not cannot_improve(bound, best):
        return False  # it may beat the best by more than the tolerance
    worse = bound > best + PRUNE_TOL * abs(best)
    return worse or box_key(box, names) >= best_key


class InfeasibleBoxes:
    """Boxes of catalogue variables proved infeasible, with the epsilon limits of the
    proof.

    A box ``B`` proved infeasible under limits ``E`` (objective name -> upper limit)
    proves every box inside ``B`` infeasible under limits that hold each of ``E``'s at
    least as tight: the NLP's feasible set of the smaller box under the tighter limits
    lies in the first one's.
    """

    def __init__(self, full: Box, items: Mapping[str, Sequence[float]] | None = None):
        self.full = dict(full)
        #: each catalogue variable's items: with them, a box is also proved infeasible
        #: when every item combination in it lies in some proved box (a union of proofs)
        self.items = {k: tuple(sorted(v)) for k, v in items.items()} if items else None
        self._proofs: list[tuple[dict[str, tuple[float, float]], dict[str, float]]] = []
        #: the nodes the searches solved (their bounds and optima), when the memo is a
        #: front's (:func:`shared_memo`); None for a single search's proofs
        self.nodes: NodeBounds | None = None
        #: grid angles where the searches' thinned points missed a row left out
        #: (:attr:`~optdesign.formulations.catalogue.node_solver.NodeSolver.learned_angles`):
        #: the next searches of a front start with them (and share their solver)
        self.learned_angles: frozenset[str] = frozenset()

    def __len__(self) -> int:
        return len(self._proofs)

    @property
    def proofs(self) -> list[tuple[dict[str, tuple[float, float]], dict[str, float]]]:
        """The stored proofs: (box, epsilon limits) pairs, oldest first."""
        return [(dict(box), dict(eps)) for box, eps in self._proofs]

    @classmethod
    def from_proofs(cls, full: Box, proofs) -> InfeasibleBoxes:
        """A memo holding ``proofs`` (as :attr:`proofs` gives them)."""
        memo = cls(full)
        for box, eps in proofs:
            memo.add_infeasible(box, eps)
        return memo

    def add_infeasible(self, box: Box, eps: Mapping[str, float]) -> None:
        self._proofs.append(({**self.full, **box}, dict(eps)))

    def known_infeasible(self, box: Box, eps: Mapping[str, float]) -> bool:
        """Whether stored proofs cover ``box`` under limits ``eps``: one proof's box holds
        it, or (with :attr:`items`) every item combination of it lies in a proof's box."""
        box = {**self.full, **box}
        applicable = [
            wide
            for wide, limits in self._proofs
            if all(k in eps and eps[k] <= v for k, v in limits.items())
        ]
        if any(_inside(box, wide) for wide in applicable):
            return True
        if self.items is None or len(applicable) < 2:
            return False
        names = list(self.items)
        lists = [items_within(self.items[k], *box[k]) for k in names]
        if math.prod(len(v) for v in lists) > MAX_COVER_COMBINATIONS:
            return False
        return all(
            any(
                _inside({k: (c, c) for k, c in zip(names, combo, strict=True)}, w)
                for w in applicable
            )
            for combo in itertools.product(*lists)
        )


#: Item combinations a box may hold for the memo to check them one by one.
MAX_COVER_COMBINATIONS = 4096


#: Memos of this process, one per (problem, node-solver settings): the points of a
#: catalogue front solved one after another share their proofs.
_MEMOS: dict[tuple, InfeasibleBoxes] = {}
_MEMO_MAX = 8


def shared_memo(
    key: tuple, full: Box, items: Mapping[str, Sequence[float]] | None = None
) -> InfeasibleBoxes:
    """The memo of ``key`` in this process (made on first use)."""
    if key not in _MEMOS:
        while len(_MEMOS) >= _MEMO_MAX:
            _MEMOS.pop(next(iter(_MEMOS)))
        memo = InfeasibleBoxes(full, items)
        memo.nodes = NodeBounds(full)
        _MEMOS[key] = memo
    return _MEMOS[key]


def first_incumbent(
    ns, candidates: Sequence[Mapping[str, float]], stats: dict, ties: bool = True
) -> tuple[Result | None, dict | None]:
    """The best feasible of ``candidates`` (item combinations), each solved as a leaf
    from the candidate's design alone (one start: its value only bounds the optimum from
    above); a tie is decided by the items (:func:`wins`), not by the candidates' order
    (``ties`` False: the first of a tie is kept, see :func:`branch_and_bound_warm`)."""
    dvars = discrete_variables(ns.problem)
    names = [v.name for v in dvars] if ties else []
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
        best_key = None if best_items is None else combination_key(best_items, names)
        if r.success and wins(r.objective, combination_key(items, names), _value(best), best_key):
            best, best_items = r, items
    return best, best_items


def _x_of_design(ns, design: Mapping[str, float]):
    """The design vector of a candidate (a start), or None when it lacks a variable."""
    if not all(n in design for n in ns.names):
        return None
    return np.array([float(design[n]) for n in ns.names])


def branch_and_bound_warm(
    ns, root: Result, candidates: Sequence[Mapping[str, float]] = (), ties: bool = True
) -> tuple[Result | None, dict]:
    """Best-first branch and bound from the relaxation ``root`` with warm child nodes and
    the best of ``candidates`` (item combinations) as its first incumbent.

    ``ties`` False: only the optimal value is wanted (the first stage of a lexicographic
    solve, whose second stage picks the design among the ties): a node whose bound ties
    with the incumbent is pruned whatever its items, and a tie never replaces the
    incumbent. The value is the same within the tie tolerance; the design is one of the
    tied combinations, still decided by the search's fixed order, not by timing.
    """
    dvars = discrete_variables(ns.problem)
    full = {v.name: (v.lower, v.upper) for v in dvars}
    counter = itertools.count()
    heap: list = []
    stats = {"nodes": 1, "pruned": 0, "infeasible": 0, "leaves": 0, "seeded": 0}
    # the variables whose items decide a tie: none when ties are not decided (every
    # combination then has the same empty key, so a tie neither wins nor keeps a box)
    names = [v.name for v in dvars] if ties else []
    all_names = [v.name for v in dvars]
    incumbent: Result | None = None  # the best leaf the search itself found
    inc_key: tuple[float, ...] | None = None
    seed: Result | None = None  # the best candidate's leaf
    seed_items: dict | None = None
    seed_key: tuple[float, ...] | None = None
    root_floor = trusted_value(root, ns.starts)
    if root.success:
        seed, seed_items = first_incumbent(ns, candidates, stats, ties)
        if seed_items is not None:
            seed_key = combination_key(seed_items, names)
        # the last field: the floor of the node's children (see NodeSolver.solve)
        heapq.heappush(heap, (root.objective, next(counter), full, root, None, None))

    solved: dict[tuple[float, ...], Result] = {}  # each combination's full multistart
    pseudo = PseudoCosts()
    # the catalogue variables that only the rows' data read, not the objective: split
    # last, at the first item a node's design meets (objective_free)
    last = split_last_variables(ns) if SPLIT_LAST else frozenset()
    first = [v for v in dvars if v.name not in last]
    order = first + [v for v in dvars if v.name in last]

    def relaxable(box: Box) -> bool:
        # a node's value on the thinned grid bounds its box's, but the variables split
        # last take the first item the node's design meets on every row of the problem:
        # a box wide only in those is solved on the problem itself
        return any(box[v.name][0] != box[v.name][1] for v in first)

    def leaf_solve(box: Box, x, floor: float | None) -> Result:
        # A combination solved before (from another node's optimum) is solved again only
        # from the new start: the rest of its multistart is the same Sobol points. The
        # full multistart runs again only when that start beats the stored value.
        key = box_key(box, all_names)
        done = solved.get(key)
        if done is not None:
            new = ns.solve(box, x, warm=True, fallback=False)
            if not (new.success and (not done.success or improves(new.objective, done.objective))):
                return done
        solved[key] = ns.solve(box, x, floor=floor)
        return solved[key]

    def prunes(bound: float, box: Box) -> bool:
        # the same rule against the search's incumbent and the candidate: worse beyond
        # the tie tolerance, or a tie that no combination of the box can win on its items
        for best, key in ((incumbent, inc_key), (seed, seed_key)):
            if best is not None and box_cannot_win(bound, box, names, best.objective, key):
                return True
        return False

    def visit(child: Box, x, below: float | None, bound: float) -> float:
        """Solve a child box and queue it unless it is infeasible or pruned; the rise
        of its value (or of an earlier search's bound on it) over ``bound``, for the
        pseudo-costs."""
        fixed = all(child[v.name][0] == child[v.name][1] for v in dvars)
        earlier = earlier_bound(ns, child)
        if earlier is not None and prunes(earlier, child):
            # no NLP: an earlier search of the front bounded it under looser limits
            stats["pruned"] += 1
            return pseudo.rise(bound, earlier)
        # a box of one combination is a leaf: its value is reported, full multistart
        if fixed:
            r = leaf_solve(child, x, below)
        else:
            test = partial(_prunes_box, prunes, child)
            r = ns.solve(child, x, warm=True, prunes=test, floor=below, relaxed=relaxable(child))
        stats["nodes"] += 1
        gain = pseudo.gain(bound, r)
        if not r.success:
            stats["infeasible"] += 1
        elif prunes(r.objective, child):
            stats["pruned"] += 1
            _bound_proof(ns, child, r)
        else:
            warm_only = not fixed and r.multistart is not None and not trusted(r, ns.starts)
            entry = (r.objective, next(counter), child, r, x if warm_only else None, below)
            heapq.heappush(heap, entry)
        return gain

    while heap:
        bound, _, box, res, warm_from, floor = heapq.heappop(heap)
        if res is None:
            # a side of a split at the first item met, bounded by its node's trusted
            # value until now: solved only when that bound no longer prunes it
            if prunes(bound, box):
                stats["pruned"] += 1
            else:
                visit(box, warm_from, floor, bound)
            continue
        if prunes(bound, box):
            if warm_from is not None and not _earlier_prunes(ns, prunes, box):
                # a bound from the warm start alone: pruned only on the full multistart
                # (or on a bound an earlier search of the front trusted)
                res = ns.solve(box, warm_from, floor=floor, relaxed=relaxable(box))
                stats["nodes"] += 1
                if not res.success:
                    stats["infeasible"] += 1
                    continue
                if not prunes(res.objective, box):
                    entry = (res.objective, next(counter), box, res, None, floor)
                    heapq.heappush(heap, entry)
                    continue
            stats["pruned"] += 1
            _bound_proof(ns, box, res)
            continue
        if (
            res.details.get(RELAXED)
            and any(box[n][0] != box[n][1] for n in last)
            and on_items(first, box, res)[0] is None
        ):
            # the node's design sits on items of every variable split first, so the items
            # of those split last are decided from its design (first_items_met): solved again on the problem itself,
            # from there (the design of the thinned grid may miss a row between its
            # angles), as a node is without the thinned grid
            test = partial(_prunes_box, prunes, box)
            res = ns.solve(box, ns.x_of(res), warm=True, prunes=test, floor=floor)
            stats["nodes"] += 1
            if not res.success:
                stats["infeasible"] += 1
                continue
            if prunes(res.objective, box):
                stats["pruned"] += 1
                _bound_proof(ns, box, res)
                continue
        x = ns.x_of(res)
        # the children's floor: this node's value when the search trusts it, else the
        # floor it had itself (a sub-box's value is never below its box's)
        own = trusted_value(res, ns.starts)
        below = own if own is not None else floor
        worst, items = on_items(dvars, box, res)
        pool = first
        if worst is not None and worst.name in last:
            # such a variable is split once the others sit on items
            reading, _ = on_items(first, box, res)
            if reading is not None:
                worst, pool = reading, first
        worst = pseudo.choose(pool, box, res, worst)
        met: list[str] = []
        if last and (worst is None or worst.name in last):
            # the first item of each such variable that the node's design meets, the
            # others on theirs: that combination's value is the node's
            worst, met = first_items_met(ns, dvars, last, box, res, items, worst)
        sides: list[tuple[Any, list[float]]] = []
        if worst is None:  # every catalogue variable sits on an item: a leaf
            one_combination = all(box[v.name][0] == box[v.name][1] for v in dvars)
            if one_combination:
                leaf = res  # already solved with every catalogue variable fixed
            elif _earlier_prunes(ns, prunes, fixed_box(items)):
                leaf = None  # it cannot win: an earlier search's bound under looser limits
                stats["pruned"] += 1
            else:
                leaf = leaf_solve(fixed_box(items), x, below)
                stats["nodes"] += 1
            stats["leaves"] += 1
            key = combination_key(items, names)
            if (
                leaf is not None
                and leaf.success
                and wins(leaf.objective, key, _value(incumbent), inc_key)
            ):
                incumbent, inc_key = leaf, key
            if one_combination or prunes(bound, box):
                continue
            # The node's relaxation sits on items, but its item data (fit ratios, screw
            # ratings) are the most favourable over the box's items, not those of the
            # items it sits on: the box's other combinations may still beat this leaf.
            lead = split_first(dvars, met, box, items, names)
            sides = split_at_items([lead] if lead else order, box, items)
        else:
            allowed = items_within(worst.values, *box[worst.name])
            sides = [(worst, side) for side in branch(res.design[worst.name], allowed)]
        gains: list[float] = []
        for var, child in side_boxes(box, sides, fixed_box(items) if worst is None else None):
            if worst is None and var.name in last:
                # beside the leaf at the first item met: this node's value bounds it, as
                # it bounds the whole box once its leaf is solved (above); a side that
                # cannot win on it goes with no NLP, now or, when the value is trusted,
                # once the side is popped
                if prunes(bound, child):
                    stats["pruned"] += 1
                    continue
                if own is not None:
                    heapq.heappush(heap, (own, next(counter), child, None, x, below))
                    continue
            gains.append(visit(child, x, below, bound))
        if worst is not None and gains:
            pseudo.record(worst.name, gains)
    if seed is not None and wins(seed.objective, seed_key, _value(incumbent), inc_key):
        # the candidate beats every leaf of the search (or ties with smaller items): it
        # is the optimum, and as a reported leaf it gets the full multistart (its own
        # start first)
        full = ns.solve(fixed_box(seed_items), ns.x_of(seed), floor=root_floor)
        stats["nodes"] += 1
        incumbent = full if full.success and full.objective <= seed.objective else seed
    return incumbent, stats


def earlier_bound(ns, box: Box) -> float | None:
    """The least value of the search's objective over ``box`` that an earlier search of
    the same front trusted under limits the search holds at least as tight
    (:meth:`~optdesign.formulations.catalogue.node_bounds.NodeBounds.lower_bound`); None
    outside a front, or when no earlier node holds the box."""
    nodes = getattr(getattr(ns, "memo", None), "nodes", None)
    return None if nodes is None else nodes.lower_bound(box, ns.eps, ns.objective)


def _earlier_prunes(ns, prunes, box: Box) -> bool:
    earlier = earlier_bound(ns, box)
    return earlier is not None and prunes(earlier, box)


def _bound_proof(ns, box: Box, res: Result) -> None:
    """A pruned box's value, when the search trusts it, is the least the objective takes
    over the box under the search's limits: under a limit on the objective below it the
    box is infeasible. Recorded in a front's shared memo (not in a single search's
    proofs), where a later point's or anchor's limit on this objective implies it: the
    tree's bounds carried from one search to the next."""
    memo = getattr(ns, "memo", None)
    if memo is None or not res.success or not trusted(res, ns.starts):
        return
    value = res.objective
    # below the value by the pruning tolerance: past the solve's own tolerance
    limit = value - PRUNE_TOL * max(abs(value), 1e-12)
    eps = dict(ns.eps)
    eps[ns.objective] = min(limit, eps.get(ns.objective, math.inf))
    memo.add_infeasible(box, eps)


def _value(result: Result | None) -> float | None:
    return None if result is None else result.objective


def _prunes_box(prunes, box: Box, value: float) -> bool:
    return prunes(value, box)
