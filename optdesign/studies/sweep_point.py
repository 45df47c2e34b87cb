"""One point of a sweep: its own global search (or its formulation's solve), a polish
round's warm start from a neighbour, which of two results is better, and the record
stored for it. :func:`optdesign.studies.sweep.run_sweep` schedules the points."""

from __future__ import annotations

import math
import threading
import time
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from optdesign.formulations.nlp.solution import has_multipliers, nlp_solution
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.parameters import at_values
from optdesign.problem.request import SolveRequest
from optdesign.solvers.multistart import tie_width
from optdesign.studies.sweep_grid import (  # noqa: F401 - the grid's names, as before
    MAX_AXES,
    MAX_GRID,
    MAX_POINTS,
    Axis,
    check_path_names,
    grid_order,
    neighbour,
    parameter_dimension,
    point_settings,
    sweep_axes,
)

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
    from optdesign.display.limits import at_bound, is_internal

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
        shared = shared_solver(task)
        if shared is not None:
            best = shared.search(problem, request.starts, request.seed, request.agree)
        else:
            from optdesign.formulations.nlp.solve import solve_nlp

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
    shared = shared_solver(task)
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
        and has_multipliers(best, request.solver)
        and nlp_solution(best) is not None
    ):
        from optdesign.formulations.nlp.sensitivities import nlp_sensitivities

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
    settings = point_settings(task["axes"], task["values"])
    key = (threading.get_ident(), task["problem"].token, tuple(settings.items()))
    with _POINTS_LOCK:
        if key in _POINTS:
            _POINTS.move_to_end(key)
            return _POINTS[key]
    point = at_values(task["problem"], settings)
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
    from optdesign.formulations.nlp.solve import solve_nlp

    return solve_nlp(problem, task["request"].objective, starts=1, x0=x0)


def shared_solver(task: Mapping[str, Any]):
    """The sweep's one NLP (:mod:`optdesign.studies.sweep_solver`), built once per
    process; None when each point builds its own (mode ``"rebuild"``) or is solved by
    its formulation."""
    if task["mode"] != "shared":
        return None
    from optdesign.runtime.runner import cached
    from optdesign.studies.sweep_solver import SweepSolver

    base = task["problem"]
    objective = task["request"].objective
    key = ("sweep-solver", base.token, tuple(task["paths"]), objective)
    return cached(key, lambda: SweepSolver(base, task["paths"], objective))


def _violated(problem: DesignProblem, result) -> list[str]:
    """What fails at the best design found: the violated requirements as read."""
    from optdesign.display.limits import limits_of, relaxation_limits, relaxation_text

    diagnosis = result.diagnosis
    if not result.violated and diagnosis is not None and diagnosis.relaxations:
        relax = relaxation_limits(problem, diagnosis.relaxations)
        return ["relax one of: " + "; ".join(relaxation_text(lim) for lim in relax)]
    if not result.violated:
        return [f"no design found ({result.status})"]
    return [lim.text() for lim in limits_of(problem, result.violated)][:10] or [
        r.describe() for r in result.violated[:10]
    ]
