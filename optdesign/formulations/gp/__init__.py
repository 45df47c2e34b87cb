"""The ``gp`` formulation: the problem as a geometric program (first-order Hertz), solved
with a dual certificate, the exact NLP solved beside it.

- :mod:`.solve`: the GP solve, its certificate and the exact NLP's comparison (and the
  sensitivities of that NLP's optimum);
- :mod:`.diagnosis`: an infeasible GP diagnosed on the exact NLP;
- :mod:`.details`: its typed record (:class:`~.details.GPDetails`).

The program itself (:class:`~optdesign.programs.gp.GPData`, its signomial algebra) lives
below the solvers, in :mod:`optdesign.programs.gp`: the GP back-ends take it.
"""

from __future__ import annotations

from optdesign.formulations.gp.details import GPDetails
from optdesign.formulations.protocol import FormulationBase


class GPFormulation(FormulationBase):
    """``formulation="gp"``: GP with certificate and the exact NLP beside it (the solve
    reports that NLP's sensitivities); an infeasible GP is diagnosed on the exact NLP."""

    name = "gp"
    description = (
        "geometric program (first-order Hertz) with a dual certificate, exact NLP beside it"
    )
    details = GPDetails
    applies_by = "optdesign.formulations.gp.solve:gp_applies"
    solve_by = "optdesign.formulations.gp.solve:solve_gp_formulation"
    diagnosis_by = "optdesign.formulations.gp.diagnosis:gp_diagnosis"
    sensitivities_by = ""
