"""Pareto fronts over catalogue designs (variables that take catalogue values).

A front of continuous NLPs would pass through designs no catalogue sells; here every point
- the anchors too - is solved by the catalogue search (branch and bound over NLP
relaxations, :func:`optdesign.formulations.catalogue.search.solve_catalogue`) with the epsilon limit
on the other objective, so every point is a catalogue design with its relaxation bound.
The points are independent once the anchors are in: they run side by side as tasks of the
checkpointed runner (resumable, local processes or Dask).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

from optdesign.errors import InputError
from optdesign.formulations.catalogue.diagnosis import catalogue_diagnosis
from optdesign.formulations.catalogue.search import solve_catalogue
from optdesign.formulations.diagnosis import Relaxing, diagnose
from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.registry import FRONT_SOLVERS
from optdesign.studies.pareto.catalogue_knowledge import (
    chain_points,
    front_knowledge,
    previous_holds,
)
from optdesign.studies.pareto.records import PointRecord, record_from_result
from optdesign.studies.pareto.tasks import ANCHOR_SLACK
from optdesign.studies.pareto.template import FrontMethod, FrontRun, Traced, has_catalogue

#: ``has_catalogue`` is defined with the template; importers here keep working.
__all__ = ["CatalogueEpsilon", "catalogue_task", "has_catalogue"]


def catalogue_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """One catalogue solve: ``min target s.t. eps`` (an anchor, its tie-break, a point)."""
    problem: DesignProblem = task["problem"]
    t0 = time.perf_counter()
    eps = dict(task.get("eps") or {})
    if "tie_of" in task:  # lexicographic tie-break: the first objective held at its optimum
        first = PointRecord.from_dict(deps[task["tie_of"]])
        if not first.success:
            first.id, first.kind = task["id"], "anchor"
            return first.to_dict()
        name = task["fixed"]
        eps = {name: first.objectives[name] * (1 + ANCHOR_SLACK) + 1e-12}
    if "eps_frac" in task:
        a, b = task["eps_name"], task["target"]
        lo_rec = PointRecord.from_dict(deps[f"anchor-{a}"])
        hi_rec = PointRecord.from_dict(deps[f"anchor-{b}"])
        if not (lo_rec.success and hi_rec.success):  # no frame: the run stops at check_anchor
            failed = a if not lo_rec.success else b
            return PointRecord(
                id=task["id"],
                kind=task["kind"],
                status="failed",
                target=b,
                message=f"anchor {failed} has no design",
            ).to_dict()
        lo = lo_rec.objectives[a] * (1 + ANCHOR_SLACK) + 1e-12
        hi = max(hi_rec.objectives[a], lo)
        eps = {a: float(lo + task["eps_frac"] * (hi - lo))}
        if task["eps_frac"] == 0.0:  # the anchor's own tie-break, at its own limit
            return _end_of_front(task, lo_rec, dict(lo_rec.eps), t0)
        if task["eps_frac"] == 1.0:
            return _end_of_front(task, hi_rec, eps, t0)
    held = previous_holds(task, deps, eps)
    if held is not None:
        held.wall_time_s = time.perf_counter() - t0
        return held.to_dict()
    result = solve_catalogue(
        problem,
        starts=task["starts"],
        seed=task["seed"],
        objective=task["target"],
        eps=eps,
        # an anchor's first stage gives its tie-break the optimal value (and a first
        # incumbent); the tie-break decides the design, so the first stage leaves ties
        ties=task["kind"] != "anchor-multistart",
        objectives=task.get("objectives", ()),
        **front_knowledge(task, deps),
    )
    if task["kind"] == "anchor-multistart" and not result.success and not result.design:
        # An anchor with no catalogue design: its best point, for the error to name the
        # requirements it violates (no relaxations: the front stops here).
        diagnose(problem, result, Relaxing(relax=False), by=catalogue_diagnosis)
    rec = record_from_result(problem, result, task["kind"], task["target"], eps, task["id"])
    info = result.details.get("catalogue")
    rec.n_solves = info.nlp_solves if info is not None else 0
    rec.wall_time_s = time.perf_counter() - t0
    return rec.to_dict()


def _end_of_front(task: Mapping[str, Any], anchor: PointRecord, eps: dict, t0: float) -> dict:
    """An end point of the front is its anchor's design, not solved again.

    The first point (``a <= a_min (1 + slack)``, minimise ``b``) is the anchor's own
    tie-break, and keeps its limit; at the last (``a <=`` the other anchor's ``a``,
    minimise ``b``) the other anchor minimised ``b`` first and meets the limit exactly,
    so no design does better on ``b`` (to the anchors' slack). The record keeps the
    anchor's design, values and check; the point's limit on ``a`` replaces the anchor's
    on ``b`` among the active rows."""
    a, b = task["eps_name"], task["target"]
    rec = PointRecord.from_dict(anchor.to_dict())
    rec.id, rec.kind, rec.target, rec.eps = task["id"], task["kind"], b, eps
    rec.active = sorted({*(r for r in rec.active if r != f"{b}_max"), f"{a}_max"})
    rec.message = f"{rec.message}; the design of {anchor.id}".lstrip("; ")
    rec.n_solves = 0
    rec.wall_time_s = time.perf_counter() - t0
    return rec.to_dict()


@dataclass
class CatalogueEpsilon(FrontMethod):
    """Epsilon-constraint front of two objectives over catalogue designs.

    Attributes
    ----------
    points
        Points between the two anchors (epsilon evenly spaced in the first objective).
    starts, seed
        Multistart of each node NLP of every catalogue search (default: the file's,
        at most 4).
    """

    points: int = 12
    starts: int | None = None
    seed: int | None = None
    name: str = "epsilon-catalogue"

    designs: ClassVar[str] = "catalogue"
    n_objectives: ClassVar[tuple[int, ...]] = (2,)
    what: ClassVar[str] = "a catalogue front"
    max_default_starts: ClassVar[int | None] = 4

    def check_settings(self) -> None:
        if self.points < 2:
            raise InputError("points", f"a front needs at least 2 points, got {self.points}")

    def identity(self, starts: int, seed: int, objectives: Sequence[str]) -> tuple[str, dict]:
        settings = {"points": self.points, "starts": starts, "seed": seed}
        return FRONT_SOLVERS.fallback, {"method": self.name, **settings}

    def settings(self, starts: int, seed: int, objectives: Sequence[str]) -> dict[str, Any]:
        return {
            "points": self.points,
            "starts": starts,
            "seed": seed,
            "spacing": "uniform in " + objectives[0],
        }

    def trace(self, ctx: FrontRun) -> Traced:
        a, b = ctx.objectives
        common = {
            "problem": ctx.problem,
            "starts": ctx.starts,
            "seed": ctx.seed,
            "objectives": (a, b),  # one node NLP for every search of the front
        }
        tasks = []
        for first, second in ((a, b), (b, a)):
            tasks.append(
                {**common, "id": f"anchor-{first}-ms", "kind": "anchor-multistart", "target": first}
            )
            tasks.append(
                {
                    **common,
                    "id": f"anchor-{first}",
                    "kind": "anchor",
                    "target": second,
                    "tie_of": f"anchor-{first}-ms",
                    "fixed": first,
                    "after": [f"anchor-{first}-ms"],
                }
            )
        points = []
        for i in range(self.points):
            points.append(
                {
                    **common,
                    "id": f"{self.name}-{i:04d}",
                    "kind": "eps",
                    "target": b,
                    "eps_name": a,
                    "eps_frac": i / (self.points - 1),
                    "index": i,
                    "after": [f"anchor-{a}", f"anchor-{b}"],
                }
            )
        chain_points(tasks, points, sequential=ctx.run.workers == 1 and not ctx.run.scheduler)
        done = ctx.tasks(
            tasks + points,
            catalogue_task,
            progress=f"{self.name}: points" if ctx.run.progress else False,
        )
        anchors = {k: PointRecord.from_dict(done[f"anchor-{k}"]) for k in ctx.objectives}
        recs = [PointRecord.from_dict(done[t["id"]]) for t in points]
        n_solves = sum(PointRecord.from_dict(r).n_solves for r in done.values())
        return Traced(recs, anchors, n_solves)
