"""Ipopt's options that the solver registry declares (no CasADi import: listing a
back-end's capabilities loads no solver library). The figures behind each choice are in
benchmarks/README.md, "Figures behind comments in the code"."""

from __future__ import annotations

from typing import Any

#: Ipopt options of a warm start from a nearby solution (primal and dual): take its
#: multipliers and start close to the central path instead of pushing the point back
#: into the interior.
IPOPT_WARM: dict[str, Any] = {
    "warm_start_init_point": "yes",
    "warm_start_bound_push": 1e-9,
    "warm_start_bound_frac": 1e-9,
    "warm_start_slack_bound_push": 1e-9,
    "warm_start_slack_bound_frac": 1e-9,
    "warm_start_mult_bound_push": 1e-9,
    "mu_init": 1e-6,
}

#: Ipopt options of the ranges of the optimal set (a warm start from the optimum, each
#: solve moving one variable as far as the objective's tie band lets it): the warm start's,
#: with the dual tolerance at 1e-7 instead of 1e-10, since a range end is shown to six
#: digits and its constraint rows keep their own tolerance (1e-9).
IPOPT_RANGE: dict[str, Any] = {**IPOPT_WARM, "tol": 1e-7}

#: Ipopt options of a solve started at a feasible point close to its optimum (a front's
#: lexicographic tie-breaks, started at an optimum of the objective fixed before): a
#: small initial barrier parameter and bound push keep Ipopt there instead of pushing it
#: back into the interior. A tie-break that converges takes a few dozen iterations; one
#: that stalls on the degenerate set is given up at 150 (the caller then tries Ipopt's
#: defaults) rather than at the default 500. The barrier starts at 1e-4: from 1e-5 the
#: adaptive barrier stalled on cs_min_backlash's ripple tie-break (150 iterations, then
#: the fallback's 47), which 1e-4 solves in 26; over the tie-breaks of 8 fronts of four
#: mechanisms none falls back, the fronts equal to 1e-7 (benchmarks/README.md, "Catalogue
#: starts checked on every other grid angle").
IPOPT_TIE: dict[str, Any] = {
    "mu_init": 1e-4,
    "bound_push": 1e-6,
    "bound_frac": 1e-6,
    "max_iter": 150,
}

#: Ipopt options of a catalogue node. Many nodes of a catalogue search are infeasible
#: boxes, and Ipopt's default filter spends ~120 iterations before its restoration phase
#: proves it; ``expect_infeasible_problem`` enters restoration sooner, with the same nodes
#: infeasible and the same optima.
IPOPT_NODE: dict[str, Any] = {"expect_infeasible_problem": "yes"}
