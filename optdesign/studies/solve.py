"""Solve a design problem: the formulation registry, the NLP multistart, the independent
check, and the ranges of the optimal set.

This is the main job of optdesign (``optdesign solve FILE``, :func:`optdesign.solve`).
The best start is re-evaluated independently on the NumPy path
(:func:`optdesign.studies.verify.verify_design`); a result is ``optimal`` only when the
solver converged *and* the check passes.

Formulations register here (:func:`register_formulation`); ``formulation="auto"`` takes
the first whose predicate holds for the problem *and the chosen objective*, in order:
catalogue (a variable takes catalogue values: never solved as continuous), robust (the
file has tolerances: never ignored), gp (the problem is a geometric program in that
objective), nlp.
"""

from __future__ import annotations

import importlib
import json
import threading
from collections import OrderedDict
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.errors import InputError, ProblemError
from optdesign.formulations.nlp import NLP, VAR, build_nlp
from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.multistart import multistart, sobol_starts
from optdesign.solvers.registry import make_solver
from optdesign.solvers.result import Diagnosis, Result, SolutionStatus, TerminationCondition
from optdesign.studies.verify import nan_notes, verify_design

# --- formulation and solver caches ------------------------------------------------------
_NLPS: OrderedDict[tuple, NLP] = OrderedDict()
_SOLVERS: OrderedDict[tuple, Any] = OrderedDict()
_CACHE_SIZE = 16

#: CasADi's symbolic layer is not thread-safe and its solvers release the GIL: two threads
#: of a threaded Dask worker building at once crashed the process. Every build holds this
#: lock, and each thread gets its own solvers (a solver object is not re-entrant); the
#: main thread's entries carry no thread id, so forked workers inherit them.
_BUILD_LOCK = threading.RLock()


def _remember(cache: OrderedDict, key: tuple, build: Callable[[], Any]) -> Any:
    owner = (
        "main" if threading.current_thread() is threading.main_thread() else threading.get_ident()
    )
    key = (owner, *key)
    with _BUILD_LOCK:
        if key in cache:
            cache.move_to_end(key)
            return cache[key]
        value = build()
        cache[key] = value
        while len(cache) > _CACHE_SIZE:
            cache.popitem(last=False)
        return value


def formulation_for(
    problem: DesignProblem,
    objectives: tuple[str, ...] | None = None,
    form: str = "epigraph",
    first_order: bool = False,
) -> NLP:
    """The NLP of ``problem`` for an objective set, built once per process and problem
    state (the cache key is the problem's token, which changes with every edit)."""
    objectives = tuple(objectives or problem.objective_names)
    key = (problem.token, objectives, form, first_order)
    return _remember(_NLPS, key, lambda: build_nlp(problem, objectives, form, first_order))


def solver_for(
    problem: DesignProblem,
    name: str = "ipopt",
    options: Mapping[str, Any] | None = None,
    objectives: tuple[str, ...] | None = None,
    form: str = "epigraph",
):
    """The back-end ``name`` of the problem's NLP, built once per process and problem
    state, shared by every start, range and front point."""
    nlp = formulation_for(problem, objectives, form)
    opts = dict(solver_options(problem, name))
    opts.update(options or {})
    key = (problem.token, nlp.fingerprint, name, json.dumps(opts, sort_keys=True, default=str))
    return _remember(_SOLVERS, key, lambda: make_solver(nlp, name, opts))


def solver_options(problem: DesignProblem, name: str) -> dict[str, Any]:
    """The problem file's own options of back-end ``name`` (``[solver] ipopt = {...}``)."""
    if name != "ipopt":
        return {}
    from optdesign.solvers.casadi_nlp import check_ipopt_options

    check_ipopt_options(problem.spec.solver.ipopt)  # before any work, naming the option
    return dict(problem.spec.solver.ipopt)


# --- the NLP path -----------------------------------------------------------------------
def start_points(problem: DesignProblem, n_starts: int, seed: int, x0=None) -> np.ndarray:
    """The multistart's starts: ``x0`` (or the declared start, else the middle of the
    bounds) first, then scrambled-Sobol points of the whole box."""
    first = problem.start() if x0 is None else np.asarray(x0, dtype=float)
    pts = [first]
    if n_starts > 1:
        pts += list(sobol_starts(problem.lower(), problem.upper(), n_starts - 1, seed))
    return np.array(pts)


def solve_nlp(
    problem: DesignProblem,
    objective: str | None = None,
    starts: int | None = None,
    seed: int | None = None,
    workers: int = 1,
    solver: str = "ipopt",
    options: Mapping[str, Any] | None = None,
    x0: np.ndarray | None = None,
    agree: int | None = None,
) -> Result:
    """Multistart NLP solve of ``problem``.

    Parameters
    ----------
    objective
        Objective to minimise (default: the problem's first).
    starts, seed
        Number of starts and Sobol seed (default: the problem file's ``[solver]``).
    workers
        Local processes for the starts.
    solver, options
        Registered back-end and its options.
    x0
        First start (default: the declared start, else the middle of the bounds).
    agree
        Stop once this many starts agree on the best value (default: the problem file's
        ``[solver] agree``, 3; 0: every start). On every shipped problem all 8 default
        starts reach the same optimum (benchmarks/README.md, "Overhead").
    """
    _no_catalogue(problem, "nlp")
    objective = objective or problem.objective_names[0]
    objectives = _objective_set(problem, objective)
    n_starts = starts if starts is not None else problem.spec.solver.starts
    seed = seed if seed is not None else problem.spec.solver.seed
    agree = agree if agree is not None else problem.spec.solver.agree
    backend = solver_for(problem, solver, options, objectives)
    target = backend.nlp.target(objective)
    pts = start_points(problem, n_starts, seed, x0)
    result = multistart(
        lambda x: backend.solve(x, target), pts, workers=workers, seed=seed, agree=agree or None
    )
    return finish(problem, result, objective)


def _objective_set(problem: DesignProblem, objective: str) -> tuple[str, ...]:
    names = problem.objective_names
    return tuple(names if objective in names else [objective, *names])


def _no_catalogue(problem: DesignProblem, name: str) -> None:
    disc = [v.name for v in problem.free if v.discrete]
    if disc:
        raise ProblemError(
            f"--formulation {name}: variables {', '.join(disc)} take catalogue values; "
            "use --formulation catalogue (or auto)"
        )


def optimal_ranges(
    problem: DesignProblem,
    result: Result,
    rel: float = 1e-6,
    solver: str = "ipopt",
    options: Mapping[str, Any] | None = None,
) -> dict[str, tuple[float, float]]:
    """Range of each free variable over the (near-)optimal set.

    Minimises and maximises each variable subject to the requirements and to the
    objective staying within ``rel`` of the optimum, with the same solver as the optimum
    (the objective's epsilon row carries the limit), started at the optimum. A wide range
    means the optimum does not fix that variable (e.g. the lead p in a backlash problem,
    or the size of a ripple-optimal linkage, since ripple is invariant when R, l, n, p
    scale together). A search that fails keeps the optimal value on its side.
    """
    objective = result.objective_name or problem.objective_names[0]
    warm = solver == "ipopt" and "lam_g" in result.raw
    if warm:
        # Primal and dual start at the optimum (benchmarks/README.md, "Overhead").
        from optdesign.solvers.casadi_nlp import IPOPT_WARM

        options = {**IPOPT_WARM, **(options or {})}
    backend = solver_for(problem, solver, options, _objective_set(problem, objective))
    nlp = backend.nlp
    limit = result.objective + rel * max(abs(result.objective), 1e-12)
    bounds = nlp.bounds(eps={objective: limit})
    x_opt = np.array([result.design[v.name] for v in problem.free])
    if warm:
        raw = result.raw
        start = nlp.start(z0=raw["z"], lam_x0=raw["lam_x"], lam_g0=raw["lam_g"])
    elif "z" in result.raw:
        start = nlp.start(z0=result.raw["z"])
    else:
        start = nlp.start(x0=x_opt)
    ranges = {}
    for var in problem.free:
        ends = []
        for sign in (1.0, -1.0):
            r = backend.solve(start, {VAR + var.name: sign}, bounds)
            ok = r.success and r.max_violation <= 1e-6
            ends.append(r.design[var.name] if ok else result.design[var.name])
        opt = result.design[var.name]
        ranges[var.name] = (float(min(*ends, opt)), float(max(*ends, opt)))
    return ranges


def finish(problem: DesignProblem, result: Result, objective: str | None = None) -> Result:
    """Check the result on the NumPy path, fill every objective and the full design."""
    result.objective_name = result.objective_name or objective or problem.objective_names[0]
    result.problem = problem.name
    result.mechanism = problem.mechanism_name
    result.problem_object = problem
    if not result.design:
        return result
    x = np.array([result.design[v.name] for v in problem.free])
    ok, violated, objectives = verify_design(problem, x)
    result.verified = ok
    result.notes += nan_notes(problem, objectives, violated)
    result.objectives = {k: float(v) for k, v in objectives.items()}
    result.design = {**problem.fixed_values, **result.design}
    if result.success and not ok:
        # The solver claims success but the independent check disagrees: not a design.
        result.status = "infeasible"
        result.termination = TerminationCondition.INFEASIBLE
        result.solution_status = SolutionStatus.INFEASIBLE
        result.violated = violated
        result.message += " (independent check failed)"
    elif not result.success and not result.violated:
        result.violated = violated
    return result


def check_fixed_design(problem: DesignProblem, objective: str | None = None) -> Result:
    """The check of a problem with no free variable: its one design, every requirement
    and objective evaluated on the NumPy path. Status ``optimal`` when it meets every
    requirement (the only feasible design is optimal), ``infeasible`` otherwise;
    formulation ``"fixed"``, solver ``"none"``."""
    import time

    from optdesign.studies.verify import constraint_rows

    t0 = time.perf_counter()
    objective = objective or problem.objective_names[0]
    if objective not in problem.objectives:
        raise InputError(
            "objective", f"unknown objective {objective!r} (known: {', '.join(problem.objectives)})"
        )
    x = np.zeros(0)
    ok, violated, objectives = verify_design(problem, x)
    active, _ = constraint_rows(problem, x)
    values = {k: float(v) for k, v in objectives.items()}
    result = Result(
        "optimal" if ok else "infeasible",
        values.get(objective, float("nan")),
        dict(problem.fixed_values),
        "none",
        "fixed",
        time.perf_counter() - t0,
        termination=TerminationCondition.CONVERGED if ok else TerminationCondition.INFEASIBLE,
        solution_status=SolutionStatus.OPTIMAL if ok else SolutionStatus.INFEASIBLE,
        message="no free variable: the fixed design checked, nothing optimised",
        objective_name=objective,
        objectives=values,
        violated=violated,
        active=active,
        max_violation=max((r.amount for r in violated), default=0.0),
        verified=ok,
        problem=problem.name,
        mechanism=problem.mechanism_name,
        problem_object=problem,
    )
    return result


# --- formulation registry ---------------------------------------------------------------
@dataclass(frozen=True)
class Formulation:
    """A way to solve a problem: ``solve(problem, **options) -> Result``;
    ``applies(problem, objective)`` says whether ``auto`` should pick it for that
    objective (None: the problem's first). Both are import paths ("module:function") or
    callables, so that listing formulations imports no solver library."""

    name: str
    solve: str | Callable[..., Result]
    applies: str | Callable[[DesignProblem, str | None], bool] | None = None
    description: str = ""

    def _load(self, ref):
        if callable(ref) or ref is None:
            return ref
        module, _, attr = ref.partition(":")
        return getattr(importlib.import_module(module), attr)

    def run(self, problem: DesignProblem, **options) -> Result:
        return self._load(self.solve)(problem, **options)

    def applies_to(self, problem: DesignProblem, objective: str | None = None) -> bool:
        fn = self._load(self.applies)
        return bool(fn(problem, objective)) if fn is not None else False


#: name -> formulation, in the order ``auto`` tries them.
FORMULATIONS: dict[str, Formulation] = {}


def register_formulation(formulation: Formulation) -> Formulation:
    """Add a formulation (``auto`` tries them in registration order, nlp last)."""
    FORMULATIONS[formulation.name] = formulation
    if "nlp" in FORMULATIONS and formulation.name != "nlp":
        FORMULATIONS["nlp"] = FORMULATIONS.pop("nlp")
    return formulation


def _solve_nlp_formulation(problem: DesignProblem, **options) -> Result:
    from optdesign.studies.reference import attach_reference

    return attach_reference(problem, solve_nlp(problem, **_pick(options, _NLP_OPTIONS)))


_NLP_OPTIONS = ("objective", "starts", "seed", "workers", "solver", "options", "x0", "agree")


def _pick(options: Mapping[str, Any], names: tuple[str, ...]) -> dict[str, Any]:
    return {k: v for k, v in options.items() if k in names and v is not None}


for _f in (
    Formulation(
        "catalogue",
        "optdesign.studies.catalogue:solve_catalogue_formulation",
        "optdesign.formulations.discrete:has_discrete",
        "branch and bound (or enumeration) over the catalogue values, NLP at each node",
    ),
    Formulation(
        "robust",
        "optdesign.studies.robust:solve_robust_formulation",
        lambda problem, objective=None: problem.spec.tolerances is not None,
        "risk measure (CVaR or mean + k std) of the objective under the tolerances",
    ),
    Formulation(
        "gp",
        "optdesign.studies.gp:solve_gp_formulation",
        "optdesign.formulations.gp:is_gp",
        "geometric program (first-order Hertz) with a dual certificate, exact NLP beside it",
    ),
    Formulation("nlp", _solve_nlp_formulation, None, "NLP (epigraph form) with Sobol multistart"),
):
    register_formulation(_f)


def choose_formulation(
    problem: DesignProblem, requested: str = "auto", objective: str | None = None
) -> str:
    """The formulation to use: the requested one, or for ``auto`` the first that applies
    to ``problem`` with ``objective`` (None: the problem's first objective)."""
    if requested != "auto":
        if requested not in FORMULATIONS:
            raise InputError(
                "formulation",
                f"unknown formulation {requested!r} (known: auto, {', '.join(FORMULATIONS)})",
            )
        return requested
    for name, f in FORMULATIONS.items():
        if f.applies_to(problem, objective):
            return name
    return "nlp"


def plan_solve(
    problem: DesignProblem, requested: str = "auto", objective: str | None = None
) -> str:
    """The formulation :func:`solve` will use for ``objective``, after the checks that need
    no solve (the file's Ipopt options, a combination no formulation honours), so that a
    caller can refuse before any work."""
    name = choose_formulation(problem, requested, objective)
    solver_options(problem, "ipopt")
    if name == "catalogue" and problem.spec.tolerances is not None and problem.free:
        disc = ", ".join(v.name for v in problem.free if v.discrete)
        raise ProblemError(
            f"tolerances: robust design needs continuous variables, and {disc} take "
            "catalogue values; remove [tolerances] for the nominal catalogue optimum"
        )
    return name


def solve(
    problem: DesignProblem,
    formulation: str = "auto",
    objective: str | None = None,
    starts: int | None = None,
    seed: int | None = None,
    workers: int = 1,
    solver: str = "ipopt",
    options: Mapping[str, Any] | None = None,
    ranges: bool = True,
    diagnose: bool = True,
    **extra: Any,
) -> Result:
    """The optimal design of ``problem`` with its evidence (see :func:`optdesign.solve`).

    A problem with no free variable is not optimised: its fixed design is checked
    (:func:`check_fixed_design`). ``diagnose``: on a result with no feasible design, the
    smallest relaxation of each conflicting requirement (:mod:`optdesign.studies.
    diagnosis`)."""
    from optdesign.safe_io import refuse_file_options

    # Before any work and whatever the formulation: no option may read or write a file.
    refuse_file_options(options, "options")
    name = plan_solve(problem, formulation, objective)
    if not problem.free:
        result = check_fixed_design(problem, objective)
    else:
        result = FORMULATIONS[name].run(
            problem,
            objective=objective,
            starts=starts,
            seed=seed,
            workers=workers,
            solver=solver,
            options=options,
            **extra,
        )
    if diagnose and not result.success:
        from optdesign.studies.diagnosis import diagnose as diagnose_result

        try:
            diagnose_result(problem, result, solver, options)
        except Exception as exc:  # a diagnosis, not the result: never lose the result
            text = " ".join(str(exc).split())[:300]
            result.diagnosis = Diagnosis(note=f"not computed: {type(exc).__name__}: {text}")
    continuous = result.formulation.startswith("nlp") and not any(v.discrete for v in problem.free)
    if ranges and result.success and continuous and result.design and "z" in result.raw:
        try:
            result.ranges = optimal_ranges(problem, result, solver=solver, options=options)
        except Exception as exc:  # a report, not the result: never lose the optimum
            result.notes.append(f"ranges of the optimal set not computed: {exc}")
    return result
