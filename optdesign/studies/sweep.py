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
   solve each, and keeps the best (:func:`polish_choice`: by value, ties keeping the
   point's own design, then the first neighbour in that order; never by timing). Round 1
   polishes every point from every neighbour; a later round only the points next to one
   that improved in the round before, and only from those (a neighbour whose design did
   not change would give the same solve again). The rounds stop when one improves
   nothing, at the latest after as many rounds as the longest axis has points (a note
   says when the cap stopped them): a better branch found at one point so spreads along
   the sweep as far as it is better.

Each round is one :func:`optdesign.studies.runner.run_tasks` call on the sweep's JSONL
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

import difflib
import functools
import math
import threading
import time
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from optdesign.errors import InputError, OptDesignError
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.request import SolveRequest
from optdesign.solvers.multistart import tie_width
from optdesign.solvers.registry import default_solver, solver_hints
from optdesign.solvers.solved_point import is_success
from optdesign.studies.run_options import RunOptions
from optdesign.studies.sensitivity import at_values

#: Most parameters of one sweep, and most points along one parameter.
MAX_AXES = 2
MAX_POINTS = 1000
#: Most points of a sweep's grid (the product of its axes' counts). Every point gets its
#: own global search (about 1 to 2 s on the shipped problems) and then its polish
#: rounds' warm starts, so 2 500 points are an hour or two on one process, and 50 x 50
#: is finer than a design chart shows; a 1000 x 1000 grid (a typo, or a count meant for
#: one axis) would be weeks. One axis keeps its MAX_POINTS.
MAX_GRID = 2500


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
def check_path_names(path: str) -> None:
    """InputError ``vary`` when a name of the dotted ``path`` is empty: a dot at its start
    or its end, or two dots in a row (``requirements.hinge_moment.``)."""
    names = path.split(".")
    empty = next((k for k, name in enumerate(names) if not name.strip()), None)
    if empty is None:
        return
    if empty == 0:
        at = "before its first dot" if len(names) > 1 else "(no name at all)"
    elif empty == len(names) - 1:
        at = "after its last dot"
    else:
        at = f"between two dots (after {'.'.join(names[:empty])})"
    raise InputError(
        "vary",
        f"{path!r}: an empty name {at}; give requirements.NAME or variables.NAME[.lower|.upper]",
    )


def parameter_dimension(problem: DesignProblem, path: str) -> str:
    """The dimension of the parameter at ``path`` (InputError ``vary`` when unknown)."""
    from optdesign.reports.display_units import _dimension

    check_path_names(path)
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
            if not hasattr(type(value), "model_fields"):
                inner = ".".join(keys[: depth + 1])
                raise InputError("vary", f"{path}: requirements.{inner} is a value, not a table")
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
    total = math.prod(len(a.values) for a in axes)
    if total > MAX_GRID:
        counts = " x ".join(str(len(a.values)) for a in axes)
        raise InputError(
            "vary",
            f"{counts} = {total} points; a sweep's grid has at most {MAX_GRID} (each point "
            "is a global search): give fewer points",
        )
    return axes


def grid_order(axes: Sequence[Axis]) -> list[tuple[int, ...]]:
    """Index tuples of the grid, the first parameter fastest."""
    if len(axes) == 1:
        return [(i,) for i in range(len(axes[0].values))]
    return [(i, j) for j in range(len(axes[1].values)) for i in range(len(axes[0].values))]


def neighbour(idx: tuple[int, ...]) -> tuple[int, ...] | None:
    """The point a point would continue from in a plain chain of warm starts: the one
    before it along the first parameter; the first point of a row continues from the
    first point of the row before. A point's ``jump`` compares its optimum with the warm
    start from it."""
    if idx[0] > 0:
        return (idx[0] - 1, *idx[1:])
    if len(idx) == 2 and idx[1] > 0:
        return (0, idx[1] - 1)
    return None


# --- one point -------------------------------------------------------------------------
#: What found a point's optimum when its own search did (``found_by``).
GLOBAL_SEARCH = "global search"
#: ... when the point was solved by its formulation (no continuation).
FORMULATION = "its formulation"
#: The grid neighbours a polish round starts from, in their order (axis, step) -> name.
FROM_NEIGHBOUR = {
    (0, -1): "from the previous point",
    (0, 1): "from the next point",
    (1, -1): "from the previous row",
    (1, 1): "from the next row",
}


def grid_neighbours(
    idx: tuple[int, ...], shape: Sequence[int]
) -> list[tuple[str, tuple[int, ...]]]:
    """The grid neighbours of ``idx`` a polish round starts from, in their fixed order
    (the previous and the next point along the first parameter, then along the second),
    each with its ``found_by`` name."""
    out = []
    for axis in range(len(idx)):
        for step in (-1, 1):
            k = idx[axis] + step
            if 0 <= k < shape[axis]:
                other = list(idx)
                other[axis] = k
                out.append((FROM_NEIGHBOUR[(axis, step)], tuple(other)))
    return out


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
    """One task of :func:`run_sweep` (a JSON-able record): round 0 solves a point on its
    own (its global search, or its formulation); a later round polishes it from its
    neighbours' designs (:func:`polish_point`)."""
    if task.get("round", 0):
        return polish_point(task, deps)
    t0 = time.perf_counter()
    problem = _point_problem(task)
    request: SolveRequest = task["request"]
    shared = None
    if not task["continuation"]:
        from optdesign.studies.solve import solve

        # a catalogue's sensitivities come with its neighbouring items
        best = solve(problem, request)
        solves, found_by = 1, FORMULATION
    else:
        shared = _shared_solver(task)
        if shared is not None:
            best = shared.search(problem, request.starts, request.seed, request.agree)
        else:
            from optdesign.studies.nlp_solve import solve_nlp

            best = solve_nlp(
                problem,
                request.objective,
                starts=request.starts,
                seed=request.seed,
                agree=request.agree,
            )
        solves, found_by = (best.multistart.n_starts if best.multistart else 1), GLOBAL_SEARCH
    record: dict[str, Any] = {
        "index": task["index"],
        "values": list(task["values"]),
        "round": 0,
        "checked": True,
        "warm_objective": None,
        "improved": False,
        "solves": solves,
    }
    record.update(_outcome(task, problem, best, shared, found_by))
    record["jump"] = _jump(record)
    record["time_s"] = time.perf_counter() - t0
    return record


def polish_point(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """A polish round at one point: one warm-started local solve from each neighbour's
    design in ``task["from"]`` (``[[found_by name, record id], ...]``, in their order),
    the best kept over the point's own record (:func:`polish_choice`). The record is the
    point's, updated: its solves and time added, ``improved``, and where a neighbour won
    its outcome and ``found_by``; ``warm_objective`` is what the start from the chain's
    predecessor (``task["chain"]``) reached, when it was among the starts."""
    t0 = time.perf_counter()
    own = {k: v for k, v in deps[task["own"]].items() if k != "id"}
    problem = _point_problem(task)
    shared = _shared_solver(task)
    tried: list[tuple[str, Any]] = []
    for name, dep in task["from"]:
        x0 = _design_vector(problem, deps[dep])
        if x0 is not None:
            tried.append((name, _warm(task, problem, shared, x0)))
    record = dict(own)
    record["round"] = task["round"]
    record["solves"] = int(own["solves"]) + len(tried)
    for name, result in tried:
        if name == task.get("chain"):
            record["warm_objective"] = _warm_value(result)
    chosen = polish_choice(own, [_rank_of(r) for _, r in tried])
    record["improved"] = chosen is not None
    if chosen is not None:
        name, result = tried[chosen]
        record.update(_outcome(task, problem, result, shared, name))
    record["jump"] = _jump(record)
    record["time_s"] = float(own.get("time_s", 0.0)) + time.perf_counter() - t0
    return record


def polish_choice(
    current: Mapping[str, Any], candidates: Sequence[Mapping[str, Any]]
) -> int | None:
    """The index of the candidate that replaces ``current`` (None: none does).

    Each is a mapping with ``success``, ``objective`` and ``max_violation``. A candidate
    replaces the best so far only when it is better beyond the tie tolerance
    (:func:`better`), so ties keep ``current``, then the earliest candidate: the choice
    depends on the values and their order alone."""
    best, chosen = current, None
    for k, cand in enumerate(candidates):
        if better(cand, best):
            best, chosen = cand, k
    return chosen


def better(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool:
    """``a`` is better than ``b`` beyond the tie tolerance: feasible over infeasible,
    then the lower objective (two feasible) or the smaller violation (two infeasible),
    by more than :data:`~optdesign.tolerances.OBJECTIVE_TIE_TOL` relative."""
    a_ok, b_ok = _usable(a), _usable(b)
    if a_ok != b_ok:
        return a_ok
    key = "objective" if a_ok else "max_violation"
    va, vb = _finite(a.get(key)), _finite(b.get(key))
    return va < vb - tie_width(vb)


def _usable(r: Mapping[str, Any]) -> bool:
    return bool(r.get("success")) and math.isfinite(_finite(r.get("objective")))


def _finite(v: Any) -> float:
    v = math.inf if v is None else float(v)
    return v if math.isfinite(v) else math.inf


def _rank_of(result) -> dict[str, Any]:
    return {
        "success": result.success,
        "objective": float(result.objective),
        "max_violation": float(result.max_violation),
    }


def _warm_value(result) -> float | None:
    return float(result.objective) if _usable(_rank_of(result)) else None


def _jump(record: Mapping[str, Any]) -> bool:
    """A solved point whose optimum a polish round found (its own search had missed it),
    or that is better than the warm start from its predecessor reached (continuation
    alone would have stayed on a worse branch)."""
    if not _usable(record):
        return False
    if record["found_by"] not in (GLOBAL_SEARCH, FORMULATION):
        return True
    warm = record.get("warm_objective")
    return bool(warm is not None and record["objective"] < warm - tie_width(warm))


def _outcome(task, problem: DesignProblem, best, shared, found_by: str) -> dict[str, Any]:
    """The part of a point's record its best result sets."""
    request: SolveRequest = task["request"]
    viol = float(best.max_violation)
    out: dict[str, Any] = {
        "status": best.status,
        "objective": float(best.objective),
        "design": {k: float(v) for k, v in best.design.items()},
        "active": active_names(problem, best) if best.success else [],
        "violated": [] if best.success else _violated(problem, best),
        "success": best.success,
        "max_violation": viol if math.isfinite(viol) else None,
        "found_by": found_by,
        "sensitivities": {},
    }
    if (
        request.sensitivities
        and best.success
        and solver_hints(best.solver).multipliers
        and "lam_g" in best.raw
    ):
        from optdesign.studies.sensitivity import nlp_sensitivities

        nlp = shared.nlp if shared is not None else None
        try:  # a point solved by its formulation has its own (a catalogue's, a robust one's)
            sens = nlp_sensitivities(problem, best, nlp=nlp) if task["continuation"] else []
        except Exception:  # a report: never lose the point
            sens = []
        sens = sens or best.sensitivities
        out["sensitivities"] = {
            s.name: s.log_sensitivity for s in sens if s.log_sensitivity is not None
        }
    return out


#: Point problems kept per process and thread (their NLPs are cached by the problem's
#: token): a point polished soon after its search reuses its NLP in mode "rebuild".
_POINTS: OrderedDict[tuple, DesignProblem] = OrderedDict()
_POINTS_SIZE = 16
_POINTS_LOCK = threading.Lock()


def _point_problem(task: Mapping[str, Any]) -> DesignProblem:
    """The point's problem (the base problem at the point's values), the same object
    for every task of the point in this process while it is among the last used."""
    key = (
        threading.get_ident(),
        task["problem"].token,
        tuple(task["paths"]),
        tuple(task["values"]),
    )
    with _POINTS_LOCK:
        if key in _POINTS:
            _POINTS.move_to_end(key)
            return _POINTS[key]
    point = at_values(task["problem"], dict(zip(task["paths"], task["values"], strict=True)))
    with _POINTS_LOCK:
        _POINTS[key] = point
        while len(_POINTS) > _POINTS_SIZE:
            _POINTS.popitem(last=False)
    return point


def _design_vector(problem: DesignProblem, record: Mapping[str, Any]) -> np.ndarray | None:
    """A record's design as a start of ``problem`` (None: it has no complete one)."""
    design = record.get("design") or {}
    try:
        x = np.array([float(design[v.name]) for v in problem.free])
    except (KeyError, TypeError, ValueError):
        return None
    return x if np.all(np.isfinite(x)) else None


def _warm(task: Mapping[str, Any], problem: DesignProblem, shared, x0: np.ndarray):
    """One local solve of the point from ``x0``, checked."""
    if shared is not None:
        return shared.warm(problem, x0)
    from optdesign.studies.nlp_solve import solve_nlp

    return solve_nlp(problem, task["request"].objective, starts=1, x0=x0)


def _shared_solver(task: Mapping[str, Any]):
    """The sweep's one NLP (:mod:`optdesign.studies.sweep_solver`), built once per
    process; None when each point builds its own (mode ``"rebuild"``) or is solved by
    its formulation."""
    if task["mode"] != "shared":
        return None
    from optdesign.studies.runner import cached
    from optdesign.studies.sweep_solver import SweepSolver

    base = task["problem"]
    objective = task["request"].objective
    key = ("sweep-solver", base.token, tuple(task["paths"]), objective)
    return cached(key, lambda: SweepSolver(base, task["paths"], objective))


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
    check_every: int | None = None,
    run: RunOptions | None = None,
) -> Sweep:
    """The sweep of :func:`optdesign.sweep` (arguments checked there).

    Parameters
    ----------
    problem, vary
        The problem and ``{path: (start, stop, count)}`` (checked here: :func:`sweep_axes`).
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
    from optdesign.studies.identity import problem_digest, solver_identity, version
    from optdesign.studies.nlp_solve import planned_starts
    from optdesign.studies.processes import process_pool
    from optdesign.studies.runner import forks_workers, run_tasks
    from optdesign.studies.sweep_solver import sweep_mode

    run = run if run is not None else RunOptions()
    t0 = time.perf_counter()
    axes = sweep_axes(problem, vary)
    objective = request.objective
    cont = continuable(problem)
    paths = [a.path for a in axes]
    mode = sweep_mode(problem, paths, [(a.values[0], a.values[-1]) for a in axes])
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
        _shared_solver({**common, "id": "", "values": []})  # the workers inherit it
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
