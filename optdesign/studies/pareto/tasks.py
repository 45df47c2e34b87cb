"""The tasks of a front's computation, run by :func:`optdesign.runtime.runner.run_tasks`.

A task is a dict (``id``, ``kind``, ``after``, settings); :func:`front_task` dispatches on
``kind`` and returns a :class:`PointRecord` as a dict. Kinds:

- ``anchor-multistart``: the individual optimum of ``order[0]`` by the global search
  (:mod:`optdesign.search`), which stops when its odds say so;
- ``anchor``: lexicographic tie-breaks from that optimum (an individual optimum is often
  not unique - the ripple of a crank-slider is invariant to scaling R, l, n, p together -
  and only the tie-broken point is on the front);
- ``eps``: one epsilon-constraint point, warm-started from its neighbour, re-solved from
  Sobol starts if it fails, gets worse as its bound loosens, or jumps in design space;
- ``weighted_sum``: one point of the weighted sum of normalised objectives;
- ``polish``: a point solved again warm from designs the run holds
  (:mod:`optdesign.studies.pareto.polish`).
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np

from optdesign.formulations.nlp.solve import (
    THIN_FROM_STARTS,
    own_starts,
    search_stand_in,
    tilted_starts,
)
from optdesign.problem.design_problem import DesignProblem
from optdesign.search.global_phase import global_search
from optdesign.solvers.multistart import improves, sobol_starts
from optdesign.solvers.result import Result
from optdesign.studies.pareto.eps_solver import EpsSolver
from optdesign.studies.pareto.records import AnchorStarts, PointRecord, record_from_result
from optdesign.tolerances import OBJECTIVE_TIE_TOL

#: Relative slack on the anchor values in lexicographic tie-breaks and at the sweep ends.
ANCHOR_SLACK = 1e-7


def _solver(task: Mapping[str, Any]) -> EpsSolver:
    return EpsSolver(task["problem"], task["objectives"], task.get("solver"))


def _records(deps: Mapping[str, Any]) -> dict[str, PointRecord]:
    return {k: PointRecord.from_dict(v) for k, v in deps.items()}


def _record(task, solver: EpsSolver, result: Result, kind: str, target: str, eps) -> PointRecord:
    return record_from_result(
        task["problem"], result, kind, target, eps, task["id"], solver.fingerprint
    )


def multistart_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """Individual optimum of ``order[0]`` by the global search (first half of an anchor):
    tilted random starts until the odds say stop (:mod:`optdesign.search`)."""
    problem: DesignProblem = task["problem"]
    order: list[str] = task["order"]
    agree = task.get("agree")
    t0 = time.perf_counter()
    solver = _solver(task)
    free = {k: np.inf for k in order[1:]}
    draws = tilted_starts(problem, order[0], task["seed"])
    # the starts on the grid thinned (the stand-in), their optima polished on the whole
    stand_in = search_stand_in(problem) if task["starts"] >= THIN_FROM_STARTS else problem
    search = (
        solver if stand_in is problem else EpsSolver(stand_in, solver.objectives, solver.method)
    )

    def run(fallback: bool) -> Result:
        def polish(x0: np.ndarray, end: Result) -> Result:
            x = np.array([end.design[v.name] for v in problem.free]) if end.success else x0
            return solver.solve(order[0], free, solver.nlp.start(x0=x), fallback)

        return global_search(
            lambda x0: search.solve(order[0], free, search.nlp.start(x0=x0), fallback),
            draws,
            own=own_starts(problem),
            max_starts=task["starts"],
            agree=3 if agree is None else agree,
            seed=task["seed"],
            polish=None if search is solver else polish,
        )

    # No per-start Ipopt fallback first: a start that fails is just a failed start.
    best = run(False)
    n_solves = best.multistart.n_starts + best.multistart.polished
    # again with the fallback where no start succeeded, or where the best one's polish on
    # the whole grid did not
    if (best.multistart.n_at_best == 0 or not best.success) and solver.has_fallback:
        best = run(True)
        n_solves += best.multistart.n_starts + best.multistart.polished
    ms = best.multistart
    rec = _record(task, solver, best, "anchor-multistart", order[0], {})
    odds = ms.odds
    rec.multistart = AnchorStarts(
        ms.n_starts,
        ms.n_planned or ms.n_starts,
        ms.n_at_best,
        agree,
        ms.stopped_early,
        optima=len(ms.optima),
        counted=ms.counted,
        p_better=None if odds is None else odds.p_better,
        stop=ms.stop,
    )
    rec.order = list(order)
    rec.n_solves = n_solves
    rec.wall_time_s = time.perf_counter() - t0
    return rec.to_dict()


def tie_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """Lexicographic tie-breaks from a multistart optimum (second half of an anchor):
    ``order[1]`` minimised with ``order[0]`` held at its optimum (plus
    :data:`ANCHOR_SLACK`), then ``order[2]`` with both held, ..."""
    order: list[str] = task["order"]
    t0 = time.perf_counter()
    rec = _records(deps)[task["multistart"]]
    n_solves = rec.n_solves  # the anchor's record counts every solve behind it
    solver = _solver(task)
    fixed: dict[str, float] = {}
    for k, name in enumerate(order[1:], start=1):
        if not rec.success:
            break
        prev = order[k - 1]
        fixed[prev] = rec.objectives[prev] * (1 + ANCHOR_SLACK) + 1e-12
        rest = {o: np.inf for o in order if o not in fixed and o != name}
        # The tie-break's feasible set is (almost) the set of optima of the objectives
        # fixed before: degenerate, and SLSQP stalls there or stops short of Ipopt's
        # value (benchmarks/README.md, "Figures behind comments in the code"). Ipopt solves it.
        start = solver.nlp.start(x0=np.asarray(rec.x))
        # Ipopt with a small barrier first; where it stalls on the degenerate set (500
        # iterations from a crank-slider's backlash anchor whose lead differs from
        # another's by 0.5 mm, both optimal), Ipopt with its default options
        for use in ("tie", "fallback"):
            res = solver.solve(name, {**fixed, **rest}, start, use=use)
            n_solves += 1
            cand = _record(task, solver, res, "anchor", name, fixed)
            # The start is feasible for the tie-break (the bound is its own value plus
            # slack): a result worse than the start is a solver failure, not a tie-break
            # (default Ipopt once returned ripple 0.99996 "optimal" from a start at 0.0555).
            limit = rec.objectives[name] * (1 + 1e-9) + 1e-15
            if cand.success and cand.objectives[name] <= limit:
                cand.multistart = rec.multistart
                rec = cand
                break
    rec.id = task["id"]
    rec.kind = "anchor"
    rec.order = list(order)
    rec.n_solves = n_solves
    rec.wall_time_s = time.perf_counter() - t0
    return rec.to_dict()


def _design_distance(problem: DesignProblem, a, b) -> float:
    span = problem.upper() - problem.lower()
    return float(np.max(np.abs((np.asarray(a) - np.asarray(b)) / span)))


def arc_eps(task: Mapping[str, Any], nb: PointRecord | None) -> dict[str, float]:
    """Epsilon of the next point of an arc-length sweep (two objectives A, B).

    In objectives normalised by the anchors' ranges, the L1 arc length of a monotone
    front from anchor A to a point is ``(a - a0)/ra + (b0 - b)/rb`` (total 2). The next
    epsilon is predicted so that the point lands at arc position ``task["arc"]``: a Newton
    step with the front's local slope dB/dA = -multiplier of the epsilon row (the
    neighbour's duals), so points are evenly spread along the front, dense where it bends.
    """
    f = task["frame"]
    a, b = task["eps_name"], task["target"]
    lo, hi = f["a_lo"], f["a_hi"]
    if nb is None or not nb.success:
        return {a: float(task["fallback_eps"])}
    a1, b1 = nb.objectives[a], nb.objectives[b]
    s1 = (a1 - f["a0"]) / f["ra"] + (f["b0"] - b1) / f["rb"]
    slope = abs(nb.slope) if nb.slope is not None and np.isfinite(nb.slope) else f["rb"] / f["ra"]
    ds_da = 1.0 / f["ra"] + slope / f["rb"]
    # Never step more than the whole remaining gap, never less than a tiny fraction.
    step = (task["arc"] - s1) / ds_da
    base = max(a1, nb.eps.get(a, a1)) if step > 0 else min(a1, nb.eps.get(a, a1))
    return {a: float(np.clip(base + step, lo, hi))}


def row_eps(task: Mapping[str, Any], head: PointRecord | None) -> dict[str, float]:
    """Epsilon of a three-objective grid point: B between its row head's B and B_max."""
    b = task["b_name"]
    lo = (
        head.objectives[b] * (1 + ANCHOR_SLACK) + 1e-12
        if head is not None and head.success
        else task["b_hi"]
    )
    lo = min(lo, task["b_hi"])
    return {**task["eps_row"], b: float(lo + task["frac"] * (task["b_hi"] - lo))}


def eps_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """One epsilon-constraint point, warm-started from its neighbour (``task["warm"]``)."""
    problem: DesignProblem = task["problem"]
    target: str = task["target"]
    t0 = time.perf_counter()
    records = _records(deps)
    nb = records.get(task.get("warm") or "")
    if "eps" in task:
        eps: dict[str, float] = dict(task["eps"])
    elif "row_head" in task:
        eps = row_eps(task, records.get(task["row_head"]))
    else:
        eps = arc_eps(task, nb)
    solver = _solver(task)
    n_solves = 1
    start = solver.start_from(nb if nb is not None and nb.success else None)
    rec = _record(task, solver, solver.solve(target, eps, start), "eps", target, eps)
    retry, why = False, ""
    if not rec.success:
        retry, why = True, "failed"
    elif nb is not None and nb.success:
        looser = all(eps[k] >= nb.eps.get(k, -np.inf) for k in eps)
        t_nb, t = nb.objectives[target], rec.objectives[target]
        jump = task.get("jump", 0.2)
        if looser and t > t_nb * (1 + OBJECTIVE_TIE_TOL) + 1e-12:
            retry, why = True, "worse than its neighbour with a looser bound"
        elif jump is not None and _design_distance(problem, rec.x, nb.x) > jump:
            retry, why = True, "jump in design space"
    n_cold = max(task.get("retry_starts", 0) if retry else 0, task.get("extra_starts", 0))
    if n_cold > 0:
        # Seeded per point, so a resumed or parallel run draws the same starts.
        pts = sobol_starts(
            problem.lower(), problem.upper(), n_cold, task.get("seed", 0) + 7919 * task["index"]
        )
        if nb is not None and nb.x is not None:
            pts = np.vstack([np.asarray(nb.x), pts])
        for x0 in pts:
            res = solver.solve(target, eps, solver.nlp.start(x0=x0))
            cand = _record(task, solver, res, "eps", target, eps)
            n_solves += 1
            # a tie (1e-6 relative) keeps the earlier point: the warm start's, else the
            # first start's - decided by value and order, not by rounding
            if cand.success and (
                not rec.success or improves(cand.objectives[target], rec.objectives[target])
            ):
                rec = cand
    if rec.success and len(eps) == 1:
        rec.slope = solver.slope(target, next(iter(eps)), rec)
    rec.warm = task.get("warm")  # the neighbour it started from (which chain computed it)
    rec.retried = why
    rec.n_solves = n_solves
    rec.wall_time_s = time.perf_counter() - t0
    return rec.to_dict()


def weighted_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """One weighted-sum point: ``min sum_k w_k (f_k - ideal_k)/(nadir_k - ideal_k)``,
    started from its neighbour (the weights are the formulation's parameters)."""
    t0 = time.perf_counter()
    weights: dict[str, float] = task["weights"]
    normalise = {k: tuple(v) for k, v in task["normalise"].items()}
    solver = _solver(task)
    nb = _records(deps).get(task.get("warm") or "")
    coefs = {k: w / max(normalise[k][1] - normalise[k][0], 1e-300) for k, w in weights.items()}
    start = solver.start_from(nb if nb is not None and nb.success else None, task["x0"])
    target = solver.nlp.target(coefs)
    res = solver.backend("fallback").solve(start, target, solver.nlp.bounds())
    rec = _record(task, solver, res, "weighted_sum", next(iter(weights)), {})
    rec.weights = dict(weights)
    rec.wall_time_s = time.perf_counter() - t0
    return rec.to_dict()


def polish_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """A front point (``task["point"]``) solved again warm from each record of
    ``task["sources"]`` in order (:mod:`optdesign.studies.pareto.polish`); the best is
    kept, the point's own record on a tie. A source that meets the point's epsilon bound
    and beats it, where the local solve from it fails, becomes the point itself (a design
    the independent check passed, with the point's bound)."""
    t0 = time.perf_counter()
    records = _records(deps)
    point = records[task["point"]]
    rec, target, eps = point, point.target, dict(point.eps)
    solver = _solver(task)
    n_solves = 0
    for src in task["sources"]:
        other = records[src]
        res = solver.solve(target, eps, solver.start_from(other))
        n_solves += 1
        cand = _record(task, solver, res, "eps", target, eps)
        if not cand.success and _meets(other, eps) and other.success:
            cand = PointRecord.from_dict({**other.to_dict(), "eps": eps, "id": task["id"]})
            cand.fallback = f"kept {src}'s design: the solve from it failed ({res.status})"
        if cand.success and (
            not rec.success or improves(cand.objectives[target], rec.objectives[target])
        ):
            rec = cand
            rec.warm = src
            rec.retried = f"polished from {src}"
    if rec is not point and rec.success and len(eps) == 1:
        rec.slope = solver.slope(target, next(iter(eps)), rec)
    rec.id = task["id"]
    rec.kind = "eps"
    rec.target = target
    rec.n_solves = point.n_solves + n_solves
    rec.wall_time_s = time.perf_counter() - t0
    return rec.to_dict()


def _meets(rec: PointRecord, eps: Mapping[str, float]) -> bool:
    return all(
        rec.objectives.get(k, np.inf) <= v * (1 + OBJECTIVE_TIE_TOL) + 1e-12 for k, v in eps.items()
    )


#: kind -> task function.
TASK_KINDS = {
    "anchor-multistart": multistart_task,
    "anchor": tie_task,
    "eps": eps_task,
    "weighted_sum": weighted_task,
    "polish": polish_task,
}


def front_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """The one task function of a front's run: dispatches on ``task["kind"]``."""
    return TASK_KINDS[task["kind"]](task, deps)
