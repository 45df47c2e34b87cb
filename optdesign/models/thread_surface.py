"""Helicoid thread flanks of the planetary roller screw ([C-PRSM], "unified equation").

Each part i (screw s, roller r, nut n) has its own frame: z along its axis, x through
the start of the thread. A flank point is given by the surface parameters (rho, theta):
radius and polar angle in that frame,

    x = rho cos(theta),   y = rho sin(theta),
    z = xi h_i(rho) / cos(lambda_i) + l_i theta / (2 pi) + start * p,

with xi = +1 the upper flank (facing +z) and xi = -1 the lower flank, h_i the thread
profile in the **normal section** (half tooth thickness as a function of radius), l_i the
lead, lambda_i the helix angle at the nominal (pitch) radius and p the pitch. Dividing by
cos(lambda_i) turns normal-section thickness into axial thickness; this is the unified
equation of Qiao et al. ([C-PRSM] ref. [8]) as far as the extracted text lets it be read
(the equation itself was lost). It is an approximation of the exact normal-to-axial
section conversion that is good to O(lambda^2) in the profile shape.

Profiles (normal section, nominal radius r0, flank half-angle beta between the flank and
the radial plane, so the axial slope of the flank at r0 is tan(beta)/cos(lambda)):

* ``"screw"`` (external, straight flank):  h = (p/4) cos(lambda) - (rho - r0) tan(beta)
* ``"nut"`` (internal, straight flank):    h = (p/4) cos(lambda) + (rho - r0) tan(beta)
* ``"roller"`` (convex arc of radius R, by default R = r0 / sin(beta) centred on the
  roller axis, the usual "spherical" roller thread):
  h = (p/4) cos(lambda) - R cos(beta) + sqrt(R^2 - (rho - rho_c)^2), rho_c = r0 - R sin(beta)

All three give half an axial pitch of tooth at r0 and the flank slope beta there. The
material of every tooth lies where ``xi (z - l theta/2pi - start p) < h/cos(lambda)``,
so the outward normal of a flank has ``sign(n_z) = xi`` (used to orient normals).

The functions take CasADi symbols (for :class:`~optdesign.models.differential_geometry.Surface`)
or floats/NumPy arrays, through :mod:`optdesign.math`.

Validity
--------
helix angle lambda : small (the profile to O(lambda^2))
    The normal-to-axial conversion h / cos(lambda) is exact to O(lambda^2) in the
    profile's shape: 1 % at lambda = 8 deg. Documented (roller screws have 2-10 deg).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models.validity import Validity

HELIX_ANGLE = Validity(
    "thread_surface.helix_angle",
    "unified thread-flank equation",
    "helix angle",
    0.0,
    float(np.radians(8.0)),
    "rad",
    "the normal-to-axial profile conversion is exact to O(lambda^2): 1 % at 8 deg",
    shown_unit="deg",
    scale=float(180.0 / np.pi),
    checked=("documented",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (HELIX_ANGLE,)


PROFILES = ("screw", "roller", "nut")


def profile_half_thickness(rho, kind: str, r0, pitch, helix_angle, beta, arc_radius=None):
    """Normal-section half tooth thickness h(rho) (mm) of a thread profile.

    Parameters
    ----------
    rho
        Radius (mm), CasADi or NumPy.
    kind
        ``"screw"``, ``"roller"`` or ``"nut"``.
    r0
        Nominal (pitch) radius of the part (mm).
    pitch
        Thread pitch p (mm).
    helix_angle
        Helix angle lambda at r0 (rad).
    beta
        Flank half-angle (rad), between flank and radial plane in the normal section.
    arc_radius
        Roller only: radius of the arc profile (mm); default ``r0 / sin(beta)``, the
        arc centred on the roller axis (spherical roller thread). Any other radius keeps
        the slope beta and the thickness at r0, with the arc centre at radius
        ``r0 - R sin(beta)``.
    """
    base = 0.25 * pitch * m.cos(helix_angle)
    if kind == "screw":
        return base - (rho - r0) * m.tan(beta)
    if kind == "nut":
        return base + (rho - r0) * m.tan(beta)
    if kind == "roller":
        R = r0 / m.sin(beta) if arc_radius is None else arc_radius
        rho_c = r0 - R * m.sin(beta)
        return base - R * m.cos(beta) + m.sqrt(R**2 - (rho - rho_c) ** 2)
    raise InputError("kind", f"thread profile must be one of {PROFILES}, got {kind!r}")


def thread_flank(
    rho, theta, *, kind: str, xi: int, r0, pitch, lead, beta, start: int = 0, arc_radius=None
):
    """Point of a helicoid thread flank in the part's own frame.

    Parameters
    ----------
    rho, theta
        Surface parameters: radius (mm) and polar angle (rad).
    kind
        Profile, ``"screw"``, ``"roller"`` or ``"nut"`` (see module docstring).
    xi
        +1 upper flank, -1 lower flank.
    r0, pitch, lead
        Nominal radius, pitch and lead (mm); the number of starts is lead / pitch.
    beta
        Flank half-angle (rad) in the normal section.
    start
        Which start of a multi-start thread (shifts the flank by ``start * pitch``).
    arc_radius
        Roller arc radius (mm), see :func:`profile_half_thickness`.

    Returns
    -------
    3x1 CasADi SX if any input is symbolic, else a NumPy array (3, ...).
    """
    if xi not in (1, -1):
        raise InputError("xi", f"flank selector must be +1 (upper) or -1 (lower), got {xi}")
    lam = m.arctan(lead / (2.0 * m.pi * r0))
    h = profile_half_thickness(rho, kind, r0, pitch, lam, beta, arc_radius)
    x = rho * m.cos(theta)
    y = rho * m.sin(theta)
    z = xi * h / m.cos(lam) + lead * theta / (2.0 * m.pi) + start * pitch
    if m.is_symbolic(rho, theta, r0, pitch, lead, beta):
        return ca.vertcat(x, y, z)
    return np.array([x, y, z])


def flank_builder(
    kind: str,
    xi: int,
    r0: float,
    pitch: float,
    lead: float,
    beta: float,
    start: int = 0,
    arc_radius: float | None = None,
):
    """A ``builder(u, v, p)`` for :class:`~optdesign.models.differential_geometry.Surface`.

    u = rho, v = theta; the geometry is baked in as numbers (p unused).
    """

    def builder(u, v, _p):
        return thread_flank(
            u,
            v,
            kind=kind,
            xi=xi,
            r0=r0,
            pitch=pitch,
            lead=lead,
            beta=beta,
            start=start,
            arc_radius=arc_radius,
        )

    return builder
