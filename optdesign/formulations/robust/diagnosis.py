"""Why a robust solve found no feasible design: the robust formulation imposes the nominal
requirements (its statistic is the objective only), so the nominal NLP's relaxations are
the robust problem's."""

from __future__ import annotations

import numpy as np

from optdesign.formulations.diagnosis import Relaxing, best_point, nothing_violated
from optdesign.formulations.nlp.relaxation import relax_together, relaxations
from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.constraint_rows import constraint_rows
from optdesign.solvers.result import Diagnosis, Result


def robust_diagnosis(problem: DesignProblem, result: Result, how: Relaxing) -> Diagnosis:
    """The nominal NLP's relaxations from the robust result's best point."""
    solver, relax = how.solver, how.relax
    basis = "the nominal NLP"
    why = "the robust formulation imposes the nominal requirements (its statistic is the objective)"
    if not result.design:
        return Diagnosis(basis=basis, note="the solver returned no point to diagnose from")
    x = np.array([result.design[v.name] for v in problem.free])
    active, violated = constraint_rows(problem, x)
    if not violated:
        return Diagnosis(basis=basis, note=nothing_violated(result))
    if not relax:
        return Diagnosis(basis=basis, note=why)
    point = best_point(problem.objective_names[0], active, violated)
    found = relaxations(problem, point, solver=solver, x_start=x)
    together = relax_together(problem, point, found, solver, x_start=x)
    return Diagnosis(found, basis, why, together)
