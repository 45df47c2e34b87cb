"""Lead screw relations ([Z00]; docs/screw.md and 8).

lambda: lead angle, tan(lambda) = p / (pi d_m); phi_f: friction angle, tan(phi_f) = mu.

Validity
--------
lead angle lambda : 0 < lambda <= 45 deg
    The square-thread analogy (the nut as a block on an inclined plane of slope lambda
    with a friction angle phi_f) is written for screws, whose leads are short against
    the circumference: ball-screw catalogues stop at a lead of about twice the diameter
    (lambda about 30 deg), and tan(lambda + phi_f) has its pole at 90 deg. Above 45 deg
    the back-driving efficiency exceeds the forward one: a "screw" that the nut drives
    better than the motor is a helical cam, which no screw catalogue or friction figure
    describes.
friction coefficient mu : 0 <= mu < 1
    Coulomb friction of lubricated threads and ball tracks (0.002-0.2); 1 would put the
    friction angle at 45 deg (checked when the problem file is read,
    ``screw.friction``).
"""

from __future__ import annotations

from optdesign import math as m
from optdesign.models.validity import Validity

LEAD_ANGLE = Validity(
    "screw.lead_angle",
    "screw efficiency",
    "lead angle",
    0.0,
    0.7853981633974483,
    "rad",
    "the inclined-plane model of a screw holds for leads short against the circumference "
    "(lambda <= 45 deg)",
    shown_unit="deg",
    scale=57.29577951308232,
    open_lower=True,
)
FRICTION_COEFFICIENT = Validity(
    "screw.friction",
    "screw efficiency",
    "friction coefficient",
    0.0,
    1.0,
    "",
    "Coulomb friction of lubricated threads and ball tracks lies well below 1",
    open_upper=True,
    checked=("file",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (LEAD_ANGLE, FRICTION_COEFFICIENT)


def lead_angle(p, d_m):
    """Lead angle lambda = atan(p / (pi d_m)) (rad)."""
    return m.arctan(p / (m.pi * d_m))


def friction_angle(mu):
    """Friction angle phi_f = atan(mu) (rad)."""
    return m.arctan(mu)


def efficiency_forward(lam, phi_f):
    """Efficiency driving the nut by the screw, tan(lambda) / tan(lambda + phi_f)."""
    return m.tan(lam) / m.tan(lam + phi_f)


def efficiency_backdrive(lam, phi_f):
    """Efficiency when the axial load drives the screw, tan(lambda - phi_f) / tan(lambda).

    Zero or negative means the screw self-locks.
    """
    return m.tan(lam - phi_f) / m.tan(lam)


def drive_torque(P, d_m, lam, phi_f):
    """Screw torque (N*mm) to push an axial load P (N): (d_m/2) P tan(lambda + phi_f), eq. 1."""
    return 0.5 * d_m * P * m.tan(lam + phi_f)


def torsional_stiffness(K_axial, d_m, h, lam, phi_f):
    """Torsional stiffness at the screw (N*mm/rad) equivalent to an axial stiffness (N/mm).

    K_theta = (d_m/2) K (h/2 pi) tan(lambda + phi_f), [Z00] eq. 5; h is the lead (mm).
    """
    return 0.5 * d_m * K_axial * h / (2.0 * m.pi) * m.tan(lam + phi_f)


def axial_stiffness(K_theta, d_m, h, lam, phi_f):
    """Axial stiffness (N/mm) equivalent to a torsional stiffness, [Z00] eq. 7.

    K = 4 pi K_theta / (d_m h tan(lambda + phi_f)), the inverse of
    :func:`torsional_stiffness`.
    """
    return 4.0 * m.pi * K_theta / (d_m * h * m.tan(lam + phi_f))


def series_stiffness(*stiffnesses):
    """Stiffness of members in series, 1/K = sum 1/K_i (same units for all K_i)."""
    if not stiffnesses:
        raise ValueError("series_stiffness needs at least one stiffness")
    total = 0.0
    for k in stiffnesses:
        total = total + 1.0 / k
    return 1.0 / total
