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

from optdesign.formulations.protocol import FormulationBase


class NLPFormulation(FormulationBase):
    """``formulation="nlp"``: the multistart NLP of the request, checked against the file's
    reference; its diagnosis and sensitivities are the defaults every formulation
    inherits."""

    name = "nlp"
    description = "NLP (epigraph form) with Sobol multistart"
    time_limit = True
    applies_by = "optdesign.formulations.nlp.solve:nlp_applies"
    solve_by = "optdesign.formulations.nlp.solve:solve_nlp_formulation"
