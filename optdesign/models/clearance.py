"""Joint clearance and its sum at the output ([D17] section 2; docs/clearance_and_backlash.md-2.4).

A joint contributes an output rotation theta_k = S_k(phi) * delta_k where delta_k is its
clearance (mm, or rad for an angular joint) and S_k the kinematic sensitivity of the
output angle to that clearance (the Jacobian of the mechanism, see
models.crank_slider / models.fork). The worst case adds the joints, the statistical
estimate takes their root-sum-square. A sized pin's clearance (fit plus contact
deformation) is :class:`optdesign.mechanisms.PinJoint`'s.

Validity
--------
joint rotation, backlash : <= 5 deg
    The map theta_k = S_k(phi) delta_k is the first-order (Jacobian) term of the
    linkage's rotation under a small clearance, with S_k taken at the nominal
    configuration, and the worst case adds the joints' terms as if each acted alone.
    Both hold while the rotations are small angles: at 5 deg (0.087 rad) sin and tan
    differ from the angle by 0.13 % and 0.25 %, and the sensitivities of the shipped
    linkages change by a few per cent over such a turn (the paper's crank-slider:
    |dS/dphi| / S of about 0.42 per rad over the stroke, 3.7 % at 5 deg); well beyond it the linkage
    reaches another configuration and the sum stops being one. [D17] asks for at most
    0.1 deg of the whole system; 5 deg is 50 times that.
fixed clearance (length) : 0 ... 1 mm
    A ``[clearances]`` entry is the play of a fitted or preloaded part (screw bearings,
    screw/nut, nut slide): micrometres in an actuator. 1 mm is above the largest
    clearance of the loosest clearance fit of the ISO 286-2 tables (H11/c11: 0.97 mm
    up to 315 mm) and above the axial play of any worn screw nut; a play of a metre is
    no joint, and the first-order map above assumes clearances small against the links.
fixed clearance (angle) : 0 ... 5 deg
    An angular play (the output shaft's) adds to the output rotation directly: the
    small-angle limit of the backlash above bounds it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from optdesign import math as m
from optdesign.models.validity import Validity

#: Largest output rotation (deg) of one joint and of the whole chain the small-angle map
#: holds for (module docstring, *Validity*).
SMALL_ANGLE_LIMIT_DEG = 5.0

JOINT_ROTATION = Validity(
    "clearance.joint_rotation",
    "small-angle clearance",
    "output rotation of a joint",
    0.0,
    SMALL_ANGLE_LIMIT_DEG,
    "deg",
    "the first-order map of a joint's clearance to the output holds for small angles",
)
BACKLASH = Validity(
    "clearance.backlash",
    "small-angle clearance",
    "worst-case backlash",
    0.0,
    SMALL_ANGLE_LIMIT_DEG,
    "deg",
    "the joints' first-order rotations add up for small angles only",
    checked=("file", "design"),
)
FIXED_CLEARANCE_LENGTH = Validity(
    "clearance.fixed_length",
    "small-angle clearance",
    "fixed clearance of a joint",
    0.0,
    1.0,
    "mm",
    "a joint's play is micrometres; 1 mm exceeds the loosest ISO 286 clearance fit "
    "(H11/c11 up to 315 mm)",
    checked=("file",),
)
FIXED_CLEARANCE_ANGLE = Validity(
    "clearance.fixed_angle",
    "small-angle clearance",
    "fixed angular clearance",
    0.0,
    math.radians(SMALL_ANGLE_LIMIT_DEG),
    "rad",
    "an angular play adds to the backlash directly, which holds below 5 deg",
    shown_unit="deg",
    scale=180.0 / math.pi,
    checked=("file",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (
    JOINT_ROTATION,
    BACKLASH,
    FIXED_CLEARANCE_LENGTH,
    FIXED_CLEARANCE_ANGLE,
)


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
