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

from typing import TYPE_CHECKING

from optdesign.formulations.protocol import FormulationBase
from optdesign.formulations.robust.details import RobustDetails

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem
    from optdesign.problem.request import SolveRequest
    from optdesign.solvers.result import Result


class RobustFormulation(FormulationBase):
    """``formulation="robust"``: the nominal optimum, then the robust optimum from it."""

    name = "robust"
    description = "risk measure (CVaR or mean + k std) of the objective under the tolerances"
    details = RobustDetails

    def applies(self, problem: DesignProblem, request: SolveRequest) -> bool | str:
        """True when the problem has tolerances and continuous variables, else why not."""
        from optdesign.formulations.robust.solve import robust_applies

        return robust_applies(problem, request)

    def solve(self, problem: DesignProblem, request: SolveRequest) -> Result:
        """The robust optimum, started at the nominal optimum."""
        from optdesign.formulations.robust.solve import solve_robust_formulation

        return solve_robust_formulation(problem, request)

    def diagnose(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """The nominal NLP's relaxations (the robust problem imposes its requirements)."""
        from optdesign.formulations.diagnosis import diagnose
        from optdesign.formulations.robust.diagnosis import robust_diagnosis

        diagnose(problem, result, request.solver, request.options, by=robust_diagnosis)

    def sensitivities(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """Nothing more: the solve reports them already (they need its samples' NLP)."""
