"""Power-off lock on the motor shaft ([Y16], Yang & Chen 2016; docs/lock.md).

A disturbance moment M at the motor shaft (the hinge moment reflected back through the
linkage, the screw and the gears) must be held with the power off and released with the
power on. The magnet of the lock must beat:

* friction-plate lock: the spring force F that presses the plates (it must produce the
  friction moment M), eq. 1-2;
* pin lock: the friction that the side force F1 = M/R raises at the pin's three contacts
  plus the return spring, eq. 3-5;
* pin lock improved with a rolling bearing, eq. 7-9 (the force balance, eq. 8, was lost in
  the extracted text; reconstructed below, assumptions in :func:`pin_lock_force_rolling`).

Units: M in N*mm, radii in mm, forces in N (the paper's SI inputs, metres, are converted
at the boundary: 0.03 m -> 30 mm). Every formula goes through :mod:`optdesign.math`, so the lock
force is a CasADi expression in a design problem and a NumPy array in a sweep.

The coupling to a mechanism is :func:`motor_shaft_lock_load`: hinge moment -> nut force
(virtual work) -> motor-shaft moment through the back-driving efficiencies -> the lock
force for the largest moment over the stroke.

Validity
--------
friction coefficient mu : 0 < mu <= 1
    Coulomb friction of lining, plate and pin contacts (0.1-0.6); above 1 the hold is
    adhesion or a form lock, which the [Y16] laws do not describe (checked when the file
    is read, ``requirements.lock.mu``).
bearing misalignment : <= 0.5 deg
    The reconstructed balance of the rolling pin lock is the paper's for a bearing plane
    within 0.5 deg of the plane of F1. Documented.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models._checks import require_nonnegative, require_positive
from optdesign.models.loads import backdriven_motor_torque
from optdesign.models.validity import Validity

LOCK_FRICTION = Validity(
    "lock.friction",
    "motor-shaft lock",
    "friction coefficient",
    0.0,
    1.0,
    "",
    "Coulomb friction of the lock's contacts lies below 1 (linings 0.1-0.6)",
    open_lower=True,
    checked=("file",),
)
MISALIGNMENT = Validity(
    "lock.misalignment",
    "rolling pin lock",
    "bearing misalignment",
    0.0,
    float(np.radians(0.5)),
    "rad",
    "the paper's balance holds for a bearing plane within 0.5 deg of the load's",
    shown_unit="deg",
    scale=float(180.0 / np.pi),
    checked=("documented",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (LOCK_FRICTION, MISALIGNMENT)


#: Pressure laws of a friction annulus: a new lining (uniform pressure) and a worn-in one
#: (uniform wear, p r = const).
FRICTION_LAWS = ("uniform_pressure", "uniform_wear")

#: Where the rolling bearing of the improved pin lock sits (see pin_lock_force_rolling).
BEARING_PLACES = ("guide", "tip")

#: The paper's bound on the angle between the bearing plane and the plane of F1 (rad).
MISALIGNMENT_DEFAULT = float(np.radians(0.5))


# --- friction-plate lock ---------------------------------------------------------------
def friction_radius(r1, r2, law: str = "uniform_pressure"):
    """Effective friction radius r_f of an annulus r1...r2 (mm), M = mu F r_f.

    Parameters
    ----------
    r1, r2
        Inner and outer radius of the friction annulus (mm), 0 <= r1 < r2.
    law
        ``"uniform_pressure"``: r_f = (2/3)(r2^3 - r1^3)/(r2^2 - r1^2) ([Y16] eq. 1);
        ``"uniform_wear"``: r_f = (r1 + r2)/2 (p r constant, a worn-in lining; the smaller
        of the two, so the conservative choice for the spring force).
    """
    require_nonnegative("r1", r1)
    require_positive("r2", r2)
    if not m.is_symbolic(r1, r2) and np.any(np.asarray(r2) <= np.asarray(r1)):
        raise InputError("r2", f"outer radius must exceed inner radius r1={r1!r}, got {r2!r}")
    if law == "uniform_pressure":
        return (2.0 / 3.0) * (r2**3 - r1**3) / (r2**2 - r1**2)
    if law == "uniform_wear":
        return 0.5 * (r1 + r2)
    raise InputError("law", f"{law!r} not in {FRICTION_LAWS}")


def friction_plate_force(M, r1, r2, mu, law: str = "uniform_pressure", faces: int = 1):
    """Spring force F (N) that lets a friction-plate lock hold the moment M (N*mm), eq. 2.

    F = M / (faces mu r_f); the magnet must pull at least F to release the lock.

    Parameters
    ----------
    M
        Moment at the motor shaft (N*mm).
    r1, r2
        Inner and outer radius of the annulus (mm).
    mu
        Friction coefficient of the plates (the paper: 0.3, metal on metal).
    law
        Pressure law, see :func:`friction_radius`.
    faces
        Number of friction faces in series (the paper: one pair of plates, 1).
    """
    require_positive("mu", mu)
    if not isinstance(faces, int) or faces < 1:
        raise InputError("faces", f"must be a positive integer, got {faces!r}")
    return M / (faces * mu * friction_radius(r1, r2, law))


# --- pin lock ----------------------------------------------------------------------------
def pin_guide_reactions(F1, lever_ratio=4.0):
    """Normal reactions (F2, F3) of the pin's two guide contacts under the side force F1.

    The pin is a beam loaded by F1 at its tip, held by the middle contact at distance La1
    from the tip and the lower contact a further La2 = lever_ratio * La1 away. Moments
    about the lower contact: F2 La2 = F1 (La1 + La2); about the middle one: F3 La2 = F1 La1.
    With La2 = 4 La1 (the paper): F2 = 1.25 F1, F3 = 0.25 F1, F2 + F3 = 1.5 F1.
    """
    require_positive("lever_ratio", lever_ratio)
    F2 = F1 * (1.0 + 1.0 / lever_ratio)
    F3 = F1 / lever_ratio
    return F2, F3


def pin_lock_force(M, R, mu_h=0.1, lever_ratio=4.0, spring_fraction=0.1):
    """Magnet force f_a (N) that retracts a sliding pin lock against the moment M, eq. 3-5.

    f_a = mu_h (F1 + F2 + F3) + f_T with F1 = M/R, the guide reactions of
    :func:`pin_guide_reactions` and the return spring f_T = spring_fraction * F1. With the
    paper's mu_h = 0.1, La2 = 4 La1, f_T = 0.1 F1: f_a = 0.35 M/R (eq. 5).

    Parameters
    ----------
    M
        Moment at the motor shaft (N*mm).
    R
        Radius of the pin's contact with the boss from the shaft axis (mm); the paper
        takes the motor radius.
    mu_h
        Sliding friction coefficient at each contact.
    lever_ratio
        La2 / La1 (guide span over tip overhang).
    spring_fraction
        Return spring force as a fraction of F1 (it only has to push the pin out).
    """
    require_positive("R", R)
    require_nonnegative("mu_h", mu_h)
    require_nonnegative("spring_fraction", spring_fraction)
    F1 = M / R
    F2, F3 = pin_guide_reactions(F1, lever_ratio)
    return mu_h * (F1 + F2 + F3) + spring_fraction * F1


def rolling_contact_resistance(N, mu_g, mu_h, misalignment):
    """Axial resistance (N) of a rolling bearing whose plane is tilted by ``misalignment``.

    The pin moves along its axis; the bearing rolls in its own plane, tilted by delta from
    that direction, so the motion splits into rolling (cos delta, resisted by the bearing's
    equivalent friction mu_g) and side slip (sin delta, resisted by sliding friction mu_h).
    Weighting each resistance by its share of the motion (an engineering approximation,
    not a Coulomb slip analysis): N (mu_g cos delta + mu_h sin delta).
    """
    return N * (mu_g * m.cos(misalignment) + mu_h * m.sin(misalignment))


def pin_lock_force_rolling(
    M,
    R,
    mu_h=0.1,
    mu_g=0.01,
    misalignment=MISALIGNMENT_DEFAULT,
    lever_ratio=4.0,
    spring_fraction=0.1,
    bearing: str = "guide",
):
    """Magnet force f_b (N) of the pin lock improved with a rolling bearing, eq. 7-9.

    **Reconstruction.** The paper's force balance (eq. 8) is lost from the extracted text;
    only eq. 7 (f_b = f1 + f_b2 + f_b3 + f_T), the data (mu_h = 0.1, mu_g = 0.01, bearing
    plane within 0.5 deg of the plane of F1, Lb2 = 4 Lb1, "the same parameters") and the
    result f_b = 0.0632 F survive. Assumptions made here:

    1. The geometry and the moment balance are those of the sliding pin
       (:func:`pin_guide_reactions`): F1 = M/R, F2 = (1 + 1/k) F1, F3 = F1/k, k = Lb2/Lb1.
    2. ``bearing="guide"`` (default): the bearing is *inside* the electromagnetic pin, as the
       text says ("在電磁銷內部增加滾動軸承"), and replaces the sliding contact that carries
       the largest reaction, the middle guide contact F2; the tip contact F1 and the lower
       contact F3 keep sliding friction mu_h.
       ``bearing="tip"``: the bearing sits at the tip, where F1 acts (the other reading of
       "the bearing plane is not exactly in the plane of F1"); both guide contacts slide.
    3. The misalignment delta of the bearing plane makes the bearing slip sideways in the
       fraction sin(delta) of its travel: :func:`rolling_contact_resistance`.
    4. Return spring f_T = spring_fraction * F1, as for the sliding pin.

    With the paper's data, "guide" gives f_b = 0.2386 M/R (6.31 % of the friction plate,
    paper 6.32 %); "tip" gives 0.2609 M/R (6.89 %). The paper's equation may differ; the
    reproduction prints both readings.

    Parameters
    ----------
    M, R, mu_h, lever_ratio, spring_fraction
        As in :func:`pin_lock_force`.
    mu_g
        Equivalent sliding friction coefficient of the rolling bearing.
    misalignment
        Angle between the bearing plane and the plane of the load (rad).
    bearing
        ``"guide"`` or ``"tip"``, see assumption 2.
    """
    require_positive("R", R)
    require_nonnegative("mu_h", mu_h)
    require_nonnegative("mu_g", mu_g)
    require_nonnegative("misalignment", misalignment)
    require_nonnegative("spring_fraction", spring_fraction)
    F1 = M / R
    F2, F3 = pin_guide_reactions(F1, lever_ratio)
    if bearing == "guide":
        friction = mu_h * F1 + rolling_contact_resistance(F2, mu_g, mu_h, misalignment) + mu_h * F3
    elif bearing == "tip":
        friction = rolling_contact_resistance(F1, mu_g, mu_h, misalignment) + mu_h * (F2 + F3)
    else:
        raise InputError("bearing", f"{bearing!r} not in {BEARING_PLACES}")
    return friction + spring_fraction * F1


# --- lock designs, usable as objects in problems -------------------------------------------
@dataclass(frozen=True)
class FrictionPlateLock:
    """Friction-plate lock: annulus r1...r2 (mm), friction mu, pressure ``law``."""

    r1: Any
    r2: Any
    mu: Any = 0.3
    law: str = "uniform_pressure"
    faces: int = 1

    def force(self, M):
        """Magnet force (N) to release against the moment M (N*mm)."""
        return friction_plate_force(M, self.r1, self.r2, self.mu, self.law, self.faces)


@dataclass(frozen=True)
class PinLock:
    """Pin lock at radius R (mm); ``bearing`` None (sliding), ``"guide"`` or ``"tip"``."""

    R: Any
    mu_h: Any = 0.1
    lever_ratio: Any = 4.0
    spring_fraction: Any = 0.1
    bearing: str | None = None
    mu_g: Any = 0.01
    misalignment: Any = MISALIGNMENT_DEFAULT

    def force(self, M):
        """Magnet force (N) to release against the moment M (N*mm)."""
        if self.bearing is None:
            return pin_lock_force(M, self.R, self.mu_h, self.lever_ratio, self.spring_fraction)
        return pin_lock_force_rolling(
            M,
            self.R,
            self.mu_h,
            self.mu_g,
            self.misalignment,
            self.lever_ratio,
            self.spring_fraction,
            self.bearing,
        )


# --- coupling to the mechanism ---------------------------------------------------------------
@dataclass
class LockLoad:
    """Result of :func:`motor_shaft_lock_load`.

    Attributes
    ----------
    moment
        Moment at the motor shaft at each grid angle (N*mm), >= 0.
    moment_max
        Its maximum over the grid (N*mm), the design load of the lock.
    force
        Magnet force the lock needs for ``moment_max`` (N); None without a lock.
    """

    moment: Any
    moment_max: Any
    force: Any = None


def motor_shaft_lock_load(
    mechanism, phi, M_h, eta_screw_back=1.0, eta_gear_back=1.0, lock=None
) -> LockLoad:
    """Hinge moment reflected to the motor shaft over the stroke, and the lock force.

    T(phi) = |F_a(phi)| p max(eta', 0) eta_g' / (2 pi i_a), with F_a = M_h / (dx/dphi) the
    nut force by virtual work (models.loads). A self-locking screw (eta' <= 0) passes no
    moment to the motor shaft, hence the clip at zero. The lock must hold the largest
    moment over the grid; ``lock.force`` turns it into the magnet force, so a problem can
    bound or minimise the lock force (CasADi) or sweep designs (NumPy, grid on the last
    axis).

    Parameters
    ----------
    mechanism
        A :class:`optdesign.mechanisms.Mechanism` (CrankSlider, ShiftingFork).
    phi
        Deflection grid (rad).
    M_h
        Hinge moment at the output (N*mm); its sign does not matter.
    eta_screw_back, eta_gear_back
        Back-driving efficiencies of the screw (e.g. models.screw.efficiency_backdrive)
        and the gear pair.
    lock
        Object with a ``force(M)`` method (:class:`FrictionPlateLock`, :class:`PinLock`),
        or None to get the moments only.
    """
    F_a = m.fabs(mechanism.nut_force(phi, M_h))
    T = backdriven_motor_torque(
        F_a, mechanism.p, mechanism.i_a, m.fmax(eta_screw_back, 0.0), m.fmax(eta_gear_back, 0.0)
    )
    T_max = m.grid_max(T)
    return LockLoad(T, T_max, None if lock is None else lock.force(T_max))
