"""A solver back-end written outside the package, for tests/solvers/test_registry.py:
Ipopt with a limited-memory Hessian, declaring its own warm-start and node options. A
new back-end is this module and one ``register_solver`` line; no study changes."""

from __future__ import annotations

from typing import Any

from optdesign.solvers import SolverHints
from optdesign.solvers.casadi_nlp import CasadiNLPSolver

#: What the back-end declares: the studies use these without naming it.
HINTS = SolverHints(
    warm_start_options={"warm_start_init_point": "yes", "mu_init": 1e-6},
    node_options={"expect_infeasible_problem": "yes"},
    iteration_option="max_iter",
    file_options="ipopt",
)


def lbfgs_ipopt(nlp, options: dict[str, Any]) -> CasadiNLPSolver:
    """Ipopt with a limited-memory Hessian (the caller's options win)."""
    return CasadiNLPSolver(nlp, "ipopt", {"hessian_approximation": "limited-memory", **options})
