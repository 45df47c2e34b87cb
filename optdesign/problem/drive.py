"""The drive of a design: the screw (catalogue item or continuous size), its efficiency
forward and back, its speed, life, static safety, and the output stiffness of the chain.

Mechanism-free: everything here reads the design's quantities (the nut velocity and force
over the grid, the clearance chain's sensitivities) and the problem's ``[screw]`` section.

**Screw data.** A catalogue screw (``[screw] catalogue = "HIWIN"``, ``d0`` and ``p`` declared
with ``catalogue = "HIWIN"``) is the catalogue's (d0, p) pair with its strongest nut of the
allowed type (highest dynamic rating, then static rating, then stiffness): root diameter
d1, ratings Ca and C0a and the nut stiffness come from that row. On the NumPy path they
are looked up from the design's d0 and p (a pair the catalogue lacks gives NaN: not a
design); on the solver path they are the problem's *parameters*, set per solve by the
catalogue search - the item's own values at a leaf, and at a relaxation node the most
favourable values of the items in the node's box (largest d1, Ca, C0a, nut stiffness),
which keeps the relaxation a valid bound. Without a catalogue, a
declared ``d0`` is a continuous mean diameter with d1 = root_ratio d0; without ``d0`` the
legacy ``requirements.screw.root_diameter`` gives d1.

**Pins with ISO 286 table fits** use a parameter the same way: the table's clearance over
the smooth formula's at the pin diameter (exact at a catalogue leaf, the smallest ratio of
the node's items in a relaxation).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import ProblemError
from optdesign.models import screw_sizing as sizing
from optdesign.models.screw_catalogue import BallScrew, load_ball_screws
from optdesign.models.screw_efficiency import MU_BALL_DEFAULT, MU_SLIDING_DEFAULT, screw_efficiency
from optdesign.models.stiffness import G_STEEL, polar_moment
from optdesign.problem import motor_catalogue_variable

#: HIWIN's design value of the forward efficiency for torque sizing, the lower end of its
#: 0.85-0.95 (BS-08-2-EN-1704-K, F 3.15).
EFFICIENCY_DESIGN_FORWARD = 0.85

#: Prefix of the design-dict keys that carry parameters on the solver path.
PARAM = "param:"

#: Screw item fields that are parameters, with the direction that is favourable for a
#: relaxation (+1: the largest value of the node's items, -1: the smallest).
SCREW_FIELDS = {"d1": +1, "Ca": +1, "C0a": +1, "K_nut": +1, "K_load": +1}


@dataclass(frozen=True)
class ScrewData:
    """The screw of one design (values or expressions, mm, N, N/mm, kg).

    ``on_catalogue``: 1 where the design's (d0, p) is a catalogue item, 0 where not
    (NumPy path; None on the solver path, where the search solves items only).
    ``K_load``: the nut's stiffness by HIWIN F 3.35 per cube root of the axial load,
    0.8 K_nut / (0.28 Ca)^(1/3) (N/mm per N^(1/3)); a relaxation takes its largest value
    over the node's items (the stiffness at any load grows with it).
    """

    d0: Any
    p: Any
    d_m: Any
    d1: Any
    Ca: Any = None
    C0a: Any = None
    K_nut: Any = None
    K_load: Any = None
    on_catalogue: Any = None


# --- catalogue ------------------------------------------------------------------------------
@cache
def catalogue_items(name: str, nut: str | None) -> dict[tuple[float, float], BallScrew]:
    """(d0, p) -> the strongest nut of the allowed type, for catalogue ``name``."""
    if name != "HIWIN":
        raise ProblemError(f"screw.catalogue: unknown catalogue {name!r} (known: HIWIN)")
    best: dict[tuple[float, float], BallScrew] = {}
    for row in load_ball_screws():
        if nut is not None and row.nut != nut:
            continue
        key = (row.d0, row.p)
        old = best.get(key)
        if old is None or (row.Ca, row.C0a, row.K_nut) > (old.Ca, old.C0a, old.K_nut):
            best[key] = row
    return best


def catalogue_values(name: str, variable: str, nut: str | None = None) -> tuple[float, ...]:
    """The values a catalogue gives variable ``d0`` or ``p``."""
    items = catalogue_items(name, nut)
    if variable == "d0":
        return tuple(sorted({k[0] for k in items}))
    if variable == "p":
        return tuple(sorted({k[1] for k in items}))
    raise ProblemError(f"variables.{variable}: the {name} screw catalogue gives d0 and p only")


def _row_value(row: BallScrew | None, field: str) -> float:
    if row is None:
        return np.nan
    if field == "K_load":
        return 0.8 * float(row.K_nut) / (0.28 * float(row.Ca)) ** (1.0 / 3.0)
    value = getattr(row, field)
    return np.nan if value is None else float(value)


def _nearest(items, d0: float, p: float) -> tuple[BallScrew, bool]:
    """The item (d0, p), or the nearest one and False when the catalogue lacks the pair."""
    key = (float(np.round(d0, 9)), float(np.round(p, 9)))
    if key in items:
        return items[key], True
    near = min(items, key=lambda k: abs(np.log(k[0] / d0)) + abs(np.log(k[1] / p)))
    return items[near], False


def _lookup(items, d0, p, fields) -> tuple[dict[str, Any], Any]:
    """The items' ``fields`` on the NumPy path, element-wise, and where the design is an
    item (1.0) or not (0.0): off the catalogue the nearest item's values stand in, so
    that the other quantities stay finite, and the ``screw_catalogue_membership`` block fails."""
    d0, p = np.broadcast_arrays(np.asarray(d0, dtype=float), np.asarray(p, dtype=float))
    out = {f: np.full(d0.shape, np.nan) for f in fields}
    on = np.zeros(d0.shape)
    for idx in np.ndindex(d0.shape):
        if not (np.isfinite(d0[idx]) and np.isfinite(p[idx]) and d0[idx] > 0 and p[idx] > 0):
            continue
        row, exact = _nearest(items, float(d0[idx]), float(p[idx]))
        on[idx] = float(exact)
        for f in fields:
            out[f][idx] = _row_value(row, f)
    if not d0.ndim:
        return {f: float(v) for f, v in out.items()}, float(on)
    return out, on


# --- parameters -----------------------------------------------------------------------------
def fit_values(problem) -> str:
    """``"table"`` or ``"smooth"``: the file's choice, else table for a catalogue pin."""
    req = problem.spec.requirements
    if req.fit_values is not None:
        return req.fit_values
    d = problem.by_name.get("d")
    return "table" if d is not None and d.discrete else "smooth"


def parameter_defaults(problem) -> dict[str, float]:
    """The problem's parameters and their defaults. With no catalogue variable free (a
    screw, a pin or a motor the file gives as one item), no catalogue search replaces
    them: the defaults are then those items' own data (:func:`parameter_values`), as the
    NumPy check reads them. Otherwise a fit ratio of 1 (the smooth formula's clearance)
    or the fit's favourable table clearance, and placeholders (1) for the screw's and the
    motor's data, which every catalogue solve replaces by its node's values."""
    out = _placeholders(problem)
    if not any(v.discrete for v in problem.free):
        out.update(parameter_values(problem, {}))
    return out


def _placeholders(problem) -> dict[str, float]:
    """Every parameter of the problem: a fit ratio of 1 (the smooth formula's clearance)
    or the fit's favourable table clearance, and placeholders (1) for the screw's and the
    motor's data."""
    out: dict[str, float] = {}
    if "d" in problem.by_name and fit_values(problem) == "table":
        d = problem.by_name["d"]
        if d.free and not d.discrete:
            raise ProblemError(
                "requirements.fit_values: table values need pin diameters from a catalogue "
                '(d = { catalogue = "ISO 2338", ... }); use "smooth" for a continuous d'
            )
        if _fit(problem).has_smooth:
            out["fit_ratio_max"] = 1.0
            out["fit_ratio_min"] = 1.0
        else:  # the parameter is the clearance itself: the catalogue's favourable one
            out.update(_fit_ratios(problem, {}))
    screw = problem.spec.screw
    if screw is not None and screw.catalogue is not None:
        for field in SCREW_FIELDS:
            out[f"screw_{field}"] = 1.0
    out.update(motor_catalogue_variable.parameter_defaults(problem))
    return out


def parameter_values(problem, box: dict[str, tuple[float, float]]) -> dict[str, float]:
    """Parameter values of a solve whose discrete variables lie in ``box`` (name ->
    (lo, hi); fixed variables as (v, v)): exact for a single item, favourable over the
    items of a wider box (a valid relaxation). Empty when the box holds no catalogue item."""
    defaults = _placeholders(problem)
    values: dict[str, float] = {}
    if "fit_ratio_max" in defaults:
        values.update(_fit_ratios(problem, box))
    if "screw_d1" in defaults:
        values.update(_screw_values(problem, box))
    values.update(motor_catalogue_variable.parameter_values(problem, box))
    return values


def parameter_owners(problem) -> dict[str, tuple[str, ...]]:
    """The variables whose catalogue item each parameter of :func:`parameter_values`
    reads (parameter name -> variable names): the fit's ratios the pin's ``d``, the
    screw's data its ``(d0, p)`` pair, the motor's data its number. A search asks which
    items' data enter a quantity through this map, not through the parameters' names."""
    out: dict[str, tuple[str, ...]] = {}
    for name in _placeholders(problem):
        if name.startswith("fit_ratio_"):
            out[name] = ("d",)
        elif name.startswith("screw_"):
            out[name] = ("d0", "p")
    out.update(motor_catalogue_variable.parameter_owners(problem))
    return out


def _range(problem, name: str, box) -> tuple[float, float]:
    v = problem.by_name[name]
    if name in box:
        return box[name]
    return (v.value, v.value) if not v.free else (v.lower, v.upper)


def _items_in(values, lo, hi) -> list[float]:
    tol = 1e-9 * max(1.0, abs(hi))
    return [v for v in values if lo - tol <= v <= hi + tol]


def _fit(problem):
    from optdesign.models.fit_formulas import Fit

    return Fit.parse(problem.spec.requirements.fit, "requirements.fit", values="table")


def _fit_ratios(problem, box) -> dict[str, float]:
    """The table fit's parameters over the node's items: the table clearance over the
    smooth one (the smallest ratio), or for a fit with no smooth formula the table
    clearance itself (the smallest, mm)."""
    d = problem.by_name["d"]
    lo, hi = _range(problem, "d", box)
    items = _items_in(d.values if d.discrete else (d.value,), lo, hi)
    fit = _fit(problem)
    out = {}
    for which in ("max", "min"):
        ratios = []
        for D in items:
            table = float(fit.clearance(D, which, values="table"))
            if not fit.has_smooth:
                ratios.append(table)
                continue
            smooth = float(fit.clearance(D, which, values="smooth"))
            ratios.append(table / smooth if smooth > 0 else 1.0)
        out[f"fit_ratio_{which}"] = min(ratios) if ratios else 1.0
    return out


def _screw_values(problem, box) -> dict[str, float]:
    screw = problem.spec.screw
    items = catalogue_items(screw.catalogue, screw.nut)
    d_lo, d_hi = _range(problem, "d0", box)
    p_lo, p_hi = _range(problem, "p", box)
    rows = [
        r
        for (d0, p), r in items.items()
        if d_lo - 1e-9 <= d0 <= d_hi + 1e-9 and p_lo - 1e-9 <= p <= p_hi + 1e-9
    ]
    if not rows:
        return {}
    out = {}
    for field, sign in SCREW_FIELDS.items():
        vals = [_row_value(r, field) for r in rows]
        vals = [v for v in vals if np.isfinite(v)] or [0.0]
        out[f"screw_{field}"] = max(vals) if sign > 0 else min(vals)
    return out


def box_has_item(problem, box) -> bool:
    """Whether a box of the discrete variables holds a catalogue screw and a catalogue
    motor (always True for one that is not a catalogue item)."""
    if motor_catalogue_variable.catalogue_of(problem) is not None and not (
        motor_catalogue_variable.parameter_values(problem, box)
    ):
        return False
    screw = problem.spec.screw
    if screw is None or screw.catalogue is None:
        return True
    return bool(_screw_values(problem, box))


def screw_shaft_inertia(q):
    """The screw shaft's inertia about its axis (kg*mm^2): a solid steel shaft of d0 over
    the support length; None when ``[screw]`` does not give them."""
    screw, data = q.problem.spec.screw, q.screw
    if screw is None or screw.length is None or data is None or data.d0 is None:
        return None
    return sizing.shaft_inertia(data.d0, screw.length)


# --- screw data and efficiency ------------------------------------------------------------
def screw_data(q) -> ScrewData | None:
    """The screw of design ``q`` (None when the problem says nothing of the screw)."""
    spec = q.problem.spec
    screw, legacy = spec.screw, spec.requirements.screw
    design = q.design
    p = design["p"]
    if screw is not None and screw.catalogue is not None:
        d0 = design["d0"]
        if PARAM + "screw_d1" in design:
            vals = {f: design[PARAM + f"screw_{f}"] for f in SCREW_FIELDS}
            return ScrewData(d0, p, d0, **vals)
        items = catalogue_items(screw.catalogue, screw.nut)
        vals, on = _lookup(items, d0, p, SCREW_FIELDS)
        return ScrewData(d0, p, d0, **vals, on_catalogue=on)
    if "d0" in design:
        d0 = design["d0"]
        ratio = screw.root_ratio if screw is not None else 0.83
        K = screw.nut_stiffness if screw is not None else None
        return ScrewData(d0, p, d0, ratio * d0, K_nut=K)
    if legacy is not None:
        d1 = legacy.root_diameter
        return ScrewData(None, p, None, d1)
    return None


def friction(spec) -> float:
    screw = spec.screw
    if screw.friction is not None:
        return screw.friction
    return MU_BALL_DEFAULT if screw.kind == "ball" else MU_SLIDING_DEFAULT


def efficiencies(q) -> tuple[Any, Any]:
    """(forward, back-driving) efficiency of the screw alone: the model of ``[screw]``
    (lead, mean diameter, friction), else the requirements' constants."""
    spec = q.problem.spec
    req = spec.requirements
    if spec.screw is None:
        back = req.lock.eta_screw_back if req.lock is not None else 1.0
        return req.eta_screw, back
    data = q.screw
    if data is None or data.d_m is None:
        raise ProblemError(
            "variables.d0: the screw's efficiency needs its mean diameter: declare d0 "
            "(or a catalogue screw)"
        )
    kind, mu = spec.screw.kind, friction(spec)
    fwd = screw_efficiency(kind, data.p, data.d_m, mu, "forward")
    back = screw_efficiency(kind, data.p, data.d_m, mu, "back")
    if spec.screw.efficiency_design == "HIWIN":
        # HIWIN's design value for torque sizing (F 3.15: 0.85-0.95 forward), its lower
        # end; the back-driving efficiency stays the friction model's, which exceeds the
        # catalogue's 0.75-0.85 and so loads the lock more (the safe side for the lock)
        # (added to 0 x the model's value: the same type and shape, and a design that
        # does not assemble stays NaN)
        fwd = EFFICIENCY_DESIGN_FORWARD + 0.0 * fwd
    return fwd, back


def gear_efficiencies(spec) -> tuple[float, float]:
    if spec.screw is not None:
        return spec.screw.gear_efficiency, spec.screw.gear_back_efficiency
    req = spec.requirements
    back = req.lock.eta_gear_back if req.lock is not None else 1.0
    return req.eta_gear, back


# --- speed, life, static safety ---------------------------------------------------------------
def screw_speed(q, phi=None):
    """Screw speed (1/min) at the required deflection rate, over the grid (or at ``phi``)."""
    rate = q.requirements.deflection_rate
    v = q.nut_velocity if phi is None else q.mechanism.nut_velocity(phi)
    return m.fabs(v) * rate / q.screw.p * 60.0


def duty_cycle_means(q) -> tuple[Any, Any]:
    """(cubic mean load F_m in N, mean speed n_m in 1/min) of the duty cycle, ISO 3408-5
    (HIWIN F 3.4, F 3.8): the steps weighted by the revolutions they take."""
    req = q.requirements
    steps = req.duty_cycle
    phis = np.array([s.deflection for s in steps])
    v = q.mechanism.nut_velocity(phis)
    v = [at_angle(v, k) for k in range(len(steps))]
    forces = [m.fabs(s.hinge_moment / v[k]) for k, s in enumerate(steps)]
    speeds = [m.fabs(v[k]) * req.deflection_rate / q.screw.p * 60.0 for k in range(len(steps))]
    times = [s.time for s in steps]
    # The cubic mean load and mean speed of the cycle (written out so it holds on CasADi).
    work = sum(F**3 * n * t for F, n, t in zip(forces, speeds, times, strict=True))
    revs = sum(n * t for n, t in zip(speeds, times, strict=True))
    return (work / revs) ** (1.0 / 3.0), revs / sum(times)


def life_hours(q):
    """Rated life (h) over the duty cycle, ISO 3408-5 L10 with the stated f_w."""
    F_m, n_m = duty_cycle_means(q)
    return (q.screw.Ca / (q.requirements.f_w * F_m)) ** 3 * 1e6 / (60.0 * n_m)


def at_angle(v, k):
    # the k-th angle: a CasADi column's row; on NumPy the last axis, kept as an axis so
    # that a population's (pop, 1) columns broadcast with the catalogue data (pop, 1)
    return v[k] if m.is_symbolic(v) else np.asarray(v)[..., k : k + 1]


# --- stiffness --------------------------------------------------------------------------------
def axial_compliance(q):
    """Axial compliance of the screw side (mm/N) over the grid: the support bearings, the
    nut and the shaft (tension/compression to the nut, and torsion from the motor end,
    turned into an axial compliance through the lead)."""
    spec = q.problem.spec
    screw = spec.screw
    data = q.screw
    total = 0.0
    if screw.bearing_stiffness is not None:
        total = total + 1.0 / screw.bearing_stiffness
    K_nut = nut_stiffness(q)
    if K_nut is not None:
        total = total + 1.0 / K_nut
    if screw.nut_offset is not None:
        x = screw.nut_offset + m.fabs(q.nut_position - at_angle(q.nut_position, 0))
        area = np.pi * data.d1**2 / 4.0
        total = total + x / (area * sizing.E_STEEL)
        # motor held: the torsion of the shaft between the drive end and the nut, as a
        # compliance x (p / 2 pi)^2 / (G J) - the inverse of torsion_to_axial(G J / x, p),
        # written out so that a population's non-assembling designs (NaN x) stay NaN
        # instead of failing the models' input checks
        total = total + x * (data.p / (2.0 * m.pi)) ** 2 / (G_STEEL * polar_moment(data.d1))
    return total


def nut_stiffness_rule(spec) -> str:
    """The file's ``nut_stiffness_rule``, else ``"load"`` for a catalogue screw (HIWIN
    F 3.35) and ``"table"`` (the given ``nut_stiffness`` as it stands) otherwise."""
    screw = spec.screw
    if screw.nut_stiffness_rule is not None:
        return screw.nut_stiffness_rule
    return "load" if screw.catalogue is not None else "table"


def nut_load(q):
    """The axial load (N) the nut stiffness is evaluated at: the nut force under the
    hinge moment at each grid angle (``stiffness_load = "hinge"``), or the duty cycle's
    cubic mean load (``"duty-mean"``, one value)."""
    if q.requirements.stiffness_load == "duty-mean":
        return duty_cycle_means(q)[0]
    return m.fabs(q.nut_force)


def nut_stiffness(q):
    """Axial stiffness of the nut (N/mm) by the problem's rule, over the grid (or one
    value): the table value, HIWIN F 3.35 at :func:`nut_load`, or F 3.34 at the preload;
    None for a rigid nut (a continuous screw without ``nut_stiffness``)."""
    spec = q.problem.spec
    data = q.screw
    rule = nut_stiffness_rule(spec)
    if rule == "table" or data.K_nut is None:
        return data.K_nut
    if rule == "preload":
        return 0.8 * data.K_nut * (spec.screw.nut_preload / 0.1) ** (1.0 / 3.0)
    # HIWIN F 3.35, 0.8 K (F / (0.28 Ca))^(1/3), with its item factor K_load (a parameter
    # on the solver path, so that a relaxation node keeps its bound)
    return data.K_load * nut_load(q) ** (1.0 / 3.0)


def output_compliance(q):
    """Compliance at the output (rad/(N*mm)) over the grid: every member in series,
    reflected through its own rate - the screw side through dx/dphi, each sized pin
    through its joint's sensitivity (its contact stiffness under the joint's force)."""
    s_axial = m.fabs(q.mechanism.sensitivity_axial(q.phi))
    total = axial_compliance(q) * s_axial**2
    for joint in q.joints:
        if joint.pin is not None:
            K = joint.pin.contact_stiffness(m.fabs(joint.force))
            total = total + joint.sensitivity**2 / K
    return total
