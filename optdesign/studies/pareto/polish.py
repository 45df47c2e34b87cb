"""The polish of a two-objective epsilon front: no point stays on a worse branch that the
run has seen a way off.

The chains of a front (:class:`~optdesign.studies.pareto.chains.TwoChains`) warm-start
each point from its neighbour, so a chain that starts on one branch of local optima
follows it. After the chains, rounds of *polish* tasks solve a point again, warm from a
design the run holds:

- at a **seam** - two neighbouring points neither of which was started from the other
  (where the two chains meet, or where a point was re-solved cold) - each point from
  the other's design;
- a point that a **design seen** by the run (any record: anchors, multistarts, points,
  earlier polish) beats - it meets the point's epsilon bound with a lower target - from
  that design;
- in later rounds, the neighbours of every point the round before **improved**, from its
  new design, so that an improvement found at a seam runs along the whole branch.

A round's tasks read only the records of the rounds before it, and a task keeps its
point's record on a tie (decided by value, then by the order of its starts): the front
is the same whatever the number of workers or the order in which tasks finish. The
rounds stop when one improves nothing, or after :data:`MAX_ROUNDS`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from optdesign.solvers.multistart import improves, tie_width
from optdesign.studies.pareto.records import PointRecord

#: Most polish rounds of a front (an improvement moves one point per round).
MAX_ROUNDS = 64


def seams(records: Sequence[PointRecord], ids: Sequence[str]) -> list[int]:
    """Indices ``i`` where points ``i`` and ``i + 1`` were not started one from the other
    (a point re-solved from cold starts counts as not started from its neighbour)."""
    out = []
    for i in range(len(records) - 1):
        left, right = records[i], records[i + 1]
        joined = (right.warm == ids[i] and not right.retried) or (
            left.warm == ids[i + 1] and not left.retried
        )
        if not joined:
            out.append(i)
    return out


def best_seen(
    point: PointRecord, seen: Sequence[PointRecord], target: str, eps: Mapping[str, float]
) -> PointRecord | None:
    """The seen design with the lowest ``target`` among those that meet ``eps``, when it
    beats ``point`` by more than a tie (None otherwise)."""
    best: PointRecord | None = None
    for rec in seen:
        if not rec.success or rec.x is None or target not in rec.objectives:
            continue
        meets = all(rec.objectives.get(k, math.inf) <= v + tie_width(v) for k, v in eps.items())
        if not meets:
            continue
        if best is None or improves(rec.objectives[target], best.objectives[target]):
            best = rec
    if best is None:
        return None
    if point.success and not improves(best.objectives[target], point.objectives[target]):
        return None
    return best


def round_tasks(
    current: Sequence[PointRecord],
    ids: Sequence[str],
    seen: Sequence[PointRecord],
    seen_ids: Sequence[str],
    improved: set[int] | None,
    round_no: int,
    name: str,
    common: Mapping[str, Any],
) -> list[dict[str, Any]]:
    """The tasks of polish round ``round_no`` (1, 2, ...).

    ``current[i]`` and ``ids[i]``: point ``i``'s record and id after the rounds before;
    ``seen``/``seen_ids``: every record the run holds; ``improved``: the points the round
    before improved (None in round 1, whose tasks are the seams and the beaten points).
    A point's task lists its starts in a fixed order: the seen design that beats it, then
    its left and its right neighbour."""
    sources: dict[int, list[str]] = {}

    def add(i: int, src: str) -> None:
        if 0 <= i < len(current) and src != ids[i] and src not in sources.setdefault(i, []):
            sources[i].append(src)

    for i, rec in enumerate(current):
        target = rec.target
        beaten_by = best_seen(rec, seen, target, rec.eps) if rec.eps else None
        if beaten_by is not None:
            add(i, seen_ids[seen.index(beaten_by)])
    if improved is None:
        for i in seams(current, ids):
            add(i + 1, ids[i])
            add(i, ids[i + 1])
    else:
        for i in sorted(improved):
            add(i - 1, ids[i])
            add(i + 1, ids[i])
    tasks = []
    for i in sorted(sources):
        deps = sorted({ids[i], *sources[i]})
        tasks.append(
            {
                **common,
                "id": f"{name}-{i:04d}-polish{round_no}",
                "kind": "polish",
                "point": ids[i],
                "sources": list(sources[i]),
                "after": deps,
                "index": i,
            }
        )
    return tasks
