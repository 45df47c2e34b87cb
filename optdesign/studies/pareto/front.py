"""A Pareto front: its points, the rejected ones, its metrics, and how to read it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optdesign.solvers.result import clean_json
from optdesign.studies.pareto.metrics import front_metrics, non_dominated
from optdesign.studies.pareto.records import PointRecord


def _of_record(name: str, doc: str) -> property:
    """A read-only attribute of a front's point that is its record's."""
    return property(lambda self: getattr(self.record, name), doc=doc)


@dataclass(eq=False)
class FrontPoint:
    """One point of a front: the solved point's record (:class:`PointRecord`, the one
    record of a solved point) seen from the front, with the method that made it and why
    it is left off the front.

    Attributes
    ----------
    record
        The point as solved and stored: objectives (every objective at the design, NumPy
        path), design (fixed and free variables), status after the independent check,
        ``verified``, active rows, epsilon bounds or weights, task id, solves, time.
    method
        The front method that produced it.
    rejected
        Why the point is not on the front ("" when it is).
    """

    record: PointRecord
    method: str
    rejected: str = ""

    objectives = _of_record("objectives", "Every objective at the design (NumPy path).")
    design = _of_record("design", "The full design (fixed and free variables).")
    status = _of_record("status", "Solver status after the independent check.")
    active = _of_record("active", "Active constraint rows (requirements, epsilon bounds).")
    verified = _of_record("verified", "The independent check (None: not checked).")
    id = _of_record("id", "Task id in the store.")
    n_solves = _of_record("n_solves", "Solves spent on the point.")
    wall_time_s = _of_record("wall_time_s", "Its wall time.")
    message = _of_record("message", "The solver's message.")
    retried = _of_record("retried", "Why it was solved again from Sobol starts (or '').")

    @property
    def eps(self) -> dict[str, float]:
        """The epsilon bounds (or weights) that defined the point."""
        return self.record.eps or self.record.weights

    @property
    def success(self) -> bool:
        """The record's success (the one rule, :func:`~optdesign.solvers.result.
        is_success`)."""
        return self.record.success

    @classmethod
    def from_record(cls, rec: PointRecord, method: str) -> FrontPoint:
        return cls(rec, method)

    def to_dict(self) -> dict[str, Any]:
        """The point as ``front.json`` writes it."""
        return clean_json(
            {
                "objectives": dict(self.objectives),
                "design": dict(self.design),
                "status": self.status,
                "active": list(self.active),
                "method": self.method,
                "verified": self.verified,
                "eps": dict(self.eps),
                "id": self.id,
                "rejected": self.rejected,
                "n_solves": self.n_solves,
                "wall_time_s": self.wall_time_s,
                "message": self.message,
                "retried": self.retried,
            }
        )


@dataclass
class Front:
    """A Pareto front: its non-dominated successful points, the rest, and its metrics.

    Attributes
    ----------
    objectives
        The front's objective names.
    method
        The method that computed it.
    points
        Successful, verified, non-dominated points (sorted by the first objective).
    rejected
        Failed, infeasible or dominated points, each with its reason.
    metrics
        Hypervolume, spacing, spread (see :mod:`optdesign.studies.pareto.metrics`).
    wall_time_s
        Wall time of the whole method (anchors included).
    anchors
        Objective values at each anchor (epsilon method).
    store
        The resumable store of the run, if any.
    n_solves
        NLP solves behind the front.
    notes
        What the reader must know about the run (a time limit that left points out).
    """

    objectives: list[str]
    method: str
    points: list[FrontPoint]
    rejected: list[FrontPoint] = field(default_factory=list)
    metrics: dict[str, Any] = field(default_factory=dict)
    wall_time_s: float = 0.0
    anchors: dict[str, dict[str, float]] = field(default_factory=dict)
    store: str = ""
    n_solves: int = 0
    settings: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    problem_object: Any = field(default=None, repr=False, compare=False)

    @property
    def n_retried(self) -> int:
        """Points re-solved from Sobol starts (failed, worse than a neighbour, jumped)."""
        return sum(1 for p in self.points + self.rejected if p.retried)

    @property
    def F(self) -> np.ndarray:
        """Objective values, one row per point."""
        return np.array(
            [[p.objectives[k] for k in self.objectives] for p in self.points], dtype=float
        ).reshape(-1, len(self.objectives))

    def to_dict(self) -> dict[str, Any]:
        return clean_json(
            {
                "method": self.method,
                "objectives": self.objectives,
                "metrics": self.metrics,
                "wall_time_s": self.wall_time_s,
                "anchors": self.anchors,
                "store": self.store,
                "n_solves": self.n_solves,
                "settings": self.settings,
                "notes": self.notes,
                "points": [p.to_dict() for p in self.points],
                "rejected": [p.to_dict() for p in self.rejected],
            }
        )

    def summary(self) -> str:
        """Metrics and a table of (a selection of) the points, with units."""
        from optdesign.reports.front_text import front_summary

        return front_summary([self])

    def to_frame(self, rejected: bool = False):
        """A pandas DataFrame: one row per point (objectives, free variables, status)."""
        from optdesign.reports.frames import front_frame

        return front_frame(self, rejected)

    def plot(self, ax=None):
        """The front in objective space with sketches of its ends and knee; returns the
        matplotlib Figure (``ax``: only the objective-space plot, on that axes)."""
        from optdesign.plots.front import plot_fronts

        return plot_fronts(self.problem_object, [self], ax=ax)


def make_front(
    points: Sequence[FrontPoint],
    objectives: Sequence[str],
    method: str,
    wall_time_s: float = 0.0,
    problem=None,
    **info: Any,
) -> Front:
    """Filter failed and dominated points, sort by the first objective, compute metrics."""
    objectives = list(objectives)
    good = [p for p in points if p.success and all(k in p.objectives for k in objectives)]
    rejected = []
    for p in points:
        if p not in good:
            p.rejected = "failed" if not p.success else "missing objective"
            rejected.append(p)
    F = np.array([[p.objectives[k] for k in objectives] for p in good], dtype=float)
    F = F.reshape(-1, len(objectives))
    mask = non_dominated(F) if len(F) else np.zeros(0, dtype=bool)
    kept = []
    for p, keep in zip(good, mask, strict=True):
        if keep:
            kept.append(p)
        else:
            p.rejected = "dominated or duplicate"
            rejected.append(p)
    kept.sort(key=lambda p: tuple(p.objectives[k] for k in objectives))
    front = Front(objectives, method, kept, rejected, wall_time_s=wall_time_s, **info)
    front.problem_object = problem
    front.metrics = front_metrics(front.F)
    front.metrics["n_failed"] = sum(1 for p in points if not p.success)
    return front


def common_hypervolumes(fronts: Sequence[Front]) -> None:
    """Hypervolumes of several fronts against one reference point (comparable), stored in
    each front's metrics as ``hypervolume_common`` and ``common_reference_point``."""
    from optdesign.studies.pareto.metrics import hypervolume, reference_point

    sets = [f.F for f in fronts if len(f.F)]
    if not sets:
        return
    ref = reference_point(np.vstack(sets))
    for f in fronts:
        f.metrics["hypervolume_common"] = hypervolume(f.F, ref)
        f.metrics["common_reference_point"] = ref.tolist()


def anchors_of(records: Mapping[str, PointRecord]) -> dict[str, dict[str, float]]:
    return {k: dict(r.objectives) for k, r in records.items()}
