"""Ball-screw sizing as the manufacturers publish it (THK, NSK, HIWIN, SKF; physics.md 8).

Buckling, shaft yield, critical speed, rated life from a duty cycle and the axial
stiffness chain. Pure functions through :mod:`optdesign.math`: a design problem passes CasADi
symbols (d1, la, ...) and gets expressions, a sweep passes arrays. The ``*_margin``
functions are constraints in the form g >= 0 (1 - demand / capacity).

Units: d1, lengths in mm; E in MPa; forces in N; speeds in min^-1 (rev/min); life in
revolutions or hours. Efficiency of the screw: :mod:`optdesign.models.screw`.
"""

from __future__ import annotations

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models._checks import require_positive
from optdesign.models.screw import series_stiffness

#: Young's modulus of screw steel used by the catalogues (MPa).
E_STEEL = 2.06e5

#: Euler end-condition factor eta_m of a column (P_cr = eta_m pi^2 E I / la^2).
EULER_END_FACTOR = {
    "fixed-free": 0.25,
    "supported-supported": 1.0,
    "fixed-supported": 2.0,
    "fixed-fixed": 4.0,
}

#: Catalogue buckling factor eta_2 in P1 = eta_2 d1^4 / la^2 x 1e4 N (safety 0.5 included).
BUCKLING_FACTOR = {
    "fixed-free": 1.3,
    "supported-supported": 5.0,
    "fixed-supported": 10.0,
    "fixed-fixed": 20.0,
}

#: Catalogue critical-speed factor lambda_2 in N1 = lambda_2 d1 / lb^2 x 1e7 min^-1
#: (includes the catalogues' 0.8 safety factor).
CRITICAL_SPEED_FACTOR = {
    "fixed-free": 3.4,
    "supported-supported": 9.7,
    "fixed-supported": 15.1,
    "fixed-fixed": 21.9,
}

#: Permissible tensile/compressive stress of the screw shaft in the catalogues (MPa).
SIGMA_ALLOWABLE = 147.0


def _factor(table: dict[str, float], mounting: str) -> float:
    try:
        return table[mounting]
    except KeyError:
        raise InputError("mounting", f"{mounting!r} not in {sorted(table)}") from None


def second_moment(d1):
    """Second moment of area of the root circle, I = pi d1^4 / 64 (mm^4)."""
    return m.pi * d1**4 / 64.0


def root_area(d1):
    """Root-circle area A = pi d1^2 / 4 (mm^2)."""
    return m.pi * d1**2 / 4.0


def buckling_load(
    d1, la, mounting: str = "fixed-supported", form: str = "catalogue", E=E_STEEL, safety=0.5
):
    """Permissible axial (buckling) load P1 (N) of the screw shaft.

    Parameters
    ----------
    d1
        Root diameter of the screw (mm).
    la
        Distance between the mounting points (mm).
    mounting
        ``"fixed-free"``, ``"supported-supported"``, ``"fixed-supported"`` or
        ``"fixed-fixed"``.
    form
        ``"catalogue"``: P1 = eta_2 d1^4 / la^2 x 1e4 with the published, rounded eta_2
        (the form the catalogues' examples use); ``"euler"``: P1 = safety eta_m pi^2 E I /
        la^2 with the exact constant (0.2 % below the catalogue's at fixed-supported,
        because eta_2 = 10 rounds 9.98).
    E
        Young's modulus (MPa), Euler form only.
    safety
        Safety factor on the Euler load, Euler form only (catalogues: 0.5).
    """
    require_positive("d1", d1)
    require_positive("la", la)
    if form == "catalogue":
        return _factor(BUCKLING_FACTOR, mounting) * d1**4 / la**2 * 1e4
    if form == "euler":
        eta_m = _factor(EULER_END_FACTOR, mounting)
        return safety * eta_m * m.pi**2 * E * second_moment(d1) / la**2
    raise InputError("form", f"{form!r} not in ('catalogue', 'euler')")


def yield_load(d1, sigma=SIGMA_ALLOWABLE):
    """Permissible tensile/compressive load of the shaft P2 = sigma pi d1^2 / 4 (N)."""
    require_positive("d1", d1)
    return sigma * root_area(d1)


def critical_speed(d1, lb, mounting: str = "fixed-supported"):
    """Permissible rotational speed N1 = lambda_2 d1 / lb^2 x 1e7 (min^-1).

    Parameters
    ----------
    d1
        Root diameter (mm).
    lb
        Distance between the supports (mm).
    mounting
        End conditions, keys of :data:`CRITICAL_SPEED_FACTOR`.
    """
    require_positive("d1", d1)
    require_positive("lb", lb)
    return _factor(CRITICAL_SPEED_FACTOR, mounting) * d1 / lb**2 * 1e7


def mean_load(forces, revolutions):
    """Cubic mean load of a duty cycle Fm = (sum F_i^3 n_i / sum n_i)^(1/3) (N).

    ``revolutions`` are the turns spent at each load, n_i t_i (speed x time share); the
    sums run over the last axis (NumPy) or the column (CasADi).
    """
    if not m.is_symbolic(forces, revolutions):
        F = np.asarray(forces, dtype=float)
        n = np.asarray(revolutions, dtype=float)
        if F.shape[-1:] != n.shape[-1:]:
            raise InputError("revolutions", "needs one entry per load step")
        if np.any(n < 0) or np.any(np.sum(n, axis=-1) <= 0):
            raise InputError("revolutions", "must be >= 0 with a positive sum")
        F = np.abs(F)
        return (np.sum(F**3 * n, axis=-1) / np.sum(n, axis=-1)) ** (1.0 / 3.0)
    return (m.grid_sum(m.fabs(forces) ** 3 * revolutions) / m.grid_sum(revolutions)) ** (1.0 / 3.0)


def mean_speed(speeds, times):
    """Time-weighted mean speed N_m = sum n_i t_i / sum t_i (min^-1)."""
    return m.grid_sum(speeds * times) / m.grid_sum(times)


def rated_life_revolutions(Ca, Fa, f_w=1.2):
    """Rated life L = (Ca / (f_w Fa))^3 x 1e6 (revolutions).

    Parameters
    ----------
    Ca
        Basic dynamic load rating (N).
    Fa
        (Mean) axial load (N), e.g. :func:`mean_load`.
    f_w
        Load factor: 1.0-1.2 smooth, 1.2-1.5 normal, 1.5-2 with impact.
    """
    require_positive("Ca", Ca)
    require_positive("Fa", Fa)
    require_positive("f_w", f_w)
    return (Ca / (f_w * Fa)) ** 3 * 1e6


def rated_life_hours(Ca, Fa, speed, f_w=1.2):
    """Rated life in hours, L / (60 N) with the mean speed N (min^-1)."""
    require_positive("speed", speed)
    return rated_life_revolutions(Ca, Fa, f_w) / (60.0 * speed)


def shaft_stiffness(d1, L, mounting: str = "fixed-free", E=E_STEEL):
    """Axial stiffness of the screw shaft (N/mm).

    ``"fixed-free"`` (one axial bearing, load at distance L): A E / L.
    ``"fixed-fixed"`` (both ends axially fixed): 4 A E / L, its minimum, with the nut at
    mid-span L/2.
    """
    require_positive("d1", d1)
    require_positive("L", L)
    if mounting == "fixed-free":
        return root_area(d1) * E / L
    if mounting == "fixed-fixed":
        return 4.0 * root_area(d1) * E / L
    raise InputError("mounting", f"{mounting!r} not in ('fixed-free', 'fixed-fixed')")


def axial_stiffness_chain(K_shaft, K_nut, K_bearing, K_housing=None):
    """Axial stiffness of the chain 1/K = 1/K_shaft + 1/K_nut + 1/K_bearing [+ 1/K_housing].

    Uses models.screw.series_stiffness (N/mm).
    """
    parts = [K_shaft, K_nut, K_bearing] + ([] if K_housing is None else [K_housing])
    return series_stiffness(*parts)


# --- constraints, g >= 0 ---------------------------------------------------------------------
def buckling_margin(F_max, d1, la, mounting: str = "fixed-supported", form: str = "catalogue"):
    """1 - F_max / P1 (>= 0 where the shaft does not buckle)."""
    return 1.0 - m.fabs(F_max) / buckling_load(d1, la, mounting, form)


def yield_margin(F_max, d1, sigma=SIGMA_ALLOWABLE):
    """1 - F_max / P2 (>= 0 where the shaft stress stays permissible)."""
    return 1.0 - m.fabs(F_max) / yield_load(d1, sigma)


def critical_speed_margin(speed_max, d1, lb, mounting: str = "fixed-supported"):
    """1 - N_max / N1 (>= 0 below the critical speed)."""
    return 1.0 - speed_max / critical_speed(d1, lb, mounting)


def life_margin(L_required_h, Ca, Fa, speed, f_w=1.2):
    """1 - L_required / L_h (>= 0 where the rated life covers the requirement)."""
    return 1.0 - L_required_h / rated_life_hours(Ca, Fa, speed, f_w)
