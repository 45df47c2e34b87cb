"""What the searches of one catalogue front learn about their nodes, for the next ones.

The points of a front minimise one objective under epsilon limits on another; with one
local worker they run one after another from the loosest limit to the tightest, sharing
one :class:`~optdesign.formulations.catalogue.bnb.InfeasibleBoxes` memo. Beside its proofs
of infeasibility the memo keeps, for every node a search solved, a :class:`NodeBounds`
entry: the box (a sub-range of each catalogue variable), the limits it was solved under,
its objective, its value when the search trusts it (a full multistart, or a start that
reached its floor: :func:`~optdesign.formulations.catalogue.bnb.trusted`) and its optimum.

Which way each piece of knowledge may travel - a box ``B`` with limits ``E`` reused for a
box ``b`` inside ``B`` under limits ``e``:

- *a lower bound* (:meth:`NodeBounds.lower_bound`): the least value of objective ``f``
  over ``B`` under ``E`` is a lower bound of ``f`` over ``b`` under ``e`` when every limit
  of ``E`` is held at least as tight by ``e`` (the feasible set only shrinks). So a
  looser point's node values bound a tighter point's nodes from below (a floor, and a
  node pruned with no NLP when the floor cannot beat the incumbent); never the other way;
- *infeasibility from another objective's bound* (:meth:`NodeBounds.infeasible`): when
  the least value of ``g`` over ``B`` under ``E`` lies above ``e``'s limit on ``g``, the
  box ``b`` is infeasible under ``e`` - e.g. a box whose least backlash is above a
  point's backlash limit, learnt while the backlash anchor was searched;
- *a start* (:meth:`NodeBounds.start`): the optimum of the same box, for the same
  objective, under whatever limits: only the first start of the node's NLP, whose
  verdicts rest on the same starts as before (a start proves nothing);
- *the node's result itself* (:meth:`NodeBounds.reuse`): an optimum of the same box and
  objective under looser limits that meets the tighter limits (its limited objectives,
  as the solve checked them, below each limit by more than the tie tolerance, so the
  limit is not active) is an optimum under them too - the feasible set shrank around
  it. The node is not solved again; its result (starts, values, what binds) is the
  earlier one.

Every value here comes from the local multistart of a non-convex NLP: a "lower bound" is
what the searches already treat as one (the pruning of each search rests on the same
values), carried to the searches under tighter limits.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.tolerances import OBJECTIVE_TIE_TOL

Box = Mapping[str, tuple[float, float]]


@dataclass(frozen=True)
class NodeEntry:
    """One node solved by a search of the front.

    Attributes
    ----------
    box
        The catalogue variables' ranges (every variable, lower and upper end).
    eps
        The epsilon limits it was solved under (objective name -> upper limit).
    objective
        The objective the node minimised.
    value
        Its optimal value when the search trusts it as a bound, else None.
    x
        Its optimum (the design vector), or None when it has no feasible point.
    result
        The node's :class:`~optdesign.solvers.result.Result` when it is feasible.
    """

    box: dict[str, tuple[float, float]]
    eps: dict[str, float]
    objective: str
    value: float | None
    x: np.ndarray | None
    result: Any = None


def looser_or_equal(stored: Mapping[str, float], eps: Mapping[str, float]) -> bool:
    """Whether limits ``eps`` hold every limit of ``stored`` at least as tight (so the
    feasible set under ``eps`` lies in the one under ``stored``)."""
    return all(k in eps and eps[k] <= v for k, v in stored.items())


def within_limits_with_room(values: Mapping[str, float], eps: Mapping[str, float]) -> bool:
    """Whether ``values`` (objective name -> value) hold every limit of ``eps`` with room:
    each below its limit by more than the tie tolerance (relative), so that no limit
    binds - an optimum under looser limits that does so is an optimum under ``eps``."""
    return all(
        k in values and values[k] < v - OBJECTIVE_TIE_TOL * max(abs(v), 1e-12)
        for k, v in eps.items()
    )


def inside(box: Box, wide: Box) -> bool:
    """Whether ``box`` lies in ``wide`` (to a rounding of 1e-12 relative)."""
    return all(
        wide[k][0] - _tol(wide[k][0]) <= lo and hi <= wide[k][1] + _tol(wide[k][1])
        for k, (lo, hi) in box.items()
        if k in wide
    )


def _tol(v: float) -> float:
    return 1e-12 * max(1.0, abs(v))


#: Nodes a memo keeps: past it the oldest half is dropped (knowledge lost, never wrong),
#: so that a process running the same front again and again does not scan ever more.
MAX_ENTRIES = 4096


class NodeBounds:
    """The nodes solved by a front's searches: lower bounds, infeasibility and starts
    for the nodes of the searches after them (see the module's text for which way each
    may travel)."""

    def __init__(self, full: Box):
        self.full = {k: (float(a), float(b)) for k, (a, b) in full.items()}
        self._entries: list[NodeEntry] = []
        self._by_box: dict[tuple, list[NodeEntry]] = {}

    def __len__(self) -> int:
        return len(self._entries)

    def _key(self, box: Box) -> tuple:
        whole = {**self.full, **box}
        return tuple((k, float(whole[k][0]), float(whole[k][1])) for k in sorted(whole))

    def add(
        self,
        box: Box,
        eps: Mapping[str, float],
        objective: str,
        value: float | None,
        x: np.ndarray | None,
        result: Any = None,
    ) -> None:
        """Record a node: ``value`` only when the search trusts it as the node's least;
        ``result`` (a feasible one) for :meth:`reuse`."""
        entry = NodeEntry(
            {**self.full, **box},
            dict(eps),
            objective,
            None if value is None or not np.isfinite(value) else float(value),
            None if x is None else np.array(x, dtype=float),
            result,
        )
        self._entries.append(entry)
        self._by_box.setdefault(self._key(box), []).append(entry)
        if len(self._entries) > MAX_ENTRIES:
            self._entries = self._entries[len(self._entries) // 2 :]
            self._by_box = {}
            for e in self._entries:
                self._by_box.setdefault(self._key(e.box), []).append(e)

    def lower_bound(self, box: Box, eps: Mapping[str, float], objective: str) -> float | None:
        """The greatest trusted value of ``objective`` over a box holding ``box``, solved
        under limits that ``eps`` holds at least as tight; None when there is none."""
        whole = {**self.full, **box}
        best = None
        for e in self._entries:
            if e.value is None or e.objective != objective:
                continue
            if (best is None or e.value > best) and looser_or_equal(e.eps, eps):
                if inside(whole, e.box):
                    best = e.value
        return best

    def infeasible(self, box: Box, eps: Mapping[str, float]) -> bool:
        """Whether a trusted value of some limited objective over a box holding ``box``,
        under limits that ``eps`` holds at least as tight, lies above ``eps``'s limit on
        it beyond the tie tolerance: no point of ``box`` meets that limit."""
        whole = {**self.full, **box}
        for e in self._entries:
            limit = eps.get(e.objective)
            if e.value is None or limit is None:
                continue
            if limit < e.value - OBJECTIVE_TIE_TOL * max(abs(e.value), 1e-12):
                if looser_or_equal(e.eps, eps) and inside(whole, e.box):
                    return True
        return False

    def reuse(self, box: Box, eps: Mapping[str, float], objective: str) -> Any:
        """A copy of the latest result of exactly ``box`` for ``objective``, solved under
        limits ``eps`` holds at least as tight, whose design meets every limit of ``eps``
        with room (the tie tolerance, relative); None when there is none."""
        for e in reversed(self._by_box.get(self._key(box), [])):
            if e.result is None or e.objective != objective or not looser_or_equal(e.eps, eps):
                continue
            if within_limits_with_room(e.result.objectives, eps):
                return copy.deepcopy(e.result)
        return None

    def start(self, box: Box, objective: str) -> np.ndarray | None:
        """The latest optimum of exactly ``box`` for ``objective`` (a first start)."""
        for e in reversed(self._by_box.get(self._key(box), [])):
            if e.objective == objective and e.x is not None:
                return e.x.copy()
        return None
