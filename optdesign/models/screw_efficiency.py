"""Screw efficiency by kind of screw, forward and back-driving (docs/screw.md, 6, 8).

One entry point, :func:`screw_efficiency`, for the three screws an actuator can use:

``"ball"``
    Rolling friction coefficient mu = tan(phi_f), 0.002-0.01 (HIWIN BS-08-2-EN-1704-K,
    Fig. 2.1 plots mu = 0.003, 0.005, 0.01):
    eta = tan(lam) / tan(lam + phi_f), eta' = tan(lam - phi_f) / tan(lam).
``"sliding"`` (trapezoidal ISO 2904 Tr, Acme)
    Flank friction mu on a flank of half-angle alpha (Tr: 30 deg thread, alpha = 15 deg;
    Acme: 29 deg thread, alpha = 14.5 deg). The flank tilts the normal force, so the
    friction force is mu N = mu F / cos(alpha_n) for an axial load F: the screw behaves as
    a square thread with mu' = mu / cos(alpha_n) (the sec(alpha) factor of the power-screw
    chapters of Shigley, *Mechanical Engineering Design*, and Bhandari, *Design of Machine
    Elements*), where alpha_n is the flank angle in the normal section, tan(alpha_n) = tan(alpha)
    cos(lam). The textbooks take alpha_n = alpha (``normal_section=False``); the
    difference is cos(lam), 0.1 % in mu' at lam = 3 deg.
``"roller"``
    Planetary roller screw, [L16] eq. 14 (:func:`roller_screw.efficiency`) forward and
    :func:`roller_screw.efficiency_backdrive` back (friction terms of eq. 11-13 reversed;
    derivation in its docstring). The screw radius is r_s = d_m / 2.

Lead angle lam = atan(p / (pi d_m)) for all three (single start; for n starts pass the
lead p = n x pitch). Every formula is smooth and goes through :mod:`optdesign.math`, so a
design problem passes CasADi symbols for p, d_m or the friction values.

Forward vs back: eta / eta' = tan^2(lam) / (tan(lam + phi) tan(lam - phi)), so eta' < eta
exactly where lam < 45 deg (above it the back-driving efficiency is the higher one); the
roller model's eta' can exceed eta at second order in the loss (see
:func:`roller_screw.efficiency_backdrive`).

Self-locking: the load cannot drive the screw where eta' <= 0. For the ball and sliding
screws that is lam <= phi_f (or phi'); :func:`self_locking_margin` gives phi_f - lam
(> 0 self-locks), a smooth constraint.

Units: p, d_m, r_RP, f_r in mm; angles in rad; mu, f_k dimensionless.

Validity
--------
The lead angle and the friction coefficient of :mod:`optdesign.models.screw` (the
inclined-plane model every kind uses; the same records), and for the roller screw the
contact angle of :mod:`optdesign.models.roller_screw`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models import roller_screw, screw
from optdesign.models._checks import require_nonnegative, require_positive

#: The ranges of validity of this model: the inclined plane's and the roller screw's.
VALIDITY = (*screw.VALIDITY, *roller_screw.VALIDITY)


#: Kinds of screw :func:`screw_efficiency` knows ("trapezoidal" and "acme" are sliding).
SCREW_KINDS = ("ball", "sliding", "trapezoidal", "acme", "roller")

#: Flank half-angle of the ISO 2904 trapezoidal thread (Tr, 30 deg included), rad.
TR_FLANK_HALF_ANGLE = float(np.radians(15.0))
#: Flank half-angle of the Acme thread (29 deg included), rad.
ACME_FLANK_HALF_ANGLE = float(np.radians(14.5))

#: Default friction coefficients: ball screw 0.003 (docs/screw.md); sliding screw 0.1, a
#: lubricated steel-on-bronze value (Bhandari's worked examples use 0.12-0.15): pass your own.
MU_BALL_DEFAULT = 0.003
MU_SLIDING_DEFAULT = 0.1

DIRECTIONS = ("forward", "back")


def normal_flank_angle(alpha, lam):
    """Flank half-angle in the normal section, tan(alpha_n) = tan(alpha) cos(lam) (rad)."""
    return m.arctan(m.tan(alpha) * m.cos(lam))


def sliding_friction_angle(mu, alpha, lam=None):
    """Friction angle phi' = atan(mu / cos(alpha_n)) of a flanked sliding thread (rad).

    ``lam=None`` takes alpha_n = alpha (the textbooks' approximation); with the lead angle
    the normal-section angle :func:`normal_flank_angle` is used.
    """
    alpha_n = alpha if lam is None else normal_flank_angle(alpha, lam)
    return m.arctan(mu / m.cos(alpha_n))


def _kind(kind: str) -> str:
    if kind not in SCREW_KINDS:
        raise InputError("kind", f"{kind!r} not in {SCREW_KINDS}")
    return "sliding" if kind in ("trapezoidal", "acme") else kind


def equivalent_friction_angle(
    kind: str,
    p,
    d_m,
    mu=None,
    flank_angle=None,
    normal_section: bool = True,
):
    """Friction angle phi with eta = tan(lam)/tan(lam + phi) for a ball or sliding screw (rad).

    Parameters
    ----------
    kind
        ``"ball"``, ``"sliding"``, ``"trapezoidal"`` or ``"acme"``.
    p, d_m
        Lead and mean (ball-centre / pitch) diameter (mm).
    mu
        Friction coefficient; defaults :data:`MU_BALL_DEFAULT`, :data:`MU_SLIDING_DEFAULT`.
    flank_angle
        Flank half-angle in the axial section (rad), sliding screws only; defaults to Tr
        (15 deg) or, for ``"acme"``, 14.5 deg.
    normal_section
        Use alpha_n with tan(alpha_n) = tan(alpha) cos(lam) (True) or alpha_n = alpha.
    """
    k = _kind(kind)
    if k == "roller":
        raise InputError(
            "kind", "a roller screw has no single friction angle; use screw_efficiency"
        )
    if k == "ball":
        mu = MU_BALL_DEFAULT if mu is None else mu
        require_nonnegative("mu", mu)
        return screw.friction_angle(mu)
    mu = MU_SLIDING_DEFAULT if mu is None else mu
    require_nonnegative("mu", mu)
    if flank_angle is None:
        flank_angle = ACME_FLANK_HALF_ANGLE if kind == "acme" else TR_FLANK_HALF_ANGLE
    lam = screw.lead_angle(p, d_m) if normal_section else None
    return sliding_friction_angle(mu, flank_angle, lam)


def screw_efficiency(
    kind: str,
    p,
    d_m,
    mu=None,
    direction: str = "forward",
    *,
    flank_angle=None,
    normal_section: bool = True,
    beta=roller_screw.BETA_DEFAULT,
    r_RP=10.0,
    f_k=0.055,
    f_r=0.01,
):
    """Efficiency of a screw, forward (torque drives the nut) or back (load drives the screw).

    Parameters
    ----------
    kind
        One of :data:`SCREW_KINDS`.
    p
        Lead (mm).
    d_m
        Mean diameter (mm): ball-centre diameter of a ball screw, pitch diameter of a
        sliding screw, 2 r_s of a roller screw.
    mu
        Friction coefficient of a ball or sliding screw (see
        :func:`equivalent_friction_angle`); ignored for a roller screw.
    direction
        ``"forward"`` or ``"back"``.
    flank_angle, normal_section
        Sliding screws: flank half-angle (rad) and normal-section reading.
    beta, r_RP, f_k, f_r
        Roller screw: contact angle (rad), roller thread curvature radius (mm), sliding
        friction, rolling friction length (mm); defaults are [L16]'s.

    Returns
    -------
    eta
        Efficiency; back-driving values <= 0 mean the screw self-locks.
    """
    if direction not in DIRECTIONS:
        raise InputError("direction", f"{direction!r} not in {DIRECTIONS}")
    require_positive("p", p)
    require_positive("d_m", d_m)
    k = _kind(kind)
    lam = screw.lead_angle(p, d_m)
    if k == "roller":
        fn = (
            roller_screw.efficiency if direction == "forward" else roller_screw.efficiency_backdrive
        )
        return fn(lam, beta, 0.5 * d_m, r_RP, f_k, f_r)
    phi = equivalent_friction_angle(kind, p, d_m, mu, flank_angle, normal_section)
    if direction == "forward":
        return screw.efficiency_forward(lam, phi)
    return screw.efficiency_backdrive(lam, phi)


def self_locking_margin(kind: str, p, d_m, mu=None, **kwargs: Any):
    """phi - lam (rad) for a ball or sliding screw: > 0 self-locks, < 0 back-drivable.

    Smooth in p, d_m and mu; a design that must hold its load with the motor unpowered
    asks for margin >= 0, one that must be back-drivable for margin <= 0. Keyword
    arguments as :func:`equivalent_friction_angle`.
    """
    return equivalent_friction_angle(kind, p, d_m, mu, **kwargs) - screw.lead_angle(p, d_m)


def is_back_drivable(kind: str, p, d_m, mu=None, **kwargs: Any):
    """True where the axial load can drive the screw (back-driving efficiency eta' > 0).

    Numeric inputs only (a boolean has no derivative): a solver uses
    ``screw_efficiency(..., direction="back")`` or :func:`self_locking_margin` as the
    constraint instead. Keyword arguments as :func:`screw_efficiency`.
    """
    if m.is_symbolic(p, d_m, mu):
        raise InputError("p", "is_back_drivable needs numbers; constrain screw_efficiency instead")
    return np.asarray(screw_efficiency(kind, p, d_m, mu, "back", **kwargs)) > 0.0
