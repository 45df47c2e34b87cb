"""The ``robust`` formulation: a risk measure (CVaR or mean + k std) of the objective
under the file's tolerances, by sample-average approximation, started at the nominal
optimum.

- :mod:`.program`: the sample-average NLP built from the problem and its samples;
- :mod:`.solve`: the nominal optimum, then the robust one (with its sensitivities);
- :mod:`.sensitivities`: what each requirement costs at the robust optimum;
- :mod:`.diagnosis`: an infeasible robust problem diagnosed on the nominal NLP;
- :mod:`.details`: its typed record (:class:`~.details.RobustDetails`).
"""

from __future__ import annotations

from optdesign.formulations.protocol import FormulationBase
from optdesign.formulations.robust.details import RobustDetails


class RobustFormulation(FormulationBase):
    """``formulation="robust"``: the nominal optimum, then the robust optimum from it (the
    solve reports its sensitivities: they need its samples' NLP); an infeasible robust
    problem is diagnosed on the nominal NLP."""

    name = "robust"
    description = "risk measure (CVaR or mean + k std) of the objective under the tolerances"
    details = RobustDetails
    applies_by = "optdesign.formulations.robust.solve:robust_applies"
    solve_by = "optdesign.formulations.robust.solve:solve_robust_formulation"
    diagnosis_by = "optdesign.formulations.robust.diagnosis:robust_diagnosis"
    sensitivities_by = ""
