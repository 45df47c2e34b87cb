"""Parametric sweeps: how the optimum moves when a requirement, a bound or a fixed
variable changes (``od.sweep``, ``optdesign sweep``).

One or two parameters, each over an evenly spaced range. Each point is a problem of its
own, and the sweep's answer at a point is what a cold solve of that point finds, or
better. Two kinds of work make it:

1. **The global search of every point** (round 0). Each point gets the global search of
   :mod:`optdesign.search` - the point's declared start, if any, then tilted random
   starts until the odds of a better optimum say stop - cold, independently of every
   other point, with the same seed at every point (the request's, else the problem
   file's): the search ``od.solve`` runs on that point's problem, from the same starts
   (in mode ``"shared"`` on the sweep's one NLP, :mod:`optdesign.studies.sweep_solver`).
   These tasks depend on nothing, so they run side by side on any number of workers.
2. **Polish rounds** (rounds 1, 2, ...). A point is warm-started from the current design
   of each of its grid neighbours (:func:`grid_neighbours`: the previous and the next
   point along the first parameter, then the previous and the next row), one local
   solve each, and keeps the best (:func:`~optdesign.studies.sweep_point.polish_choice`: by value, ties keeping the
   point's own design, then the first neighbour in that order; never by timing). Round 1
   polishes every point from every neighbour; a later round only the points next to one
   that improved in the round before, and only from those (a neighbour whose design did
   not change would give the same solve again). The rounds stop when one improves
   nothing, at the latest after as many rounds as the longest axis has points (a note
   says when the cap stopped them): a better branch found at one point so spreads along
   the sweep as far as it is better.

Each round is one :func:`optdesign.runtime.runner.run_tasks` call on the sweep's JSONL
store, its tasks depending only on the records of the rounds before it: the sweep is
the same for any number of workers, every record goes to the store as it finishes, and
a killed sweep resumes where it stopped (a resume with other settings is refused naming
what changed). A point's latest record is its answer: ``found_by`` says what found its
optimum (``"global search"``, or the neighbour a polish round started from: ``"from
the previous point"``, ``"from the next point"``, ``"from the previous row"``,
``"from the next row"``), ``solves`` counts every local solve behind it, and ``jump``
marks a point where plain continuation would have been wrong: its optimum is better
than what a warm start from its predecessor along the chain (:func:`neighbour`) reaches,
or a polish round improved on its own global search.

A problem with catalogue variables or tolerances is solved point by point by its own
formulation (:func:`optdesign.studies.solve.solve`), without continuation or polish (a
note says so). An infeasible point is a point: its record says what fails at the best
design found.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.request import SolveRequest
from optdesign.runtime.run_options import RunOptions
from optdesign.solvers.registry import default_solver
from optdesign.solvers.solved_point import is_success
from optdesign.studies.sweep_grid import Axis, grid_order, neighbour, point_settings, sweep_axes
from optdesign.studies.sweep_point import (
    GLOBAL_SEARCH,
    continuable,
    grid_neighbours,
    shared_solver,
    sweep_point,
)


@dataclass
class SweepPoint:
    """One point of a sweep (its latest record, see :func:`sweep_point`).

    ``active_change``: the binding set or a catalogue item differs from the point before
    it in the sweep's order (both solved); ``checked``: the point got its own global
    search (or its formulation's solve); ``jump``: plain continuation would have stayed on
    a worse branch here - the optimum is better than the warm start from the point before
    reached, or a polish round improved on the point's own search; ``found_by``: what
    found the optimum (``"global search"``, ``"from the previous point"``, ...);
    ``solves``: every local solve spent on the point."""

    index: int
    values: tuple[float, ...]
    status: str
    objective: float
    design: dict[str, float]
    active: list[str] = field(default_factory=list)
    violated: list[str] = field(default_factory=list)
    checked: bool = False
    jump: bool = False
    active_change: bool = False
    solves: int = 0
    time_s: float = 0.0
    sensitivities: dict[str, float] = field(default_factory=dict)
    found_by: str = "global search"

    @property
    def success(self) -> bool:
        """The one success rule (:func:`~optdesign.solvers.solved_point.is_success`); a
        stored point's status is already the checked one (a design the independent check
        refused is ``"infeasible"``, :func:`optdesign.formulations.nlp.solve.finish`)."""
        return is_success(self.status)


@dataclass
class Sweep:
    """A parametric sweep: the points in grid order (first axis fastest).

    ``wall_time_s`` is the time of this run (a resumed run: of the points it computed).
    """

    problem: DesignProblem
    objective: str
    axes: list[Axis]
    points: list[SweepPoint]
    wall_time_s: float
    continuation: bool
    store: Path | None = None
    notes: list[str] = field(default_factory=list)

    def summary(self) -> str:
        """The plain-text table the command line prints."""
        from optdesign.reports.sweep_text import sweep_summary

        return sweep_summary(self)

    def to_frame(self):
        """A pandas DataFrame, one row per point: the parameters, the status, the
        objective and every free variable (columns ``"name [unit]"``), the binding set."""
        from optdesign.reports.sweep_text import sweep_frame

        return sweep_frame(self)

    def plot(self):
        """The design chart (a matplotlib Figure outside pyplot)."""
        from optdesign.plots.sweep import plot_sweep

        return plot_sweep(self)


# --- the run ---------------------------------------------------------------------------
def run_sweep(
    problem: DesignProblem,
    vary: Any,
    request: SolveRequest,
    *,
    linked: Mapping[str, str] | None = None,
    check_every: int | None = None,
    run: RunOptions | None = None,
) -> Sweep:
    """The sweep of :func:`optdesign.sweep` (arguments checked there).

    Parameters
    ----------
    problem, vary
        The problem and ``{path: (start, stop, count)}`` (checked here: :func:`sweep_axes`).
    linked
        ``{path: swept path}``: parameters set, at every point, to the value of the swept
        parameter they follow (:func:`~optdesign.studies.sweep_grid.point_settings`).
    request
        How each point is solved: its objective, the global search (``starts``: the most
        starts, ``seed``: its draws, the same at every point; None: the problem file's),
        the sensitivities; a point a formulation solves (no continuation) is solved with
        it as it is.
    check_every
        Ignored: every point gets its global search (kept so that older calls run).
    run
        Where and how the points run (store folder, resume, workers, progress).
    """
    from optdesign.formulations.nlp.solve import planned_starts
    from optdesign.runtime.identity import problem_digest, solver_identity, version
    from optdesign.runtime.processes import process_pool
    from optdesign.runtime.runner import forks_workers, run_tasks
    from optdesign.studies.sweep_solver import sweep_mode

    run = run if run is not None else RunOptions()
    t0 = time.perf_counter()
    axes = sweep_axes(problem, vary, linked)
    objective = request.objective
    cont = continuable(problem)
    # every parameter a point sets, a linked one with the range of the one it follows
    first = point_settings(axes, [a.values[0] for a in axes])
    last = point_settings(axes, [a.values[-1] for a in axes])
    paths = list(first)
    mode = sweep_mode(problem, paths, [(first[p], last[p]) for p in paths])
    mode = mode if cont else "formulation"
    # the file's, stated in the identity; a point its formulation solves gets the
    # caller's starts as they are (None: the formulation's own default, as od.solve)
    starts = planned_starts(problem, request.starts) if cont else request.starts
    seed = request.seed if request.seed is not None else problem.spec.solver.seed
    agree = request.agree if request.agree is not None else problem.spec.solver.agree
    request = replace(request, starts=starts, seed=seed, agree=agree if cont else request.agree)
    order = grid_order(axes)
    shape = [len(a.values) for a in axes]
    common = {
        "problem": problem,
        "paths": paths,
        "axes": axes,
        "request": request,
        "continuation": cont,
        "mode": mode,
    }
    points = {
        idx: {
            "values": [a.values[i] for a, i in zip(axes, idx, strict=True)],
            "index": k,
        }
        for k, idx in enumerate(order)
    }
    key = {
        "problem": problem_digest(problem),
        "objectives": [objective],
        "method": {
            "sweep": {a.path: list(a.values) for a in axes},
            # only when some are, so that the stores of sweeps without them still resume
            **(
                {"linked": {p: a.path for a in axes for p in a.linked}}
                if len(paths) > len(axes)
                else {}
            ),
            "continuation": "global+polish" if cont else False,
            "mode": mode,
            "sensitivities": bool(request.sensitivities),
            "starts": starts,
            "seed": seed,
            "agree": agree,
        },
        "solver": solver_identity(problem, default_solver("nlp")),
        "optdesign": version(),
    }
    store = run.folder("sweep") / "sweep.jsonl"
    local = run.workers if run.scheduler is None else 1
    if mode == "shared" and local > 1 and forks_workers():
        shared_solver({**common, "id": "", "values": []})  # the workers inherit it
    notes = []
    with process_pool(local) as pool:
        phase = functools.partial(
            run_tasks,
            fn=sweep_point,
            store_path=store,
            key=key,
            check=sweep_store_check,
            workers=run.workers,
            scheduler=run.scheduler,
            pool=pool,
            on_record=run.on_record,
        )
        first = [{**common, **points[idx], "id": _point_id(idx)} for idx in order]
        done = phase(
            first,
            resume=run.resume,
            overwrite=run.overwrite,
            progress="sweep" if run.progress else False,
        )
        latest = {idx: done[_point_id(idx)] for idx in order}
        if cont:
            cap = max(shape)
            moved = set(order)  # the points whose design is new since the last round
            for r in range(1, cap + 1):
                tasks = polish_tasks(r, order, shape, latest, moved, common, points)
                if not tasks:
                    break
                done = phase(
                    tasks,
                    resume=True,
                    progress=f"sweep: polish {r}" if run.progress else False,
                )
                moved = set()
                for t in tasks:
                    idx = tuple(t["point"])
                    latest[idx] = done[t["id"]]
                    if latest[idx]["improved"]:
                        moved.add(idx)
                if not moved:
                    break
            else:
                if moved:
                    notes.append(
                        f"the polish rounds stopped at their cap ({cap}) with "
                        f"{len(moved)} points still improving"
                    )
    swept = []
    for idx in sorted(order, key=lambda idx: tuple(reversed(idx))):
        rec = latest[idx]
        swept.append(
            SweepPoint(
                index=rec["index"],
                values=tuple(rec["values"]),
                status=rec["status"],
                objective=_float(rec["objective"]),
                design=rec["design"],
                active=list(rec["active"]),
                violated=list(rec["violated"]),
                checked=rec["checked"],
                jump=rec["jump"],
                active_change=_changed(problem, latest, idx),
                solves=rec["solves"],
                time_s=rec["time_s"],
                sensitivities=dict(rec.get("sensitivities") or {}),
                found_by=rec.get("found_by", GLOBAL_SEARCH),
            )
        )
    if not cont:
        notes.append(
            "catalogue variables or tolerances: every point solved by its formulation, "
            "no continuation"
        )
    if mode == "rebuild":
        notes.append("each point builds its own NLP (the swept parameter changes the model)")
    return Sweep(problem, objective, axes, swept, time.perf_counter() - t0, cont, store, notes)


def polish_tasks(
    r: int,
    order: Sequence[tuple[int, ...]],
    shape: Sequence[int],
    latest: Mapping[tuple[int, ...], Mapping[str, Any]],
    moved: set[tuple[int, ...]],
    common: Mapping[str, Any],
    points: Mapping[tuple[int, ...], Mapping[str, Any]],
) -> list[dict[str, Any]]:
    """The tasks of polish round ``r``: every point with a neighbour in ``moved`` (the
    points whose design changed in the round before; round 1: all), each warm-started
    from those neighbours' latest records, in :func:`grid_neighbours` order. A task needs
    only records of earlier rounds (``after``), so the round is the same whatever ran
    first."""
    tasks = []
    for idx in order:
        sources = [(name, nb) for name, nb in grid_neighbours(idx, shape) if nb in moved]
        if not sources:
            continue
        before = neighbour(idx)
        chain = next((name for name, nb in sources if nb == before), None)
        own = latest[idx]["id"]
        frm = [[name, latest[nb]["id"]] for name, nb in sources]
        tasks.append(
            {
                **common,
                **points[idx],
                "id": f"{_point_id(idx)}-r{r}",
                "after": [own, *(dep for _, dep in frm)],
                "round": r,
                "point": list(idx),
                "own": own,
                "from": frm,
                "chain": chain,
            }
        )
    return tasks


def _changed(problem: DesignProblem, records, idx) -> bool:
    """The binding set or a catalogue item differs from the neighbour's (both solved)."""
    before = neighbour(idx)
    if before is None:
        return False
    rec, prev = records[idx], records[before]
    if not (rec["success"] and prev["success"]):
        return False
    items = [v.name for v in problem.free if v.discrete]
    return rec["active"] != prev["active"] or any(
        rec["design"].get(n) != prev["design"].get(n) for n in items
    )


def _point_id(idx) -> str:
    return "p" + "-".join(f"{i:04d}" for i in idx)


def _float(v: Any) -> float:
    return float("nan") if v is None else float(v)


def sweep_store_check(record: Mapping[str, Any]) -> str | None:
    """Why a stored point cannot be trusted on resume (None: it can)."""
    obj = record.get("objective")
    if record.get("success") and (not isinstance(obj, float) or not math.isfinite(obj)):
        return "is a solved point without a finite objective"
    if not isinstance(record.get("design"), dict) or not isinstance(record.get("values"), list):
        return "has no design or no parameter values"
    return None
