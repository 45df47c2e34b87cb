"""Planetary roller screw efficiency ([L16], Li et al. 2016, eq. 7-14; docs/roller_screw.md),
and a selector between it and the ball-screw efficiency of models.screw.

Eq. 14 as read in docs/roller_screw.md (a = alpha_s helix angle, b = beta contact angle,
tan rho = f_r / (r_RP sin b), rho the equivalent rolling-friction angle):

    eta = r_s tan(a) [cos a cos rho sin b - sin a sin rho
                      - f_k (sin a cos rho + cos a sin rho sin b)]
          / ( r_s (cos rho sin a sin b + sin rho cos a)
              + r_RP (1 - cos rho)(sin rho + cos rho) cos a cos b )

The extracted text drops "alpha_s" after "tan"; with it, eta = 1 when f_k = f_r = 0
(eq. 8-9 of the paper), which the tests check. The helix angle is the screw's lead angle
(tan a = P_s / (2 pi r_s), eq. 9), the same angle as models.screw.lead_angle(p, 2 r_s).

Units: r_s, r_RP and the rolling-friction coefficient f_r are lengths in mm (the paper
gives metres: r_s = 0.04 m -> 40 mm, f_r = 1e-5 m -> 0.01 mm); f_k is dimensionless.

Validity
--------
contact angle beta : 0 < beta < 90 deg
    Eq. 10-14 resolve the contact force on a flank inclined by beta; sin(beta) > 0 is
    needed for the rolling-friction angle (refused by the functions outside (0, pi)).
    The paper's figures span 30-60 deg.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models import screw
from optdesign.models.validity import Validity

CONTACT_ANGLE = Validity(
    "roller_screw.contact_angle",
    "planetary roller screw efficiency",
    "contact angle beta",
    0.0,
    float(np.pi),
    "rad",
    "the rolling-friction angle needs a flank that carries load, sin(beta) > 0",
    shown_unit="deg",
    scale=float(180.0 / np.pi),
    open_lower=True,
    open_upper=True,
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (CONTACT_ANGLE,)


def rolling_friction_angle(f_r, r_RP, beta):
    """Equivalent rolling-friction angle rho, tan rho = f_r / (r_RP sin beta) (rad), eq. 10."""
    return m.arctan(f_r / (r_RP * m.sin(beta)))


def _check(beta, r_s, r_RP, f_k, f_r) -> None:
    for field, value in (("r_s", r_s), ("r_RP", r_RP)):
        if not m.is_symbolic(value) and np.any(~(np.asarray(value, dtype=float) > 0)):
            raise InputError(field, f"must be > 0, got {value!r}")
    for field, value in (("f_k", f_k), ("f_r", f_r)):
        if not m.is_symbolic(value) and np.any(~(np.asarray(value, dtype=float) >= 0)):
            raise InputError(field, f"must be >= 0, got {value!r}")
    if not m.is_symbolic(beta) and np.any(np.sin(np.asarray(beta, dtype=float)) <= 0):
        raise InputError("beta", f"contact angle must lie in (0, pi), got {beta!r}")


def efficiency(alpha_s, beta, r_s, r_RP, f_k, f_r):
    """Forward efficiency of a planetary roller screw, eq. 14 (docs/roller_screw.md reading).

    Parameters
    ----------
    alpha_s
        Helix (lead) angle of the screw (rad).
    beta
        Contact angle (rad), in (0, pi/2].
    r_s
        Screw radius (mm).
    r_RP
        Curvature radius of the roller thread (mm).
    f_k
        Sliding friction coefficient (the paper: 0.055).
    f_r
        Rolling friction coefficient, a length (mm; the paper: 1e-5 m = 0.01 mm).

    Returns
    -------
    eta
        Efficiency (can fall to <= 0 for tiny helix angles: the drive then jams).
    """
    _check(beta, r_s, r_RP, f_k, f_r)
    a, b = alpha_s, beta
    rho = rolling_friction_angle(f_r, r_RP, b)
    sa, ca_, sb, cb = m.sin(a), m.cos(a), m.sin(b), m.cos(b)
    sr, cr = m.sin(rho), m.cos(rho)
    num = r_s * m.tan(a) * (ca_ * cr * sb - sa * sr - f_k * (sa * cr + ca_ * sr * sb))
    den = r_s * (cr * sa * sb + sr * ca_) + r_RP * (1.0 - cr) * (sr + cr) * ca_ * cb
    return num / den


def efficiency_backdrive(alpha_s, beta, r_s, r_RP, f_k, f_r):
    """Back-driving efficiency (the axial load drives the screw), derived from eq. 11-14.

    Seed 003 derives only the forward efficiency. Its eq. 11 turns the contact normal by
    the rolling-friction angle rho against the motion and eq. 12 adds sliding friction
    f_k along the tangent; when the load drives, the motion reverses, so both friction
    terms change sign (rho -> -rho, f_k -> -f_k), and the efficiency is output over input
    power, eta' = 2 pi M / (P_s F_a) = M / (r_s tan(a) F_a):

        F_a / N = cos a cos rho sin b + sin a sin rho + f_k (sin a cos rho - cos a sin rho sin b)
        M / N   = r_s (cos rho sin a sin b - sin rho cos a)
                  - r_RP (1 - cos rho)(cos rho - sin rho) cos a cos b

    The last (rolling-resistance) term of eq. 14's denominator is a loss in either
    direction, so it is subtracted from the output torque here (the reading of this
    project; it is O(rho^2), 1e-6 of the first term at the paper's numbers). Checks (see
    the tests): eta' = 1 without friction; eta' = tan(a - rho)/tan(a), the ball-screw
    back-driving form, at beta = 90 deg with f_k = 0. Eq. 12 models sliding friction as a
    force f_k N along the tangent, not as a friction angle; that term alone gives
    eta = 1 - x forward and 1/(1 + x) back, so eta' can exceed eta at second order in the
    loss (0.975016 vs 0.974796 at the paper's 10/45 deg). eta' <= 0 means the screw
    self-locks under axial load. Arguments and units as :func:`efficiency`.
    """
    _check(beta, r_s, r_RP, f_k, f_r)
    a, b = alpha_s, beta
    rho = rolling_friction_angle(f_r, r_RP, b)
    sa, ca_, sb, cb = m.sin(a), m.cos(a), m.sin(b), m.cos(b)
    sr, cr = m.sin(rho), m.cos(rho)
    force = ca_ * cr * sb + sa * sr + f_k * (sa * cr - ca_ * sr * sb)
    torque = r_s * (cr * sa * sb - sr * ca_) - r_RP * (1.0 - cr) * (cr - sr) * ca_ * cb
    return torque / (r_s * m.tan(a) * force)


def helix_angle(P_s, r_s):
    """Helix angle alpha_s with tan alpha_s = P_s / (2 pi r_s), eq. 9 (rad).

    The same as models.screw.lead_angle(P_s, 2 r_s).
    """
    return screw.lead_angle(P_s, 2.0 * r_s)


#: Kinds of screw the selector knows.
SCREW_KINDS = ("ball", "roller")

#: The contact angle of the paper's example (rad).
BETA_DEFAULT = float(np.radians(45.0))


@dataclass(frozen=True)
class ScrewEfficiency:
    """Which efficiency the drive uses: ball screw by friction angle, or roller screw by
    eq. 14. Build with :meth:`ball` or :meth:`roller`; evaluate with :meth:`forward` on the
    lead angle (rad), CasADi or NumPy.

    Example
    -------
    >>> lam = screw.lead_angle(5.0, 20.0)
    >>> eta = ScrewEfficiency.roller(r_s=10.0).forward(lam)
    >>> T = mechanism.motor_torque(phi, M_h, eta_screw=eta)      # doctest: +SKIP
    """

    kind: str
    mu: Any = 0.003
    beta: Any = BETA_DEFAULT
    r_s: Any = 40.0
    r_RP: Any = 10.0
    f_k: Any = 0.055
    f_r: Any = 0.01

    def __post_init__(self):
        if self.kind not in SCREW_KINDS:
            raise InputError("efficiency.kind", f"{self.kind!r} not in {SCREW_KINDS}")

    @classmethod
    def ball(cls, mu=0.003) -> ScrewEfficiency:
        """Ball screw with friction coefficient mu = tan(phi_f) (0.002-0.01)."""
        return cls("ball", mu=mu)

    @classmethod
    def roller(cls, r_s=40.0, beta=BETA_DEFAULT, r_RP=10.0, f_k=0.055, f_r=0.01) -> ScrewEfficiency:
        """Planetary roller screw (eq. 14); defaults are the paper's (in mm)."""
        return cls("roller", beta=beta, r_s=r_s, r_RP=r_RP, f_k=f_k, f_r=f_r)

    def forward(self, lam):
        """Forward efficiency (screw drives nut) at lead/helix angle ``lam`` (rad)."""
        if self.kind == "ball":
            return screw.efficiency_forward(lam, screw.friction_angle(self.mu))
        return efficiency(lam, self.beta, self.r_s, self.r_RP, self.f_k, self.f_r)

    def backdrive(self, lam):
        """Back-driving efficiency (load drives screw) at lead/helix angle ``lam`` (rad).

        Ball screw: models.screw.efficiency_backdrive. Roller screw: [L16] gives only
        the forward efficiency; :func:`efficiency_backdrive` derives the counterpart by
        reversing the friction terms of eq. 11-13 (stated there).
        """
        if self.kind == "ball":
            return screw.efficiency_backdrive(lam, screw.friction_angle(self.mu))
        return efficiency_backdrive(lam, self.beta, self.r_s, self.r_RP, self.f_k, self.f_r)
