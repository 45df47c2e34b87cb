"""Benchmark configurations of the catalogue searches (issue 25), by name.

Not in the default selection (each solves a catalogue problem many NLPs deep); name them
with ``--solvers``: ``catalogue-bnb`` (optdesign's default search), ``catalogue-enumerate``
(every combination: the reference), ``bonmin-b-bb``, ``bonmin-b-oa``, ``bonmin-b-hyb``
(Bonmin through CasADi on the one-hot encoding). They apply to instances with catalogue
variables only. The seeded catalogue family and the table comparing them with
differential evolution are in ``benchmarks/bench_catalogue_solvers.py``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.bonmin import BONMIN_ALGORITHMS
from optdesign.solvers.result import Result


def _has_catalogue(problem: DesignProblem) -> bool:
    return any(v.discrete for v in problem.free)


def _catalogue_run(method: str, options: Mapping[str, Any] | None = None):
    def run(problem: DesignProblem, objective: str, time_limit: float) -> Result:
        from optdesign.studies.catalogue import solve_catalogue

        return solve_catalogue(problem, method=method, objective=objective, options=options)

    return run


def register_catalogue_configs(register, config) -> None:
    """Register the catalogue configurations with ``register(config(...))``."""
    searches = [
        ("catalogue-bnb", "bnb", None, "optdesign catalogue branch and bound (warm nodes)"),
        ("catalogue-enumerate", "enumerate", None, "every catalogue combination's NLP"),
    ]
    for alg in BONMIN_ALGORITHMS:
        searches.append(
            (
                f"bonmin-{alg.lower()}",
                "bonmin",
                {"algorithm": alg},
                f"Bonmin {alg} (CasADi), one-hot catalogue items",
            )
        )
    for name, method, options, description in searches:
        register(
            config(
                name,
                "global",
                _catalogue_run(method, options),
                description,
                dict(options or {}, method=method),
                hidden=True,
                time_factor=20.0,
                applies=_has_catalogue,
            )
        )
