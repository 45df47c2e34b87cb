"""Joint clearance and its sum at the output ([D17] section 2; docs/clearance_and_backlash.md-2.4).

A joint contributes an output rotation theta_k = S_k(phi) * delta_k where delta_k is its
clearance (mm, or rad for an angular joint) and S_k the kinematic sensitivity of the
output angle to that clearance (the Jacobian of the mechanism, see
models.crank_slider / models.fork). The worst case adds the joints, the statistical
estimate takes their root-sum-square. A sized pin's clearance (fit plus contact
deformation) is :class:`optdesign.mechanisms.PinJoint`'s.
"""

from __future__ import annotations

from collections.abc import Sequence

from optdesign import math as m


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
