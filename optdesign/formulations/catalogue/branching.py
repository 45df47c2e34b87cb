"""How the catalogue branch and bound splits a node: the variable to split (the farthest
from an item, then by pseudo-costs), the sides of a box whose relaxation sits on items,
and a depth-first search for any feasible combination
(:mod:`optdesign.formulations.catalogue.bnb` is the search itself)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from optdesign.formulations.catalogue.discrete import (
    ON_ITEM_TOL,
    branch,
    discrete_variables,
    items_within,
    nearest_item,
)
from optdesign.solvers.result import Result

Box = Mapping[str, tuple[float, float]]


def fixed_box(values: Mapping[str, float]) -> dict[str, tuple[float, float]]:
    """The box of one item combination (each variable fixed to its item)."""
    return {k: (v, v) for k, v in values.items()}


def item_distances(dvars, box: Box, res: Result) -> list[tuple[Any, float, float]]:
    """(variable, nearest item within the box, relative distance to it) of each catalogue
    variable at the node ``res`` over ``box``, in the declared order."""
    out = []
    for v in dvars:
        item, dist = nearest_item(res.design[v.name], tuple(items_within(v.values, *box[v.name])))
        out.append((v, item, dist))
    return out


def on_items(dvars, box: Box, res: Result) -> tuple[Any, dict[str, float]]:
    """The catalogue variable to branch on - the one farthest (relatively) from an item
    in its range, None when every one sits on an item - and the nearest items."""
    worst, worst_d, items = None, ON_ITEM_TOL, {}
    for v, item, dist in item_distances(dvars, box, res):
        items[v.name] = item
        if dist > worst_d:
            worst, worst_d = v, dist
    return worst, items


class PseudoCosts:
    """Pseudo-costs of the search's branching: what splitting each catalogue variable has
    cost so far.

    A branching's cost is the product of its two children's relative rises over the
    parent's value (SCIP's product rule; an infeasible child counts as
    :attr:`INFEASIBLE_GAIN`, a side with no items as the other side); a variable's
    pseudo-cost is the mean over its branchings. Once every variable off its items has a
    history, the one with the highest pseudo-cost is split; before that, the farthest
    from an item (:func:`on_items`). The history is the search's own, in its order, so
    the choice never depends on timing or the number of workers.
    """

    #: The relative rise counted for an infeasible child (as if its value doubled).
    INFEASIBLE_GAIN = 1.0

    def __init__(self) -> None:
        self.scores: dict[str, list[float]] = {}

    def gain(self, parent: float, child: Result) -> float:
        """The relative rise of a child's value over its parent's ``parent``."""
        if not child.success:
            return self.INFEASIBLE_GAIN
        return self.rise(parent, child.objective)

    @staticmethod
    def rise(parent: float, value: float) -> float:
        """The relative rise of ``value`` over ``parent`` (none when below it)."""
        return max(value - parent, 0.0) / max(abs(parent), 1e-300)

    def record(self, name: str, gains: Sequence[float]) -> None:
        """One branching on ``name`` whose children rose by ``gains`` (one or two)."""
        g = [max(x, 1e-6) for x in gains]
        self.scores.setdefault(name, []).append(g[0] * (g[1] if len(g) > 1 else g[0]))

    def choose(self, dvars, box: Box, res: Result, worst):
        """The variable to split at the node ``res`` over ``box``: ``worst`` (the search's
        own choice, None at a leaf) unless every variable off its items has a history."""
        if worst is None:
            return None
        off = [v for v, _, dist in item_distances(dvars, box, res) if dist > ON_ITEM_TOL]
        if len(off) < 2 or not all(v.name in self.scores for v in off):
            return worst
        # the first of equal pseudo-costs, in the declared order (max keeps the first)
        return max(off, key=lambda v: sum(self.scores[v.name]) / len(self.scores[v.name]))


def split_at_items(dvars, box: Box, items: Mapping[str, float]) -> list[tuple[Any, list[float]]]:
    """The sides of a box whose relaxation sits on ``items`` though it holds other
    combinations: its first wide variable's items below, at and above the item (a side
    may be empty). The box must hold more than one combination."""
    var = next(v for v in dvars if box[v.name][0] != box[v.name][1])
    allowed = items_within(var.values, *box[var.name])
    at = items[var.name]
    below, above = [a for a in allowed if a < at], [a for a in allowed if a > at]
    return [(var, below), (var, [at]), (var, above)]


def first_feasible(ns: Any) -> Result | None:
    """A feasible catalogue design of the node solver's problem, or None: branch and bound
    from the continuous relaxation, depth first, stopping at the first feasible leaf (a
    design, not the optimum; e.g. which items allow a requirement to be dropped).
    ``ns``: a :class:`~optdesign.formulations.catalogue.node_solver.NodeSolver`."""
    dvars = discrete_variables(ns.problem)
    root = ns.solve({})
    stack = [({v.name: (v.lower, v.upper) for v in dvars}, root)] if root.success else []
    while stack:
        box, res = stack.pop()
        worst, items = on_items(dvars, box, res)
        if worst is None:  # on items: the leaf with them fixed
            leaf = ns.solve(fixed_box(items), ns.x_of(res))
            if leaf.success:
                return leaf
            # The relaxation's item data are the most favourable over the box's items,
            # not those of the items it sits on: the box's other combinations may still
            # work (split as the branch and bound does).
            if all(box[v.name][0] == box[v.name][1] for v in dvars):
                continue
            splits = split_at_items(dvars, box, items)
        else:
            allowed = items_within(worst.values, *box[worst.name])
            splits = [(worst, side) for side in branch(res.design[worst.name], allowed)]
        children = []
        for _, child in side_boxes(box, splits, fixed_box(items) if worst is None else None):
            r = ns.solve(child, ns.x_of(res))
            if r.success:
                children.append((r.objective, child, r))
        # the better child on top of the stack (explored first)
        for _, child, r in sorted(children, key=lambda c: -c[0]):
            stack.append((child, r))
    return None


def side_boxes(box: Box, sides, leaf: Box | None = None):
    """The child boxes of ``box`` split into ``sides`` ((variable, its items) pairs; an
    empty side makes none), without the box of the ``leaf`` just solved: (variable,
    child box) pairs."""
    for var, side in sides:
        if not side:
            continue
        child = dict(box)
        child[var.name] = (side[0], side[-1])
        if child != leaf:
            yield var, child
