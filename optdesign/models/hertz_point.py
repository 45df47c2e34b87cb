"""Hertz point contact of two bodies whose principal planes make an angle omega ([C-PRSM]).

Geometry. Body i has principal curvatures rho_i1, rho_i2 (1/mm) in its principal planes
1 and 2, counted **positive where the body is convex** towards the other body (a concave
nut flank has a negative curvature). Plane 1 of body 1 and plane 1 of body 2 make the
angle omega. Near the contact the gap between the bodies is ``h = A x^2 + B y^2``
(x along the major axis of the contact ellipse, ``0 < A <= B``) with (Timoshenko &
Goodier section 140; Johnson, *Contact Mechanics*, eq. 2.3-2.4)

    A + B = sum_rho / 2,   sum_rho = rho_11 + rho_12 + rho_21 + rho_22
    B - A = 1/2 sqrt((rho_11 - rho_12)^2 + (rho_21 - rho_22)^2
                     + 2 (rho_11 - rho_12)(rho_21 - rho_22) cos(2 omega))

and the curvature difference ``F(rho) = (B - A) / (A + B)`` (Timoshenko's cos(theta)).
With omega = 0 the root collapses to ``|(rho_11 - rho_12) + (rho_21 - rho_22)|``: the
usual simplification that assumes the principal planes coincide.

Ellipse. With k = b/a <= 1, e^2 = 1 - k^2 and the complete elliptic integrals K(e),
E(e) (SciPy's parameter m = e^2), the eccentricity solves (Harris, *Rolling Bearing
Analysis*, with kappa = 1/k)

    F(rho) = ((1 + k^2) E(e) - 2 k^2 K(e)) / ((1 - k^2) E(e)),

and with the effective modulus ``1/E* = (1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2`` and the
normal load Q (Johnson eq. 3.64-3.67, rearranged)

    a = (3 kappa^2 E(e) Q / (pi E* sum_rho))^(1/3),   b = k a,
    p_max = 3 Q / (2 pi a b),   approach delta = p_max b K(e) / E*.

These reduce to the sphere-on-flat closed forms for F(rho) = 0 (docs/thread_contact.md).
Hamrock & Brewe's curve fits (kappa, E, K as power/log laws in Ry/Rx) are in
:func:`hamrock_brewe` for comparison; they are approximations, not used by the solver.

The elliptic solve is numeric (SciPy); this module is NumPy/SciPy only.

Validity
--------
curvature difference F(rho) : 0 <= F(rho) < 1
    An ellipse of contact exists for a gap A x^2 + B y^2 with 0 < A <= B (refused
    otherwise, and where the ellipse is beyond double precision).
semi-axes small against the radii, linear elasticity
    Hertz's half-space, as for the line contact; E, nu in the ranges of
    :mod:`optdesign.models.validity`. Documented (the thread-contact study).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from optdesign.errors import InputError
from optdesign.models.validity import ELASTIC_MODULUS, POISSON_RATIO, Validity

CURVATURE_DIFFERENCE = Validity(
    "hertz_point.curvature_difference",
    "Hertz point contact",
    "curvature difference F(rho)",
    0.0,
    1.0,
    "",
    "an elliptical contact needs a gap A x^2 + B y^2 with 0 < A <= B",
    open_upper=True,
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (CURVATURE_DIFFERENCE, ELASTIC_MODULUS, POISSON_RATIO)


# Series coefficients c_n = ((2n)! / (2^(2n) (n!)^2))^2 of K(m) = pi/2 sum c_n m^n; used
# to evaluate F(rho) near e = 0 where the closed form loses all digits to cancellation.
_N_SERIES = 40
_C = np.array([(math.comb(2 * n, n) / 4.0**n) ** 2 for n in range(_N_SERIES + 1)])
# Numerator (2 - m) E(m) - 2 (1 - m) K(m) = pi/2 sum_j d_j m^j, with d_0 = d_1 = 0.
_D = np.array(
    [
        _C[j] * (2.0 / (1.0 - 2.0 * j) - 2.0)
        + (_C[j - 1] * (2.0 - 1.0 / (1.0 - 2.0 * (j - 1))) if j >= 1 else 0.0)
        for j in range(_N_SERIES + 1)
    ]
)
_SERIES_BELOW_M = 0.05


def effective_modulus(E1: float, nu1: float, E2: float | None = None, nu2: float | None = None):
    """Effective modulus E* (MPa): ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2``.

    Body 2 defaults to the material of body 1.
    """
    E2 = E1 if E2 is None else E2
    nu2 = nu1 if nu2 is None else nu2
    for name, val in (("E1", E1), ("E2", E2)):
        if not val > 0:
            raise InputError(name, f"Young's modulus must be positive, got {val}")
    for name, val in (("nu1", nu1), ("nu2", nu2)):
        if not -1.0 < val < 0.5:
            raise InputError(name, f"Poisson's ratio must lie in (-1, 0.5), got {val}")
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


def curvature_sum_difference(rho11, rho12, rho21, rho22, omega):
    """Curvature sum and curvature difference F(rho) for principal planes at angle omega.

    Parameters
    ----------
    rho11, rho12, rho21, rho22
        Principal curvatures (1/mm), convex positive; first index body, second plane.
    omega
        Angle (rad) between principal plane 1 of body 1 and principal plane 1 of body 2.

    Returns
    -------
    (sum_rho, F_rho)
        ``sum_rho`` (1/mm) and ``F_rho = (B - A)/(A + B)`` in [0, 1]. Works element-wise
        on NumPy arrays.
    """
    d1 = np.asarray(rho11) - np.asarray(rho12)
    d2 = np.asarray(rho21) - np.asarray(rho22)
    s = np.asarray(rho11) + np.asarray(rho12) + np.asarray(rho21) + np.asarray(rho22)
    # d1^2 + d2^2 + 2 d1 d2 cos 2w written as a sum of two non-negative terms, so that
    # nearly cancelling differences (d1 ~ -d2 at w = 0) keep their relative accuracy:
    # (d1 + d2)^2 + 4 |d1 d2| sin^2 w when d1 d2 <= 0, (d1 - d2)^2 + 4 d1 d2 cos^2 w else.
    w = np.asarray(omega)
    p = d1 * d2
    radicand = np.where(
        p <= 0.0,
        (d1 + d2) ** 2 - 4.0 * p * np.sin(w) ** 2,
        (d1 - d2) ** 2 + 4.0 * p * np.cos(w) ** 2,
    )
    return s, np.sqrt(radicand) / s


def curvature_sum_difference_aligned(rho11, rho12, rho21, rho22):
    """The omega = 0 simplification: ``F = |rho11 - rho12 + rho21 - rho22| / sum_rho``.

    This is what the earlier PRSM studies use (principal planes assumed coincident); it
    equals :func:`curvature_sum_difference` at omega = 0.
    """
    s = np.asarray(rho11) + np.asarray(rho12) + np.asarray(rho21) + np.asarray(rho22)
    return s, np.abs(np.asarray(rho11) - rho12 + rho21 - rho22) / s


def curvature_difference_from_k2(k2: float) -> float:
    """F(rho) of an ellipse with squared axis ratio ``k2 = (b/a)^2`` (forward map).

    Uses the closed form with ``K = ellipkm1(k2)`` (accurate as e -> 1) and, for
    ``e^2 < 0.05``, a 40-term series of the numerator that avoids the cancellation of
    the closed form near e = 0.
    """
    from scipy.special import ellipe, ellipkm1  # SciPy on call: importing models stays light

    m = 1.0 - k2
    if m <= 0.0:
        return 0.0
    Em = float(ellipe(m))
    if m < _SERIES_BELOW_M:
        num = 0.5 * math.pi * float(np.polyval(_D[::-1], m))
        return num / (m * Em)
    Km = float(ellipkm1(k2))
    return ((1.0 + k2) * Em - 2.0 * k2 * Km) / ((1.0 - k2) * Em)


def eccentricity_from_curvature_difference(F_rho: float) -> float:
    """Eccentricity e of the contact ellipse from F(rho), by Brent's method on (b/a)^2.

    Parameters
    ----------
    F_rho
        Curvature difference in [0, 1).

    Returns
    -------
    float
        e in [0, 1); e = 0 for a circular contact.
    """
    from scipy.optimize import brentq

    F_rho = float(F_rho)
    if not 0.0 <= F_rho < 1.0:
        raise InputError("F_rho", f"curvature difference must lie in [0, 1), got {F_rho}")
    if F_rho == 0.0:
        return 0.0
    lo = 1e-300
    if curvature_difference_from_k2(lo) < F_rho:
        raise InputError("F_rho", f"{F_rho!r} too close to 1: ellipse beyond double precision")
    k2 = brentq(lambda t: curvature_difference_from_k2(t) - F_rho, lo, 1.0, xtol=1e-300, rtol=1e-15)
    return math.sqrt(1.0 - k2)


@dataclass(frozen=True)
class HertzPointContact:
    """Result of a Hertz point contact (mm, N, MPa)."""

    sum_rho: float  #: curvature sum (1/mm)
    F_rho: float  #: curvature difference (B - A)/(A + B)
    eccentricity: float  #: e = sqrt(1 - (b/a)^2)
    kappa: float  #: a / b >= 1
    K: float  #: complete elliptic integral of the first kind K(e)
    E: float  #: complete elliptic integral of the second kind E(e)
    a: float  #: semi-major axis (mm)
    b: float  #: semi-minor axis (mm)
    approach: float  #: approach of distant points of the two bodies (mm)
    p_max: float  #: maximum contact pressure (MPa)

    @property
    def area(self) -> float:
        """Area of the contact ellipse pi a b (mm^2)."""
        return math.pi * self.a * self.b


def hertz_from_curvatures(sum_rho: float, F_rho: float, Q: float, E_star: float):
    """Hertz ellipse from curvature sum and difference.

    Parameters
    ----------
    sum_rho
        Curvature sum (1/mm), must be positive (bodies touching at one point).
    F_rho
        Curvature difference in [0, 1).
    Q
        Normal load (N), positive.
    E_star
        Effective modulus (MPa), see :func:`effective_modulus`.

    Returns
    -------
    HertzPointContact
    """
    from scipy.special import ellipe, ellipkm1

    if not sum_rho > 0:
        raise InputError("sum_rho", f"curvature sum must be positive, got {sum_rho}")
    if not Q > 0:
        raise InputError("Q", f"normal load must be positive, got {Q}")
    e = eccentricity_from_curvature_difference(F_rho)
    k2 = 1.0 - e * e
    Ke = float(ellipkm1(k2)) if e > 0 else 0.5 * math.pi
    Ee = float(ellipe(e * e))
    kappa = 1.0 / math.sqrt(k2)
    a = (3.0 * kappa**2 * Ee * Q / (math.pi * E_star * sum_rho)) ** (1.0 / 3.0)
    b = a / kappa
    p_max = 3.0 * Q / (2.0 * math.pi * a * b)
    approach = p_max * b * Ke / E_star
    return HertzPointContact(
        sum_rho=float(sum_rho),
        F_rho=float(F_rho),
        eccentricity=e,
        kappa=kappa,
        K=Ke,
        E=Ee,
        a=a,
        b=b,
        approach=approach,
        p_max=p_max,
    )


def hertz_point_contact(rho11, rho12, rho21, rho22, omega, Q, E_star):
    """General Hertz point contact for principal planes at angle omega (rad).

    Curvatures as in :func:`curvature_sum_difference`; Q in N; E_star in MPa.
    """
    for name, val in (("rho11", rho11), ("rho12", rho12), ("rho21", rho21), ("rho22", rho22)):
        if not math.isfinite(float(val)):
            raise InputError(name, f"curvature must be finite, got {val}")
    s, F = curvature_sum_difference(rho11, rho12, rho21, rho22, omega)
    if not float(F) < 1.0:
        raise InputError("omega", "bodies do not touch at a point (one gap curvature <= 0)")
    return hertz_from_curvatures(float(s), float(F), Q, E_star)


def hertz_point_contact_aligned(rho11, rho12, rho21, rho22, Q, E_star):
    """Hertz point contact with the omega = 0 simplification (planes coincident)."""
    s, F = curvature_sum_difference_aligned(rho11, rho12, rho21, rho22)
    if not float(F) < 1.0:
        raise InputError("rho", "bodies do not touch at a point (one gap curvature <= 0)")
    return hertz_from_curvatures(float(s), float(F), Q, E_star)


def timoshenko_m_n(theta: float) -> tuple[float, float]:
    """Timoshenko's coefficients m, n with ``cos(theta) = (B - A)/(A + B)``.

    ``a = m (3 P / (4 E* (A + B)))^(1/3)`` and ``b = n (...)^(1/3)``; computed with this
    module's solver (Timoshenko & Goodier, *Theory of Elasticity*, section 140 table).
    """
    # Unit load, E* and A + B: the bracket is (3/4)^(1/3); sum_rho = 2 (A + B) = 2.
    c = hertz_from_curvatures(2.0, math.cos(theta), 1.0, 1.0)
    ref = 0.75 ** (1.0 / 3.0)
    return c.a / ref, c.b / ref


def hamrock_brewe(Rx, Ry):
    """Hamrock-Brewe (1983) curve fits of kappa = a/b, E(e) and K(e).

    Parameters
    ----------
    Rx, Ry
        Effective radii of the gap in the two principal directions (mm), with
        ``h = x^2/(2 Rx) + y^2/(2 Ry)`` and ``alpha_r = Ry / Rx >= 1`` (so
        ``Ry/Rx = B/A``; the major axis lies along y).

    Returns
    -------
    (kappa, E, K)
        ``kappa = 1.0339 alpha_r^0.6360``, ``E = 1.0003 + 0.5968 / alpha_r``,
        ``K = 1.5277 + 0.6023 ln(alpha_r)``. Their published accuracy is a few per
        cent over 1 <= alpha_r <= 100; the tests check the error against the exact
        solution of :func:`hertz_from_curvatures`.
    """
    alpha_r = np.asarray(Ry, dtype=float) / np.asarray(Rx, dtype=float)
    kappa = 1.0339 * alpha_r**0.6360
    E = 1.0003 + 0.5968 / alpha_r
    K = 1.5277 + 0.6023 * np.log(alpha_r)
    return kappa, E, K


def curvature_difference_closed_form(e: float) -> float:
    """F(rho) of eccentricity e via SciPy's ``ellipk``/``ellipe`` directly (test helper).

    Plain closed form without the series; used by the tests as an independent check of
    :func:`curvature_difference_from_k2` away from e = 0.
    """
    from scipy.special import ellipe, ellipk

    m = e * e
    k2 = 1.0 - m
    return float(((1 + k2) * ellipe(m) - 2 * k2 * ellipk(m)) / ((1 - k2) * ellipe(m)))
