"""One benchmark run, sandboxed: an (instance, configuration) pair solved in a forked child
with a hard timeout (the runner's isolation: a hung or crashed solver becomes a failure
row with its reason), its design verified on the NumPy path, and a JSON row returned.

Catalogue variables: configurations on a continuous formulation (NLP, GP) enumerate the
catalogue (one continuous solve per combination, best kept; time and evaluations
summed); differential evolution searches catalogue indices directly.
"""

from __future__ import annotations

import copy
import itertools
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.errors import ProblemError
from optdesign.formulations.verify import verify_design
from optdesign.problem import DesignProblem, problem_from_dict
from optdesign.solvers.blas import one_blas_thread
from optdesign.solvers.result import Result
from optdesign.solvers.solved_point import SOLVED_STATUSES, is_success
from optdesign.studies.bench.configs import Config, NotApplicable, get_config
from optdesign.studies.bench.instances import Instance, make_instance
from optdesign.studies.bench.rows import BenchRow, BenchRowError, is_number
from optdesign.tolerances import FEASIBILITY_TOL

#: After this many hard timeouts of one configuration on one mechanism in one worker
#: process, its further runs on that mechanism are recorded as failures without running
#: (sqpmethod+qrqp hangs inside a QP on every crank-slider; without this the default
#: suite would spend most of its time waiting for it).
TIMEOUT_STRIKES = 2


def task_instance(task: Mapping[str, Any]) -> Instance:
    """The instance of a task: generated from (family, seed), or the user's problem."""
    if task.get("problem") is not None:
        return Instance("user", int(task["seed"]), {}, task["problem"])
    return make_instance(task["family"], task["seed"])


def _catalogue_combos(problem: DesignProblem) -> list[dict[str, float]]:
    disc = [v for v in problem.free if v.discrete]
    if not disc:
        return [{}]
    return [
        dict(zip([v.name for v in disc], c, strict=True))
        for c in itertools.product(*(v.values for v in disc))
    ]


@dataclass
class Attempt:
    """One continuous solve of a run (a catalogue combination, or the run itself) and what
    the independent check made of the design it returned.

    ``why`` is empty when the design passed: inside the bounds, every requirement met on
    the NumPy path, every objective finite and within its physical range
    (:meth:`~optdesign.problem.objectives.ObjectiveInfo.range_problem`); ``value`` and
    ``violation`` are then the objective and the largest violation there, on the NumPy
    path (never the solver's own value)."""

    result: Result
    combo: dict[str, float]
    design: dict[str, float] | None = None
    value: float | None = None
    violation: float | None = None
    why: str = "no design returned"

    @property
    def verified(self) -> bool:
        return self.design is not None and not self.why

    @property
    def solved(self) -> bool:
        """A solved status at a design the independent check confirmed."""
        return self.verified and is_success(self.result.status, True)


def check_design(problem: DesignProblem, objective: str, x: np.ndarray) -> tuple[str, Any, Any]:
    """``(why, value, violation)`` of the free-variable vector ``x``: ``why`` is ``""`` when
    ``x`` lies in the bounds, meets every requirement on the NumPy path and every objective
    there is a finite number within its physical range; ``value`` is then ``objective`` on
    the NumPy path and ``violation`` the largest (relative) violation, else both None."""
    outside = _outside_bounds(problem, x)
    if outside:
        return f"returned a design outside the bounds: {outside}", None, None
    ok, violated, objs = verify_design(problem, x)
    if not ok:
        return f"independent check failed: {violated[0].describe()}", None, None
    why = objective_range_problem(problem, objs, objective)
    if why:
        return f"independent check failed: {why}", None, None
    return "", float(objs[objective]), float(problem.evaluate(x).violation)


def objective_range_problem(
    problem: DesignProblem, values: Mapping[str, Any], first: str | None = None
) -> str:
    """Why one of the objective ``values`` (name -> value at a design, on the NumPy path)
    cannot be a result, or ``""``: NaN, infinite, or outside the physical range its
    declaration gives (``first`` is checked first: the objective minimised)."""
    infos = problem.objectives
    for name in sorted(values, key=lambda k: k != first):
        info = infos.get(name)
        if info is not None:
            why = info.range_problem(values[name])
        else:
            why = "" if _finite(values[name]) else f"{name} is {values[name]!r}, not finite"
        if why:
            return why
    return ""


def _finite(v: Any) -> bool:
    return is_number(v) and math.isfinite(v)


def _solve_single(
    config: Config, inst: Instance, objective: str, time_limit: float
) -> dict[str, Any]:
    """Run a single-objective configuration; catalogues enumerated for nlp/gp kinds.

    The row holds one design, checked on the NumPy path (:func:`check_design`): the best
    solved one (an enumeration cut short by the time limit: status ``feasible``, the best
    combination found is not proven best), else the best verified point of an unfinished
    solve (time or iteration limit: its status, not a success), else none - the objective
    of a row is never the solver's own value, nor one of a design the check refused.
    """
    problem = inst.problem()
    combos = _catalogue_combos(problem) if config.kind in ("nlp", "gp") else [{}]
    t0 = time.perf_counter()
    attempts: list[Attempt] = []
    iters, evals, n_na, n_items, cut = 0, {}, 0, 0, False
    for combo in combos:
        remaining = time_limit - (time.perf_counter() - t0)
        if remaining <= 0:
            cut = True
            break
        try:
            sub = _fix(inst, problem, combo) if combo else problem
        except ProblemError:
            # e.g. a screw catalogue's (d0, p): not every pair of its values is an item
            n_items += 1
            continue
        try:
            r = config.run(sub, objective, remaining)
        except NotApplicable:
            n_na += 1
            continue
        iters += r.iterations or 0
        for k, v in (r.n_evals or {}).items():
            evals[k] = evals.get(k, 0) + int(v)
        attempt = Attempt(r, combo)
        attempts.append(attempt)
        if not r.design:
            continue
        design = {**r.design, **combo}
        x = np.array([design[v.name] for v in problem.free], dtype=float)
        attempt.design = {k: float(v) for k, v in design.items()}
        attempt.why, attempt.value, attempt.violation = check_design(problem, objective, x)
        if attempt.why.startswith("returned a design outside"):
            # The models reject such a design (e.g. a negative length): not a design.
            r.status = "failed"
    elapsed = time.perf_counter() - t0
    if n_na + n_items == len(combos) and combos:
        if n_na:
            raise NotApplicable("not applicable to any catalogue combination")
        raise ProblemError("no catalogue combination is an item of its catalogue")
    row: dict[str, Any] = {
        "time_s": elapsed,
        "iterations": iters,
        "n_evals": evals,
        "n_subproblems": len(combos),
    }
    solved = [a for a in attempts if a.solved]
    verified = [a for a in attempts if a.verified]
    tried = f"{len(attempts)} of {len(combos) - n_items} catalogue combinations"
    if solved:
        chosen = min(solved, key=lambda a: a.value)
        status, reason = chosen.result.status, chosen.result.message
        if cut:
            status = "feasible"
            reason = f"time limit reached after {tried}: the best of them ({reason})"
    elif verified:
        chosen = min(verified, key=lambda a: a.value)
        status = chosen.result.status
        reason = f"{chosen.result.message}; not solved: its best verified point"
    else:
        last = attempts[-1] if attempts else None
        status = "time_limit" if cut or last is None else last.result.status
        why = last.why if last is not None else "no combination solved"
        message = last.result.message if last is not None else f"time limit after {tried}"
        row.update(
            status=status,
            reason=f"{message}; no verified point: {why}" if message else why,
            design=None,
            solver_objective=None,
            objective=None,
            violation=None,
            verified=False,
            success=False,
        )
        return row
    success = is_success(status, True)
    r = chosen.result
    row.update(
        status=status,
        reason=reason,
        design=chosen.design,
        # the solver's own value only where it finished at a confirmed design (an
        # unfinished iterate's epigraph variable is no objective)
        solver_objective=float(r.objective) if success and _finite(r.objective) else None,
        objective=chosen.value,
        violation=chosen.violation,
        verified=True,
        success=success,
    )
    return row


def _outside_bounds(problem: DesignProblem, x: np.ndarray) -> str:
    """'' if ``x`` lies in the bounds (to 1e-9 of the span), else the first offender."""
    lo, hi = problem.lower(), problem.upper()
    tol = 1e-9 * np.maximum(hi - lo, 1.0)
    for k, v in enumerate(problem.free):
        if not lo[k] - tol[k] <= x[k] <= hi[k] + tol[k]:
            return f"{v.name} = {x[k]:.6g} {v.unit} not in [{lo[k]:g}, {hi[k]:g}]".replace(
                " ]", "]"
            )
    return ""


def _solve_front(config: Config, inst: Instance, time_limit: float) -> dict[str, Any]:
    problem = inst.problem()
    t0 = time.perf_counter()
    out = config.run(problem, inst.objectives, time_limit)
    elapsed = time.perf_counter() - t0
    worst = 0.0
    F = []
    why = ""
    for d in out["designs"]:
        x = np.array([d[v.name] for v in problem.free], dtype=float)
        ev = problem.evaluate(x)
        v = float(ev.violation)
        worst = max(worst, v) if not math.isnan(v) else math.inf
        values = {k: ev.objectives[k] for k in inst.objectives}
        why = why or objective_range_problem(problem, values)
        F.append([float(values[k]) for k in inst.objectives])
    ok = len(F) >= 2 and worst <= FEASIBILITY_TOL and not why
    if ok:
        reason = f"{len(F)} front points"
    elif why:
        reason = f"{len(F)} front points, one not a result: {why}"
    else:
        reason = f"{len(F)} front points (fewer than 2 or infeasible)"
    return {
        "time_s": elapsed,
        "status": "optimal" if ok else "failed",
        "reason": reason,
        # JSON has no NaN: a value that is not a finite number is stored as null
        "front": [[v if math.isfinite(v) else None for v in f] for f in F],
        "violation": worst if F and math.isfinite(worst) else None,
        "success": ok,
        "iterations": out.get("iterations"),
        "n_evals": {},
    }


def _execute(task: Mapping[str, Any]) -> dict[str, Any]:
    """The run itself (in the forked child)."""
    config = get_config(task["config"])
    inst = task_instance(task)
    tl = float(task["time_limit"])
    if config.kind == "front":
        return _solve_front(config, inst, tl)
    return _solve_single(config, inst, inst.objectives[0], tl)


_STRIKES: dict[tuple[str, str], int] = {}


def _row_base(task: Mapping[str, Any]) -> dict[str, Any]:
    config = get_config(task["config"])
    inst = task_instance(task)
    return {
        "instance": inst.id,
        "family": inst.family,
        "seed": inst.seed,
        "mechanism": inst.mechanism,
        "objective_name": "+".join(inst.objectives),
        "catalogue": any(v.discrete for v in inst.problem().free),
        "config": config.name,
        "kind": config.kind,
        "applicable": True,
    }


def run_task(task: Mapping[str, Any], deps: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """One (instance, configuration) run -> JSON row.

    ``task``: ``id``, ``family``, ``seed`` (or ``problem``), ``config``, ``time_limit``
    (soft, s), ``hard_timeout`` (s). :func:`~optdesign.studies.bench.run_bench` runs it
    isolated (:data:`ISOLATION`: a forked child per run, killed after ``hard_timeout``; a
    crash, hang or exception becomes the row of :func:`failed_run`); called directly it
    runs in this process.
    """
    # One BLAS thread (threaded OpenBLAS on a loaded 2-core machine made a trust-constr QR
    # 100x slower in a trial), the caller's own count restored when called directly.
    with one_blas_thread():
        return _run_task(task)


def _run_task(task: Mapping[str, Any]) -> dict[str, Any]:
    base = _row_base(task)
    # The strikes are counted by failed_run in the worker; this (forked) run sees them.
    if _STRIKES.get((base["config"], base["mechanism"]), 0) >= TIMEOUT_STRIKES:
        reason = (
            f"not run: hit the hard timeout on {TIMEOUT_STRIKES} earlier "
            f"{base['mechanism']} instances in this worker"
        )
        return {**base, **_failure("skipped", reason, 0.0)}
    return {**base, **_execute_or_na(task)}


def failed_run(task: Mapping[str, Any], kind: str, reason: str, wall_s: float) -> dict[str, Any]:
    """The row of a run that timed out, crashed or raised (in the worker, not the child)."""
    base = _row_base(task)
    if kind == "timeout":
        key = (base["config"], base["mechanism"])
        _STRIKES[key] = _STRIKES.get(key, 0) + 1
    return {**base, **_failure(kind, reason, wall_s)}


def _execute_or_na(task):
    try:
        return _execute(task)
    except NotApplicable as exc:
        return {
            "applicable": False,
            "status": "n/a",
            "reason": str(exc),
            "success": False,
            "time_s": 0.0,
        }


def _failure(kind: str, reason: str, wall: float) -> dict[str, Any]:
    return {
        "status": kind,
        "reason": reason,
        "success": False,
        "time_s": wall,
        "objective": None,
        "violation": None,
        "iterations": None,
        "n_evals": {},
    }


def _fix(inst: Instance, problem: DesignProblem, combo: Mapping[str, float]) -> DesignProblem:
    """The problem with the catalogue variables of ``combo`` fixed."""
    if inst.given is None:
        data = copy.deepcopy(inst.data)
        data["variables"].update(combo)
        return problem_from_dict(data, source=inst.id)
    data = problem.spec.model_dump(mode="python")
    data["variables"] = {**data["variables"], **{k: float(v) for k, v in combo.items()}}
    from optdesign.problem.spec_validation import validate_spec
    from optdesign.problem.variables import parse_variable, variable_table

    spec = validate_spec(data, problem.mechanism, inst.id, internal=True)
    table = variable_table(problem.mechanism)
    variables = [
        parse_variable(k, v, table[k], problem.mechanism_name) for k, v in spec.variables.items()
    ]
    sub = DesignProblem(spec, variables, problem.mechanism)
    for info in problem.objectives.values():
        sub._objectives.setdefault(info.name, info)
    sub._constraints = list(problem.user_constraints)
    return sub


# --- trusting a stored row ---------------------------------------------------------------
def row_check(tasks: list[Mapping[str, Any]]):
    """``check(row)`` for the runner's resume: why a stored benchmark row cannot be
    trusted (see :func:`row_problem`); each instance's problem is built once."""
    by_id = {t["id"]: t for t in tasks}
    problems: dict[str, DesignProblem] = {}

    def check(row: Mapping[str, Any]) -> str | None:
        task = by_id.get(row["id"])
        if task is None:
            return None  # not a run of this benchmark: never read
        return row_problem(task, row, problems)

    return check


def row_problem(
    task: Mapping[str, Any], row: Mapping[str, Any], problems: dict[str, DesignProblem]
) -> str | None:
    """Why a stored row of ``task`` cannot be trusted, or None.

    Every row must name its configuration and be a :class:`BenchRow` (its identity, a
    status, a success flag and a finite time; :meth:`BenchRow.from_dict`). A successful
    single-objective row must hold a finite objective and a design inside the instance's
    bounds that the independent check confirms, with the same objective value (a resumed
    benchmark recomputes nothing it trusts); a successful front row finite objective
    vectors and a violation within the check's tolerance.
    """
    if not isinstance(row, Mapping) or row.get("config") != task["config"]:
        return f"is not a run of configuration {task['config']!r}"
    try:
        r = BenchRow.from_dict(row)
    except BenchRowError as exc:
        return str(exc)
    if not r.success:
        return None
    if r.status not in SOLVED_STATUSES:
        return f"counts as a success with status {r.status!r}"
    inst = task_instance(task)
    if inst.id not in problems:
        problems[inst.id] = inst.problem()
    problem = problems[inst.id]
    if get_config(task["config"]).kind == "front":
        return _front_row_problem(r, problem, inst.objectives)
    objective = inst.objectives[0]
    design = r.design
    if r.verified is not True or not isinstance(design, dict):
        return "counts as a success without a design confirmed by the independent check"
    if not (is_number(r.objective) and math.isfinite(r.objective)):
        return f"counts as a success with objective {r.objective!r}"
    missing = [v.name for v in problem.free if not is_number(design.get(v.name))]
    if missing:
        return f"has no value of {missing[0]} in its design"
    x = np.array([design[v.name] for v in problem.free], dtype=float)
    if not np.isfinite(x).all():
        return "has a design that is not finite"
    outside = _outside_bounds(problem, x)
    if outside:
        return f"has a design outside the bounds: {outside}"
    ok, violated, objs = verify_design(problem, x)
    if not ok:
        return f"has a design that violates {violated[0].describe()}"
    why = objective_range_problem(problem, {**objs, objective: r.objective}, objective)
    if why:
        return f"counts as a success where {why}"
    value = float(objs[objective])
    if abs(r.objective - value) > 1e-7 * max(abs(value), 1e-12):
        return f"has objective {r.objective:.10g}, but its design gives {value:.10g}"
    return None


def _front_row_problem(
    row: BenchRow, problem: DesignProblem, objectives: tuple[str, ...]
) -> str | None:
    front = row.front
    if not (
        isinstance(front, list)
        and len(front) >= 2
        and all(
            isinstance(p, list) and p and all(is_number(v) and math.isfinite(v) for v in p)
            for p in front
        )
    ):
        return "counts as a success without at least two finite front points"
    v = row.violation
    if not (is_number(v) and 0 <= v <= FEASIBILITY_TOL):
        return f"counts as a success with violation {v!r}"
    for point in front:
        why = objective_range_problem(problem, dict(zip(objectives, point, strict=False)))
        if why:
            return f"counts as a success where {why}"
    return None
