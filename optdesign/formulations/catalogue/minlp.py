"""Catalogue optimum by a MINLP back-end on the one-hot encoding.

The problem's NLP with its catalogue variables encoded as one-hot binaries over the
items (:mod:`optdesign.formulations.catalogue.minlp_program`) goes to a back-end that declares a
MINLP solve (:attr:`~optdesign.solvers.registry.SolverHints.minlp`; built in: Bonmin
through CasADi, with its algorithms ``B-BB``: NLP branch and bound, ``B-OA``: outer
approximation, ``B-Hyb``: the hybrid - the last two exact only for convex problems, and
the catalogue problems are not). The back-end picks the items; the design reported is
the node NLP of those items (:class:`optdesign.formulations.catalogue.node_solver.NodeSolver`, started
from the back-end's point), so that the result carries the same evidence as the default
search's.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Mapping
from typing import Any

from optdesign.formulations.catalogue.details import MINLPDetails
from optdesign.solvers.registry import solver_hints
from optdesign.solvers.result import Result


def solve_minlp(
    ns, solver: str, options: Mapping[str, Any] | None = None
) -> tuple[Result | None, MINLPDetails]:
    """The catalogue optimum of the node solver's problem chosen by MINLP back-end
    ``solver``.

    Returns
    -------
    (Result or None, MINLPDetails)
        The node NLP of the back-end's items (None when it found no integer-feasible
        point or its items' NLP fails), and what the back-end did: algorithm, return
        status, its objective (the NLP's scaled one), items, seconds.
    """
    from optdesign.formulations.catalogue.bnb import fixed_box
    from optdesign.formulations.catalogue.minlp_program import build_catalogue_minlp

    module, _, attr = str(solver_hints(solver).minlp).partition(":")
    solve = getattr(importlib.import_module(module), attr)
    problem = ns.problem
    t0 = time.perf_counter()
    minlp = build_catalogue_minlp(problem, ns.nlp, ns.target, ns.eps)
    sol = solve(minlp, minlp.start(problem.start()), options)
    info = MINLPDetails(
        solver=solver,
        algorithm=sol.algorithm,
        status=sol.status,
        binaries=int(sum(minlp.discrete)),
        groups=[list(g.names) for g in minlp.groups],
        seconds=time.perf_counter() - t0,
    )
    if not sol.found:
        return None, info
    info.items = minlp.items(sol.x)
    info.objective_scaled = sol.objective
    design = ns.nlp.x_from_z(sol.x[: minlp.n_z])
    leaf = ns.solve(fixed_box(info.items), design, warm=True)
    return (leaf if leaf.success else None), info
