"""Solver benchmarks: configurations registry, one run per (instance, configuration),
metrics, Dolan-More performance profiles and the Markdown summary.

- :data:`CONFIGS` maps a configuration name to a :class:`Config`: how to solve a
  :class:`DesignProblem` (or trace a front) and return the common
  :class:`~optdesign.solvers.result.Result`. Configurations whose back-end is missing
  (the GP and front modules) are simply not registered.
- :func:`run_task` does one (instance, configuration) run - in a forked child with a
  hard timeout, through the runner's :class:`~optdesign.studies.runner.Isolation` (a
  hung or crashed solver becomes a failure row with its reason) -, verifies the
  design on the NumPy path (:func:`optdesign.studies.verify.verify_design`) and returns a
  JSON row. :func:`run_bench` streams the rows through
  :func:`optdesign.studies.runner.run_tasks` (JSONL store, ``resume``, local processes or
  Dask) and then writes ``bench_runs.csv``, the profiles and ``summary.md``.
- Catalogue variables: configurations on a continuous formulation (NLP, GP) enumerate the
  catalogue (one continuous solve per catalogue combination, best kept; time and
  evaluations summed); differential evolution searches catalogue indices directly.
"""

from __future__ import annotations

import copy
import csv
import ctypes
import hashlib
import io
import itertools
import json
import math
import os
import signal
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from optdesign.problem import DesignProblem, problem_from_dict
from optdesign.solvers.result import Result
from optdesign.storage import atomic_output, atomic_write_text
from optdesign.studies.instances import Instance, make_instance, suite
from optdesign.studies.verify import VERIFY_TOL, verify_design

#: A run solved an instance when it succeeded and its gap is at most this (relative).
SOLVED_GAP = 1e-4

#: Floor of the gap measure in the gap profile (a gap of 0 counts as this).
GAP_FLOOR = 1e-6

#: After this many hard timeouts of one configuration on one mechanism in one worker
#: process, its further runs on that mechanism are recorded as failures without running
#: (sqpmethod+qrqp hangs inside a QP on every crank-slider; without this the default
#: suite would spend most of its time waiting for it).
TIMEOUT_STRIKES = 2


class NotApplicable(Exception):
    """The configuration does not apply to this instance (e.g. a GP solver on a non-GP)."""


@dataclass(frozen=True)
class Config:
    """A solver configuration.

    Attributes
    ----------
    name
        Registry key (CLI ``--solvers``).
    kind
        ``"nlp"`` (continuous formulation; catalogues enumerated), ``"gp"`` (as nlp, and
        only for GP instances), ``"global"`` (NumPy path), ``"front"`` (two objectives),
        ``"debug"`` (hidden; tests).
    run
        ``run(problem, objective, time_limit) -> Result`` (front configurations:
        ``run(problem, objectives, time_limit) -> dict`` with ``F`` and ``X``).
    description, options
        What it is, for the summary; the solver options used.
    hidden
        Not part of the default selection.
    time_factor
        Multiplies the soft limit and the hard timeout (a front is a dozen solves).
    """

    name: str
    kind: str
    run: Callable[..., Any]
    description: str = ""
    options: dict[str, Any] = field(default_factory=dict)
    hidden: bool = False
    time_factor: float = 1.0


#: name -> configuration, in registration order.
CONFIGS: dict[str, Config] = {}


def register(config: Config) -> Config:
    """Add ``config`` to :data:`CONFIGS` (a later registration of a name replaces it)."""
    CONFIGS[config.name] = config
    return config


# ---------------------------------------------------------------------------------------
# Configurations
# ---------------------------------------------------------------------------------------
def _nlp_run(make_solver: Callable, form: str) -> Callable[..., Result]:
    def run(problem: DesignProblem, objective: str, time_limit: float) -> Result:
        from optdesign.formulations.nlp import build_nlp

        nlp = build_nlp(problem, objective=objective, form=form)
        solver = make_solver(nlp, time_limit)
        return solver.solve(problem.start())

    return run


def _ipopt(options: Mapping[str, Any]) -> Callable:
    def make(nlp, time_limit):
        from optdesign.solvers.casadi_nlp import CasadiNLPSolver

        opts = {**options, "max_wall_time": float(time_limit), "max_cpu_time": float(time_limit)}
        return CasadiNLPSolver(nlp, "ipopt", opts)

    return make


#: sqpmethod common options: quiet, bounded iterations, convexified exact Hessian.
SQP_BASE: dict[str, Any] = {
    "print_header": False,
    "print_iteration": False,
    "print_status": False,
    "max_iter": 200,
    "hessian_approximation": "exact",
    "convexify_strategy": "regularize",
    "error_on_fail": False,
}

#: QP solvers of sqpmethod and their quiet options (all in the casadi 3.8 wheel:
#: casadi.has_conic also lists highs, proxqp, hpipm, daqp; highs failed on the
#: convexified QPs of the shipped fork problem in a trial, so it is left out).
SQP_QPSOLVERS: dict[str, dict[str, Any]] = {
    "qrqp": {"print_iter": False, "print_header": False, "error_on_fail": False},
    "osqp": {
        "osqp": {"verbose": False, "eps_abs": 1e-9, "eps_rel": 1e-9, "max_iter": 20000},
        "error_on_fail": False,
    },
    "qpoases": {"printLevel": "none", "error_on_fail": False},
}


def _sqp(qpsol: str) -> Callable:
    def make(nlp, time_limit):
        from optdesign.solvers.casadi_nlp import CasadiNLPSolver

        # sqpmethod has no time limit option: the hard per-task timeout covers it.
        opts = {**SQP_BASE, "qpsol": qpsol, "qpsol_options": copy.deepcopy(SQP_QPSOLVERS[qpsol])}
        return CasadiNLPSolver(nlp, "sqpmethod", opts)

    return make


def _scipy(method: str, derivatives: str) -> Callable:
    def make(nlp, time_limit):
        from optdesign.solvers.scipy_nlp import ScipyNLPSolver

        return ScipyNLPSolver(nlp, method, derivatives, time_limit=time_limit)

    return make


def _de_run(problem: DesignProblem, objective: str, time_limit: float) -> Result:
    from optdesign.solvers.scipy_nlp import differential_evolution

    def evaluate(X: np.ndarray):
        ev = problem.evaluate(X)
        return np.asarray(ev["objectives"][objective], dtype=float), np.asarray(
            ev["violation"], dtype=float
        )

    catalogues = {k: v.values for k, v in enumerate(problem.free) if v.discrete}
    return differential_evolution(
        evaluate,
        problem.lower(),
        problem.upper(),
        [v.name for v in problem.free],
        catalogues=catalogues,
        seed=0,
        popsize=DE_OPTIONS["popsize"],
        maxiter=DE_OPTIONS["maxiter"],
        tol=DE_OPTIONS["tol"],
        time_limit=time_limit,
    )


#: Differential evolution settings (population = popsize * number of variables).
DE_OPTIONS: dict[str, Any] = {"popsize": 15, "maxiter": 1000, "tol": 1e-6, "polish": False}

IPOPT_EXACT = {"hessian_approximation": "exact", "linear_solver": "mumps"}
IPOPT_LBFGS = {"hessian_approximation": "limited-memory", "linear_solver": "mumps"}
IPOPT_SPRAL = {"hessian_approximation": "exact", "linear_solver": "spral"}


def _register_defaults() -> None:
    nlp_configs = [
        (
            "ipopt-exact",
            _ipopt(IPOPT_EXACT),
            "epigraph",
            "Ipopt, exact Hessian, MUMPS",
            IPOPT_EXACT,
        ),
        (
            "ipopt-lbfgs",
            _ipopt(IPOPT_LBFGS),
            "epigraph",
            "Ipopt, limited-memory Hessian, MUMPS",
            IPOPT_LBFGS,
        ),
        (
            "ipopt-spral",
            _ipopt(IPOPT_SPRAL),
            "epigraph",
            "Ipopt, exact Hessian, SPRAL",
            IPOPT_SPRAL,
        ),
        (
            "ipopt-naive",
            _ipopt(IPOPT_EXACT),
            "naive",
            "Ipopt exact, naive max/min objective",
            IPOPT_EXACT,
        ),
    ]
    for qp in SQP_QPSOLVERS:
        nlp_configs.append(
            (
                f"sqp-{qp}",
                _sqp(qp),
                "epigraph",
                f"CasADi sqpmethod, exact Hessian (regularised), {qp}",
                {**SQP_BASE, "qpsol": qp},
            )
        )
    for method, short in (("SLSQP", "slsqp"), ("trust-constr", "trust-constr")):
        for der in ("exact", "fd"):
            nlp_configs.append(
                (
                    f"{short}-{der}",
                    _scipy(method, der),
                    "epigraph",
                    f"scipy {method}, {'CasADi exact derivatives' if der == 'exact' else 'finite differences'}",
                    {"method": method, "derivatives": der},
                )
            )
    nlp_configs.append(
        (
            "slsqp-naive",
            _scipy("SLSQP", "exact"),
            "naive",
            "scipy SLSQP exact, naive max/min objective",
            {"method": "SLSQP", "derivatives": "exact"},
        )
    )
    for name, make, form, desc, opts in nlp_configs:
        register(Config(name, "nlp", _nlp_run(make, form), desc, {**opts, "form": form}))
    register(
        Config(
            "de",
            "global",
            _de_run,
            "scipy differential_evolution on the NumPy path (vectorised)",
            dict(DE_OPTIONS),
        )
    )
    register(Config("debug-crash", "debug", _debug_crash, "raises (tests)", hidden=True))
    register(Config("debug-hang", "debug", _debug_hang, "sleeps forever (tests)", hidden=True))
    register(
        Config("debug-abort", "debug", _debug_abort, "kills its own process (tests)", hidden=True)
    )
    _register_gp()
    _register_fronts()


def _debug_crash(problem, objective, time_limit):
    raise RuntimeError("deliberate crash")


def _debug_hang(problem, objective, time_limit):
    while True:
        time.sleep(1.0)


def _debug_abort(problem, objective, time_limit):
    os.kill(os.getpid(), signal.SIGKILL)


def _register_gp() -> None:
    try:
        from optdesign.formulations.gp import build_gp
        from optdesign.solvers.cvxpy_gp import solve_gp
    except ImportError:  # GP back-end not available: no GP configurations
        return

    def make(solver: str):
        def run(problem: DesignProblem, objective: str, time_limit: float) -> Result:
            gp = build_gp(problem, objective)
            if not gp.is_gp:
                raise NotApplicable("not a GP: " + gp.explain().splitlines()[0])
            options: dict[str, Any] = {}
            if solver == "SCS":
                options = {"max_iters": 100_000, "time_limit_secs": float(time_limit)}
            elif solver == "CLARABEL":
                options = {"time_limit": float(time_limit)}
            return solve_gp(gp, solver, options)

        return run

    register(
        Config("gp-clarabel", "gp", make("CLARABEL"), "cvxpy GP (first-order Hertz), Clarabel")
    )
    register(Config("gp-scs", "gp", make("SCS"), "cvxpy GP (first-order Hertz), SCS"))


#: Front settings: points of the epsilon-constraint sweep, NSGA-II population/generations.
FRONT_OPTIONS: dict[str, Any] = {"eps_points": 12, "pop_size": 40, "generations": 100}


def _register_fronts() -> None:
    try:
        from optdesign.studies import pareto
    except ImportError:
        return
    if not hasattr(pareto, "epsilon_constraint_front") or not hasattr(pareto, "nsga2_front"):
        return

    def eps(problem, objectives, time_limit):
        import tempfile

        with tempfile.TemporaryDirectory() as tmp:
            front = pareto.epsilon_constraint_front(
                problem, list(objectives), n_points=FRONT_OPTIONS["eps_points"], out=tmp
            )
        return _front_dict(front)

    def nsga(problem, objectives, time_limit):
        front = pareto.nsga2_front(
            problem,
            list(objectives),
            pop_size=FRONT_OPTIONS["pop_size"],
            generations=FRONT_OPTIONS["generations"],
            seed=0,
        )
        return _front_dict(front)

    register(
        Config(
            "front-epsilon",
            "front",
            eps,
            "epsilon-constraint front (SLSQP sweep, Ipopt tie-breaks)",
            dict(FRONT_OPTIONS),
            time_factor=10.0,
        )
    )
    register(
        Config(
            "front-nsga2",
            "front",
            nsga,
            "NSGA-II front (pymoo, NumPy path)",
            dict(FRONT_OPTIONS),
            time_factor=10.0,
        )
    )


def _front_dict(front) -> dict[str, Any]:
    X = [dict(p.design) for p in front.points]
    return {"F": front.F.tolist(), "designs": X, "iterations": None}


# ---------------------------------------------------------------------------------------
# One run
# ---------------------------------------------------------------------------------------
def _catalogue_combos(problem: DesignProblem) -> list[dict[str, float]]:
    disc = [v for v in problem.free if v.discrete]
    if not disc:
        return [{}]
    return [
        dict(zip([v.name for v in disc], c, strict=True))
        for c in itertools.product(*(v.values for v in disc))
    ]


def _solve_single(
    config: Config, inst: Instance, objective: str, time_limit: float
) -> dict[str, Any]:
    """Run a single-objective configuration; catalogues enumerated for nlp/gp kinds."""
    problem = inst.problem()
    combos = _catalogue_combos(problem) if config.kind in ("nlp", "gp") else [{}]
    t0 = time.perf_counter()
    best: tuple[float, Result, dict] | None = None
    last: tuple[Result, dict] | None = None
    iters, evals, statuses, n_na = 0, {}, [], 0
    for combo in combos:
        remaining = time_limit - (time.perf_counter() - t0)
        if remaining <= 0:
            statuses.append("time_limit")
            break
        if combo:
            data = copy.deepcopy(inst.data)
            data["variables"].update(combo)
            sub = problem_from_dict(data, source=inst.id)
        else:
            sub = problem
        try:
            r = config.run(sub, objective, remaining)
        except NotApplicable:
            n_na += 1
            continue
        statuses.append(r.status)
        iters += r.iterations or 0
        for k, v in (r.n_evals or {}).items():
            evals[k] = evals.get(k, 0) + int(v)
        if not r.design:
            continue
        x = np.array([{**r.design, **combo}[v.name] for v in problem.free], dtype=float)
        last = (r, combo)
        outside = _outside_bounds(problem, x)
        if outside:
            # The models reject such a design (e.g. a negative length): not a design.
            r.status, r.message = "failed", f"returned a design outside the bounds: {outside}"
            statuses[-1] = "failed"
            continue
        ok, _viol, objs = verify_design(problem, x)
        if r.success and ok and math.isfinite(objs[objective]):
            if best is None or objs[objective] < best[0]:
                best = (float(objs[objective]), r, combo)
    elapsed = time.perf_counter() - t0
    if n_na == len(combos):
        raise NotApplicable("not applicable to any catalogue combination")
    chosen = (best[1], best[2]) if best is not None else last
    row: dict[str, Any] = {
        "time_s": elapsed,
        "iterations": iters,
        "n_evals": evals,
        "n_subproblems": len(combos),
    }
    if chosen is None:
        row.update(
            status=statuses[-1] if statuses else "failed", reason="no design returned", design=None
        )
        return row
    r, combo = chosen
    design = {**r.design, **combo}
    if best is None:
        status = next(
            (s for s in statuses if s != "optimal"), statuses[-1] if statuses else "failed"
        )
    else:
        status = r.status
    row.update(
        status=status,
        reason=r.message,
        design={k: float(v) for k, v in design.items()},
        solver_objective=float(r.objective) if math.isfinite(r.objective) else None,
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
    for d in out["designs"]:
        x = np.array([d[v.name] for v in problem.free], dtype=float)
        ev = problem.evaluate(x)
        worst = max(worst, float(ev["violation"]))
        F.append([float(ev["objectives"][k]) for k in inst.objectives])
    ok = len(F) >= 2 and worst <= VERIFY_TOL
    return {
        "time_s": elapsed,
        "status": "optimal" if ok else "failed",
        "reason": f"{len(F)} front points" + ("" if ok else " (fewer than 2 or infeasible)"),
        "front": F,
        "violation": worst if F else None,
        "success": ok,
        "iterations": out.get("iterations"),
        "n_evals": {},
    }


def _execute(task: Mapping[str, Any]) -> dict[str, Any]:
    """The run itself (in the forked child)."""
    config = CONFIGS[task["config"]]
    inst = make_instance(task["family"], task["seed"])
    tl = float(task["time_limit"])
    if config.kind == "front":
        return _solve_front(config, inst, tl)
    objective = inst.objectives[0]
    row = _solve_single(config, inst, objective, tl)
    problem = inst.problem()
    x = None
    if row.get("design"):
        x = np.array([row["design"][v.name] for v in problem.free], dtype=float)
        if _outside_bounds(problem, x):
            x = None
    if x is not None:
        ok, violated, objs = verify_design(problem, x)
        ev = problem.evaluate(x)
        row["objective"] = float(objs[objective])
        row["violation"] = float(ev["violation"])
        row["verified"] = bool(ok)
        row["success"] = bool(row["status"] in ("optimal", "feasible") and ok)
        if row["status"] in ("optimal", "feasible") and not ok:
            row["reason"] = f"independent check failed: {violated[0].describe()}"
    else:
        row.update(objective=None, violation=None, verified=False, success=False)
    return row


_STRIKES: dict[tuple[str, str], int] = {}
_BLAS_SET = False


def _single_thread_blas() -> None:
    """One BLAS thread per process: threaded OpenBLAS on a loaded 2-core machine made a
    trust-constr QR 100x slower in a trial. (threadpoolctl is not installed.)"""
    global _BLAS_SET
    if _BLAS_SET:
        return
    _BLAS_SET = True
    try:
        with open("/proc/self/maps") as fh:
            libs = {
                line.split()[-1]
                for line in fh
                if "openblas" in line.lower() and line.split()[-1].startswith("/")
            }
    except OSError:
        return
    for lib in libs:
        try:
            handle = ctypes.CDLL(lib)
        except OSError:
            continue
        for sym in (
            "scipy_openblas_set_num_threads64_",
            "scipy_openblas_set_num_threads",
            "openblas_set_num_threads64_",
            "openblas_set_num_threads",
        ):
            fn = getattr(handle, sym, None)
            if fn is not None:
                fn(1)
                break


def _row_base(task: Mapping[str, Any]) -> dict[str, Any]:
    config = CONFIGS[task["config"]]
    inst = make_instance(task["family"], task["seed"])
    return {
        "instance": inst.id,
        "family": inst.family,
        "seed": inst.seed,
        "mechanism": inst.mechanism,
        "objective_name": "+".join(inst.objectives),
        "catalogue": any(
            isinstance(v, dict) and "catalogue" in v for v in inst.data["variables"].values()
        ),
        "config": config.name,
        "kind": config.kind,
        "applicable": True,
    }


def run_task(task: Mapping[str, Any], deps: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """One (instance, configuration) run -> JSON row.

    ``task``: ``id``, ``family``, ``seed``, ``config``, ``time_limit`` (soft, s),
    ``hard_timeout`` (s). :func:`run_bench` runs it isolated (a forked child per run,
    killed after ``hard_timeout``; a crash, hang or exception becomes the failure row
    made by :func:`failed_run`); called directly it runs in this process.
    """
    _single_thread_blas()
    base = _row_base(task)
    # The strikes are counted by failed_run in the worker; this (forked) run sees them.
    if _STRIKES.get((base["config"], base["mechanism"]), 0) >= TIMEOUT_STRIKES:
        return {
            **base,
            **_failure(
                "skipped",
                f"not run: hit the hard timeout on {TIMEOUT_STRIKES} earlier {base['mechanism']} instances in this worker",
                0.0,
            ),
        }
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


# ---------------------------------------------------------------------------------------
# Whole benchmark
# ---------------------------------------------------------------------------------------
def default_configs(include_hidden: bool = False) -> list[str]:
    """Names of the registered configurations (hidden ones on request)."""
    return [n for n, c in CONFIGS.items() if include_hidden or not c.hidden]


def make_tasks(
    instances: Sequence[Instance], configs: Sequence[str], time_limit: float, hard_timeout: float
) -> list[dict[str, Any]]:
    """One task per applicable (instance, configuration); fronts only with front configs."""
    tasks = []
    for inst in instances:
        for name in configs:
            c = CONFIGS[name]
            if (c.kind == "front") != inst.is_front and c.kind != "debug":
                continue
            if c.kind == "gp" and inst.mechanism != "fork":
                # Only the fork problems are GPs (the crank-slider ratio has sqrt(l^2-u^2));
                # the GP configuration still checks each fork instance itself.
                continue
            tasks.append(
                {
                    "id": f"{inst.id}|{name}",
                    "family": inst.family,
                    "seed": inst.seed,
                    "config": name,
                    "time_limit": time_limit * c.time_factor,
                    "hard_timeout": hard_timeout * c.time_factor,
                }
            )
    return tasks


def run_bench(
    suite_name: str = "default",
    configs: Sequence[str] | None = None,
    out: Path | str = "benchmarks/results",
    workers: int = 1,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
    time_limit: float = 1.0,
    hard_timeout: float | None = None,
    instances: Sequence[Instance] | None = None,
) -> dict[str, Any]:
    """Run the benchmark, stream rows to ``out/bench_runs.jsonl``, write CSV, profiles, summary.

    Returns
    -------
    dict
        ``rows`` (with gaps), ``summary`` (Markdown), ``paths``, ``wall_time_s``.
    """
    from optdesign.studies.runner import Isolation, read_store, run_tasks

    all_names = default_configs(include_hidden=True)
    configs = list(configs) if configs else default_configs()
    unknown = [c for c in configs if c not in all_names]
    if unknown:
        from optdesign.errors import InputError

        raise InputError(
            "--solvers",
            f"unknown configuration(s) {unknown} (known: {', '.join(default_configs())})",
        )
    hard = hard_timeout if hard_timeout is not None else time_limit + 3.0
    if instances is None:
        instances = suite(suite_name, fronts=any(CONFIGS[c].kind == "front" for c in configs))
    tasks = make_tasks(instances, configs, time_limit, hard)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    store = out / "bench_runs.jsonl"
    key = hashlib.sha256(
        json.dumps(
            {"suite": suite_name, "ids": [t["id"] for t in tasks], "tl": time_limit, "hard": hard}
        ).encode()
    ).hexdigest()[:16]
    t0 = time.perf_counter()
    if resume and store.exists():
        prev_key, _ = read_store(store)
        if prev_key is not None and prev_key != key:
            from optdesign.errors import OptDesignError

            raise OptDesignError(
                f"--resume: {store} holds another run (other suite, configurations or time limit); "
                "use the same settings or a new --out"
            )
    records = run_tasks(
        tasks,
        run_task,
        store,
        workers=workers,
        scheduler=scheduler,
        resume=resume,
        progress="bench" if progress else False,
        key=key,
        isolate=Isolation(timeout="hard_timeout", failure=failed_run, quiet=True),
    )
    wall = time.perf_counter() - t0
    # Wall time over all invocations of this run (a resumed run adds to the stored one).
    meta_path = out / "bench_meta.json"
    if resume and meta_path.exists():
        meta = json.loads(meta_path.read_text())
        if meta.get("key") == key:
            wall += float(meta.get("wall_time_s", 0.0))
    atomic_write_text(meta_path, json.dumps({"key": key, "wall_time_s": wall}))
    rows = [dict(records[t["id"]]) for t in tasks if t["id"] in records]
    rows = add_gaps(rows)
    paths = write_outputs(rows, out, configs, suite_name, wall, time_limit, hard)
    return {"rows": rows, "summary": paths["summary_text"], "paths": paths, "wall_time_s": wall}


def add_gaps(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Objective gap of every successful row to the best known value of its instance.

    Single objective: ``(f - f_best) / max(|f_best|, 1e-12)`` with ``f_best`` the least
    objective of the successful runs. Fronts: ``1 - HV / HV_best`` with one reference
    point per instance (nadir of all successful fronts + 10 % of their range). Failed
    rows get ``gap = None``.
    """
    by_inst: dict[str, list[dict]] = {}
    for r in rows:
        if r.get("applicable", True):
            by_inst.setdefault(r["instance"], []).append(r)
    for inst_rows in by_inst.values():
        ok = [r for r in inst_rows if r.get("success")]
        for r in inst_rows:
            r["gap"] = None
            r["best_known"] = None
        if not ok:
            continue
        if any("front" in r for r in ok):
            from optdesign.studies.front_metrics import hypervolume, reference_point

            allF = np.vstack([np.asarray(r["front"], dtype=float) for r in ok])
            ref = reference_point(allF)
            hv = {id(r): float(hypervolume(np.asarray(r["front"], dtype=float), ref)) for r in ok}
            best = max(hv.values())
            for r in ok:
                r["hypervolume"] = hv[id(r)]
                r["best_known"] = best
                r["gap"] = max(0.0, 1.0 - hv[id(r)] / best) if best > 0 else 0.0
            continue
        best = min(float(r["objective"]) for r in ok)
        for r in inst_rows:
            r["best_known"] = best
        for r in ok:
            r["gap"] = (float(r["objective"]) - best) / max(abs(best), 1e-12)
    return rows


# ---------------------------------------------------------------------------------------
# Profiles and tables
# ---------------------------------------------------------------------------------------
def performance_profile(table: np.ndarray, taus: np.ndarray, floor: float = 0.0) -> np.ndarray:
    """Dolan-More performance profile.

    Parameters
    ----------
    table
        (n_instances, n_configs) measure, lower is better (time, gap); ``inf`` = failed,
        ``nan`` = not applicable (left out of that configuration's denominator).
    taus
        Ratios at which to evaluate the profile (>= 1).
    floor
        Measures below ``floor`` count as ``floor`` (the gap of the best run is 0).

    Returns
    -------
    ndarray
        (n_configs, n_taus): fraction of each configuration's applicable instances whose
        ratio ``t_{p,s} / min_s t_{p,s}`` is at most tau (0 where no configuration solved
        the instance).
    """
    T = np.asarray(table, dtype=float)
    applicable = ~np.isnan(T)
    M = np.where(applicable, np.maximum(T, floor), np.inf)
    best = M.min(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(np.isfinite(best) & (best > 0), M / best, np.where(M == best, 1.0, np.inf))
    ratio = np.where(np.isfinite(M), ratio, np.inf)
    taus = np.asarray(taus, dtype=float)
    n_app = applicable.sum(axis=0)
    rho = np.zeros((T.shape[1], len(taus)))
    for s in range(T.shape[1]):
        if n_app[s] == 0:
            rho[s] = np.nan
            continue
        r = ratio[applicable[:, s], s]
        rho[s] = (r[:, None] <= taus[None, :]).sum(axis=0) / n_app[s]
    return rho


def measure_table(
    rows: Sequence[Mapping[str, Any]], configs: Sequence[str], measure: str
) -> tuple[list[str], np.ndarray]:
    """(instances, table) of ``measure`` ("time" or "gap"): inf for failures, nan where a
    configuration did not apply."""
    instances = sorted({r["instance"] for r in rows if r.get("applicable", True)})
    idx = {k: i for i, k in enumerate(instances)}
    cidx = {c: j for j, c in enumerate(configs)}
    T = np.full((len(instances), len(configs)), np.nan)
    for r in rows:
        if not r.get("applicable", True) or r["config"] not in cidx or r["instance"] not in idx:
            continue
        ok = bool(r.get("success"))
        if measure == "time":
            v = float(r["time_s"]) if ok else np.inf
        else:
            v = float(r["gap"]) if ok and r.get("gap") is not None else np.inf
        T[idx[r["instance"]], cidx[r["config"]]] = v
    return instances, T


def config_stats(
    rows: Sequence[Mapping[str, Any]], configs: Sequence[str]
) -> dict[str, dict[str, Any]]:
    """Per configuration: runs, success rate, solved rate (gap <= SOLVED_GAP), median time
    of successful runs, median gap, failure reasons."""
    stats = {}
    for c in configs:
        rs = [r for r in rows if r["config"] == c and r.get("applicable", True)]
        ok = [r for r in rs if r.get("success")]
        solved = [r for r in ok if r.get("gap") is not None and r["gap"] <= SOLVED_GAP]
        reasons: dict[str, int] = {}
        for r in rs:
            if not r.get("success"):
                st = str(r.get("status"))
                if st in ("optimal", "feasible"):
                    st = "check failed"  # the solver claimed success, the NumPy check did not
                reasons[st] = reasons.get(st, 0) + 1
        stats[c] = {
            "runs": len(rs),
            "success_rate": len(ok) / len(rs) if rs else float("nan"),
            "solved_rate": len(solved) / len(rs) if rs else float("nan"),
            "median_time_s": float(np.median([r["time_s"] for r in ok])) if ok else float("nan"),
            "median_gap": float(np.median([r["gap"] for r in ok])) if ok else float("nan"),
            "failures": reasons,
        }
    return stats


def best_config(stats: Mapping[str, Mapping[str, Any]]) -> str | None:
    """The best configuration among those run on the most instances: highest solved rate,
    ties broken by median time. (A configuration that applies to a subset only, such as
    the GP on the fork instances, is not crowned on that easier subset.)"""
    most = max((s["runs"] for s in stats.values()), default=0)
    cands = [
        (c, s)
        for c, s in stats.items()
        if s["runs"] == most and most and math.isfinite(s["median_time_s"])
    ]
    if not cands:
        return None
    return min(cands, key=lambda cs: (-round(cs[1]["solved_rate"], 9), cs[1]["median_time_s"]))[0]


def paired_time_ratio(
    rows: Sequence[Mapping[str, Any]], config: str, best: str
) -> tuple[float, int]:
    """Median over the instances both configurations solved successfully of
    time(config) / time(best), and the number of such instances."""
    t: dict[tuple[str, str], float] = {
        (r["instance"], r["config"]): float(r["time_s"])
        for r in rows
        if r.get("success") and r["config"] in (config, best)
    }
    ratios = [
        t[(i, config)] / t[(i, best)]
        for (i, c) in t
        if c == config and (i, best) in t and t[(i, best)] > 0
    ]
    return (float(np.median(ratios)) if ratios else float("nan")), len(ratios)


def stats_table(
    stats: Mapping[str, Mapping[str, Any]],
    descriptions: Mapping[str, str],
    rows: Sequence[Mapping[str, Any]],
) -> str:
    """Markdown table of :func:`config_stats`, best configuration first, with the median
    per-instance ratio of each configuration's time to the best one's."""
    best = best_config(stats)
    order = sorted(
        stats,
        key=lambda c: (
            c != best,
            -(stats[c]["solved_rate"] or 0),
            stats[c]["median_time_s"] if math.isfinite(stats[c]["median_time_s"]) else 1e9,
        ),
    )
    lines = [
        "| configuration | what | runs | success | solved (gap <= 1e-4) | median time (s) "
        "| time / best (median, paired) | median gap | failures |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for c in order:
        s = stats[c]
        if not s["runs"]:
            continue
        ratio, n_pairs = paired_time_ratio(rows, c, best) if best else (float("nan"), 0)
        fails = ", ".join(f"{k} {v}" for k, v in sorted(s["failures"].items())) or "-"
        lines.append(
            f"| {'**' + c + '**' if c == best else c} | {descriptions.get(c, '')} | {s['runs']} | "
            f"{100 * s['success_rate']:.0f} % | {100 * s['solved_rate']:.0f} % | "
            f"{_fmt(s['median_time_s'], '.3g')} | {_fmt(ratio, '.2f')} ({n_pairs}) | "
            f"{_fmt(s['median_gap'], '.1e')} | {fails} |"
        )
    return "\n".join(lines)


def _fmt(v: float, spec: str) -> str:
    return "-" if v is None or not math.isfinite(v) else format(v, spec)


CSV_FIELDS = [
    "instance",
    "family",
    "seed",
    "mechanism",
    "objective_name",
    "catalogue",
    "config",
    "kind",
    "status",
    "success",
    "objective",
    "best_known",
    "gap",
    "violation",
    "time_s",
    "iterations",
    "n_fun",
    "n_grad",
    "n_hess",
    "n_subproblems",
    "reason",
]


def eval_counts(n_evals: Mapping[str, int]) -> tuple[int | None, int | None, int | None]:
    """(function, first-derivative, Hessian) evaluation counts from a back-end's counters.

    Ipopt: nlp_f / nlp_grad_f / nlp_hess_l; sqpmethod: nlp_fg / nlp_jac_fg / nlp_hess_l;
    scipy: f / grad_f / hess_f; DE: designs evaluated. ``None`` when not reported.
    """
    if not n_evals:
        return None, None, None
    f = n_evals.get("nlp_f", n_evals.get("nlp_fg", n_evals.get("f")))
    g = n_evals.get("nlp_grad_f", n_evals.get("nlp_jac_fg", n_evals.get("grad_f")))
    h = n_evals.get("nlp_hess_l", n_evals.get("hess_f"))
    return f, g, h


def write_outputs(rows, out: Path, configs, suite_name, wall, time_limit, hard) -> dict[str, Any]:
    """bench_runs.csv, bench_profiles.png, summary.md, bench_stats.json in ``out``."""
    from optdesign.plots.profiles import plot_profiles

    out = Path(out)
    with io.StringIO() as fh:
        w = csv.DictWriter(fh, CSV_FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            f, g, h = eval_counts(r.get("n_evals") or {})
            w.writerow(
                {
                    **r,
                    "n_fun": f,
                    "n_grad": g,
                    "n_hess": h,
                    "reason": str(r.get("reason", ""))[:200],
                }
            )
        atomic_write_text(out / "bench_runs.csv", fh.getvalue())
    single = [c for c in configs if CONFIGS[c].kind not in ("front", "debug")]
    fronts = [c for c in configs if CONFIGS[c].kind == "front"]
    taus_t = np.logspace(0, 3, 200)
    taus_g = np.logspace(0, 6, 200)
    profiles = {}
    if single:
        _, Tt = measure_table([r for r in rows if r["config"] in single], single, "time")
        _, Tg = measure_table([r for r in rows if r["config"] in single], single, "gap")
        profiles["time"] = (taus_t, performance_profile(Tt, taus_t))
        profiles["gap"] = (taus_g, performance_profile(Tg, taus_g, floor=GAP_FLOOR))
        with atomic_output(out / "bench_profiles.png") as tmp:
            plot_profiles(profiles, single, tmp, gap_floor=GAP_FLOOR)
    desc = {c: CONFIGS[c].description for c in configs}
    stats_all = config_stats([r for r in rows if r["config"] in single], single)
    shipped = [r for r in rows if r["family"] == "shipped"]
    n_inst = len({r["instance"] for r in rows})
    lines = [
        f"Suite `{suite_name}`: {n_inst} instances, {len(rows)} runs, wall time {wall:.0f} s "
        f"(soft time limit {time_limit:g} s per run, hard timeout {hard:g} s). "
        "Time = wall time of one run from the problem to the answer (formulation, solver "
        "set-up and solve; catalogue combinations summed), median over successful runs. "
        "Success = the solver reports success and the independent NumPy check passes "
        f"(violation <= {VERIFY_TOL:g}); solved = success with gap <= {SOLVED_GAP:g} to the "
        "best value any configuration found. Best configuration (bold) = among those run "
        "on every instance of the table, the highest solved rate, then the lowest median "
        "time; 'time / best' = median over the instances both solved of the per-instance "
        "time ratio (number of such instances in brackets).",
        "",
        "### All single-objective instances",
        "",
        stats_table(stats_all, desc, rows),
    ]
    if shipped:
        lines += [
            "",
            "### Shipped problems (problems/*.toml)",
            "",
            stats_table(
                config_stats([r for r in shipped if r["config"] in single], single), desc, shipped
            ),
        ]
        lines += ["", _shipped_table(shipped, single)]
    if fronts:
        st = config_stats([r for r in rows if r["config"] in fronts], fronts)
        lines += [
            "",
            "### Pareto-front instances (gap = 1 - hypervolume / best hypervolume)",
            "",
            stats_table(st, desc, rows),
        ]
    text = "\n".join(lines) + "\n"
    atomic_write_text(out / "summary.md", text)
    atomic_write_text(
        out / "bench_stats.json",
        json.dumps(
            {"all": stats_all, "wall_time_s": wall, "suite": suite_name}, indent=1, default=str
        ),
    )
    return {
        "csv": out / "bench_runs.csv",
        "profiles": out / "bench_profiles.png",
        "summary": out / "summary.md",
        "summary_text": text,
    }


def _shipped_table(rows, configs) -> str:
    insts = sorted({r["instance"] for r in rows})
    head = "| configuration | " + " | ".join(f"{i}: time (s) / gap" for i in insts) + " |"
    lines = [head, "|---|" + "---|" * len(insts)]
    by = {(r["instance"], r["config"]): r for r in rows}
    for c in configs:
        cells = []
        for i in insts:
            r = by.get((i, c))
            if r is None or not r.get("applicable", True):
                cells.append("n/a")
            elif not r.get("success"):
                cells.append(f"{r['status']}")
            else:
                cells.append(f"{r['time_s']:.3g} / {r['gap']:.1e}")
        lines.append(f"| {c} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


#: Markers of the generated block in benchmarks/README.md.
README_BEGIN = "<!-- bench-summary:begin (generated by optdesign bench) -->"
README_END = "<!-- bench-summary:end -->"


def update_readme(readme: Path, summary: str) -> bool:
    """Replace the text between the markers of ``readme`` by ``summary``; False if the
    markers are absent."""
    text = readme.read_text()
    a, b = text.find(README_BEGIN), text.find(README_END)
    if a < 0 or b < a:
        return False
    atomic_write_text(readme, text[: a + len(README_BEGIN)] + "\n" + summary + text[b:])
    return True


# Registered at import so that every process (forked, spawned or a Dask worker) sees the
# same registry.
_register_defaults()
