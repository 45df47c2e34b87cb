"""A problem with no free variable: its one design checked, not optimised, and the exact
relaxations of what it violates."""

from __future__ import annotations

import time

import numpy as np

from optdesign.errors import InputError
from optdesign.formulations.verify import verify_design
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.request import SolveRequest
from optdesign.solvers.constraint_rows import constraint_rows
from optdesign.solvers.result import (
    ConstraintReport,
    Diagnosis,
    Globality,
    Relaxation,
    Result,
    SolutionStatus,
    TerminationCondition,
)


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


def fixed_diagnosis(problem: DesignProblem, result: Result) -> Diagnosis:
    """Exact relaxations of a design with no free variable."""
    groups: dict[str, list[ConstraintReport]] = {}
    for r in result.violated:
        groups.setdefault(r.name.split("[", 1)[0], []).append(r)
    basis = "the fixed design"
    out = []
    for name, rows in groups.items():
        worst = max(rows, key=lambda r: r.amount)
        upper = worst.upper is not None and (
            worst.lower is None or worst.value - worst.upper > worst.lower - worst.value
        )
        written = worst.upper if upper else worst.lower
        needed: float | None = None  # with another requirement violated, not enough
        if len(groups) == 1:
            values = [r.value for r in rows]
            needed = max(values) if upper else min(values)
        out.append(Relaxation(name, upper, written, needed, worst.lower, worst.upper, 0))
    note = "" if len(groups) <= 1 else "several requirements are violated: relax them together"
    return Diagnosis(out, basis, note)


class FixedDesign:
    """The stand-in for a formulation when no variable is free: the design is checked,
    and a violated requirement's relaxation is exact."""

    name = "fixed"
    description = "no free variable: the fixed design checked, nothing optimised"
    details = None

    def applies(self, problem: DesignProblem, request: SolveRequest) -> bool | str:
        """True when no variable is free."""
        return not problem.free or "a variable is free"

    def solve(self, problem: DesignProblem, request: SolveRequest) -> Result:
        """The fixed design's check."""
        return check_fixed_design(problem, request.objective)

    def diagnose(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """The exact relaxations of what the design violates."""
        from optdesign.formulations.diagnosis import Relaxing, diagnose

        how = Relaxing(request.solver, request.options)
        diagnose(
            problem, result, how, by=lambda problem, result, _: fixed_diagnosis(problem, result)
        )

    def sensitivities(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """None: nothing was optimised."""


#: The one stand-in (it keeps no state).
FIXED_DESIGN = FixedDesign()
