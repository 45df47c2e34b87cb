"""``--formulation gp`` and ``--formulation catalogue`` of ``optdesign solve`` (issue 4).

``auto`` picks ``catalogue`` first when a variable takes catalogue values (such a
problem must never be solved as continuous), then ``gp`` when the problem is a
geometric program (:func:`optdesign.formulations.gp.is_gp`), else the NLP.
"""

from __future__ import annotations

from optdesign.commands.solve import AUTO_ORDER, formulation
from optdesign.formulations.discrete import has_discrete
from optdesign.formulations.gp import is_gp
from optdesign.solvers.result import Result


def _finish(problem, result: Result) -> Result:
    from optdesign.studies.reference import attach_reference

    return attach_reference(problem, result)


@formulation("gp")
def solve_gp_formulation(problem, args) -> Result:
    """GP with certificate and the exact NLP beside it; error naming the non-DGP terms."""
    from optdesign.studies.gp import solve_gp_problem
    from optdesign.studies.reference import reference_design

    reference_design(problem)  # validate [reference] before solving
    result = solve_gp_problem(
        problem, objective=args.objective, nlp_starts=args.starts, seed=args.seed
    )
    return _finish(problem, result)


def _catalogue(method: str):
    def solve(problem, args) -> Result:
        from optdesign.studies.catalogue import solve_catalogue
        from optdesign.studies.reference import reference_design

        reference_design(problem)
        result = solve_catalogue(
            problem,
            method=method,
            starts=args.starts,
            seed=args.seed,
            objective=args.objective,
            plugin=args.solver,
        )
        return _finish(problem, result)

    solve.__doc__ = f"Catalogue optimum ({method}): items chosen and the relaxation bound."
    return solve


formulation("catalogue")(_catalogue("auto"))
formulation("catalogue-enumerate")(_catalogue("enumerate"))
formulation("catalogue-bnb")(_catalogue("bnb"))

# Discrete first: a catalogue problem must not fall through to a continuous formulation.
AUTO_ORDER.insert(0, ("catalogue", has_discrete))
AUTO_ORDER.append(("gp", is_gp))
