"""Catalogue optimum by a MINLP solver: Bonmin (through CasADi) on the one-hot encoding.

The problem's NLP with its catalogue variables encoded as one-hot binaries over the
items (:mod:`optdesign.formulations.catalogue_minlp`) goes to Bonmin with one of its
algorithms (``B-BB``: NLP branch and bound; ``B-OA``: outer approximation; ``B-Hyb``:
the hybrid; the last two are exact only for convex problems, and the catalogue
problems are not). Bonmin picks the items; the design reported is the node NLP of
those items (:class:`optdesign.studies.catalogue.NodeSolver`, started from Bonmin's
point), so that the result carries the same evidence as the default search's.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np

from optdesign.interrupts import solver_call
from optdesign.solvers.bonmin import BONMIN_FOUND, bonmin_options, quiet_stdout
from optdesign.solvers.result import Result


def solve_bonmin(ns, options: Mapping[str, Any] | None = None) -> tuple[Result | None, dict]:
    """The catalogue optimum of the node solver's problem chosen by Bonmin.

    Returns
    -------
    (Result or None, dict)
        The node NLP of Bonmin's items (None when Bonmin found no integer-feasible
        point or its items' NLP fails), and what Bonmin did: algorithm, return status,
        its objective (the NLP's scaled one), items, seconds.
    """
    import casadi as ca

    from optdesign.formulations.catalogue_minlp import build_catalogue_minlp
    from optdesign.studies.catalogue_bnb import fixed_box

    opts = bonmin_options(options)
    problem = ns.problem
    t0 = time.perf_counter()
    minlp = build_catalogue_minlp(problem, ns.nlp, ns.target, ns.eps)
    solver = ca.nlpsol(
        "optdesign_bonmin",
        "bonmin",
        {"x": minlp.x, "f": minlp.f, "g": minlp.g},
        {"discrete": minlp.discrete, "print_time": False, "bonmin": opts},
    )
    x0 = minlp.start(problem.start())
    with solver_call(), quiet_stdout():
        try:
            sol = solver(x0=x0, lbx=minlp.lbx, ubx=minlp.ubx, lbg=minlp.lbg, ubg=minlp.ubg)
            status = str(solver.stats().get("return_status", ""))
        except RuntimeError as exc:  # an evaluation error Bonmin cannot recover from
            sol, status = None, f"error: {str(exc).splitlines()[-1]}"
    info: dict[str, Any] = {
        "algorithm": opts["algorithm"],
        "status": status,
        "binaries": int(sum(minlp.discrete)),
        "groups": [list(g.names) for g in minlp.groups],
        "seconds": time.perf_counter() - t0,
    }
    if sol is None or status not in BONMIN_FOUND:
        return None, info
    x = np.asarray(sol["x"], dtype=float).ravel()
    items = minlp.items(x)
    info["items"] = items
    info["objective_scaled"] = float(sol["f"])
    design = ns.nlp.x_from_z(x[: minlp.n_z])
    leaf = ns.solve(fixed_box(items), design, warm=True)
    return (leaf if leaf.success else None), info
