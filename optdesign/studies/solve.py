"""Solve a design problem: :func:`solve`, the main job (``optdesign solve FILE``,
:func:`optdesign.solve`).

The caller's arguments arrive as one :class:`~optdesign.problem.request.SolveRequest`;
the formulation is the one it names or, for ``auto``, the first registered one that
applies with its objective (:mod:`optdesign.formulations.registry`: catalogue, robust,
gp, a user's own, nlp). The formulation solves (a problem with no free variable is
checked instead: :mod:`optdesign.formulations.fixed`); a result is ``optimal`` only when
the solver converged *and* the independent check on the NumPy path passes. After the
solve comes the evidence the request asks for, each formulation's own (its ``diagnose``
and ``sensitivities``): the diagnosis of a result with no feasible design, the
sensitivities and the ranges of an optimum.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from optdesign.formulations.fixed import FIXED_DESIGN, check_fixed_design
from optdesign.formulations.nlp.solve import solver_options
from optdesign.formulations.protocol import (
    Formulation,
    check_with,
    diagnose_with,
    sensitivities_with,
)
from optdesign.formulations.registry import pick_formulation
from optdesign.formulations.verify import validity_report
from optdesign.models.impossibility import Impossibility
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.necessary import impossibilities
from optdesign.problem.request import SolveRequest
from optdesign.problem.validity import is_validity, outside_ranges
from optdesign.safe_io import refuse_file_options
from optdesign.solvers.deadline import deadline, passed
from optdesign.solvers.result import (
    Diagnosis,
    Globality,
    Result,
    SolutionStatus,
    TerminationCondition,
)

__all__ = ["check_fixed_design", "name_outside_ranges", "plan_solve", "solve"]


def plan_solve(problem: DesignProblem, request: SolveRequest | None = None) -> Formulation:
    """The formulation :func:`solve` will take for ``request`` (None: the problem's
    defaults), after the checks that need no solve (a named formulation that does not
    apply, the file's options of the default NLP back-end, a combination no formulation
    honours), so that a caller can refuse before any work."""
    request = request or SolveRequest.for_problem(problem)
    formulation = pick_formulation(problem, request)
    solver_options(problem)  # the file's options of the default NLP back-end, checked
    check_with(formulation, problem, request)
    return formulation


def solve(problem: DesignProblem, request: SolveRequest) -> Result:
    """The optimal design of ``problem`` as ``request`` asks, with its evidence (see
    :func:`optdesign.solve`, which checks the arguments and builds the request).

    A problem with no free variable is not optimised: its fixed design is checked
    (:func:`check_fixed_design`). ``request.diagnose``: on a result with no feasible
    design, the smallest relaxation of each conflicting requirement (the formulation's
    ``diagnose``). ``request.time_limit``: wall-clock seconds for the NLP
    multistart (a note says when it stopped the solve); the diagnosis and the ranges,
    which come after, are skipped with a note once it has passed.
    ``request.sensitivities``: what each requirement costs at an NLP or catalogue
    optimum (and a catalogue optimum's neighbouring items; a sweep asks for them only
    when its caller does)."""
    # Before any work and whatever the formulation: no option may read or write a file.
    refuse_file_options(request.options, "options")
    formulation = plan_solve(problem, request)
    t0 = time.perf_counter()
    proofs = impossibilities(problem) if problem.free else []
    if proofs:  # the mechanism's own geometry rules out every design: no search
        result = impossible_result(problem, formulation.name, proofs, request.objective)
        result.wall_time_s = time.perf_counter() - t0
        return result
    time_limit = request.time_limit
    with deadline(time_limit):
        result = _solve_within(problem, formulation, request)
        late = passed()
    name_outside_ranges(problem, result)
    if late and ((request.diagnose and not result.success) or (request.ranges and result.success)):
        what = "the diagnosis" if not result.success else "the ranges of the optimal set"
        result.notes.append(f"{what} not computed: the time limit of {time_limit:g} s was reached")
        return result
    result = _evidence(problem, formulation if problem.free else FIXED_DESIGN, result, request)
    # the diagnosis may give a failed result its best point (a GP's, the exact NLP's)
    name_outside_ranges(problem, result)
    return result


def impossible_result(
    problem: DesignProblem,
    formulation: str,
    proofs: list[Impossibility],
    objective: str | None = None,
) -> Result:
    """The verdict of a problem whose mechanism proves, before any solve, that no design
    within the bounds meets the requirements the ``proofs`` name: infeasible, with no
    design, the proofs in its diagnosis (``objective``: the one asked, None: the
    problem's first)."""
    label = problem.mechanism.label()
    return Result(
        status="infeasible",
        objective=float("nan"),
        solver="none",
        formulation=formulation,
        termination=TerminationCondition.INFEASIBLE,
        solution_status=SolutionStatus.NO_SOLUTION,
        message=f"no {label} within the bounds can meet {_names(proofs)} together (proved "
        "by a closed form of its geometry: no solve was run)",
        objective_name=objective or problem.objective_names[0],
        problem=problem.name,
        mechanism=problem.mechanism_name,
        problem_object=problem,
        diagnosis=Diagnosis(
            basis=f"a closed form of the {label}'s geometry, before any solve",
            impossible=list(proofs),
        ),
        globality=Globality(basis="proved infeasible by a closed form: nothing to search"),
    )


def _names(proofs: list[Impossibility]) -> str:
    names = list(dict.fromkeys(n for p in proofs for n in p.requirements))
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"


def name_outside_ranges(problem: DesignProblem, result: Result) -> None:
    """Add to a failed result's violated rows the quantities of its best point outside
    their models' ranges of validity (:func:`optdesign.formulations.verify.validity_report`),
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


def _evidence(
    problem: DesignProblem, formulation: Formulation, result: Result, request: SolveRequest
) -> Result:
    """The formulation's evidence, as ``request`` asks: the diagnosis of a result with no
    feasible design; the sensitivities (and ranges) of an optimum."""
    if request.diagnose and not result.success:
        try:
            diagnose_with(formulation)(problem, result, request)
        except Exception as exc:  # a diagnosis, not the result: never lose the result
            text = " ".join(str(exc).split())[:300]
            result.diagnosis = Diagnosis(note=f"not computed: {type(exc).__name__}: {text}")
    if result.success and (request.sensitivities or request.ranges):
        try:
            sensitivities_with(formulation)(problem, result, request)
        except Exception as exc:  # a report, not the result: never lose the optimum
            result.notes.append(f"sensitivities not computed: {exc}")
    return result
