"""Why an NLP solve found no feasible design: the smallest relaxation of each requirement
in the conflict, from the result's best point, on the problem's NLP
(:mod:`optdesign.formulations.nlp.relaxation`)."""

from __future__ import annotations

from optdesign.formulations.diagnosis import Relaxing, nothing_violated
from optdesign.formulations.nlp.relaxation import relax_together, relaxations
from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.result import Diagnosis, Result


def nlp_diagnosis(problem: DesignProblem, result: Result, how: Relaxing) -> Diagnosis:
    """The relaxations of the problem's NLP from ``result``'s best point (``how.solver``:
    the NLP back-end of the relaxations; ``how.relax`` False: the best point's basis
    only)."""
    solver, relax = how.solver, how.relax
    if not result.design:
        return Diagnosis(note="the solver returned no point to diagnose from")
    if not result.violated:
        return Diagnosis(basis="the NLP", note=nothing_violated(result))
    if not relax:
        return Diagnosis(basis="the NLP")
    found = relaxations(problem, result, solver=solver)
    return Diagnosis(found, "the NLP", together=relax_together(problem, result, found, solver))
