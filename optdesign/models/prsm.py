"""Planetary roller screw (PRSM): geometry, thread-contact matching, principal-plane angle.

Standard PRSM relations ([C-PRSM]; Jones & Velinsky 2013):

* nut nominal diameter ``d_n = d_s + 2 d_r``;
* equal pitch p on all parts; the screw and the nut have the same number of starts n and
  the same lead ``l_s = l_n = n p``; the roller is single-start, ``l_r = p``;
* roller and nut have the same helix angle (no axial drift of the rollers in the nut),
  ``n p / (pi d_n) = p / (pi d_r)``, hence ``d_n = n d_r`` and ``d_s = (n - 2) d_r``.
  A 30 mm, 5-start screw therefore has 10 mm rollers and a 50 mm nut;
* all threads have the same hand (right-hand here).

Contact matching. The loaded flanks are the screw's upper flank against the roller's
lower flank (screw side), and the roller's upper flank against the nut's lower flank
(nut side). The roller axis sits at ``a = r_s + r_r`` from the screw axis, at polar
angle psi (the contact position). Unknowns: the surface parameters (rho, theta) of both
flanks and the axial shift dz of the roller (a rotation of a helicoid about its own axis
is equivalent to a shift along it). Equations: same point (3) and the normal of one body
perpendicular to both tangent vectors of the other (2): a true tangency, solved by
Newton's method with the Jacobian from CasADi. Unlike the paper, which assumes the
screw-side contact on the nominal helix and then averages two plane angles because the
surfaces interfere there, this gives an exact common tangent plane; the contact drifts a
little off the nominal radii (reported).

Principal-plane angle. At the contact the two outward normals are opposite; each body's
two principal directions lie in the common tangent plane. Plane 1 of each body is its
direction of larger convex-positive curvature (kappa_1 = H + sqrt(H^2 - K) with the
normal pointing into the body), and omega in [0, 90 deg] is the angle between the two
planes 1 -- the literal reading of the paper's "[t_s1; n_s] against [t_rs1; n_rs]".
The exact Hertz curvature difference (with cos 2 omega) does not depend on this
labelling; the "omega = 0" simplification does, so :meth:`ThreadContact.hertz_aligned`
offers both the index pairing and the nearest-plane pairing. When the roller thread is
nearly spherical (arc centred on its axis) its two curvatures are close and its
principal directions are set by the helix twist, about 45 deg off the axial plane.

Validity
--------
flank half-angle beta : 5 ... 80 deg; starts n >= 3
    The roller's arc profile and the tooth that fits in the roller need them (refused
    by :class:`PRSMGeometry` otherwise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import casadi as ca
import numpy as np

from optdesign.errors import InputError
from optdesign.models.differential_geometry import Surface, SurfacePoint
from optdesign.models.hertz_point import (
    HertzPointContact,
    effective_modulus,
    hertz_point_contact,
    hertz_point_contact_aligned,
)
from optdesign.models.thread_surface import flank_builder, thread_flank
from optdesign.models.validity import Validity

FLANK_HALF_ANGLE = Validity(
    "prsm.flank_half_angle",
    "planetary roller screw geometry",
    "flank half-angle beta",
    float(np.radians(5.0)),
    float(np.radians(80.0)),
    "rad",
    "the roller's arc profile and a tooth that fits in the roller need 5 < beta < 80 deg",
    shown_unit="deg",
    scale=float(180.0 / np.pi),
    open_lower=True,
    open_upper=True,
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (FLANK_HALF_ANGLE,)


#: Steel (docs/thread_contact.md): E (MPa), Poisson's ratio.
STEEL_E = 2.06e5
STEEL_NU = 0.3


@dataclass(frozen=True)
class PRSMGeometry:
    """Standard planetary roller screw geometry (mm, rad).

    Parameters
    ----------
    d_s
        Screw nominal (pitch) diameter (mm).
    n_starts
        Number of starts of screw and nut (>= 3 so that the roller has a positive size).
    pitch
        Thread pitch p (mm), equal on all parts.
    beta
        Flank half-angle (rad) in the normal section, in (5 deg, 80 deg).
    roller_arc
        Radius of the roller's convex arc profile (mm); ``None`` (default) for
        ``r_r / sin(beta)``, the arc centred on the roller axis (spherical roller thread).
    """

    d_s: float = 30.0
    n_starts: int = 5
    pitch: float = 2.0
    beta: float = math.radians(45.0)
    roller_arc: float | None = None

    def __post_init__(self):
        if not (isinstance(self.n_starts, int | np.integer) and self.n_starts >= 3):
            raise InputError(
                "n_starts", f"need an integer >= 3 (d_r = d_s/(n-2)), got {self.n_starts}"
            )
        if not (math.isfinite(self.d_s) and self.d_s > 0):
            raise InputError("d_s", f"screw diameter must be positive, got {self.d_s}")
        if not (math.isfinite(self.pitch) and self.pitch > 0):
            raise InputError("pitch", f"pitch must be positive, got {self.pitch}")
        if not math.radians(5.0) < self.beta < math.radians(80.0):
            raise InputError(
                "beta",
                f"flank half-angle must lie in (5, 80) deg, got {math.degrees(self.beta):.4g} deg",
            )
        if self.roller_arc is not None and not (
            math.isfinite(self.roller_arc) and self.roller_arc > self.pitch
        ):
            raise InputError(
                "roller_arc", f"roller arc radius must exceed the pitch, got {self.roller_arc}"
            )
        # The roller's arc profile needs R = r_r / sin(beta) and a tooth that fits in the
        # roller: the axial tooth height p/(2 tan beta) must stay well inside the roller.
        if self.pitch / (2.0 * math.tan(self.beta)) >= 0.5 * self.r_r:
            raise InputError(
                "pitch",
                f"tooth height p/(2 tan beta) = {self.pitch / (2 * math.tan(self.beta)):.4g}"
                f" mm does not fit a roller of radius {self.r_r:.4g} mm",
            )

    @property
    def d_r(self) -> float:
        """Roller nominal diameter d_s / (n - 2) (mm)."""
        return self.d_s / (self.n_starts - 2)

    @property
    def d_n(self) -> float:
        """Nut nominal diameter d_s + 2 d_r (mm)."""
        return self.d_s + 2.0 * self.d_r

    @property
    def r_s(self) -> float:
        """Screw nominal radius (mm)."""
        return 0.5 * self.d_s

    @property
    def r_r(self) -> float:
        """Roller nominal radius (mm)."""
        return 0.5 * self.d_r

    @property
    def r_n(self) -> float:
        """Nut nominal radius (mm)."""
        return 0.5 * self.d_n

    @property
    def lead_s(self) -> float:
        """Screw lead n p (mm)."""
        return self.n_starts * self.pitch

    @property
    def lead_r(self) -> float:
        """Roller lead p (single start, mm)."""
        return self.pitch

    @property
    def lead_n(self) -> float:
        """Nut lead n p (mm)."""
        return self.n_starts * self.pitch

    def helix_angle(self, part: str) -> float:
        """Helix angle atan(l / (pi d)) (rad) of ``"screw"``, ``"roller"`` or ``"nut"``."""
        lead, d = {
            "screw": (self.lead_s, self.d_s),
            "roller": (self.lead_r, self.d_r),
            "nut": (self.lead_n, self.d_n),
        }[part]
        return math.atan(lead / (math.pi * d))

    @property
    def roller_profile_radius(self) -> float:
        """Radius of the roller's arc profile (mm), by default r_r / sin(beta)."""
        return self.r_r / math.sin(self.beta) if self.roller_arc is None else self.roller_arc

    def describe(self) -> str:
        """One line stating the geometry (for printed reports)."""
        return (
            f"d_s = {self.d_s:g} mm, d_r = {self.d_r:g} mm, d_n = {self.d_n:g} mm, "
            f"{self.n_starts}-start screw/nut, single-start roller, p = {self.pitch:g} mm, "
            f"beta = {math.degrees(self.beta):g} deg, roller arc R = "
            f"{self.roller_profile_radius:.4g} mm, lambda_s = "
            f"{math.degrees(self.helix_angle('screw')):.3f} deg, lambda_r = lambda_n = "
            f"{math.degrees(self.helix_angle('roller')):.3f} deg"
        )


# The two contacts: (body a, xi_a) with the roller (body b, xi_b); body a is coaxial with
# the global frame, the roller axis is at (a cos psi, a sin psi).
_SIDES = {
    "screw": ("screw", +1, -1),  # screw upper flank on roller lower flank
    "nut": ("nut", -1, +1),  # nut lower flank on roller upper flank
}


def _part_params(g: PRSMGeometry, part: str) -> tuple[float, float]:
    return {"screw": (g.r_s, g.lead_s), "roller": (g.r_r, g.lead_r), "nut": (g.r_n, g.lead_n)}[part]


def _roller_flank(g: PRSMGeometry, rho, theta, xi):
    """A point of the roller's arc-profiled flank ``xi`` at (rho, theta), roller frame."""
    return thread_flank(
        rho,
        theta,
        kind="roller",
        xi=xi,
        r0=g.r_r,
        pitch=g.pitch,
        lead=g.lead_r,
        beta=g.beta,
        arc_radius=g.roller_profile_radius,
    )


@dataclass(frozen=True)
class ThreadContact:
    """A matched contact between a screw or nut flank (body 1) and a roller flank (body 2)."""

    side: str  #: "screw" or "nut"
    psi: float  #: contact position: polar angle of the roller axis (rad)
    params: np.ndarray  #: (rho_1, theta_1, rho_2, theta_2, dz) at the solution
    point: np.ndarray  #: contact point, global frame (mm)
    normal: np.ndarray  #: outward unit normal of body 1 (points into the roller)
    rho1: np.ndarray  #: convex-positive principal curvatures of body 1, descending
    rho2: np.ndarray  #: of body 2 (roller), descending
    dirs1: np.ndarray  #: principal directions of body 1 (2, 3), rows match rho1
    dirs2: np.ndarray  #: principal directions of body 2 (2, 3), rows match rho2
    omega: float  #: angle between the principal planes 1 (rad), in [0, pi/2]
    residual: float  #: max |equation residual| at the solution
    normal_mismatch: float  #: |n1 + n2| (0 for a tangent contact)

    def hertz(self, Q: float, E_star: float | None = None) -> HertzPointContact:
        """Hertz ellipse with the principal-plane angle omega (load Q in N)."""
        E_star = effective_modulus(STEEL_E, STEEL_NU) if E_star is None else E_star
        return hertz_point_contact(*self.rho1, *self.rho2, self.omega, Q, E_star)

    def hertz_aligned(
        self, Q: float, E_star: float | None = None, pairing: str = "index"
    ) -> HertzPointContact:
        """Hertz ellipse with the omega = 0 simplification (principal planes coincide).

        Parameters
        ----------
        Q
            Normal load (N).
        E_star
            Effective modulus (MPa); default steel on steel.
        pairing
            Which planes are taken as coincident: ``"index"`` (plane 1 = larger
            curvature on both bodies, the literal kappa_1-with-kappa_1 reading) or
            ``"nearest"`` (plane 1 of body 1 with the nearer plane of body 2).
        """
        E_star = effective_modulus(STEEL_E, STEEL_NU) if E_star is None else E_star
        if pairing not in ("index", "nearest"):
            raise InputError("pairing", f"must be 'index' or 'nearest', got {pairing!r}")
        rho2 = self.rho2
        if pairing == "nearest" and self.omega > 0.25 * math.pi:
            rho2 = rho2[::-1]
        return hertz_point_contact_aligned(*self.rho1, *rho2, Q, E_star)


class PRSMContact:
    """Contact solver for one PRSM geometry (CasADi functions built once, reused).

    Parameters
    ----------
    geometry
        The PRSM geometry.
    """

    def __init__(self, geometry: PRSMGeometry):
        self.g = geometry

    @cached_property
    def _surfaces(self) -> dict[str, Surface]:
        g = self.g
        out = {}
        for key, (part, xi) in {
            "screw": ("screw", +1),
            "roller_lower": ("roller", -1),
            "roller_upper": ("roller", +1),
            "nut": ("nut", -1),
        }.items():
            r0, lead = _part_params(g, part)
            arc = g.roller_profile_radius if part == "roller" else None
            out[key] = Surface(
                flank_builder(part, xi, r0, g.pitch, lead, g.beta, arc_radius=arc), 0, key
            )
        return out

    def _equations(self, side: str) -> ca.Function:
        cache = self.__dict__.setdefault("_eq_cache", {})
        if side in cache:
            return cache[side]
        g = self.g
        part, xi_a, xi_b = _SIDES[side]
        r0a, lead_a = _part_params(g, part)
        x = ca.SX.sym("x", 5)
        psi = ca.SX.sym("psi")
        a = g.r_s + g.r_r
        centre = ca.vertcat(a * ca.cos(psi), a * ca.sin(psi), x[4])
        pa = thread_flank(
            x[0], x[1], kind=part, xi=xi_a, r0=r0a, pitch=g.pitch, lead=lead_a, beta=g.beta
        )
        pb = centre + _roller_flank(g, x[2], x[3], xi_b)
        Ja = ca.jacobian(pa, x[0:2])
        Jb = ca.jacobian(pb, x[2:4])
        ta_u = Ja[:, 0] / ca.norm_2(Ja[:, 0])
        ta_v = Ja[:, 1] / ca.norm_2(Ja[:, 1])
        nb = ca.cross(Jb[:, 0], Jb[:, 1])
        nb = nb / ca.norm_2(nb)
        res = ca.vertcat(pa - pb, ca.dot(nb, ta_u), ca.dot(nb, ta_v))
        f = ca.Function(f"contact_{side}", [x, psi], [res, ca.jacobian(res, x)])
        cache[side] = f
        return f

    def _initial_guess(self, side: str, psi: float) -> np.ndarray:
        g = self.g
        part, xi_a, xi_b = _SIDES[side]
        r0a, lead_a = _part_params(g, part)
        # Body 1 at its nominal radius facing the roller axis; roller at its nominal
        # radius on the line of centres (towards the screw, or away from it to the nut).
        theta_b = psi + math.pi if side == "screw" else psi
        za = thread_flank(
            r0a, psi, kind=part, xi=xi_a, r0=r0a, pitch=g.pitch, lead=lead_a, beta=g.beta
        )[2]
        zb = _roller_flank(g, g.r_r, theta_b, xi_b)[2]
        return np.array([r0a, psi, g.r_r, theta_b, za - zb])

    def contact(self, side: str, psi: float = 0.0, tol: float = 1e-12) -> ThreadContact:
        """Solve the tangency of body ``side`` ("screw" or "nut") with the roller.

        Parameters
        ----------
        side
            ``"screw"`` (screw-roller contact) or ``"nut"`` (roller-nut contact).
        psi
            Contact position: polar angle (rad) of the roller axis about the screw axis.
        tol
            Newton tolerance on the residual (mm and unit-vector components).

        Returns
        -------
        ThreadContact
        """
        if side not in _SIDES:
            raise InputError("side", f"must be 'screw' or 'nut', got {side!r}")
        f = self._equations(side)
        x = self._initial_guess(side, psi)
        res = np.inf
        for _ in range(50):
            r, J = f(x, psi)
            r = np.asarray(r).ravel()
            res = float(np.max(np.abs(r)))
            if res < tol:
                break
            x = x - np.linalg.solve(np.asarray(J), r)
        if not res < 1e-9:
            raise InputError(
                "geometry", f"no tangent {side}-roller contact found (residual {res:.3g})"
            )
        return self._analyse(side, psi, x, res)

    def _analyse(self, side: str, psi: float, x: np.ndarray, res: float) -> ThreadContact:
        _part, xi_a, xi_b = _SIDES[side]
        sa = self._surfaces["screw" if side == "screw" else "nut"].evaluate(x[0], x[1])
        sb = self._surfaces["roller_lower" if side == "screw" else "roller_upper"].evaluate(
            x[2], x[3]
        )
        ka, da, na = _convex(sa, xi_a)
        kb, db, nb = _convex(sb, xi_b)
        # Index convention: plane 1 of each body is its larger convex curvature.
        c = abs(float(np.dot(da[0], db[0])))
        phi = math.acos(min(c, 1.0))
        return ThreadContact(
            side=side,
            psi=float(psi),
            params=x.copy(),
            point=sa.point,
            normal=na,
            rho1=ka,
            rho2=kb,
            dirs1=da,
            dirs2=db,
            omega=phi,
            residual=res,
            normal_mismatch=float(np.linalg.norm(na + nb)),
        )


def _convex(sp: SurfacePoint, xi: int):
    """Convex-positive principal curvatures (descending), directions, outward normal."""
    # Outward normal has sign(n_z) = xi (thread_surface docstring); kappa is w.r.t. the
    # parametrisation's normal, convex-positive curvature is -kappa w.r.t. the outward one.
    s = 1.0 if sp.normal[2] * xi > 0 else -1.0
    k = -s * sp.kappa
    order = np.argsort(k)[::-1]
    return k[order], sp.directions[order], s * sp.normal
