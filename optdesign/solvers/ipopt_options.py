"""Ipopt's options that the solver registry declares (no CasADi import: listing a
back-end's capabilities loads no solver library)."""

from __future__ import annotations

from typing import Any

#: Ipopt options of a warm start from a nearby solution (primal and dual): take its
#: multipliers and start close to the central path instead of pushing the point back
#: into the interior. The ranges of the optimal set from the optimum: 179 iterations
#: instead of 244 (cs_min_backlash), 135 instead of 257 (cs_min_ripple), same ranges.
IPOPT_WARM: dict[str, Any] = {
    "warm_start_init_point": "yes",
    "warm_start_bound_push": 1e-9,
    "warm_start_bound_frac": 1e-9,
    "warm_start_slack_bound_push": 1e-9,
    "warm_start_slack_bound_frac": 1e-9,
    "warm_start_mult_bound_push": 1e-9,
    "mu_init": 1e-6,
}
