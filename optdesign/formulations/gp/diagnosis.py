"""Why a GP solve found no feasible design: a GP solver returns no point for an infeasible
program, so the exact NLP of the same problem (exact Hertz) gives the best point and the
relaxations."""

from __future__ import annotations

from optdesign.formulations.diagnosis import Relaxing, adopt, nothing_violated
from optdesign.formulations.nlp.relaxation import relax_together, relaxations
from optdesign.formulations.nlp.solve import solve_nlp
from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.result import Diagnosis, Result


def gp_diagnosis(problem: DesignProblem, result: Result, how: Relaxing) -> Diagnosis:
    """The exact NLP's best point and relaxations (the GP back-end gives no point; the
    relaxations take the registry's default NLP back-end, whatever ``solver``)."""
    relax = how.relax
    objective = result.objective_name or problem.objective_names[0]
    nlp = solve_nlp(problem, objective=objective)
    basis = "the exact NLP"
    why = (
        "a GP solver gives no point for an infeasible program; the exact NLP has the same "
        "requirements (exact Hertz)"
    )
    if not result.design and nlp.design:
        adopt(result, nlp)
        result.notes.append("best point found: the exact NLP's (the GP solver gives none)")
    if nlp.success:
        return Diagnosis(
            basis=basis,
            note=(
                f"the exact NLP found a feasible design ({objective} = {nlp.objective:.8g}) "
                "although the GP (first-order Hertz) has none: solve with formulation='nlp'"
            ),
        )
    if not nlp.violated:
        return Diagnosis(basis=basis, note=nothing_violated(nlp))
    if not relax:
        return Diagnosis(basis=basis, note=why)
    found = relaxations(problem, nlp)
    return Diagnosis(found, basis, why, relax_together(problem, nlp, found))
