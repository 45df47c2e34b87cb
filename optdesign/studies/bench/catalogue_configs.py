"""Benchmark configurations of the catalogue searches, by name.

Not in the default selection (each solves a catalogue problem many NLPs deep); name them
with ``--solvers``: ``catalogue-bnb`` (optdesign's default search), ``catalogue-enumerate``
(every combination: the reference), ``bonmin-b-bb``, ``bonmin-b-oa``, ``bonmin-b-hyb``
(Bonmin through CasADi on the one-hot encoding: method ``"minlp"``). They apply to instances with catalogue
variables only. The seeded catalogue family and the table comparing them with
differential evolution are in ``benchmarks/bench_catalogue_solvers.py``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.result import Result


def _has_catalogue(problem: DesignProblem) -> bool:
    return any(v.discrete for v in problem.free)


def _catalogue_run(method: str, solver: str | None, options: Mapping[str, Any] | None):
    def run(problem: DesignProblem, objective: str, time_limit: float) -> Result:
        from optdesign.formulations.catalogue.search import solve_catalogue

        return solve_catalogue(
            problem, method=method, objective=objective, solver=solver, options=options
        )

    return run


def register_catalogue_configs(
    register,
    config,
    searches: Sequence[tuple[str, str, str | None, Mapping[str, Any] | None, str]],
) -> None:
    """Register ``searches`` (name, method, MINLP back-end or None, its options,
    description; the table is in :func:`optdesign.studies.bench.configs.
    _register_defaults`) with ``register(config(...))``."""
    for name, method, solver, options, description in searches:
        register(
            config(
                name,
                "global",
                _catalogue_run(method, solver, options),
                description,
                dict(options or {}, method=method),
                hidden=True,
                time_factor=20.0,
                applies=_has_catalogue,
            )
        )
