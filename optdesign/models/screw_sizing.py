"""Ball-screw sizing as the manufacturers publish it (THK, NSK, HIWIN, SKF; docs/screw.md).

Buckling, shaft yield, critical speed, rated life from a duty cycle and the axial
stiffness chain. Pure functions through :mod:`optdesign.math`: a design problem passes CasADi
symbols (d1, la, ...) and gets expressions, a sweep passes arrays. The ``*_margin``
functions are constraints in the form g >= 0 (1 - demand / capacity).

Units: d1, lengths in mm; E in MPa; forces in N; speeds in min^-1 (rev/min); life in
revolutions or hours; mass in kg; inertia in kg*mm^2 (x 1e-3 gives N*mm*s^2, the unit
that pairs with N*mm torques). Efficiency of the screw:
:mod:`optdesign.models.screw_efficiency`; catalogue data:
:mod:`optdesign.models.screw_catalogue`.

Validity
--------
buckling (Euler) : slenderness 4 la / d1 >= 90, or the yield load governs
    Euler's load holds for an elastic, slender column; a shorter shaft yields first,
    and the problem checks the catalogues' yield load P2 beside it (``check_yield``),
    so the smaller of the two stands. Documented, not checked.
life : load factor f_w 1 ... 3
    ISO 3408-5's L10 life with the makers' load factors (1-1.2 smooth, 1.2-1.5 normal,
    1.5-3 with impact); checked when the file is read (``requirements.f_w``).
"""

from __future__ import annotations

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models._checks import require_positive
from optdesign.models.screw import series_stiffness
from optdesign.models.validity import Validity

BUCKLING_SLENDERNESS = Validity(
    "screw_sizing.buckling_slenderness",
    "Euler buckling of the screw shaft",
    "slenderness 4 la / d1",
    90.0,
    None,
    "",
    "Euler's load is elastic; shorter shafts yield first, which the yield load P2 covers",
    checked=("documented",),
)
LOAD_FACTOR = Validity(
    "screw_sizing.load_factor",
    "rated life (ISO 3408-5)",
    "load factor f_w",
    1.0,
    3.0,
    "",
    "the makers' load factors run from 1 (smooth running) to 3 (heavy impact)",
    checked=("file",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (BUCKLING_SLENDERNESS, LOAD_FACTOR)


#: Young's modulus of screw steel used by the catalogues (MPa).
E_STEEL = 2.06e5

#: Euler end-condition factor eta_m of a column (P_cr = eta_m pi^2 E I / la^2).
EULER_END_FACTOR = {
    "fixed-free": 0.25,
    "supported-supported": 1.0,
    "fixed-supported": 2.0,
    "fixed-fixed": 4.0,
}

#: HIWIN's mounting factors, BS-08-2-EN-1704-K section 3.7.4-3.7.5 (p. 28): buckling
#: F_kmax = 0.5 x 4.072e5 f_k dk^4 / ls^2 (F 3.25-3.26) and critical speed
#: n_kmax = 0.8 x 2.71e8 f_n dk / ls^2 (F 3.27-3.28).
HIWIN_FK = {
    "fixed-free": 0.0625,
    "supported-supported": 0.25,
    "fixed-supported": 0.5,
    "fixed-fixed": 1.0,
}
HIWIN_FN = {
    "fixed-free": 0.147,
    "supported-supported": 0.446,
    "fixed-supported": 0.692,
    "fixed-fixed": 1.0,
}

#: Buckling factor eta_2 in P1 = eta_2 d1^4 / la^2 x 1e4 N (safety 0.5 included), by the
#: rule that gives it: ``"HIWIN"`` 0.5 x 40.72 f_k (F 3.25-3.26, exact); ``"common"`` the
#: rounded factors printed by THK, NSK and others ([CAT]), whose fixed-free 1.3 lies 2.2 %
#: above HIWIN's 1.2725 (unsafe side); ``"conservative"`` (the default) the smaller of the
#: two for each mounting.
BUCKLING_FACTORS: dict[str, dict[str, float]] = {
    "HIWIN": {k: 0.5 * 40.72 * f for k, f in HIWIN_FK.items()},
    "common": {
        "fixed-free": 1.3,
        "supported-supported": 5.0,
        "fixed-supported": 10.0,
        "fixed-fixed": 20.0,
    },
}

#: Critical-speed factor lambda_2 in N1 = lambda_2 d1 / lb^2 x 1e7 min^-1 (the catalogues'
#: 0.8 safety factor included), by rule: ``"HIWIN"`` 0.8 x 27.1 f_n (F 3.27-3.28);
#: ``"common"`` 3.4, 9.7, 15.1, 21.9 ([CAT]; the fixed-free 3.4 is 6.7 % above HIWIN's
#: 3.187); ``"conservative"`` the smaller of the two for each mounting.
CRITICAL_SPEED_FACTORS: dict[str, dict[str, float]] = {
    "HIWIN": {k: 0.8 * 27.1 * f for k, f in HIWIN_FN.items()},
    "common": {
        "fixed-free": 3.4,
        "supported-supported": 9.7,
        "fixed-supported": 15.1,
        "fixed-fixed": 21.9,
    },
}
for _table in (BUCKLING_FACTORS, CRITICAL_SPEED_FACTORS):
    _table["conservative"] = {
        k: min(_table["HIWIN"][k], _table["common"][k]) for k in _table["HIWIN"]
    }

#: The rules :func:`buckling_load` and :func:`critical_speed` know; the default is the
#: conservative one.
MOUNTING_RULES = ("conservative", "HIWIN", "common")

#: Buckling and critical-speed factors of the default (conservative) rule.
BUCKLING_FACTOR = BUCKLING_FACTORS["conservative"]
CRITICAL_SPEED_FACTOR = CRITICAL_SPEED_FACTORS["conservative"]

#: Permissible tensile/compressive stress of the screw shaft in the catalogues (MPa).
SIGMA_ALLOWABLE = 147.0

#: Density of steel (kg/mm^3).
STEEL_DENSITY = 7.85e-6

#: DN = d0 x n_max limits (mm x min^-1), HIWIN *Ballscrews & Accessories*
#: BS-08-2-EN-1704-K, section 3.7.6 (p. 29): rolled 70 000, peeled and ground 90 000,
#: high-speed series 180 000, on the nominal (shaft) diameter ds. Other makers print their own limits.
DN_LIMIT = {"rolled": 70_000.0, "peeled": 90_000.0, "ground": 90_000.0, "high-speed": 180_000.0}

#: A DN rule: which diameter it multiplies by the speed and its limit for each grade.
#: ``"HIWIN"``: the nominal diameter d0 (HIWIN's ds), :data:`DN_LIMIT`. ``"ball-centre"``
#: (the default, the conservative one): the ball-centre diameter d_m and 70 000 whatever
#: the grade - the rule of the makers that rate DN on the ball circle ([CAT]; THK's
#: selection example checks N2 = 70 000 / D, D the ball center-to-center diameter,
#: [THK-EX] in docs/references.md), at or below HIWIN's limit for every grade.
DN_RULES: dict[str, tuple[str, dict[str, float]]] = {
    "HIWIN": ("nominal", DN_LIMIT),
    "ball-centre": ("ball-centre", {grade: 70_000.0 for grade in DN_LIMIT}),
}


def dn_rule(rule: str, grade: str | None = None) -> tuple[str, float | None]:
    """(diameter it applies to, limit for ``grade``) of DN rule ``rule``.

    The diameter is ``"nominal"`` (d0) or ``"ball-centre"`` (d_m); the limit is None when
    no grade is named (a limit given as a number).
    """
    if rule not in DN_RULES:
        raise InputError("dn_rule", f"{rule!r} not in {sorted(DN_RULES)}")
    diameter, limits = DN_RULES[rule]
    if grade is None:
        return diameter, None
    if grade not in limits:
        raise InputError("dn_max", f"{grade!r} not in {sorted(limits)}")
    return diameter, limits[grade]


def _factor(table: dict[str, float], mounting: str) -> float:
    try:
        return table[mounting]
    except KeyError:
        raise InputError("mounting", f"{mounting!r} not in {sorted(table)}") from None


def _rule_table(tables: dict[str, dict[str, float]], rule: str) -> dict[str, float]:
    try:
        return tables[rule]
    except KeyError:
        raise InputError("rule", f"{rule!r} not in {list(MOUNTING_RULES)}") from None


def second_moment(d1):
    """Second moment of area of the root circle, I = pi d1^4 / 64 (mm^4)."""
    return m.pi * d1**4 / 64.0


def root_area(d1):
    """Root-circle area A = pi d1^2 / 4 (mm^2)."""
    return m.pi * d1**2 / 4.0


def buckling_load(
    d1,
    la,
    mounting: str = "fixed-supported",
    form: str = "catalogue",
    E=E_STEEL,
    safety=0.5,
    rule: str = "conservative",
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
        ``"catalogue"``: P1 = eta_2 d1^4 / la^2 x 1e4 with eta_2 of
        :data:`BUCKLING_FACTORS` by ``rule`` (the form the catalogues' examples use);
        ``"euler"``: P1 = safety eta_m pi^2 E I / la^2 with the end factor eta_m of
        :data:`EULER_END_FACTOR` and the exact constant. With E = 2.06e5 MPa and safety
        0.5 the Euler form is eta_2 = 0.5 eta_m pi^3 E / 64 x 1e-4 = 1.2475, 4.99, 9.98,
        19.96; the catalogue's 10 and 20 round these up by 0.2 %, but its fixed-free
        1.3 lies 4.2 % above the Euler value 1.2475, on the unsafe side. HIWIN
        (BS-08-2-EN-1704-K, F 3.25-3.26) writes the same Euler load as
        0.5 x 4.072e5 f_k dk^4 / ls^2 with f_k = 1, 0.5, 0.25, 0.0625 (E = 2.1e5 MPa).
    E
        Young's modulus (MPa), Euler form only.
    safety
        Safety factor on the Euler load, Euler form only (catalogues: 0.5).
    rule
        ``"conservative"`` (default), ``"HIWIN"`` or ``"common"``: whose factors
        (:data:`BUCKLING_FACTORS`), catalogue form only.
    """
    require_positive("d1", d1)
    require_positive("la", la)
    if form == "catalogue":
        return _factor(_rule_table(BUCKLING_FACTORS, rule), mounting) * d1**4 / la**2 * 1e4
    if form == "euler":
        eta_m = _factor(EULER_END_FACTOR, mounting)
        return safety * eta_m * m.pi**2 * E * second_moment(d1) / la**2
    raise InputError("form", f"{form!r} not in ('catalogue', 'euler')")


def yield_load(d1, sigma=SIGMA_ALLOWABLE):
    """Permissible tensile/compressive load of the shaft P2 = sigma pi d1^2 / 4 (N)."""
    require_positive("d1", d1)
    return sigma * root_area(d1)


def critical_speed(d1, lb, mounting: str = "fixed-supported", rule: str = "conservative"):
    """Permissible rotational speed N1 = lambda_2 d1 / lb^2 x 1e7 (min^-1).

    Parameters
    ----------
    d1
        Root diameter (mm).
    lb
        Distance between the supports (mm).
    mounting
        End conditions, keys of :data:`CRITICAL_SPEED_FACTOR`.
    rule
        ``"conservative"`` (default), ``"HIWIN"`` or ``"common"``: whose factors
        (:data:`CRITICAL_SPEED_FACTORS`).
    """
    require_positive("d1", d1)
    require_positive("lb", lb)
    return _factor(_rule_table(CRITICAL_SPEED_FACTORS, rule), mounting) * d1 / lb**2 * 1e7


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


def rated_life_revolutions(Ca, Fa, f_w=1.0):
    """Rated life L = (Ca / (f_w Fa))^3 x 1e6 (revolutions).

    Parameters
    ----------
    Ca
        Basic dynamic load rating (N).
    Fa
        (Mean) axial load (N), e.g. :func:`mean_load`.
    f_w
        Load factor. ISO 3408-5 (7.2.1) defines the nominal life with none, f_w = 1.0, the
        default here; the catalogues multiply the load by an operating factor: 1.0-1.2
        smooth, 1.2-1.5 normal, 1.5-2 with impact (docs/screw.md), HIWIN's f_p 1.1-1.2
        without impact (BS-08-2-EN-1704-K, F 3.8). Pass the factor you assume.
    """
    require_positive("Ca", Ca)
    require_positive("Fa", Fa)
    require_positive("f_w", f_w)
    return (Ca / (f_w * Fa)) ** 3 * 1e6


def rated_life_hours(Ca, Fa, speed, f_w=1.0):
    """Rated life in hours, L / (60 N) with the mean speed N (min^-1); f_w as
    :func:`rated_life_revolutions` (default 1.0, ISO 3408-5)."""
    require_positive("speed", speed)
    return rated_life_revolutions(Ca, Fa, f_w) / (60.0 * speed)


def duty_cycle_life_hours(Ca, forces, speeds, times, f_w=1.0):
    """Rated life (h) over a duty cycle of steps (axial force, speed, time).

    The steps count by the revolutions they take, n_i t_i: mean speed
    N_m = sum n_i t_i / sum t_i, cubic mean load Fm over n_i t_i (:func:`mean_load`), and
    L_h = (Ca / (f_w Fm))^3 1e6 / (60 N_m) (ISO 3408-5 7.1-7.2; HIWIN F 3.4, F 3.8-3.12).

    Parameters
    ----------
    Ca
        Basic dynamic load rating (N).
    forces, speeds, times
        Per step: axial force (N, sign ignored), speed (min^-1, >= 0) and time (any unit,
        only the shares matter).
    f_w
        Load factor applied to every step (stated by the caller; ISO default 1.0).
    """
    if not m.is_symbolic(forces, speeds, times):
        n = np.asarray(speeds, dtype=float)
        t = np.asarray(times, dtype=float)
        if n.shape != t.shape or np.asarray(forces).shape[-1:] != n.shape[-1:]:
            raise InputError("times", "needs one force, speed and time per step")
        if np.any(n < 0) or np.any(t < 0):
            raise InputError("speeds", "speeds and times must be >= 0")
        speeds, times = n, t
    revs = speeds * times
    Fm = mean_load(forces, revs)
    return rated_life_hours(Ca, Fm, mean_speed(speeds, times), f_w)


def static_safety_factor(C0a, Fa_max):
    """Static safety factor f_s = C0a / |Fa_max| (ISO 3408-5; HIWIN F 3.3: S0 Fa_max < C0).

    The minimum to ask for is the designer's (service conditions); none is assumed here.
    """
    require_positive("C0a", C0a)
    return C0a / m.fabs(Fa_max)


def dn_value(d0, n_max):
    """DN = d0 x n_max (mm x min^-1), nominal diameter times the highest speed; compare
    with :data:`DN_LIMIT` (HIWIN: rolled 70 000, ground 90 000)."""
    require_positive("d0", d0)
    return d0 * n_max


def shaft_mass(d0, length, density=STEEL_DENSITY):
    """Mass of the screw shaft as a solid cylinder of the nominal diameter, rho pi d0^2 L / 4 (kg).

    The thread grooves remove a few per cent; catalogues compute the same way (HIWIN
    F 3.19 takes m_r with the nominal diameter).
    """
    require_positive("d0", d0)
    require_positive("length", length)
    return density * m.pi * d0**2 * length / 4.0


def shaft_inertia(d0, length, density=STEEL_DENSITY):
    """Polar moment of inertia of the shaft about its axis, m d0^2 / 8 (kg*mm^2)."""
    return shaft_mass(d0, length, density) * d0**2 / 8.0


def reflected_inertia(J_screw, m_load, p, i_a=1.0, J_driven=0.0, J_driving=0.0):
    """Inertia at the motor shaft (kg*mm^2) of the screw, the translating mass and the gears.

    J = J_driving + (J_driven + J_screw) / i_a^2 + m_load (p / (2 pi i_a))^2, with i_a the
    gear ratio (motor turns per screw turn) and p the lead (mm); HIWIN F 3.19 in mm units.
    The linkage behind the nut adds its own reflected inertia through the nut rate
    (dm/dphi); that is the mechanism's to add.
    """
    require_positive("i_a", i_a)
    return J_driving + (J_driven + J_screw) / i_a**2 + m_load * (p / (2.0 * m.pi * i_a)) ** 2


#: Mountings :func:`shaft_stiffness` knows.
STIFFNESS_MOUNTINGS = ("fixed-free", "fixed-supported", "fixed-fixed")


def shaft_stiffness(d1, L, mounting: str = "fixed-free", E=E_STEEL, x=None):
    """Axial stiffness of the screw shaft between its axial bearing(s) and the nut (N/mm).

    Parameters
    ----------
    d1
        Root diameter (mm); HIWIN (F 3.31-3.33) uses the load diameter
        dc = PCD - D_ball cos(alpha), slightly larger: the root is the conservative choice.
    L
        ``"fixed-free"``: distance from the axial bearing to the nut (as before);
        ``"fixed-supported"`` and ``"fixed-fixed"``: distance between the bearings.
    mounting
        ``"fixed-free"`` / ``"fixed-supported"``: one axial bearing (a floating support
        takes no axial load), K = A E / x. ``"fixed-fixed"``: both ends axially fixed, the
        two shaft parts act in parallel, K = A E L / (x (L - x)) (HIWIN F 3.32).
    E
        Young's modulus (MPa).
    x
        Nut position measured from the (first) axial bearing (mm). Default: the worst
        case, x = L (one axial bearing) or x = L/2 (fixed-fixed, K = 4 A E / L).
    """
    require_positive("d1", d1)
    require_positive("L", L)
    if mounting not in STIFFNESS_MOUNTINGS:
        raise InputError("mounting", f"{mounting!r} not in {STIFFNESS_MOUNTINGS}")
    AE = root_area(d1) * E
    if mounting == "fixed-fixed":
        x = 0.5 * L if x is None else x
        _check_nut_position(x, L)
        return AE * L / (x * (L - x))
    x = L if x is None else x
    _check_nut_position(x, L, closed=True)
    return AE / x


def _check_nut_position(x, L, closed: bool = False) -> None:
    if m.is_symbolic(x, L):
        return
    xa, La = np.asarray(x, dtype=float), np.asarray(L, dtype=float)
    inside = (xa > 0) & ((xa <= La) if closed else (xa < La))
    if not np.all(inside):
        raise InputError("x", f"nut position must lie in (0, L{']' if closed else ')'}, got {x!r}")


def axial_stiffness_chain(K_shaft, K_nut, K_bearing, K_housing=None):
    """Axial stiffness of the chain 1/K = 1/K_shaft + 1/K_nut + 1/K_bearing [+ 1/K_housing].

    Uses models.screw.series_stiffness (N/mm).
    """
    parts = [K_shaft, K_nut, K_bearing] + ([] if K_housing is None else [K_housing])
    return series_stiffness(*parts)


# --- nut stiffness by the catalogue's rule ------------------------------------------------
#: Nut stiffness rules: ``"table"`` the printed value as it stands; ``"load"`` HIWIN F 3.35
#: (a single nut with play, at an axial load); ``"preload"`` HIWIN F 3.34 (a preloaded nut).
NUT_STIFFNESS_RULES = ("load", "table", "preload")


def nut_stiffness_at_load(K_table, Ca, Fa):
    """Stiffness of a single nut with play under the axial load ``Fa`` (N/mm), HIWIN
    BS-08-2-EN-1704-K F 3.35: R_n = 0.8 K (F / (0.28 Ca))^(1/3).

    Parameters
    ----------
    K_table
        The dimension table's rigidity (N/mm; HIWIN's ground-screw tables print it
        "calculated without preload for loading of 30 % of the dynamic load rating").
    Ca
        Dynamic load rating of the nut (N).
    Fa
        Axial load on the nut (N, sign ignored). The catalogue writes the mean operating
        load F_bm; a requirement passes the load it concerns (the hinge moment's nut force
        for a stiffness requirement). The ball contacts are Hertzian (deflection as
        F^(2/3)), hence the cube root: the nut is softer at light load.
    """
    require_positive("K_table", K_table)
    require_positive("Ca", Ca)
    return 0.8 * K_table * (m.fabs(Fa) / (0.28 * Ca)) ** (1.0 / 3.0)


def nut_stiffness_preloaded(K_table, Ca, preload):
    """Stiffness of a preloaded nut (N/mm), HIWIN BS-08-2-EN-1704-K F 3.34:
    R_n = 0.8 K (F_pr / (0.1 Ca))^(1/3), with the preload F_pr (N); the catalogue's
    highest preload is 10 % of Ca (double nut), 5 % for a single nut (F 3.5)."""
    require_positive("K_table", K_table)
    require_positive("Ca", Ca)
    require_positive("preload", preload)
    return 0.8 * K_table * (preload / (0.1 * Ca)) ** (1.0 / 3.0)


# --- constraints, g >= 0 ---------------------------------------------------------------------
def buckling_margin(
    F_max, d1, la, mounting: str = "fixed-supported", form: str = "catalogue", rule="conservative"
):
    """1 - F_max / P1 (>= 0 where the shaft does not buckle)."""
    return 1.0 - m.fabs(F_max) / buckling_load(d1, la, mounting, form, rule=rule)


def yield_margin(F_max, d1, sigma=SIGMA_ALLOWABLE):
    """1 - F_max / P2 (>= 0 where the shaft stress stays permissible)."""
    return 1.0 - m.fabs(F_max) / yield_load(d1, sigma)


def critical_speed_margin(
    speed_max, d1, lb, mounting: str = "fixed-supported", rule: str = "conservative"
):
    """1 - N_max / N1 (>= 0 below the critical speed)."""
    return 1.0 - speed_max / critical_speed(d1, lb, mounting, rule)


def static_safety_margin(Fa_max, C0a, f_s_min):
    """1 - f_s_min |Fa_max| / C0a (>= 0 where the static safety factor reaches f_s_min)."""
    return 1.0 - f_s_min * m.fabs(Fa_max) / C0a


def dn_margin(d0, n_max, limit=DN_LIMIT["rolled"]):
    """1 - d0 n_max / DN_limit (>= 0 below the DN limit; default HIWIN rolled, 70 000)."""
    return 1.0 - dn_value(d0, n_max) / limit


def life_margin(L_required_h, Ca, Fa, speed, f_w=1.0):
    """1 - L_required / L_h (>= 0 where the rated life covers the requirement)."""
    return 1.0 - L_required_h / rated_life_hours(Ca, Fa, speed, f_w)
