"""Shifting-fork (pin-in-slot) kinematics ([D17] eq. 6-9, Fig. 5; docs/kinematics.md, 2.3).

The nut pin C moves on a line at perpendicular distance R from the output axis O and
slides in a slot of the output arm; at deflection phi (arm at a = phi0 + phi, phi0 = 0 in
the paper) the nut sits at s = R tan a and the pin at R / cos a from O.

Validity
--------
arm angle phi0 + phi : |a| < 90 deg
    s = R tan(a) is exact and has its pole at 90 deg (the pin leaves along the slot).
    The stroke of a problem stays far from it (checked by the ratio's rows: a finite,
    positive ratio).
"""

from __future__ import annotations

import numpy as np

from optdesign import math as m
from optdesign.models.ratio import ratio_from_nut_velocity
from optdesign.models.validity import Validity

ARM_ANGLE = Validity(
    "fork.arm_angle",
    "shifting-fork kinematics",
    "arm angle phi0 + phi",
    float(-np.pi / 2),
    float(np.pi / 2),
    "rad",
    "s = R tan(a) is exact and has its pole at 90 deg",
    shown_unit="deg",
    scale=float(180.0 / np.pi),
    open_lower=True,
    open_upper=True,
    checked=("documented",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (ARM_ANGLE,)


@m.shareable
def nut_position(R, phi, phi0=0.0):
    """s = R tan(phi0 + phi) (mm), eq. 6."""
    return R * m.tan(phi0 + phi)


@m.shareable
def nut_velocity(R, phi, phi0=0.0):
    """ds/dphi = R / cos^2(phi0 + phi) (mm/rad)."""
    c = m.cos(phi0 + phi)
    return R / c**2


@m.shareable
def ratio(R, p, i_a, phi, phi0=0.0):
    """Exact reduction ratio 2 pi i_a R / (p cos^2 phi)."""
    return ratio_from_nut_velocity(nut_velocity(R, phi, phi0), p, i_a)


@m.shareable
def sensitivity_slot_normal(R, phi, phi0=0.0):
    """Output rotation per unit slot-normal clearance at the pin (rad/mm) = cos a / R."""
    return m.cos(phi0 + phi) / R


@m.shareable
def sensitivity_axial(R, phi, phi0=0.0):
    """Output rotation per unit axial (nut-side) clearance (rad/mm) = cos^2 a / R."""
    return 1.0 / nut_velocity(R, phi, phi0)
