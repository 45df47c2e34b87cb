"""Joint clearance and its sum at the output (seed 000 section 2; physics.md 2.2-2.4).

A joint contributes an output rotation theta_k = S_k(phi) * delta_k where delta_k is its
clearance (mm, or rad for an angular joint) and S_k the kinematic sensitivity of the
output angle to that clearance (the Jacobian of the mechanism, see
models.crank_slider / models.fork). The worst case adds the joints, the statistical
estimate takes their root-sum-square.
"""

from __future__ import annotations

from collections.abc import Sequence

from optdesign import math as m
from optdesign.models.fits import Fit, fit_clearance
from optdesign.models.hertz_line import pin_flattening, pin_flattening_first_order


def pin_joint_clearance(
    d, F, L, E, nu, fit: str | Fit, which: str = "max", surfaces: int = 2, first_order=False
):
    """Effective clearance (mm) of a loaded pin in its bore.

    Fit clearance (ISO 286, ``which`` = "max" or "min") plus ``surfaces`` times the Hertz
    flattening under the normal force F (pin and bore: 2, the reading that comes close to
    the paper's 0.012 mm; see models.hertz_line).
    """
    flat = pin_flattening_first_order if first_order else pin_flattening
    return fit_clearance(d, fit, which) + surfaces * flat(d, F, L, E, nu)


def worst_case(contributions: Sequence):
    """Worst-case total: sum of |theta_k|."""
    total = 0.0
    for c in contributions:
        total = total + m.fabs(c)
    return total


def root_sum_square(contributions: Sequence):
    """Statistical total: sqrt(sum theta_k^2)."""
    total = 0.0
    for c in contributions:
        total = total + c**2
    return m.sqrt(total)
