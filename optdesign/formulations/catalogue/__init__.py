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


class CatalogueFormulation(FormulationBase):
    """``formulation="catalogue"``: the exact catalogue optimum and its relaxation bound;
    an infeasible search is diagnosed at the items nearest its best point, an optimum's
    sensitivities are its continuous part's and its neighbouring items."""

    name = "catalogue"
    description = "branch and bound (or enumeration) over the catalogue values, NLP at each node"
    details = CatalogueDetails
    applies_by = "optdesign.formulations.catalogue.search:catalogue_applies"
    solve_by = "optdesign.formulations.catalogue.search:solve_catalogue_formulation"
    diagnosis_by = "optdesign.formulations.catalogue.diagnosis:catalogue_diagnosis"
    sensitivities_by = "optdesign.formulations.catalogue.sensitivities:catalogue_evidence"

    def check(self, problem: DesignProblem, request: SolveRequest) -> None:
        """Refuse tolerances: robust design needs continuous variables."""
        if problem.spec.tolerances is not None and problem.free:
            disc = ", ".join(v.name for v in problem.free if v.discrete)
            raise ProblemError(
                f"tolerances: robust design needs continuous variables, and {disc} take "
                "catalogue values; remove [tolerances] for the nominal catalogue optimum"
            )
