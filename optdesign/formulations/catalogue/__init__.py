"""The ``catalogue`` formulation: the exact optimum over the catalogue values of the
discrete variables (a screw, a motor, a pin diameter), an NLP at each combination of
items, with the continuous relaxation's bound.

- :mod:`.discrete`: the discrete variables and their coordinates;
- :mod:`.search`: the search (enumeration, branch and bound, or a MINLP back-end) and
  the node solver;
- :mod:`.bnb`: the branch and bound, its memo of infeasible boxes and the depth-first
  search for a first feasible combination;
- :mod:`.minlp_program`, :mod:`.minlp`: the one-hot MINLP and its solve;
- :mod:`.sensitivities`: the continuous part's costs and the neighbouring items;
- :mod:`.diagnosis`: an infeasible search diagnosed at the best items;
- :mod:`.details`: its typed record (:class:`~.details.CatalogueDetails`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from optdesign.errors import ProblemError
from optdesign.formulations.catalogue.details import CatalogueDetails
from optdesign.formulations.protocol import FormulationBase

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem
    from optdesign.problem.request import SolveRequest
    from optdesign.solvers.result import Result


class CatalogueFormulation(FormulationBase):
    """``formulation="catalogue"``: the exact catalogue optimum and its relaxation bound."""

    name = "catalogue"
    description = "branch and bound (or enumeration) over the catalogue values, NLP at each node"
    details = CatalogueDetails

    def applies(self, problem: DesignProblem, request: SolveRequest) -> bool | str:
        """True when some free variable takes catalogue values."""
        from optdesign.formulations.catalogue.search import catalogue_applies

        return catalogue_applies(problem, request)

    def check(self, problem: DesignProblem, request: SolveRequest) -> None:
        """Refuse tolerances: robust design needs continuous variables."""
        if problem.spec.tolerances is not None and problem.free:
            disc = ", ".join(v.name for v in problem.free if v.discrete)
            raise ProblemError(
                f"tolerances: robust design needs continuous variables, and {disc} take "
                "catalogue values; remove [tolerances] for the nominal catalogue optimum"
            )

    def solve(self, problem: DesignProblem, request: SolveRequest) -> Result:
        """The exact catalogue optimum, its relaxation bound and globality."""
        from optdesign.formulations.catalogue.search import solve_catalogue_formulation

        return solve_catalogue_formulation(problem, request)

    def diagnose(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """The relaxations at the catalogue items nearest the best point."""
        from optdesign.formulations.catalogue.diagnosis import catalogue_diagnosis
        from optdesign.formulations.diagnosis import diagnose

        diagnose(problem, result, request.solver, request.options, by=catalogue_diagnosis)

    def sensitivities(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """The continuous part's costs at the chosen items, and the neighbouring items."""
        from optdesign.formulations.catalogue.sensitivities import catalogue_evidence

        catalogue_evidence(problem, result, request)
