"""Conforming pin-in-bore contact (beside [D17] eq. 11) and Palmgren's line-contact approach.

Problem (Persson 1964; Ciavarella & Decuzzi 2001, part I): a pin of radius R in a bore of
radius R + dR (dR the radial clearance) in a large plate, same material (E, nu), plane
strain, frictionless, load F over the length L (P = F/L per unit length). The contact arc
is |theta| < eps. Everything depends on one number, the load parameter

    P* = P / (E* dR),   1/E* = 2 (1 - nu^2) / E   (elastically similar pair)

and the results scale as p_max = (E* dR / R) q0(P*), approach delta = dR d(P*).

**Exact (implicit) solution**, :func:`persson_exact`. With p(theta) = sum p_n cos(n theta)
the radial gap opening of pin and bore under the pressure is, mode by mode (Michell's
solution for a disc and for a hole in an infinite plate; this project's derivation),

    w_0 = R p_0 / E*,   w_1 absorbed in the rigid approach,   w_n = (2R/E*) n/(n^2 - 1) p_n

and contact needs dR (1 - cos theta) - delta' cos theta + w(theta) = 0 on the arc,
p >= 0, gap >= 0 outside, with P = pi R p_1. The function solves this on a grid (active
set). delta' is the approach of the pin centre towards the bore wall beyond first contact,
without the net-force (n = 1) mode: in a plane model that mode's displacement depends on
where it is measured (the log term of 2D contact), so the approach here is the part that
the contact itself adds. Small loads recover Hertz for conforming cylinders,
1/R_eq = 1/R - 1/(R + dR) ~ dR/R^2: eps = sqrt(4 P*/pi), q0 = sqrt(P*/pi). Large loads
wrap the pin: eps -> 90 deg (no clearance: half the circumference).

**Explicit approximation** (smooth, CasADi-safe), fitted by this project to
:func:`persson_exact` on P* = 0.01...100 (26 loads, 2000 nodes) and exact in the Hertz
limit by construction:

    eps   = (pi/2) z / (1 + 1.1168 z^1.9034)^(1/1.9034),  z = sqrt(4 P*/pi) / (pi/2)
    q0    = sqrt(P*/pi) (1 + 0.63665 x + 0.72757 x^2) / (1 + 0.74097 x),  x = sqrt(4 P*/pi)
    d     = P* (0.33103 + ln(1 + 1.1019 / P*) / pi)

largest deviation from the exact solution over that range: eps 1.0 %, q0 1.0 %, d 0.6 %.
The contact stiffness dF/d(delta) = L E* / d'(P*) follows from d.

**Validity.** Hertz (eq. 10-11 type formulas) holds for small arcs: eps <= 15 deg
(P* <~ 0.055), where its half-angle and pressure are within 3 % of the exact solution
(:func:`in_hertz_range`). The explicit form holds for P* <= 100, eps <= 84 deg
(:func:`in_fit_range`); beyond it the arc is too wide for the fit, and in any case the
model assumes a frictionless, elastically similar, plane-strain pair with clearance
(dR > 0, no interference). Example: [D17]'s pin, D = 10 mm, L = 20 mm, 20 kN, with an
H7/g6 fit's largest clearance (30.9 um on the diameter, dR = 15.5 um), has P* = 0.56 and
eps = 41 deg: far outside Hertz's range.

**Palmgren** (empirical, steel line contact; Palmgren, *Ball and Roller Bearing
Engineering*, 1959, as used by Harris, *Rolling Bearing Analysis*): approach
delta = 3.84e-5 Q^0.9 / l^0.8 mm (Q in N, l in mm), independent of the radii.

No published table of Persson's solution was found to test against (see the tests):
the checks are the Hertz limit, Lame's solution for the uniform mode, the 90 deg limit
and equilibrium of the computed pressure.

Validity
--------
P* : (0, 100]
    The explicit approximation (what a design problem evaluates) was fitted to the exact
    solution on P* = 0.01 ... 100 and is exact in the Hertz limit P* -> 0; beyond 100 the
    arc exceeds 84 deg, the pin wraps its bore, and the fit was never checked there.
    P* > 0 needs a radial gap (a clearance fit, checked when the problem is read).
Hertz's half-angle of the conforming pair : <= 15 deg
    :func:`hertz_half_angle` and :func:`hertz_max_pressure` are within 3 % of the exact
    solution up to eps = 15 deg (:func:`in_hertz_range`); a comparison, not used by the
    design problems.
E (Palmgren) : 1.9e5 ... 2.2e5 MPa
    Palmgren's law is an empirical fit to steel line contacts (bearing rollers): it has
    no modulus in it, so it holds for steel only (refused otherwise when the pin joint
    is built).

Units: mm, N, MPa, rad.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models._checks import require_positive
from optdesign.models.validity import Validity

#: Half-angle up to which Hertz's formulas are within 3 % of the exact solution (rad).
HERTZ_MAX_HALF_ANGLE = float(np.radians(15.0))
#: Largest load parameter P* of the explicit approximation's fit.
FIT_MAX_LOAD = 100.0

# Fitted constants of the explicit approximation (module docstring).
_EPS_C, _EPS_K = 1.1168, 1.9034
_Q_A1, _Q_A2, _Q_B1 = 0.63665, 0.72757, 0.74097
_D_ALPHA, _D_GAMMA = 0.33103, 1.1019

#: Palmgren's constant for steel line contact (mm N^-0.9 mm^0.8).
PALMGREN_CONSTANT = 3.84e-5

LOAD_PARAMETER = Validity(
    "pin_contact.load_parameter",
    "conforming pin-in-bore contact",
    "load parameter P*",
    0.0,
    FIT_MAX_LOAD,
    "",
    "the explicit approximation was fitted to the exact solution for P* up to 100",
    open_lower=True,
)
HERTZ_CONFORMING_HALF_ANGLE = Validity(
    "pin_contact.hertz_half_angle",
    "Hertz's formulas for a conforming pin",
    "contact half-angle",
    0.0,
    HERTZ_MAX_HALF_ANGLE,
    "rad",
    "Hertz's small-arc formulas are within 3 % of the exact solution up to 15 deg",
    shown_unit="deg",
    scale=180.0 / np.pi,
    checked=("documented",),
)
PALMGREN_MODULUS = Validity(
    "pin_contact.palmgren_modulus",
    "Palmgren's approach",
    "pin modulus",
    1.9e5,
    2.2e5,
    "MPa",
    "an empirical law of steel line contacts (E about 2.1e5 MPa)",
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (LOAD_PARAMETER, HERTZ_CONFORMING_HALF_ANGLE, PALMGREN_MODULUS)


def effective_modulus_similar(E, nu):
    """E* of two bodies of the same material, E / (2 (1 - nu^2)) (MPa)."""
    return E / (2.0 * (1.0 - nu**2))


def load_parameter(F, L, dR, E, nu):
    """P* = (F/L) / (E* dR): load F (N) over length L (mm), radial clearance dR (mm)."""
    require_positive("L", L)
    require_positive("dR", dR)
    return (F / L) / (effective_modulus_similar(E, nu) * dR)


# --- explicit forms in P* (dimensionless) -----------------------------------------------------
def half_angle_star(P_star):
    """Contact half-angle eps (rad) from P*, explicit approximation."""
    z = m.sqrt(4.0 * P_star / m.pi) / (0.5 * m.pi)
    return 0.5 * m.pi * z / (1.0 + _EPS_C * z**_EPS_K) ** (1.0 / _EPS_K)


def max_pressure_star(P_star):
    """q0 = p_max R / (E* dR) from P*, explicit approximation."""
    x = m.sqrt(4.0 * P_star / m.pi)
    return m.sqrt(P_star / m.pi) * (1.0 + _Q_A1 * x + _Q_A2 * x**2) / (1.0 + _Q_B1 * x)


def approach_star(P_star):
    """d = delta / dR from P*, explicit approximation."""
    return P_star * (_D_ALPHA + m.log(1.0 + _D_GAMMA / P_star) / m.pi)


def approach_star_slope(P_star):
    """d d / d P* (exact derivative of :func:`approach_star`)."""
    return _D_ALPHA + (m.log(1.0 + _D_GAMMA / P_star) - _D_GAMMA / (P_star + _D_GAMMA)) / m.pi


# --- dimensional -------------------------------------------------------------------------------
def contact_half_angle(F, L, R, dR, E, nu):
    """Half-angle eps (rad) of the contact arc of a pin (radius R, mm) in a bore R + dR."""
    require_positive("R", R)
    return half_angle_star(load_parameter(F, L, dR, E, nu))


def max_pressure(F, L, R, dR, E, nu):
    """Largest contact pressure (MPa), at the centre of the arc."""
    require_positive("R", R)
    E_s = effective_modulus_similar(E, nu)
    return E_s * dR / R * max_pressure_star(load_parameter(F, L, dR, E, nu))


def approach(F, L, R, dR, E, nu):
    """Elastic approach of the pin towards the bore wall beyond first contact (mm):
    the load-dependent lost motion of the joint on top of its clearance (net-force mode
    excluded, see the module docstring)."""
    require_positive("R", R)
    return dR * approach_star(load_parameter(F, L, dR, E, nu))


def contact_stiffness(F, L, R, dR, E, nu):
    """Tangent contact stiffness dF / d(delta) (N/mm) = L E* / d'(P*)."""
    require_positive("R", R)
    E_s = effective_modulus_similar(E, nu)
    return L * E_s / approach_star_slope(load_parameter(F, L, dR, E, nu))


def hertz_half_angle(F, L, R, dR, E, nu):
    """Hertz's half-angle for the conforming pair, a / R = sqrt(4 P* / pi) (rad)."""
    require_positive("R", R)
    return m.sqrt(4.0 * load_parameter(F, L, dR, E, nu) / m.pi)


def hertz_max_pressure(F, L, R, dR, E, nu):
    """Hertz's largest pressure for the conforming pair, (E* dR / R) sqrt(P*/pi) (MPa)."""
    require_positive("R", R)
    E_s = effective_modulus_similar(E, nu)
    return E_s * dR / R * m.sqrt(load_parameter(F, L, dR, E, nu) / m.pi)


def in_hertz_range(F, L, R, dR, E, nu):
    """True where Hertz's small-arc formulas hold to 3 % (eps <= 15 deg); numeric only."""
    return np.asarray(contact_half_angle(F, L, R, dR, E, nu)) <= HERTZ_MAX_HALF_ANGLE


def in_fit_range(F, L, dR, E, nu):
    """True where the explicit approximation was fitted (0 < P* <= 100); numeric only."""
    P_star = np.asarray(load_parameter(F, L, dR, E, nu))
    return (P_star > 0) & (P_star <= FIT_MAX_LOAD)


# --- Palmgren ----------------------------------------------------------------------------------
def palmgren_approach(Q, l):
    """Palmgren's empirical approach of a steel line contact, 3.84e-5 Q^0.9 / l^0.8 (mm);
    Q in N, contact length l in mm."""
    require_positive("l", l)
    return PALMGREN_CONSTANT * Q**0.9 / l**0.8


def palmgren_stiffness(Q, l):
    """Tangent stiffness of Palmgren's contact, dQ/d(delta) = Q / (0.9 delta) (N/mm)."""
    return Q / (0.9 * palmgren_approach(Q, l))


# --- exact solution ----------------------------------------------------------------------------
@dataclass(frozen=True)
class PerssonSolution:
    """Exact solution at one load parameter (dimensionless; see the module docstring).

    Attributes
    ----------
    P_star
        Load parameter.
    eps
        Contact half-angle (rad).
    q0
        p_max R / (E* dR).
    d
        delta / dR.
    theta, q
        Grid (rad, 0...pi) and pressure q(theta) = p R / (E* dR).
    """

    P_star: float
    eps: float
    q0: float
    d: float
    theta: np.ndarray
    q: np.ndarray


def gap_compliance(n):
    """Dimensionless opening per pressure mode, w_n / (R p_n / E*): 1 for n = 0, 0 for
    n = 1 (rigid approach), 2n / (n^2 - 1) for n >= 2."""
    n = np.asarray(n, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(n >= 2, 2.0 * n / (n**2 - 1.0), 0.0)
    return np.where(n == 0, 1.0, c)


@functools.lru_cache(maxsize=4)
def _influence_cached(n_nodes: int, n_modes: int):
    # influence matrix: gap opening at node i per unit pressure on node j (dimensionless)
    theta = (np.arange(n_nodes) + 0.5) * np.pi / n_nodes
    w = np.pi / n_nodes
    n = np.arange(n_modes + 1)
    C = np.cos(np.outer(n, theta))
    coef = C * (2.0 * w / np.pi)
    coef[0] *= 0.5
    return theta, w, (C.T * gap_compliance(n)) @ coef


def persson_exact(P_star: float, n_nodes: int = 2000) -> PerssonSolution:
    """Exact solution of the conforming contact at the load parameter P* (numerical).

    Grid of ``n_nodes`` points on 0...pi, Fourier modes up to 2 n_nodes, active-set
    iteration on the complementarity conditions; the arc's end eps is where q^2, linear
    in theta near a smooth edge, extrapolates to zero. Accuracy: 0.1 % in eps for
    P* >= 0.1 with 2000 nodes, coarser for small arcs (use Hertz there).
    """
    if not P_star > 0:
        raise InputError("P_star", f"must be positive, got {P_star!r}")
    theta, w, A = _influence_cached(int(n_nodes), 2 * int(n_nodes))
    active = theta < min(np.pi / 2, 2.0 * np.sqrt(4.0 * P_star / np.pi))
    for _ in range(200):
        idx = np.flatnonzero(active)
        k = idx.size
        M = np.zeros((k + 1, k + 1))
        rhs = np.zeros(k + 1)
        M[:k, :k] = A[np.ix_(idx, idx)]
        M[:k, k] = -np.cos(theta[idx])
        rhs[:k] = -(1.0 - np.cos(theta[idx]))
        M[k, :k] = 2.0 * w * np.cos(theta[idx])  # pi q_1 = P*
        rhs[k] = P_star
        sol = np.linalg.solve(M, rhs)
        q = np.zeros_like(theta)
        q[idx] = sol[:k]
        d = sol[k]
        gap = (1.0 - np.cos(theta)) - d * np.cos(theta) + A @ q
        new = active.copy()
        new[q < 0] = False
        new[~active & (gap < 0)] = True
        if np.array_equal(new, active):
            break
        active = new
    else:  # pragma: no cover - the active set settles in a few passes
        raise RuntimeError("persson_exact: active set did not settle")
    last = idx.max()
    j = np.arange(max(last - 6, 0), last + 1)
    slope, icpt = np.polyfit(theta[j], q[j] ** 2, 1)
    eps = -icpt / slope
    return PerssonSolution(float(P_star), float(eps), float(q[0]), float(d), theta, q)
