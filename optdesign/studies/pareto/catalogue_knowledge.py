"""What one point of a catalogue front passes to the next (see
:mod:`optdesign.formulations.catalogue.bnb`).

- First incumbents: a point's search starts from the best feasible of its neighbours'
  discrete optima - the previous point (when the points run one after another), then the
  nearer anchor, then the other; the anchor's tie-break starts from the anchor's items.
  The candidates come from the task's declared dependencies only, so a point computes
  the same with any number of workers except where two combinations tie within the
  pruning tolerance (then the candidate tried first is kept).
- Infeasible boxes: with one local worker the tasks run in order in one process - the
  anchors, then the points from the loosest epsilon limit to the tightest - and they
  share one :class:`~optdesign.formulations.catalogue.bnb.InfeasibleBoxes` memo (a box proved
  infeasible under looser limits is not solved again).
- The previous point's optimum: when its design meets this point's tighter limits with
  room, it is this point's optimum, and the point is not searched (:func:`previous_holds`).
- Node bounds and starts: the same memo keeps every node's trusted value and optimum
  (:class:`~optdesign.formulations.catalogue.node_bounds.NodeBounds`); a value bounds the
  nodes of the searches under tighter limits from below (their floor, or a prune with no
  NLP), and an optimum is the first start of the same items' node in a later search.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from typing import Any

from optdesign.formulations.catalogue.bnb import shared_memo
from optdesign.formulations.catalogue.discrete import discrete_variables
from optdesign.formulations.catalogue.node_bounds import (
    looser_or_equal,
    within_limits_with_room,
)
from optdesign.runtime.identity import problem_digest
from optdesign.studies.pareto.records import PointRecord


def chain_points(tasks: list[dict], points: list[dict], sequential: bool) -> None:
    """Mark the tasks of a front that share a memo, and chain the points (each after the
    previous one) when they run one after another anyway."""
    if not sequential:
        return
    for t in tasks:
        t["memo"] = True
    # from the loosest limit to the tightest: a box proved infeasible at one point is
    # then implied infeasible at every later one (InfeasibleBoxes)
    loose_first = sorted(points, key=lambda t: -t["eps_frac"])
    for prev, pt in itertools.pairwise(loose_first):
        pt["previous"] = prev["id"]
        pt["after"] = [*pt["after"], prev["id"]]
    for pt in points:
        pt["memo"] = True


def _design(deps: Mapping[str, Any], key: str | None) -> dict[str, float] | None:
    if key is None or key not in deps:
        return None
    rec = PointRecord.from_dict(deps[key])
    return dict(rec.design) if rec.success and rec.design else None


def front_knowledge(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """``incumbents`` and ``memo`` arguments of the catalogue search of ``task``."""
    if "tie_of" in task:
        keys = [task["tie_of"]]
    elif "eps_frac" in task:
        near, far = f"anchor-{task['eps_name']}", f"anchor-{task['target']}"
        if task["eps_frac"] > 0.5:
            near, far = far, near
        keys = [task.get("previous"), near, far]
    else:
        keys = []
    found = [_design(deps, k) for k in keys]
    incumbents = [d for d in found if d is not None]
    memo = None
    if task.get("memo"):
        problem = task["problem"]
        dvars = discrete_variables(problem)
        full = {v.name: (v.lower, v.upper) for v in dvars}
        items = {v.name: v.values for v in dvars}
        memo = shared_memo((problem_digest(problem), task["starts"], task["seed"]), full, items)
    return {"incumbents": incumbents, "memo": memo}


def previous_holds(
    task: Mapping[str, Any], deps: Mapping[str, Any], eps: Mapping[str, float]
) -> PointRecord | None:
    """The record of the point before ``task`` (its looser neighbour, when the points run
    one after another: :func:`chain_points`) as this point's, when its design meets this
    point's limits ``eps`` with room (each below its limit by more than the tie
    tolerance). That design is the optimum of a catalogue search over a feasible set that
    holds this point's: it is this point's optimum too - the set shrank around it, and
    among its ties (decided by their items) it stays the winner. None otherwise: the
    point is searched."""
    key = task.get("previous")
    if key is None or key not in deps or not eps:
        return None
    rec = PointRecord.from_dict(deps[key])
    if not (rec.success and rec.design) or not looser_or_equal(rec.eps, eps):
        return None
    if not within_limits_with_room(rec.objectives, eps):
        return None
    rec.id, rec.kind, rec.eps = task["id"], task["kind"], dict(eps)
    rec.message = f"{rec.message}; the design of {key}, inside this point's limits".lstrip("; ")
    rec.n_solves = 0
    return rec
