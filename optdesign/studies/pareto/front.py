"""A Pareto front: its points, the rejected ones, its metrics, and how to read it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any

import numpy as np

from optdesign.solvers.result import clean_json
from optdesign.solvers.solved_point import SolvedPoint
from optdesign.studies.pareto.metrics import front_metrics, non_dominated
from optdesign.studies.pareto.records import PointRecord, RawSolution

if TYPE_CHECKING:
    from optdesign.studies.pareto.costs import PointCosts


@dataclass(kw_only=True)
class FrontPoint(PointRecord):
    """One point of a front: the solved point's record (:class:`PointRecord`, the one
    record of a solved point, whose success rule it keeps) with the method that made it
    and why it is left off the front. Its ``eps`` holds the epsilon bounds, or the
    weights, that defined it; it carries no warm start (``raw``).

    Attributes
    ----------
    method
        The front method that produced it.
    rejected
        Why the point is not on the front ("" when it is).
    multipliers
        The primal-dual solution of the point's own solve (the record's ``raw``), kept
        for what each limit costs there (:mod:`optdesign.studies.pareto.costs`) and
        never as a warm start; None when the record kept none. Not written to files.
    """

    method: str = ""
    rejected: str = ""
    multipliers: RawSolution | None = field(default=None, repr=False, compare=False)

    @classmethod
    def from_record(cls, rec: PointRecord, method: str) -> FrontPoint:
        kw = {f.name: getattr(rec, f.name) for f in fields(PointRecord)}
        kw.update(
            objectives=dict(rec.objectives),
            design=dict(rec.design),
            active=list(rec.active),
            eps=dict(rec.eps or rec.weights),
            raw=None,
        )
        return cls(**kw, method=method, multipliers=rec.raw)

    def costs(self, problem: Any, objectives: Sequence[str]) -> PointCosts:
        """What each limit costs at this point of a front of ``objectives`` on
        ``problem``, from the point's own solve, or why that cannot be known (a
        :class:`~optdesign.studies.pareto.costs.PointCosts`). Worked out on call, not
        at the front's solve: only a page that shows a point needs them, and they may
        take a solve again; the report reads them here without importing the study."""
        from optdesign.studies.pareto.costs import point_costs

        return point_costs(problem, objectives, self)

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

    def no_point_text(self, problem: Any) -> str:
        """Why the front has no point: the requirements its least violating design
        violates (the command line's line for an infeasible front)."""
        from optdesign.formulations.diagnosis import violated_text

        head = f"{self.method}: no feasible design"
        designs = [p.design for p in self.rejected if p.design]
        if not designs:
            return head
        X = np.array([[d[v.name] for v in problem.free] for d in designs])
        worst = np.asarray(problem.evaluate(X).violation, dtype=float)
        best = X[int(np.argmin(np.where(np.isfinite(worst), worst, np.inf)))]
        shown = violated_text(problem, best)
        return f"{head} among {len(designs)} designs; the least violating one: {shown or 'none'}"

    def summary(self) -> str:
        """Metrics and a table of (a selection of) the points, with units."""
        from optdesign.reports.front_text import front_summary

        return front_summary([self])

    def point_costs(self, problem: Any) -> list[PointCosts]:
        """:meth:`FrontPoint.costs` of every point, in their order, the points' models
        evaluated together (what a page of the whole front shows)."""
        from optdesign.studies.pareto.costs import front_costs

        return front_costs(problem, self.objectives, self.points)

    def to_frame(self, rejected: bool = False):
        """A pandas DataFrame: one row per point (objectives, free variables, status)."""
        from optdesign.display.frames import front_frame

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
            p.rejected = ""  # a point another front rejected is on this one
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


def anchors_of(records: Mapping[str, SolvedPoint]) -> dict[str, dict[str, float]]:
    """The objective values of each anchor's solved point."""
    return {k: dict(r.objectives) for k, r in records.items()}
