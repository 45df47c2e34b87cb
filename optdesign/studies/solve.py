"""Solve a design problem: :func:`solve`, the main job (``optdesign solve FILE``,
:func:`optdesign.solve`).

The caller's arguments arrive as one :class:`~optdesign.problem.request.SolveRequest`;
the formulation is the one it names or, for ``auto``, the first registered one that
applies with its objective (:mod:`optdesign.studies.formulation_registry`: catalogue,
robust, gp, a user's own, nlp). The NLP path the formulations share - caches,
multistart, independent check, ranges of the optimal set - is :mod:`optdesign.studies.
nlp_solve`. The best start is re-evaluated independently on the NumPy path
(:func:`optdesign.studies.verify.verify_design`); a result is ``optimal`` only when the
solver converged *and* the check passes. After the solve come the evidence the request
asks for: the diagnosis of a result with no feasible design, the sensitivities and the
ranges of an optimum.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from optdesign.errors import InputError, ProblemError
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.request import SolveRequest
from optdesign.problem.validity import is_validity, outside_ranges
from optdesign.safe_io import refuse_file_options
from optdesign.solvers.constraint_rows import constraint_rows
from optdesign.solvers.deadline import deadline, passed
from optdesign.solvers.registry import solver_hints
from optdesign.solvers.result import (
    Diagnosis,
    Globality,
    Result,
    SolutionStatus,
    TerminationCondition,
)
from optdesign.studies.diagnosis import diagnose as diagnose_result
from optdesign.studies.formulation_registry import Formulation, pick_formulation
from optdesign.studies.nlp_solve import optimal_ranges, solver_options
from optdesign.studies.verify import validity_report, verify_design


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
        status="optimal" if ok else "infeasible",
        objective=values.get(objective, float("nan")),
        design=dict(problem.fixed_values),
        solver="none",
        formulation="fixed",
        wall_time_s=time.perf_counter() - t0,
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
        globality=Globality(basis="no free variable: nothing to search"),
    )
    return result


def plan_solve(problem: DesignProblem, request: SolveRequest | None = None) -> Formulation:
    """The formulation :func:`solve` will take for ``request`` (None: the problem's
    defaults), after the checks that need no solve (a named formulation that does not
    apply, the file's options of the default NLP back-end, a combination no formulation
    honours), so that a caller can refuse before any work."""
    request = request or SolveRequest.for_problem(problem)
    formulation = pick_formulation(problem, request)
    solver_options(problem)  # the file's options of the default NLP back-end, checked
    if formulation.name == "catalogue" and problem.spec.tolerances is not None and problem.free:
        disc = ", ".join(v.name for v in problem.free if v.discrete)
        raise ProblemError(
            f"tolerances: robust design needs continuous variables, and {disc} take "
            "catalogue values; remove [tolerances] for the nominal catalogue optimum"
        )
    return formulation


def solve(problem: DesignProblem, request: SolveRequest) -> Result:
    """The optimal design of ``problem`` as ``request`` asks, with its evidence (see
    :func:`optdesign.solve`, which checks the arguments and builds the request).

    A problem with no free variable is not optimised: its fixed design is checked
    (:func:`check_fixed_design`). ``request.diagnose``: on a result with no feasible
    design, the smallest relaxation of each conflicting requirement (:mod:`optdesign.
    studies.diagnosis`). ``request.time_limit``: wall-clock seconds for the NLP
    multistart (a note says when it stopped the solve); the diagnosis and the ranges,
    which come after, are skipped with a note once it has passed.
    ``request.sensitivities``: what each requirement costs at an NLP or catalogue
    optimum (and a catalogue optimum's neighbouring items; a sweep asks for them only
    when its caller does)."""
    # Before any work and whatever the formulation: no option may read or write a file.
    refuse_file_options(request.options, "options")
    formulation = plan_solve(problem, request)
    time_limit = request.time_limit
    with deadline(time_limit):
        result = _solve_within(problem, formulation, request)
        late = passed()
    name_outside_ranges(problem, result)
    if late and ((request.diagnose and not result.success) or (request.ranges and result.success)):
        what = "the diagnosis" if not result.success else "the ranges of the optimal set"
        result.notes.append(f"{what} not computed: the time limit of {time_limit:g} s was reached")
        return result
    result = _evidence(problem, result, request)
    # the diagnosis may give a failed result its best point (a GP's, the exact NLP's)
    name_outside_ranges(problem, result)
    return result


def name_outside_ranges(problem: DesignProblem, result: Result) -> None:
    """Add to a failed result's violated rows the quantities of its best point outside
    their models' ranges of validity (:func:`optdesign.studies.verify.validity_report`),
    when the rows it has are the solver's own; a success, and a failure the independent
    check refused, name them already."""
    if result.success or not result.design or any(is_validity(r) for r in result.violated):
        return
    try:
        x = np.array([result.design[v.name] for v in problem.free], dtype=float)
        found = outside_ranges(problem, x)
    except Exception:  # the best point of a failed solve: its own rows say what failed
        return
    if found:
        result.violated = [*result.violated, *(validity_report(o) for o in found)]
        result.verified = False


def _solve_within(
    problem: DesignProblem, formulation: Formulation, request: SolveRequest
) -> Result:
    """The formulation's solve (the fixed design's check without a free variable)."""
    if not problem.free:
        return check_fixed_design(problem, request.objective)
    if request.time_limit is None or getattr(formulation, "time_limit", False):
        return formulation.solve(problem, request)
    result = formulation.solve(problem, replace(request, time_limit=None))
    result.notes.append(  # its solves are not watched
        f"time_limit: not applied (the {formulation.name} formulation runs no NLP multistart)"
    )
    return result


def _multipliers(result: Result, requested: str | None) -> bool:
    """Whether the result carries multipliers a sensitivity can read. ``result.solver``
    is the label the run reports (``scipy-slsqp-exact`` for the ``slsqp`` back-end), not
    always a registered name: the requested back-end answers then."""
    if "lam_g" not in result.raw:
        return False
    try:
        return solver_hints(result.solver).multipliers
    except InputError:
        return solver_hints(requested).multipliers


def _evidence(problem: DesignProblem, result: Result, request: SolveRequest) -> Result:
    """The diagnosis of a result with no feasible design, the ranges of an optimum."""
    solver, options = request.solver, request.options
    diagnose, ranges, sensitivities = request.diagnose, request.ranges, request.sensitivities
    if diagnose and not result.success:
        try:
            diagnose_result(problem, result, solver, options)
        except Exception as exc:  # a diagnosis, not the result: never lose the result
            text = " ".join(str(exc).split())[:300]
            result.diagnosis = Diagnosis(note=f"not computed: {type(exc).__name__}: {text}")
    continuous = result.formulation.startswith("nlp") and not any(v.discrete for v in problem.free)
    if sensitivities and result.success and continuous and _multipliers(result, solver):
        try:  # what each requirement costs, from Ipopt's multipliers
            from optdesign.studies.sensitivity import nlp_sensitivities

            result.sensitivities = nlp_sensitivities(problem, result)
        except Exception as exc:  # a report, not the result: never lose the optimum
            result.notes.append(f"sensitivities not computed: {exc}")
    if (
        sensitivities
        and result.success
        and result.formulation.startswith("catalogue")
        and _multipliers(result, solver)
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
