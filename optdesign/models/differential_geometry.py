"""Differential geometry of parametric surfaces by CasADi automatic differentiation.

A surface ``r(u, v; p)`` (3-vector, mm) is written once as a CasADi expression of the
symbols u, v and a parameter vector p. Its first and second derivatives come from
``casadi.jacobian`` of that expression (no hand-derived derivatives), and from them

    first fundamental form   E = r_u.r_u,  F = r_u.r_v,  G = r_v.r_v
    second fundamental form  L = r_uu.n,   M = r_uv.n,   N = r_vv.n,
    n = r_u x r_v / |r_u x r_v|,

the mean and Gaussian curvature ``H = (EN - 2FM + GL) / (2(EG - F^2))``,
``K = (LN - M^2)/(EG - F^2)``, the principal curvatures ``H +- sqrt(H^2 - K)`` and the
principal directions, the eigenvectors (du, dv) of ``II x = kappa I x`` mapped to 3-D
tangent vectors ``r_u du + r_v dv``.

Sign: curvatures are normal curvatures with respect to n, so a sphere parametrised with
an outward n has kappa = -1/R. Contact mechanics wants "convex positive": with n the
outward normal of the body, the convex-positive curvature is ``-kappa``
(see :mod:`optdesign.models.prsm`).

Validity
--------
a regular surface : E G - F^2 > 0
    The fundamental forms and curvatures exist where the parametrisation is regular
    (its tangent vectors independent). Documented.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np

from optdesign.models.validity import Validity

REGULARITY = Validity(
    "differential_geometry.regularity",
    "surface curvature",
    "E G - F^2 of the first fundamental form",
    0.0,
    None,
    "mm^2",
    "curvatures exist where the parametrisation is regular",
    open_lower=True,
    checked=("documented",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (REGULARITY,)


def fundamental_forms(r: ca.SX, u: ca.SX, v: ca.SX) -> dict[str, ca.SX]:
    """Symbolic first/second fundamental forms and curvatures of ``r(u, v)``.

    Parameters
    ----------
    r
        3x1 CasADi SX expression of the surface point.
    u, v
        Scalar SX symbols, the surface parameters.

    Returns
    -------
    dict
        SX expressions ``r_u, r_v, r_uu, r_uv, r_vv, n, E, F, G, L, M, N, H, K,
        kappa1, kappa2`` (kappa1 >= kappa2; normal curvatures w.r.t. n).
    """
    uv = ca.vertcat(u, v)
    J = ca.jacobian(r, uv)  # 3x2: [r_u, r_v]
    r_u, r_v = J[:, 0], J[:, 1]
    J_u = ca.jacobian(r_u, uv)  # [r_uu, r_uv]
    r_uu, r_uv = J_u[:, 0], J_u[:, 1]
    r_vv = ca.jacobian(r_v, v)
    cr = ca.cross(r_u, r_v)
    n = cr / ca.norm_2(cr)
    E, F, G = ca.dot(r_u, r_u), ca.dot(r_u, r_v), ca.dot(r_v, r_v)
    L, M, N = ca.dot(r_uu, n), ca.dot(r_uv, n), ca.dot(r_vv, n)
    det1 = E * G - F**2
    H = (E * N - 2 * F * M + G * L) / (2 * det1)
    K = (L * N - M**2) / det1
    # fmax: H^2 - K >= 0 in exact arithmetic; round-off can make it -1e-17 at umbilics.
    root = ca.sqrt(ca.fmax(H**2 - K, 0))
    return {
        "r_u": r_u,
        "r_v": r_v,
        "r_uu": r_uu,
        "r_uv": r_uv,
        "r_vv": r_vv,
        "n": n,
        "E": E,
        "F": F,
        "G": G,
        "L": L,
        "M": M,
        "N": N,
        "H": H,
        "K": K,
        "kappa1": H + root,
        "kappa2": H - root,
    }


@dataclass(frozen=True)
class SurfacePoint:
    """Numeric differential geometry at one surface point (NumPy arrays)."""

    point: np.ndarray  #: r (3,)
    r_u: np.ndarray  #: dr/du (3,)
    r_v: np.ndarray  #: dr/dv (3,)
    normal: np.ndarray  #: unit normal n = r_u x r_v / |.| (3,)
    first_form: np.ndarray  #: [[E, F], [F, G]]
    second_form: np.ndarray  #: [[L, M], [M, N]]
    kappa: np.ndarray  #: principal (normal) curvatures, descending (2,)
    directions: np.ndarray  #: unit principal directions in 3-D, rows match kappa (2, 3)
    directions_uv: np.ndarray  #: principal directions (du, dv), rows match kappa (2, 2)

    @property
    def mean_curvature(self) -> float:
        """H = (kappa1 + kappa2)/2."""
        return float(0.5 * (self.kappa[0] + self.kappa[1]))

    @property
    def gaussian_curvature(self) -> float:
        """K = kappa1 kappa2."""
        return float(self.kappa[0] * self.kappa[1])


class Surface:
    """A parametric surface ``r(u, v; p)`` compiled to a CasADi Function.

    Parameters
    ----------
    builder
        ``builder(u, v, p) -> 3x1 SX`` building the surface point from SX symbols
        (use CasADi or :mod:`optdesign.math` functions).
    n_params
        Length of the parameter vector p (0 for none).
    name
        Name of the CasADi Function.
    """

    def __init__(
        self,
        builder: Callable[[ca.SX, ca.SX, ca.SX], ca.SX],
        n_params: int = 0,
        name: str = "surface",
    ):
        u, v = ca.SX.sym("u"), ca.SX.sym("v")
        p = ca.SX.sym("p", n_params)
        r = builder(u, v, p)
        self.forms = fundamental_forms(r, u, v)
        f = self.forms
        self.u, self.v, self.p, self.r = u, v, p, r
        self.n_params = n_params
        outs = [r, f["r_u"], f["r_v"], f["n"], f["E"], f["F"], f["G"], f["L"], f["M"], f["N"]]
        self.function = ca.Function(name, [u, v, p], outs)
        # Point, normal and tangents only: what the contact-matching equations need.
        self.frame = ca.Function(name + "_frame", [u, v, p], [r, f["n"], f["r_u"], f["r_v"]])

    def evaluate(self, u: float, v: float, p=()) -> SurfacePoint:
        """Fundamental forms, principal curvatures and directions at (u, v)."""
        out = self.function(u, v, np.asarray(p, dtype=float).reshape(-1))
        r, r_u, r_v, n = (np.asarray(o).ravel() for o in out[:4])
        E, F, G, L, M, N = (float(o) for o in out[4:])
        I1 = np.array([[E, F], [F, G]])
        I2 = np.array([[L, M], [M, N]])
        return _principal(r, r_u, r_v, n, I1, I2)


def _principal(r, r_u, r_v, n, I1, I2) -> SurfacePoint:
    # Generalised symmetric eigenproblem II x = kappa I x (I positive definite): the
    # eigenvalues are the principal curvatures, the eigenvectors the principal directions.
    import scipy.linalg  # here: the validity table imports this module, not its solver

    w, X = scipy.linalg.eigh(I2, I1)
    order = np.argsort(w)[::-1]
    w, X = w[order], X[:, order]
    dirs = np.array([r_u * X[0, k] + r_v * X[1, k] for k in range(2)])
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    return SurfacePoint(r, r_u, r_v, n, I1, I2, w, dirs, X.T)
