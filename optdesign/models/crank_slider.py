"""Crank-slider kinematics ([D17] eq. 1-5, Fig. 2; docs/kinematics.md and 2.3).

Output shaft axis O at the origin; the arm of length R carries pin B at
(R sin a, R cos a) with a = phi0 + phi (phi the deflection, phi0 the neutral angle);
the nut pin C = (m, n) slides on the line y = n parallel to the screw axis; the rod BC
has length l. With u = R cos a - n and s = sqrt(l^2 - u^2) (the rod's run along the
screw axis):

    m(phi)     = R sin a - s                               (eq. 2)
    dm/dphi    = R cos a - u R sin a / s
    d|BC|/dphi = (dm/dphi) s / l        (rate of the pin distance with the nut held)

All functions accept floats, NumPy arrays or CasADi symbols (see optdesign.math).
``floor`` guards the square root of the assembly margin for solvers: with ``floor=None``
the NumPy path returns NaN where the linkage cannot assemble (the mechanism layer checks
and names the angle); a solver passes a small positive floor so no NaN ever reaches it.

Validity
--------
assembly margin (l^2 - u^2)/l^2 : > 0 (a problem keeps it above 0.01)
    The closed forms are exact (no small-angle term) wherever the linkage assembles;
    at the toggle position the nut velocity and the forces are singular. A design
    problem bounds the margin (``assembly_margin_min``).
"""

from __future__ import annotations

from optdesign import math as m
from optdesign.models.ratio import ratio_from_nut_velocity
from optdesign.models.validity import Validity

ASSEMBLY_MARGIN = Validity(
    "crank_slider.assembly_margin",
    "crank-slider kinematics",
    "assembly margin (l^2 - u^2)/l^2",
    0.0,
    1.0,
    "",
    "the closed forms hold wherever the linkage assembles, away from its toggle position",
    open_lower=True,
    checked=("file", "design"),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (ASSEMBLY_MARGIN,)


def arm_angle(phi, phi0=0.0):
    """Arm angle a = phi0 + phi, measured from the perpendicular to the screw axis."""
    return phi0 + phi


@m.shareable
def rod_rise(R, n, phi, phi0=0.0):
    """u = R cos a - n: the rod's extent perpendicular to the screw axis (mm)."""
    return R * m.cos(arm_angle(phi, phi0)) - n


@m.shareable
def assembly_margin(R, l, n, phi, phi0=0.0):
    """l^2 - u^2 (mm^2); the linkage assembles only where it is positive."""
    u = rod_rise(R, n, phi, phi0)
    return l**2 - u**2


@m.shareable
def rod_run(R, l, n, phi, phi0=0.0, floor=None):
    """s = sqrt(l^2 - u^2): the rod's extent along the screw axis (mm)."""
    margin = assembly_margin(R, l, n, phi, phi0)
    if floor is not None:
        margin = m.fmax(margin, floor)
    return m.sqrt(margin)


@m.shareable
def nut_position(R, l, n, phi, phi0=0.0, floor=None):
    """Nut pin abscissa m(phi) = R sin a - sqrt(l^2 - u^2) (mm), eq. 2."""
    a = arm_angle(phi, phi0)
    return R * m.sin(a) - rod_run(R, l, n, phi, phi0, floor)


@m.shareable
def nut_velocity(R, l, n, phi, phi0=0.0, floor=None):
    """dm/dphi = R cos a - u R sin a / s (mm/rad): derivative of eq. 2.

    With a ``floor`` (the solver path) it is kept away from zero (``m.away_from_zero``):
    at a dead point of the linkage (R = l, n = 0: the nut stands still) the sensitivities
    and forces, which divide by it, stay finite."""
    a = arm_angle(phi, phi0)
    u = R * m.cos(a) - n
    s = rod_run(R, l, n, phi, phi0, floor)
    v = R * m.cos(a) - u * R * m.sin(a) / s
    return v if floor is None else m.away_from_zero(v)


@m.shareable
def ratio(R, l, n, p, i_a, phi, phi0=0.0, floor=None):
    """Exact reduction ratio i(phi) = 2 pi i_a (dm/dphi) / p."""
    return ratio_from_nut_velocity(nut_velocity(R, l, n, phi, phi0, floor), p, i_a)


@m.shareable
def rod_length_rate(R, l, n, phi, phi0=0.0, floor=None):
    """d|BC|/dphi with the nut held (mm/rad) = (dm/dphi) s / l (docs/clearance_and_backlash.md)."""
    s = rod_run(R, l, n, phi, phi0, floor)
    return nut_velocity(R, l, n, phi, phi0, floor) * s / l


@m.shareable
def transmission_angle(R, l, n, phi, phi0=0.0, floor=None):
    """Angle at B between the arm (B->O) and the rod (B->C), in rad; 90 deg is ideal.

    cos(mu) = (s sin a + u cos a) / l.
    """
    a = arm_angle(phi, phi0)
    u = R * m.cos(a) - n
    s = rod_run(R, l, n, phi, phi0, floor)
    return m.arccos((s * m.sin(a) + u * m.cos(a)) / l)


@m.shareable
def transmission_angle_cos(R, l, n, phi, phi0=0.0, floor=None):
    """cos of the transmission angle (smooth; constraints use it instead of arccos)."""
    a = arm_angle(phi, phi0)
    u = R * m.cos(a) - n
    s = rod_run(R, l, n, phi, phi0, floor)
    return (s * m.sin(a) + u * m.cos(a)) / l


@m.shareable
def rod_inclination(R, l, n, phi, phi0=0.0, floor=None):
    """Signed inclination of the rod to the screw axis, atan2(u, s), in rad."""
    u = rod_rise(R, n, phi, phi0)
    return m.arctan2(u, rod_run(R, l, n, phi, phi0, floor))


@m.shareable
def sensitivity_rod_length(R, l, n, phi, phi0=0.0, floor=None):
    """Output rotation per unit change of the effective rod length (rad/mm)."""
    return 1.0 / rod_length_rate(R, l, n, phi, phi0, floor)


@m.shareable
def sensitivity_axial(R, l, n, phi, phi0=0.0, floor=None):
    """Output rotation per unit axial (nut-side) clearance (rad/mm) = 1/(dm/dphi)."""
    return 1.0 / nut_velocity(R, l, n, phi, phi0, floor)


@m.shareable
def sensitivity_lateral(R, l, n, phi, phi0=0.0, floor=None):
    """Output rotation per unit clearance of the nut slide across the screw axis (rad/mm).

    Moving C by dy with the nut held changes the loop closure
    (R sin a - m)^2 + (R cos a - n)^2 = l^2; implicit differentiation gives
    da/dn = u / (s dm/dphi).
    """
    u = rod_rise(R, n, phi, phi0)
    s = rod_run(R, l, n, phi, phi0, floor)
    return m.fabs(u) / (s * m.fabs(nut_velocity(R, l, n, phi, phi0, floor)))
