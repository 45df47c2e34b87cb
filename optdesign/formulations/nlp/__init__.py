"""The ``nlp`` formulation: the problem's smooth NLP on CasADi (epigraph forms of the
min-max objectives, scaled variables, exact derivatives) solved by a Sobol multistart.

- :mod:`.solve`: the multistart solve, its caches and the independent check;
- :mod:`.diagnosis`: the relaxations of an infeasible NLP (:mod:`.relaxation`);
- :mod:`.sensitivities`: what each requirement costs, from the multipliers, and the
  ranges of the optimal set.

The program itself (:class:`~optdesign.programs.nlp.NLP`) lives below the solvers, in
:mod:`optdesign.programs.nlp`: every back-end takes it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from optdesign.formulations.protocol import FormulationBase

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem
    from optdesign.problem.request import SolveRequest
    from optdesign.solvers.result import Result


class NLPFormulation(FormulationBase):
    """``formulation="nlp"``: the multistart NLP; its diagnosis and sensitivities are the
    defaults every formulation inherits."""

    name = "nlp"
    description = "NLP (epigraph form) with Sobol multistart"
    time_limit = True

    def applies(self, problem: DesignProblem, request: SolveRequest) -> bool | str:
        """True unless a variable takes catalogue values (then the reason)."""
        from optdesign.formulations.nlp.solve import nlp_applies

        return nlp_applies(problem, request)

    def solve(self, problem: DesignProblem, request: SolveRequest) -> Result:
        """The multistart NLP of the request, checked against the file's reference."""
        from optdesign.formulations.nlp.solve import solve_nlp_formulation

        return solve_nlp_formulation(problem, request)
