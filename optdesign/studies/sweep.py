"""Parametric sweeps: how the optimum moves when a requirement, a bound or a fixed
variable changes (``od.sweep``, ``optdesign sweep``).

One or two parameters, each over an evenly spaced range. The points are solved by
*continuation*: every point is warm-started from its neighbour's design (one Ipopt solve;
the point before it along the first parameter, the first point of a row from the first
point of the row before: every row a chain, :func:`neighbour`), and a full multistart
checks the point - independently of the neighbour - every ``check_every`` points, at
the ends of every row, wherever the warm start fails and wherever the binding set differs
from the neighbour's. A multistart that finds a better optimum than the warm start marks a
*jump* (the chain had followed a local optimum), and the chain goes on from the better one.

A problem with catalogue variables or tolerances is solved point by point by its own
formulation (:func:`optdesign.studies.solve.solve`), without continuation (a note says so).

The points go to a JSONL store as they finish (:func:`optdesign.studies.runner.run_tasks`,
the store of fronts): a killed sweep resumes where it stopped, and a resume with other
settings is refused naming what changed. An infeasible point is a point: its record says
what fails at the best design found.
"""

from __future__ import annotations

import difflib
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from optdesign.errors import InputError, OptDesignError
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.request import SolveRequest
from optdesign.solvers.registry import default_solver, solver_hints
from optdesign.solvers.solved_point import is_success
from optdesign.studies.run_options import RunOptions
from optdesign.studies.sensitivity import at_values
from optdesign.tolerances import OBJECTIVE_TIE_TOL

#: Most parameters of one sweep, and most points along one parameter.
MAX_AXES = 2
MAX_POINTS = 1000


@dataclass(frozen=True)
class Axis:
    """One swept parameter.

    Attributes
    ----------
    path
        Where the file states it: ``"requirements.hinge_moment"``,
        ``"requirements.mean_ratio.min"``, ``"variables.R.upper"``, ``"variables.i_a"``.
    values
        The values, internal units.
    unit, shown
        The unit the values are shown in and the values in it.
    """

    path: str
    values: tuple[float, ...]
    unit: str
    shown: tuple[float, ...]

    @property
    def label(self) -> str:
        name = self.path.split(".", 1)[1] if "." in self.path else self.path
        return f"{name} [{self.unit}]" if self.unit else name


@dataclass
class SweepPoint:
    """One point of a sweep (see the record written by :func:`sweep_point`).

    ``active_change``: the binding set or a catalogue item differs from the point before
    it in the sweep's order (both solved); ``checked``: a full multistart checked it;
    ``jump``: that multistart found a better optimum than the warm start."""

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

    @property
    def success(self) -> bool:
        """The one success rule (:func:`~optdesign.solvers.solved_point.is_success`); a
        stored point's status is already the checked one (a design the independent check
        refused is ``"infeasible"``, :func:`optdesign.studies.nlp_solve.finish`)."""
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
        from optdesign.reports.sweep import sweep_summary

        return sweep_summary(self)

    def to_frame(self):
        """A pandas DataFrame, one row per point: the parameters, the status, the
        objective and every free variable (columns ``"name [unit]"``), the binding set."""
        from optdesign.reports.sweep import sweep_frame

        return sweep_frame(self)

    def plot(self):
        """The design chart (a matplotlib Figure outside pyplot)."""
        from optdesign.plots.sweep import plot_sweep

        return plot_sweep(self)


# --- parameters ----------------------------------------------------------------------
def parameter_dimension(problem: DesignProblem, path: str) -> str:
    """The dimension of the parameter at ``path`` (InputError ``vary`` when unknown)."""
    from optdesign.reports.display_units import _dimension

    head, _, rest = path.partition(".")
    if head == "variables":
        name, _, side = rest.partition(".")
        var = problem.by_name.get(name)
        if var is None:
            raise InputError("vary", f"{path}: no variable {name!r} ({_known(problem)})")
        if var.discrete:
            raise InputError("vary", f"{path}: {name} takes catalogue values; sweep a requirement")
        if side not in (("lower", "upper") if var.free else ("",)):
            want = f"{name}.lower or {name}.upper" if var.free else name
            raise InputError(
                "vary",
                f"{path}: {name} is {'free' if var.free else 'fixed'}: sweep variables.{want}",
            )
        return var.dimension
    if head != "requirements" or not rest:
        raise InputError(
            "vary", f"{path!r}: give requirements.NAME or variables.NAME[.lower|.upper]"
        )
    model: Any = problem.spec.requirements
    keys = rest.split(".")
    for depth, key in enumerate(keys):
        fields = type(model).model_fields
        if key not in fields:
            close = difflib.get_close_matches(key, list(fields), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise InputError("vary", f"{path}: unknown requirement{hint}")
        value = getattr(model, key)
        if depth < len(keys) - 1:
            if value is None:
                raise InputError("vary", f"{path}: requirements.{key} is not set in the problem")
            model = value
            continue
        info = fields[key]
        if hasattr(type(value), "model_fields"):
            raise InputError(
                "vary",
                f"{path}: a table; sweep one of its numbers "
                f"({', '.join(type(value).model_fields)})",
            )
        if not isinstance(value, float) and not (value is None and _numeric(info)):
            raise InputError("vary", f"{path}: not a number (a {type(value).__name__})")
        return _dimension(info) or "dimensionless"
    raise AssertionError("unreachable")


def _numeric(info: Any) -> bool:
    import typing

    stack, seen = [info.annotation], []
    while stack:
        t = stack.pop()
        seen.append(t)
        stack += list(typing.get_args(t))
    return float in seen


def _known(problem: DesignProblem) -> str:
    return "known: " + ", ".join(v.name for v in problem.variables)


def sweep_axes(problem: DesignProblem, vary: Any) -> list[Axis]:
    """The axes of ``vary`` (``{path: (start, stop, count)}``), checked: a known parameter
    path, quantities of its dimension (a bare number only for a plain number), a range
    that is not empty, a problem that validates at both ends. InputError naming the field."""
    from optdesign.reports.display_units import Shown, _value, variable_shown
    from optdesign.units import to_internal

    if not isinstance(vary, Mapping) or not vary:
        raise InputError(
            "vary",
            "give {parameter path: (start, stop, count)}, e.g. "
            '{"requirements.hinge_moment": ("200 N*m", "1000 N*m", 20)}',
        )
    if len(vary) > MAX_AXES:
        raise InputError("vary", f"{len(vary)} parameters; at most {MAX_AXES}")
    axes = []
    for path, spec in vary.items():
        if not isinstance(path, str):
            raise InputError("vary", f"a parameter path is text, got {path!r}")
        where = f"vary.{path}"
        dim = parameter_dimension(problem, path)
        if not isinstance(spec, Sequence) or isinstance(spec, str) or len(spec) != 3:
            raise InputError(where, f"give (start, stop, count), got {spec!r}")
        start, stop, count = spec
        if isinstance(count, bool) or not isinstance(count, int | np.integer):
            raise InputError(where, f"count: an integer, got {count!r}")
        if not 2 <= count <= MAX_POINTS:
            raise InputError(where, f"count: {count} is outside 2..{MAX_POINTS}")
        lo = to_internal(start, dim, f"{where} start", bare="refuse")
        hi = to_internal(stop, dim, f"{where} stop", bare="refuse")
        if lo == hi:
            raise InputError(where, f"an empty range: start and stop are both {start}")
        values = tuple(float(v) for v in np.linspace(lo, hi, int(count)))
        for end in (lo, hi):
            try:
                at_values(problem, {path: end})
            except InputError:
                raise
            except OptDesignError as exc:
                raise InputError(where, f"{start}..{stop}: {exc}") from None
        head, _, rest = path.partition(".")
        if head == "variables":
            var = problem.by_name[rest.partition(".")[0]]
            shown = [variable_shown(problem, var, v) for v in values]
        else:
            shown = [
                _value(problem, path, v, None if dim == "dimensionless" else dim) for v in values
            ]
            shown = [s if isinstance(s, Shown) else Shown(float(s), "") for s in shown]
        axes.append(Axis(path, values, shown[0].unit, tuple(float(s.value) for s in shown)))
    if len({a.path for a in axes}) < len(axes):
        raise InputError("vary", "the same parameter twice")
    return axes


def grid_order(axes: Sequence[Axis]) -> list[tuple[int, ...]]:
    """Index tuples of the grid, the first parameter fastest."""
    if len(axes) == 1:
        return [(i,) for i in range(len(axes[0].values))]
    return [(i, j) for j in range(len(axes[1].values)) for i in range(len(axes[0].values))]


def neighbour(idx: tuple[int, ...]) -> tuple[int, ...] | None:
    """The point a point continues from: the one before it along the first parameter;
    the first point of a row continues from the first point of the row before. Every
    row is so a chain of its own (rows run side by side with several workers)."""
    if idx[0] > 0:
        return (idx[0] - 1, *idx[1:])
    if len(idx) == 2 and idx[1] > 0:
        return (0, idx[1] - 1)
    return None


# --- one point -------------------------------------------------------------------------
def active_names(problem: DesignProblem, result) -> list[str]:
    """The binding set of a result: requirement (block) names and ``VAR.lower/upper``."""
    from optdesign.reports.limits import at_bound, is_internal

    names = {r.name.split("[", 1)[0] for r in result.active if not is_internal(r.name)}
    for var in problem.free:
        value = result.design.get(var.name)
        side = None if value is None else at_bound(var, value)
        if side is not None:
            names.add(f"{var.name}.{side}")
    return sorted(names)


def continuable(problem: DesignProblem) -> bool:
    """True when the points are NLPs a warm start can follow (no catalogue variable,
    no tolerances)."""
    return not any(v.discrete for v in problem.free) and problem.spec.tolerances is None


def sweep_point(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """Solve one point of a sweep (a task of :func:`run_sweep`; JSON-able record)."""
    from optdesign.studies.nlp_solve import solve_nlp

    t0 = time.perf_counter()
    base: DesignProblem = task["problem"]
    problem = at_values(base, dict(zip(task["paths"], task["values"], strict=True)))
    request: SolveRequest = task["request"]
    objective = request.objective
    prev = next(iter(deps.values()), None) if deps else None
    solves = 0
    warm = None
    if not task["continuation"]:
        from optdesign.studies.solve import solve

        # a catalogue's sensitivities come with its neighbouring items
        best = solve(problem, request)
        solves, checked = 1, True
    else:
        shared = _shared_solver(task)
        if prev is not None and prev.get("design"):
            x0 = np.array([prev["design"][v.name] for v in problem.free])
            if shared is not None:
                warm = shared.warm(problem, x0)
            else:
                warm = solve_nlp(problem, objective, starts=1, x0=x0)
            solves += 1
        best = warm
        changed = (
            warm is None
            or not warm.success
            or (prev is not None and active_names(problem, warm) != prev.get("active"))
        )
        checked = changed or task["scheduled_check"]
        if checked:
            if shared is not None:
                full = shared.multistart(problem, request.starts, request.seed)
            else:
                full = solve_nlp(problem, objective, starts=request.starts, seed=request.seed)
            solves += full.multistart.n_starts if full.multistart else 1
            if best is None or _better(full, best):
                best = full
    jump = bool(
        warm is not None
        and best is not warm
        and warm.success
        and best.objective < warm.objective - OBJECTIVE_TIE_TOL * max(1.0, abs(warm.objective))
    )
    active = active_names(problem, best) if best.success else []
    record: dict[str, Any] = {
        "index": task["index"],
        "values": list(task["values"]),
        "status": best.status,
        "objective": float(best.objective),
        "design": {k: float(v) for k, v in best.design.items()},
        "active": active,
        "violated": [] if best.success else _violated(problem, best),
        "checked": bool(checked),
        "jump": jump,
        "success": best.success,
        "solves": solves,
        "warm_objective": None if warm is None else float(warm.objective),
        "sensitivities": {},
    }
    if (
        request.sensitivities
        and best.success
        and solver_hints(best.solver).multipliers
        and "lam_g" in best.raw
    ):
        from optdesign.studies.sensitivity import nlp_sensitivities

        nlp = shared.nlp if task["continuation"] and shared is not None else None
        try:  # a point solved by its formulation has its own (a catalogue's, a robust one's)
            sens = nlp_sensitivities(problem, best, nlp=nlp) if task["continuation"] else []
        except Exception:  # a report: never lose the point
            sens = []
        sens = sens or best.sensitivities
        record["sensitivities"] = {
            s.name: s.log_sensitivity for s in sens if s.log_sensitivity is not None
        }
    record["time_s"] = time.perf_counter() - t0
    return record


def _shared_solver(task: Mapping[str, Any]):
    """The sweep's one NLP (:mod:`optdesign.studies.sweep_solver`), built once per
    process; None when each point builds its own (mode ``"rebuild"``)."""
    if task["mode"] != "shared":
        return None
    from optdesign.studies.runner import cached
    from optdesign.studies.sweep_solver import SweepSolver

    base = task["problem"]
    objective = task["request"].objective
    key = ("sweep-solver", base.token, tuple(task["paths"]), objective)
    return cached(key, lambda: SweepSolver(base, task["paths"], objective))


def _better(a, b) -> bool:
    if a.success != b.success:
        return a.success
    if not a.success:
        return a.max_violation < b.max_violation
    return a.objective < b.objective - OBJECTIVE_TIE_TOL * max(1.0, abs(b.objective))


def _violated(problem: DesignProblem, result) -> list[str]:
    """What fails at the best design found: the violated requirements as read."""
    from optdesign.reports.limits import limits_of, relaxation_limits, relaxation_text

    diagnosis = result.diagnosis
    if not result.violated and diagnosis is not None and diagnosis.relaxations:
        relax = relaxation_limits(problem, diagnosis.relaxations)
        return ["relax one of: " + "; ".join(relaxation_text(lim) for lim in relax)]
    if not result.violated:
        return [f"no design found ({result.status})"]
    return [lim.text() for lim in limits_of(problem, result.violated)][:10] or [
        r.describe() for r in result.violated[:10]
    ]


# --- the run ---------------------------------------------------------------------------
def run_sweep(
    problem: DesignProblem,
    vary: Any,
    request: SolveRequest,
    *,
    check_every: int = 10,
    run: RunOptions | None = None,
) -> Sweep:
    """The sweep of :func:`optdesign.sweep` (arguments checked there).

    Parameters
    ----------
    problem, vary
        The problem and ``{path: (start, stop, count)}`` (checked here: :func:`sweep_axes`).
    request
        How each point is solved: its objective, the multistart (``starts``, ``seed``;
        None: the problem file's), the sensitivities; a point a formulation solves (no
        continuation) is solved with it as it is.
    check_every
        A full multistart every this many points along a row.
    run
        Where and how the points run (store folder, resume, workers, progress).
    """
    from optdesign.studies.identity import problem_digest, solver_identity, version
    from optdesign.studies.runner import run_tasks

    run = run if run is not None else RunOptions()
    t0 = time.perf_counter()
    axes = sweep_axes(problem, vary)
    objective = request.objective
    cont = continuable(problem)
    from optdesign.studies.sweep_solver import sweep_mode

    paths = [a.path for a in axes]
    mode = sweep_mode(problem, paths, [(a.values[0], a.values[-1]) for a in axes])
    mode = mode if cont else "formulation"
    starts = request.starts if request.starts is not None else problem.spec.solver.starts
    seed = request.seed if request.seed is not None else problem.spec.solver.seed
    request = replace(request, starts=starts, seed=seed)  # the file's, stated in the identity
    order = grid_order(axes)
    tasks = []
    n0 = len(axes[0].values)
    for k, idx in enumerate(order):
        before = neighbour(idx)
        tasks.append(
            {
                "id": _point_id(idx),
                "after": [_point_id(before)] if before is not None and cont else [],
                "problem": problem,
                "paths": paths,
                "values": [a.values[i] for a, i in zip(axes, idx, strict=True)],
                "index": k,
                # the ends of every row and every check_every-th point along it
                "scheduled_check": idx[0] % check_every == 0 or idx[0] == n0 - 1,
                "request": request,
                "continuation": cont,
                "mode": mode,
            }
        )
    key = {
        "problem": problem_digest(problem),
        "objectives": [objective],
        "method": {
            "sweep": {a.path: list(a.values) for a in axes},
            "check_every": check_every,
            "continuation": cont,
            "mode": mode,
            "sensitivities": bool(request.sensitivities),
            "starts": starts,
            "seed": seed,
        },
        "solver": solver_identity(problem, default_solver("nlp")),
        "optdesign": version(),
    }
    store = run.folder("sweep") / "sweep.jsonl"
    records = run_tasks(
        tasks,
        sweep_point,
        store,
        resume=run.resume,
        overwrite=run.overwrite,
        progress="sweep" if run.progress else False,
        key=key,
        check=sweep_store_check,
        workers=run.workers,
        scheduler=run.scheduler,
    )
    by_grid = sorted(order, key=lambda idx: tuple(reversed(idx)))
    points = []
    for idx in by_grid:
        rec = records[_point_id(idx)]
        points.append(
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
                active_change=_changed(problem, records, idx),
                solves=rec["solves"],
                time_s=rec["time_s"],
                sensitivities=dict(rec.get("sensitivities") or {}),
            )
        )
    notes = []
    if not cont:
        notes.append(
            "catalogue variables or tolerances: every point solved by its formulation, "
            "no continuation"
        )
    if mode == "rebuild":
        notes.append("each point builds its own NLP (the swept parameter changes the model)")
    return Sweep(problem, objective, axes, points, time.perf_counter() - t0, cont, store, notes)


def _changed(problem: DesignProblem, records, idx) -> bool:
    """The binding set or a catalogue item differs from the neighbour's (both solved)."""
    before = neighbour(idx)
    if before is None:
        return False
    rec, prev = records[_point_id(idx)], records[_point_id(before)]
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
