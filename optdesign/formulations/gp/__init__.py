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

from typing import TYPE_CHECKING

from optdesign.formulations.gp.details import GPDetails
from optdesign.formulations.protocol import FormulationBase

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem
    from optdesign.problem.request import SolveRequest
    from optdesign.solvers.result import Result


class GPFormulation(FormulationBase):
    """``formulation="gp"``: GP with certificate and the exact NLP beside it."""

    name = "gp"
    description = (
        "geometric program (first-order Hertz) with a dual certificate, exact NLP beside it"
    )
    details = GPDetails

    def applies(self, problem: DesignProblem, request: SolveRequest) -> bool | str:
        """True when the problem is a GP in the request's objective, else what breaks
        DGP form."""
        from optdesign.formulations.gp.solve import gp_applies

        return gp_applies(problem, request)

    def solve(self, problem: DesignProblem, request: SolveRequest) -> Result:
        """The GP optimum, its certificate and the exact NLP's comparison."""
        from optdesign.formulations.gp.solve import solve_gp_formulation

        return solve_gp_formulation(problem, request)

    def diagnose(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """The exact NLP's best point and relaxations (a GP solver gives no point)."""
        from optdesign.formulations.diagnosis import diagnose
        from optdesign.formulations.gp.diagnosis import gp_diagnosis

        diagnose(problem, result, request.solver, request.options, by=gp_diagnosis)

    def sensitivities(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """Nothing more: the solve reports the exact NLP's sensitivities already."""
