"""Solve a design problem: the formulation registry and :func:`solve`, the main job (the
NLP path it shares with the other formulations and studies - caches, multistart,
independent check, ranges of the optimal set - is :mod:`optdesign.studies.nlp_solve`).

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
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.errors import InputError, ProblemError
from optdesign.problem.design_problem import DesignProblem
from optdesign.safe_io import refuse_file_options
from optdesign.solvers.deadline import deadline, passed
from optdesign.solvers.registry import solver_hints
from optdesign.solvers.result import Diagnosis, Result, SolutionStatus, TerminationCondition
from optdesign.studies.diagnosis import diagnose as diagnose_result
from optdesign.studies.nlp_solve import optimal_ranges, solve_nlp, solver_options
from optdesign.studies.reference import attach_reference
from optdesign.studies.verify import constraint_rows, verify_design


def check_fixed_design(problem: DesignProblem, objective: str | None = None) -> Result:
    """The check of a problem with no free variable: its one design, every requirement
    and objective evaluated on the NumPy path. Status ``optimal`` when it meets every
    requirement (the only feasible design is optimal), ``infeasible`` otherwise;
    formulation ``"fixed"``, solver ``"none"``."""
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
    return attach_reference(problem, solve_nlp(problem, **_pick(options, _NLP_OPTIONS)))


_NLP_OPTIONS = (
    "objective",
    "starts",
    "seed",
    "workers",
    "solver",
    "options",
    "x0",
    "agree",
    "time_limit",
)


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
    solver_options(problem)  # the file's options of the default NLP back-end, checked
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
    solver: str | None = None,
    options: Mapping[str, Any] | None = None,
    ranges: bool = True,
    diagnose: bool = True,
    time_limit: float | None = None,
    sensitivities: bool = True,
    **extra: Any,
) -> Result:
    """The optimal design of ``problem`` with its evidence (see :func:`optdesign.solve`).

    A problem with no free variable is not optimised: its fixed design is checked
    (:func:`check_fixed_design`). ``diagnose``: on a result with no feasible design, the
    smallest relaxation of each conflicting requirement (:mod:`optdesign.studies.
    diagnosis`). ``time_limit``: wall-clock seconds for the NLP multistart (a note says
    when it stopped the solve); the diagnosis and the ranges, which come after, are
    skipped with a note once it has passed. ``sensitivities``: what each requirement costs
    at an NLP or catalogue optimum (and a catalogue optimum's neighbouring items; a sweep
    asks for them only when its caller does)."""
    # Before any work and whatever the formulation: no option may read or write a file.
    refuse_file_options(options, "options")
    name = plan_solve(problem, formulation, objective)
    with deadline(time_limit):
        result = _solve_within(
            problem, name, objective, starts, seed, workers, solver, options, time_limit, extra
        )
        late = passed()
    if late and ((diagnose and not result.success) or (ranges and result.success)):
        what = "the diagnosis" if not result.success else "the ranges of the optimal set"
        result.notes.append(f"{what} not computed: the time limit of {time_limit:g} s was reached")
        return result
    return _evidence(problem, result, solver, options, ranges, diagnose, sensitivities)


def _solve_within(
    problem: DesignProblem,
    name: str,
    objective: str | None,
    starts: int | None,
    seed: int | None,
    workers: int,
    solver: str | None,
    options: Mapping[str, Any] | None,
    time_limit: float | None,
    extra: dict[str, Any],
) -> Result:
    """The formulation's solve (the fixed design's check without a free variable)."""
    if time_limit is not None and name == "nlp":
        extra = {**extra, "time_limit": time_limit}
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
        if time_limit is not None and name != "nlp":  # its solves are not watched
            result.notes.append(
                f"time_limit: not applied (the {name} formulation runs no NLP multistart)"
            )
    return result


def _evidence(
    problem, result: Result, solver, options, ranges: bool, diagnose: bool, sensitivities: bool
) -> Result:
    """The diagnosis of a result with no feasible design, the ranges of an optimum."""
    if diagnose and not result.success:
        try:
            diagnose_result(problem, result, solver, options)
        except Exception as exc:  # a diagnosis, not the result: never lose the result
            text = " ".join(str(exc).split())[:300]
            result.diagnosis = Diagnosis(note=f"not computed: {type(exc).__name__}: {text}")
    continuous = result.formulation.startswith("nlp") and not any(v.discrete for v in problem.free)
    if (
        sensitivities
        and result.success
        and continuous
        and solver_hints(result.solver).multipliers
        and "lam_g" in result.raw
    ):
        try:  # what each requirement costs, from Ipopt's multipliers
            from optdesign.studies.sensitivity import nlp_sensitivities

            result.sensitivities = nlp_sensitivities(problem, result)
        except Exception as exc:  # a report, not the result: never lose the optimum
            result.notes.append(f"sensitivities not computed: {exc}")
    if (
        sensitivities
        and result.success
        and result.formulation.startswith("catalogue")
        and solver_hints(result.solver).multipliers
        and "lam_g" in result.raw
    ):
        try:  # the continuous part at the chosen items, and the neighbouring items
            from optdesign.studies.catalogue_sensitivity import catalogue_sensitivities

            # a MINLP back-end only picked the items: the default NLP back-end solved
            # them (optdesign.studies.catalogue_minlp), and re-solves their neighbours
            minlp = solver_hints(solver).minlp is not None
            result.sensitivities, result.item_steps = catalogue_sensitivities(
                problem, result, None if minlp else solver, None if minlp else options
            )
        except Exception as exc:  # a report, not the result: never lose the optimum
            result.notes.append(f"sensitivities not computed: {exc}")
    if ranges and result.success and continuous and result.design and "z" in result.raw:
        try:
            result.ranges = optimal_ranges(problem, result, solver=solver, options=options)
        except Exception as exc:  # a report, not the result: never lose the optimum
            result.notes.append(f"ranges of the optimal set not computed: {exc}")
    return result
