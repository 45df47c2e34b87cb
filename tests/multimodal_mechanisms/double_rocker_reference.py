"""An independent model of the screw-driven double rocker and a global search on it, to
judge whether optdesign's own search finds the global optimum of
:func:`double_rocker.problem`.

Written separately from the plug-in (``double_rocker.py``), in plain NumPy/SciPy, from
the description of the linkage only (O the horn's axis at the origin, H the horn pin at
radius R and angle phi0 + phi from +x; the input rocker about K = (k_x, k_y) with its
coupler arm K -> C of length r_c, C on the left of H -> K, and its rod arm K -> Q of
length r_q turned gamma from it; the coupler |C - H| = l_c; the screw axis of direction
beta at the signed distance e from O, the nut N behind Q with |Q - N| = l_r).

What is independent of the plug-in and of optdesign's mechanism framework:

- positions: the rocker's angle from the loop closure in closed form,
  psi = atan2(K - H) + arccos(...) (the plug-in intersects two circles in Cartesian
  form); the nut from the quadratic |Q - N(x)| = l_r (``tests`` also check both by
  scipy root finding);
- the ratio: 2 pi i_a x'(phi) / p with x' by a five-point central difference of the nut
  position (the plug-in differentiates in closed form, the framework by CasADi);
- clearance sensitivities: by *perturbing* the rod's and the coupler's length by
  +-delta (and the rocker's pivot along x and y) and *re-solving* the angle at which the
  nut is back where it was (chord iterations on the position); the pivot's is the norm of
  its two (the largest output turn per unit shift of the pivot, in the worst direction);
  the screw's axial joints turn the output by 1/x';
- forces: by the statics of the horn (moments about O) and of the rocker (moments about
  K, then the force balance for the pivot's reaction); the nut force as the rod force's
  axial component;
- the requirements: angles by arccos / arcsin of the geometry, the ratio's mean over the
  grid, the travel, the pin's bearing pressure and double shear, all rewritten here;
- the search: scipy's differential evolution on a penalty function, run in each of the
  four configurations of :data:`CELLS` (the rod arm turned either way from the coupler
  arm, the rocker's pivot above or below the horn's axis), each result polished by
  SLSQP in epigraph form, the best kept; no CasADi, no Ipopt, no optdesign formulation
  or solver.

What is shared with optdesign (the physics of one pin, which is not under test here):
the ISO 286 fit clearance (:func:`optdesign.models.fit_formulas.fit_clearance`, the
smooth formulas, as optdesign uses for a continuous d) and the pin's Hertz flattening
(:func:`optdesign.models.hertz_line.pin_flattening`, counted twice per pin joint: pin and
bore, as :class:`optdesign.PinJoint` does), and the worst-case sum
(:func:`optdesign.models.clearance.worst_case`). The problem's numbers (bounds, fixed
values, requirements, clearances, materials) are read from the plug-in module's
``problem()`` dict by a parser of its own here, so that both solve the same problem.

Run ``python tests/multimodal_mechanisms/double_rocker_reference.py backlash 0 1 2``
(from the repository's root) to search with those seeds: each configuration's optimum,
the best, the time (see ``main``).
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import differential_evolution, minimize

from optdesign.models.clearance import worst_case
from optdesign.models.fit_formulas import fit_clearance
from optdesign.models.hertz_line import pin_flattening

#: Units the problem dict writes, to internal units (mm, N, MPa, N*mm, rad).
_UNITS = {
    "": 1.0,
    "mm": 1.0,
    "m": 1000.0,
    "deg": math.pi / 180.0,
    "rad": 1.0,
    "N": 1.0,
    "N*m": 1000.0,
    "N*mm": 1.0,
    "MPa": 1.0,
}

#: Finite-difference step of the nut position in phi (rad) and the perturbation of a
#: length (mm) for the sensitivities.
PHI_STEP = 1e-3
DELTA = 1e-4
CHORD_STEPS = 3

#: Differential evolution's settings (per free variable: DE_POPSIZE designs).
DE_POPSIZE = 20
DE_MAXITER = 2000
DE_STRATEGY = "best1bin"
DE_WEIGHT = 10.0


def quantity(value) -> float:
    """A problem-file quantity ("25 deg", "300 N*m", 2) in internal units."""
    if isinstance(value, (int, float)):
        return float(value)
    number, _, unit = value.strip().partition(" ")
    return float(number) * _UNITS[unit.strip()]


@dataclass
class Spec:
    """The problem as this module reads it: free variables with bounds, fixed values,
    the deflection grid and the requirements (internal units)."""

    free: list[str]
    lower: np.ndarray
    upper: np.ndarray
    fixed: dict[str, float]
    phi: np.ndarray
    hinge_moment: float
    mean_ratio: tuple[float, float]
    nut_travel_max: float
    transmission: tuple[float, float]
    rod_inclination_max: float
    bearing_max: float
    shear_max: float
    fit: str
    clearances: dict[str, float]
    E: float
    nu: float
    objective: str

    @classmethod
    def of(cls, problem: dict) -> Spec:
        free, lower, upper, fixed = [], [], [], {}
        for name, value in problem["variables"].items():
            if isinstance(value, dict):
                free.append(name)
                lower.append(quantity(value["lower"]))
                upper.append(quantity(value["upper"]))
            else:
                fixed[name] = quantity(value)
        req = problem["requirements"]
        deflection = req["deflection"]
        band = req["transmission_angle"]
        pin = problem.get("materials", {}).get("pin", {})
        return cls(
            free=free,
            lower=np.array(lower),
            upper=np.array(upper),
            fixed=fixed,
            phi=np.linspace(
                quantity(deflection["min"]), quantity(deflection["max"]), deflection["points"]
            ),
            hinge_moment=quantity(req["hinge_moment"]),
            mean_ratio=(float(req["mean_ratio"]["min"]), float(req["mean_ratio"]["max"])),
            nut_travel_max=quantity(req["nut_travel_max"]),
            transmission=(quantity(band["min"]), quantity(band["max"])),
            rod_inclination_max=quantity(req["rod_inclination_max"]),
            bearing_max=quantity(req["pin_bearing_pressure_max"]),
            shear_max=quantity(req["pin_shear_stress_max"]),
            fit=req["fit"],
            clearances={k: quantity(v) for k, v in problem.get("clearances", {}).items()},
            E=quantity(pin.get("E", "2.1e5 MPa")),
            nu=float(pin.get("nu", 0.3)),
            objective=problem["objective"]["minimize"],
        )

    def design(self, x) -> dict[str, float]:
        """The full design (free and fixed) of the free values ``x``."""
        return {**self.fixed, **{k: float(v) for k, v in zip(self.free, x, strict=True)}}


def default_spec(objective: str = "backlash") -> Spec:
    """The problem of the plug-in module (its numbers only; none of its model)."""
    here = str(Path(__file__).resolve().parents[1])
    if here not in sys.path:
        sys.path.insert(0, here)
    from multimodal_mechanisms.double_rocker import problem

    return Spec.of(problem(objective))


# --- positions ----------------------------------------------------------------------
def rocker_angle(v, phi):
    """The input rocker's angle psi (from +x) and the horn pin H, from the loop closure
    |K + r_c e(psi) - H| = l_c on the branch with C left of H -> K, plus cos of the angle
    at H between H -> K and H -> C (law of cosines)."""
    a = v["phi0"] + phi
    hx, hy = v["R"] * np.cos(a), v["R"] * np.sin(a)
    dx, dy = v["k_x"] - hx, v["k_y"] - hy  # H -> K
    dist = np.hypot(dx, dy)
    # |D + r_c e(psi)|^2 = l_c^2:  dist cos(psi - theta) = (l_c^2 - r_c^2 - dist^2) / (2 r_c)
    k = (v["l_c"] ** 2 - v["r_c"] ** 2 - dist**2) / (2.0 * v["r_c"] * dist)
    with np.errstate(invalid="ignore"):
        psi = np.arctan2(dy, dx) + np.arccos(k)  # sin(psi - theta) > 0: C left of H -> K
    cos_H = (v["l_c"] ** 2 + dist**2 - v["r_c"] ** 2) / (2.0 * v["l_c"] * dist)
    return psi, (hx, hy), cos_H


def chain(v, phi):
    """Points H, K, C, Q, N (each (x, y)), the nut coordinate x, cos of the angle at H
    (four-bar) and the rod's height over the screw axis."""
    psi, H, cos_H = rocker_angle(v, phi)
    K = (v["k_x"] + 0.0 * psi, v["k_y"] + 0.0 * psi)
    C = (K[0] + v["r_c"] * np.cos(psi), K[1] + v["r_c"] * np.sin(psi))
    Q = (K[0] + v["r_q"] * np.cos(psi + v["gamma"]), K[1] + v["r_q"] * np.sin(psi + v["gamma"]))
    ux, uy = np.cos(v["beta"]), np.sin(v["beta"])
    nx, ny = -uy, ux
    # N(x) = e n + x u; |Q - N(x)|^2 = l_r^2 is x^2 - 2 b x + c = 0, the nut on the smaller root
    px, py = Q[0] - v["e"] * nx, Q[1] - v["e"] * ny
    b = px * ux + py * uy
    c = px**2 + py**2 - v["l_r"] ** 2
    with np.errstate(invalid="ignore"):
        x = b - np.sqrt(b**2 - c)
    N = (v["e"] * nx + x * ux, v["e"] * ny + x * uy)
    height = px * nx + py * ny
    return H, K, C, Q, N, x, cos_H, height


def nut(v, phi):
    return chain(v, phi)[5]


def nut_rate(v, phi, h=PHI_STEP):
    """dx/dphi by the five-point central difference."""
    return (
        -nut(v, phi + 2 * h) + 8.0 * nut(v, phi + h) - 8.0 * nut(v, phi - h) + nut(v, phi - 2 * h)
    ) / (12.0 * h)


def held_nut_angle(v, phi, x0, rate, name, delta):
    """The angle at which the nut is at ``x0`` again once ``name`` changed by ``delta``:
    chord iterations from phi with the unperturbed design's rate (each step multiplies
    the error by about delta / length, so three reach rounding)."""
    w = {**v, name: v[name] + delta}
    f = phi
    for _ in range(CHORD_STEPS):
        f = f - (nut(w, f) - x0) / rate
    return f


def turn_per_length(v, phi, x0, rate, name, delta=DELTA):
    """d(phi)/d(name) with the nut held, by re-solving at +-delta (signed, rad/mm)."""
    up = held_nut_angle(v, phi, x0, rate, name, delta)
    down = held_nut_angle(v, phi, x0, rate, name, -delta)
    return (up - down) / (2.0 * delta)


# --- the whole model ----------------------------------------------------------------
def model(spec: Spec, v: dict, phi=None) -> dict:
    """Every quantity of designs ``v`` (values broadcast against the grid) over ``phi``
    (default the problem's grid): positions, ratio, forces, sensitivities, backlash,
    requirement values."""
    phi = spec.phi if phi is None else np.asarray(phi, dtype=float)
    H, K, C, Q, N, x, cos_H, height = chain(v, phi)
    rate = nut_rate(v, phi)
    ratio = 2.0 * math.pi * v["i_a"] * rate / v["p"]
    # statics (tensions positive; the hinge moment M_h loads the horn)
    M_h = spec.hinge_moment
    wx, wy = (C[0] - H[0]) / v["l_c"], (C[1] - H[1]) / v["l_c"]  # H -> C
    vx, vy = (Q[0] - N[0]) / v["l_r"], (Q[1] - N[1]) / v["l_r"]  # N -> Q
    T_c = M_h / (H[0] * wy - H[1] * wx)  # moments about O on the horn
    arm_C = (C[0] - K[0]) * wy - (C[1] - K[1]) * wx
    arm_Q = (Q[0] - K[0]) * vy - (Q[1] - K[1]) * vx
    T_r = -T_c * arm_C / arm_Q  # moments about K on the rocker
    F_K = np.hypot(T_c * wx + T_r * vx, T_c * wy + T_r * vy)  # force balance of the rocker
    F_nut = T_r * (vx * np.cos(v["beta"]) + vy * np.sin(v["beta"]))
    forces = {"rod": np.abs(T_r), "pivot": F_K, "coupler": np.abs(T_c)}
    # sensitivities by perturbed lengths and positions, nut held
    S_rod = np.abs(turn_per_length(v, phi, x, rate, "l_r"))
    S_coupler = np.abs(turn_per_length(v, phi, x, rate, "l_c"))
    S_pivot = np.hypot(
        turn_per_length(v, phi, x, rate, "k_x"), turn_per_length(v, phi, x, rate, "k_y")
    )
    S_axial = np.abs(1.0 / rate)
    sens = {"rod": S_rod, "pivot": S_pivot, "coupler": S_coupler}
    # clearances: the pin's fit and flattening (optdesign's physics), the fixed ones
    d = v["d"]
    L = v["pin_length_ratio"] * d
    fit = fit_clearance(d, spec.fit, "max")
    pin_clearance = {
        k: fit + 2.0 * pin_flattening(d, forces[k], L, spec.E, spec.nu) for k in forces
    }
    pins = {
        "rod pin (nut)": "rod",
        "rod pin (rocker)": "rod",
        "rocker pivot": "pivot",
        "coupler pin (rocker)": "coupler",
        "coupler pin (horn)": "coupler",
    }
    turns = {name: sens[k] * pin_clearance[k] for name, k in pins.items()}
    cl = spec.clearances
    turns["A"] = S_axial * cl.get("A", 0.0)
    turns["B"] = S_axial * cl.get("B", 0.0)
    turns["O"] = cl.get("O", 0.0) + 0.0 * S_axial
    backlash = np.degrees(worst_case(list(turns.values())))
    F_pin = np.maximum(np.maximum(forces["rod"], forces["pivot"]), forces["coupler"])
    # angles of the requirements
    to_O = (-H[0], -H[1])
    to_C = (C[0] - H[0], C[1] - H[1])
    mu_H = np.arccos(
        np.clip((to_O[0] * to_C[0] + to_O[1] * to_C[1]) / (v["R"] * v["l_c"]), -1.0, 1.0)
    )
    to_K, to_N = (K[0] - Q[0], K[1] - Q[1]), (N[0] - Q[0], N[1] - Q[1])
    mu_Q = np.arccos(
        np.clip((to_K[0] * to_N[0] + to_K[1] * to_N[1]) / (v["r_q"] * v["l_r"]), -1.0, 1.0)
    )
    inclination = np.arcsin(np.clip(height / v["l_r"], -1.0, 1.0))
    return {
        "H": H,
        "K": K,
        "C": C,
        "Q": Q,
        "N": N,
        "x": x,
        "rate": rate,
        "ratio": ratio,
        "forces": forces,
        "nut_force": np.abs(F_nut),
        "sensitivities": {**sens, "axial": S_axial},
        "pin_clearance": pin_clearance,
        "backlash_per_joint": {k: np.degrees(t) for k, t in turns.items()},
        "backlash": backlash,
        "pin_force": F_pin,
        "four_bar_sin2": 1.0 - cos_H**2,
        "rod_cos2": 1.0 - (height / v["l_r"]) ** 2,
        "mu_H": mu_H,
        "mu_Q": mu_Q,
        "inclination": inclination,
        "d": d,
        "L": L,
    }


def constraint_rows(spec: Spec, q: dict) -> dict[str, np.ndarray]:
    """The requirements as normalised margins, >= 0 where met: name -> array over the
    grid (designs x angles) or one column (designs x 1)."""
    ratio = q["ratio"]
    mean = np.mean(ratio, axis=-1, keepdims=True)
    travel = q["x"][..., -1:] - q["x"][..., :1]
    lo_mu, hi_mu = spec.transmission
    F, d, L = q["pin_force"], q["d"], q["L"]
    lo_i, hi_i = spec.mean_ratio
    return {
        "ratio_positive": ratio - 1.0,
        "four_bar_reach": (q["four_bar_sin2"] - 0.05) / 0.05,
        "rod_reach": (q["rod_cos2"] - 0.25) / 0.25,
        "mean_ratio_min": (mean - lo_i) / lo_i,
        "mean_ratio_max": (hi_i - mean) / hi_i,
        "nut_travel": (spec.nut_travel_max - travel) / spec.nut_travel_max,
        "transmission_horn_min": q["mu_H"] - lo_mu,
        "transmission_horn_max": hi_mu - q["mu_H"],
        "transmission_rocker_min": q["mu_Q"] - lo_mu,
        "transmission_rocker_max": hi_mu - q["mu_Q"],
        "rod_inclination": spec.rod_inclination_max - np.abs(q["inclination"]),
        "pin_bearing_pressure": (spec.bearing_max - F / (d * L)) / spec.bearing_max,
        "pin_shear_stress": (spec.shear_max - 4.0 * F / (2.0 * math.pi * d**2)) / spec.shear_max,
    }


def objectives_of(q: dict) -> dict[str, np.ndarray]:
    """Backlash (largest over the grid, degrees) and ripple (a fraction) of designs."""
    ratio = q["ratio"]
    i_max, i_min = np.max(ratio, axis=-1), np.min(ratio, axis=-1)
    return {
        "backlash": np.max(q["backlash"], axis=-1),
        "ripple": (i_max - i_min) / (i_max + i_min),
    }


def evaluate(design: dict, objective: str = "backlash", spec: Spec | None = None) -> dict:
    """Objectives and constraints of one design dict (internal units: mm, rad) on the
    independent model: the objective's value, both objectives, each requirement's
    smallest normalised margin over the grid (>= 0 where met) and ``feasible`` (every
    margin >= -1e-7, the linkage assembled at every angle)."""
    spec = spec or default_spec(objective)
    v = {**spec.fixed, **{k: float(x) for k, x in design.items()}}
    with np.errstate(all="ignore"):
        q = model(spec, v)
        objectives = {k: float(x) for k, x in objectives_of(q).items()}
        margins = {k: float(np.min(r)) for k, r in constraint_rows(spec, q).items()}
    values = [*objectives.values(), *margins.values()]
    return {
        **objectives,
        "objective": objectives[objective],
        "constraints": margins,
        "feasible": bool(np.all(np.isfinite(values)) and min(margins.values()) >= -1e-7),
    }


# --- the search ---------------------------------------------------------------------
def _population(spec: Spec, X: np.ndarray) -> dict:
    """Designs of the free values X (free variables x designs) as column arrays."""
    v = {k: np.asarray(val, dtype=float) for k, val in spec.fixed.items()}
    for name, row in zip(spec.free, X, strict=True):
        v[name] = np.asarray(row, dtype=float)[:, None]
    return v


#: Scale of each objective (its order of magnitude), for the penalty and the polish.
SCALE = {"backlash": 0.1, "ripple": 0.01}


def penalised(spec: Spec, objective: str, weight: float = DE_WEIGHT):
    """The DE's function of X (free variables x designs): the objective plus ``weight``
    times its scale times the sum of the requirements' violations over the grid; a
    design that does not assemble somewhere counts each such angle as a violation of 10
    and its objective as 100 times the scale (so does one with a ratio <= 0 somewhere)."""
    scale = SCALE[objective]

    def f(X):
        X = X[:, None] if X.ndim == 1 else X
        with np.errstate(all="ignore"):
            q = model(spec, _population(spec, X))
            value = objectives_of(q)[objective]
            rows = constraint_rows(spec, q)
        violation = sum(
            np.sum(np.maximum(0.0, -np.nan_to_num(r, nan=-10.0)), axis=-1) for r in rows.values()
        )
        # the ripple is a ripple only where every ratio is positive
        valid = np.isfinite(value) & (np.min(q["ratio"], axis=-1) > 0.0)
        out = np.where(valid, value, 100.0 * scale) + weight * scale * violation
        return out if out.size > 1 else float(out[0])

    return f


def polish(spec: Spec, objective: str, x0: np.ndarray) -> np.ndarray:
    """SLSQP from x0 in epigraph form, the variables scaled to [0, 1] by their bounds:
    backlash: minimise t subject to t >= backlash(phi_k); ripple: minimise
    (hi - lo)/(hi + lo) subject to lo <= i(phi_k) <= hi; every requirement row by row.
    Derivatives by central differences (step 1e-6 of the scaled variables, well above
    the model's own finite-difference noise), all the shifted designs in one evaluation.
    Returns the free values."""
    lo, span = spec.lower, spec.upper - spec.lower
    n = len(lo)
    extra = 1 if objective == "backlash" else 2

    def rows(Z):  # Z: designs (one per row, scaled variables and epigraph ones) -> rows
        with np.errstate(all="ignore"):
            q = model(spec, _population(spec, (lo + span * Z[:, :n]).T))
        m = len(Z)
        margins = [np.broadcast_to(r, (m, r.shape[-1])) for r in constraint_rows(spec, q).values()]
        if objective == "backlash":
            margins.append((Z[:, n : n + 1] - q["backlash"]) / SCALE[objective])
        else:
            i_lo, i_hi = Z[:, n : n + 1], Z[:, n + 1 : n + 2]
            margins += [(i_hi - q["ratio"]) / i_hi, (q["ratio"] - i_lo) / i_lo]
        return np.nan_to_num(np.concatenate(margins, axis=1), nan=-10.0)

    def goal(z):
        if objective == "backlash":
            return z[n] / SCALE[objective]
        return (z[n + 1] - z[n]) / (z[n + 1] + z[n]) / SCALE[objective]

    def goal_grad(z):
        g = np.zeros_like(z)
        if objective == "backlash":
            g[n] = 1.0 / SCALE[objective]
        else:
            s = (z[n + 1] + z[n]) ** 2 * SCALE[objective]
            g[n], g[n + 1] = -2.0 * z[n + 1] / s, 2.0 * z[n] / s
        return g

    def jac(z, step=1e-6):
        shifts = np.eye(len(z)) * step
        both = rows(np.concatenate([z + shifts, z - shifts]))
        return ((both[: len(z)] - both[len(z) :]) / (2 * step)).T

    z0 = np.clip((x0 - lo) / span, 0.0, 1.0)
    with np.errstate(all="ignore"):
        q0 = model(spec, _population(spec, (lo + span * z0)[:, None]))
    if objective == "backlash":
        start = np.concatenate([z0, [np.max(q0["backlash"])]])
        bounds = [(0.0, 1.0)] * n + [(0.0, None)]
    else:
        start = np.concatenate([z0, [np.min(q0["ratio"]), np.max(q0["ratio"])]])
        bounds = [(0.0, 1.0)] * n + [(1.0, None)] * extra
    res = minimize(
        goal,
        np.nan_to_num(start, nan=1.0),
        method="SLSQP",
        jac=goal_grad,
        bounds=bounds,
        constraints=[{"type": "ineq", "fun": lambda z: rows(z[None, :])[0], "jac": jac}],
        options={"maxiter": 500, "ftol": 1e-15},
    )
    return lo + span * np.clip(res.x[:n], 0.0, 1.0)


#: The four configurations the search runs in turn (rad, mm), each intersected with the
#: problem's bounds: the rod arm turned counter-clockwise (gamma < 180 deg) or clockwise
#: (gamma > 180 deg) from the coupler arm; the rocker's pivot below (k_y < 0) or above
#: (k_y > 0) the horn's axis. One differential evolution over the whole box tends to
#: settle in the configuration whose basin is widest, not in the best one.
CELLS = tuple(
    {"gamma": g, "k_y": k}
    for g in ((-math.inf, math.pi), (math.pi, math.inf))
    for k in ((-math.inf, 0.0), (0.0, math.inf))
)


def cell_optima(objective: str = "backlash", seed: int = 0, **settings) -> list[dict]:
    """Differential evolution (penalty, seeded) in each configuration of :data:`CELLS`,
    each polished by SLSQP over the whole box: per cell its bounds, the design (every
    variable, internal units), the objective and whether the independent model finds it
    feasible."""
    spec = default_spec(objective)
    settings = {
        "strategy": DE_STRATEGY,
        "popsize": DE_POPSIZE,
        "maxiter": DE_MAXITER,
        "weight": DE_WEIGHT,
        **settings,
    }
    weight = settings.pop("weight")
    out = []
    for cell in CELLS:
        lower, upper = spec.lower.copy(), spec.upper.copy()
        for name, (a, b) in cell.items():
            j = spec.free.index(name)
            lower[j], upper[j] = max(lower[j], a), min(upper[j], b)
        if np.any(lower >= upper):
            continue
        found = differential_evolution(
            penalised(spec, objective, weight),
            list(zip(lower, upper, strict=True)),
            seed=seed,
            tol=1e-8,
            atol=0.0,
            mutation=(0.5, 1.0),
            recombination=0.9,
            init="sobol",
            polish=False,
            vectorized=True,
            updating="deferred",
            **settings,
        )
        best, value, feasible = found.x, math.inf, False
        for x in (polish(spec, objective, found.x), found.x):
            check = evaluate(spec.design(x), objective, spec)
            if check["feasible"] and check["objective"] < value:
                best, value, feasible = x, check["objective"], True
        out.append(
            {
                "cell": {
                    k: [float(max(a, -1e9)), float(min(b, 1e9))] for k, (a, b) in cell.items()
                },
                "design": spec.design(best),
                "value": value if feasible else float(found.fun),
                "feasible": feasible,
                "generations": int(found.nit),
            }
        )
    return out


def reference_optimum(
    objective: str = "backlash", seed: int = 0, **settings
) -> tuple[dict[str, float], float]:
    """The reference optimum: the best feasible design of :func:`cell_optima` (seeded
    differential evolution on the penalised independent model in each configuration,
    polished by SLSQP). Returns the design (every variable, internal units: mm, rad) and
    the objective's value (backlash in degrees, ripple as a fraction)."""
    cells = [c for c in cell_optima(objective, seed, **settings) if c["feasible"]]
    if not cells:
        raise RuntimeError(f"no feasible design found for {objective} (seed {seed})")
    best = min(cells, key=lambda c: c["value"])
    return best["design"], best["value"]


def main(argv=None) -> None:
    """``python double_rocker_reference.py OBJECTIVE SEED...``: per seed, the optimum of
    each configuration, the reference optimum and the time."""
    args = list(sys.argv[1:] if argv is None else argv)
    objective = args[0] if args else "backlash"
    seeds = [int(s) for s in args[1:]] or [0]
    for seed in seeds:
        t = time.perf_counter()
        cells = cell_optima(objective, seed)
        for c in cells:
            shown = {k: round(v, 6) for k, v in c["design"].items()}
            print(f"  cell {c['cell']}: {c['value']:.10g} feasible={c['feasible']} {shown}")
        best = min((c for c in cells if c["feasible"]), key=lambda c: c["value"])
        print(f"seed {seed}: {objective} = {best['value']:.10g} ({time.perf_counter() - t:.0f} s)")


if __name__ == "__main__":
    main()
