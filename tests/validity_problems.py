"""Random design problems drawn from the shipped ones, and the quantities the models'
ranges bound, computed by hand (issue 35, "No answer that cannot be true").

Shared by the property tests of tests/models/test_validity.py and the 1 000-problem run of
benchmarks/validity/run.py:

- :func:`variant` and :data:`VARIANTS`: a shipped problem as written, or with the
  requirements that rarely hold at a random design dropped (``open``), a soft pin
  (``soft``), the longest pins (``long``), an output play near the small-angle limit
  (``play``);
- :func:`random_problem`: seed -> a problem dict: a shipped problem and one of those
  variants, its requirement values redrawn, its bounds narrowed or shifted, the pin's
  material, fit, contact model, shear planes and length, the fixed clearances and the
  gear ratio perturbed, every input inside the range its model declares;
- :func:`by_hand`: the bounded quantities of a design from the problem's public
  quantities and the models' equations written out here ([D17] eq. 10, P*, t/d, the
  lead angle);
- :func:`judge` and :func:`run_one`: a problem solved and its result classified -
  ``verified`` (every by-hand quantity inside its range), ``violation`` (reported a
  success or verified, yet a by-hand quantity lies outside: the bug the property hunts),
  ``flagged`` (not verified, a model's range named), ``failed`` (no feasible design,
  no range named), ``refused`` (the drawn file refused when read), ``error``.
"""

from __future__ import annotations

import copy
import math
import time
import tomllib
import traceback
import warnings
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

import optdesign as od
from optdesign.errors import OptDesignError
from optdesign.models.clearance import BACKLASH
from optdesign.models.hertz_line import HALF_WIDTH_RATIO
from optdesign.models.loads import PIN_LENGTH_OVER_SIZE, PIN_SLENDERNESS
from optdesign.models.lug_flexibility import THICKNESS_RATIO
from optdesign.models.pin_contact import LOAD_PARAMETER
from optdesign.models.ratio import RATIO
from optdesign.models.screw import LEAD_ANGLE
from optdesign.models.validity import Validity
from optdesign.problem.validity import is_validity

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"

#: The shipped problems the property draws from, each with the variants it may take.
STEMS = (
    "cs_min_backlash",
    "cs_min_backlash_catalogue",
    "cs_min_backlash_robust",
    "cs_min_ripple",
    "duan2017_redesign",
    "fin_actuator",
    "fork_min_backlash",
    "pivot_min_backlash",
)
KINDS = ("shipped", "open", "soft", "long", "play")


@cache
def _shipped_text(stem: str) -> str:
    return (PROBLEMS / f"{stem}.toml").read_text()


def shipped(stem: str) -> dict[str, Any]:
    """A fresh dict of the shipped problem ``problems/<stem>.toml``."""
    return tomllib.loads(_shipped_text(stem))


def variant(stem: str, kind: str) -> dict[str, Any]:
    """The shipped problem ``stem`` as variant ``kind`` (module docstring); without its
    tolerances (the nominal problem)."""
    data = shipped(stem)
    req = data["requirements"]
    if kind in ("open", "soft", "long", "play"):
        # the models kept, the requirements that rarely hold at a random design dropped
        keep = {"deflection", "hinge_moment", "fit", "fit_clearance", "pin_shear_planes"}
        data["requirements"] = {k: v for k, v in req.items() if k in keep}
        data.pop("screw", None)
        data["variables"].pop("d0", None)
        for name in ("p", "d"):  # continuous: the catalogues belong to the screw and pins
            v = data["variables"].get(name)
            if isinstance(v, dict) and "catalogue" in v:
                data["variables"][name] = {"lower": v["lower"], "upper": v["upper"]}
    data.pop("tolerances", None)
    if kind == "soft":  # a polymer pin: within its input range, often beyond Hertz's
        data.setdefault("materials", {})["pin"] = {"E": "300 MPa", "nu": 0.4}
    if kind == "long":  # the longest pins allowed, on the smallest linkages
        data["variables"]["pin_length_ratio"] = 5
    if kind == "play":  # an output shaft's play near the small-angle limit
        data["clearances"] = {"O": "4.97 deg"}
    return data


#: (stem, kind) of the shipped problems with a pin and no tolerances, for the property
#: over random designs.
VARIANTS = [
    (stem, kind)
    for stem in (
        "cs_min_backlash",
        "cs_min_backlash_catalogue",
        "duan2017_redesign",
        "fin_actuator",
        "fork_min_backlash",
        "pivot_min_backlash",
    )
    for kind in KINDS
]


# --- the quantities by hand ----------------------------------------------------------------
def _worst(record: Validity, values: Any) -> float:
    """The value of ``values`` farthest outside ``record``'s range (any one inside)."""
    values = np.atleast_1d(np.asarray(values, dtype=float)).ravel()
    return float(values[int(np.argmax(record.excess(values)))])


def by_hand(problem: od.DesignProblem, x: np.ndarray) -> dict[Validity, float]:
    """The bounded quantities of design ``x`` (the free-variable vector), the worst value
    of each, from the problem's public quantities (the design, the pin's force, the
    objectives) and the equations written out here: L/d, L/size, the Hertz half-width
    b = sqrt(4 d (F/L)(1 - nu^2)/(pi E)) over d/2 ([D17] eq. 10, where the problem's
    contact model uses it), P* = (F/L) / (E/(2(1 - nu^2)) c/2) (conforming contact), Huth's
    t/d, the worst-case backlash, the smallest ratio 2 pi i_a (dx/dphi)/p, the lead angle
    atan(p/(pi d_m)) (a [screw] with a free d0)."""
    x = np.asarray(x, dtype=float)
    q = problem.quantities(problem.design_dict(x))
    req = problem.spec.requirements
    out: dict[Validity, float] = {}
    with np.errstate(all="ignore"):  # a design that does not assemble: NaN, outside
        ev = problem.evaluate(x)
        v = np.asarray(q.nut_velocity, dtype=float)
        out[RATIO] = _worst(RATIO, 2.0 * math.pi * float(q.design["i_a"]) * v / q.design["p"])
        if "d" in q.design:
            d = float(q.design["d"])
            L = float(q.design.get("pin_length", q.design.get("pin_length_ratio", 0.0) * d))
            mat = problem.spec.materials.pin
            F = np.abs(np.asarray(q.pin_force, dtype=float))
            # L/d of a pin given by its length ratio is the ratio (not (ratio d)/d, whose
            # round-off left the range at a ratio of 5: benchmarks/README.md)
            out[PIN_SLENDERNESS] = float(q.design.get("pin_length_ratio", L / d))
            out[PIN_LENGTH_OVER_SIZE] = L / float(ev.objectives["size"])
            contact = req.pin_contact
            if contact == "duan2017" or (
                contact in ("palmgren", "huth") and req.pin_contact_pressure_max is not None
            ):
                b = np.sqrt(4.0 * d * (F / L) * (1.0 - mat.nu**2) / (math.pi * mat.E))
                out[HALF_WIDTH_RATIO] = _worst(HALF_WIDTH_RATIO, b / (0.5 * d))
            if contact == "conforming":
                c = float(np.asarray(q.pin.fit_clearance(), dtype=float))
                e_star = mat.E / (2.0 * (1.0 - mat.nu**2))
                out[LOAD_PARAMETER] = _worst(LOAD_PARAMETER, (F / L) / (e_star * 0.5 * c))
            lug = problem.spec.materials.lug
            if contact == "huth" and lug is not None:
                inner = L if lug.thickness is None else lug.thickness
                ratios = [inner / d, lug.cheek_thickness / d]
                out[THICKNESS_RATIO] = _worst(THICKNESS_RATIO, ratios)
            out[BACKLASH] = float(ev.objectives["backlash"])
        screw = q.screw if problem.spec.screw is not None else None
        if screw is not None and screw.d_m is not None:
            d_m = float(np.asarray(screw.d_m, dtype=float))
            out[LEAD_ANGLE] = math.atan(float(q.design["p"]) / (math.pi * d_m))
    return out


def named(record: Validity) -> str:
    """How a violated row names ``record``: ``validity: <model>: <quantity>``; the ratio's
    range is the requirement row ``ratio_positive`` every problem has."""
    if record is RATIO:
        return "ratio_positive"
    return f"validity: {record.model}: {record.quantity}"


# --- random problems --------------------------------------------------------------------------
def _split(text: str) -> tuple[float, str]:
    number, _, unit = str(text).strip().partition(" ")
    return float(number), unit


def _scaled(text: str, factor: float) -> str:
    value, unit = _split(text)
    return f"{value * factor:.6g} {unit}".strip()


def _log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def _bounds(rng: np.random.Generator, entry: dict[str, Any]) -> dict[str, Any]:
    """A continuous variable's bounds narrowed to 25-100 % of their width and shifted by
    up to 15 % of it; a positive lower bound stays above half of itself."""
    lo, unit = _split(entry["lower"])
    hi, _ = _split(entry["upper"])
    width = hi - lo
    span = width * rng.uniform(0.25, 1.0)
    a = rng.uniform(lo - 0.15 * width, hi + 0.15 * width - span)
    if lo > 0.0:
        a = max(a, 0.5 * lo)
    return {"lower": f"{a:.6g} {unit}", "upper": f"{a + span:.6g} {unit}"}


def _requirements(rng: np.random.Generator, req: dict[str, Any]) -> None:
    """Redraw the requirement values the problem states (in place)."""
    d = req["deflection"]
    # the stroke keeps the duty cycle's angles (fin_actuator's reach -25 and +15 deg)
    duty = [_split(point["deflection"])[0] for point in req.get("duty_cycle", ())]
    low, high = -max([15.0, *(-a for a in duty)]), max([15.0, *duty])
    d["min"], d["max"] = f"{rng.uniform(low - 15, low):.4g} deg", f"{rng.uniform(high, 35):.4g} deg"
    d["points"] = int(rng.choice([21, 31, 41, 61]))
    req["hinge_moment"] = _scaled(req["hinge_moment"], _log_uniform(rng, 0.3, 3.0))
    if "mean_ratio" in req:
        band = req["mean_ratio"]
        mid = 0.5 * (band["min"] + band["max"]) * rng.uniform(0.6, 1.4)
        half = 0.5 * (band["max"] - band["min"]) * rng.uniform(0.5, 2.0)
        req["mean_ratio"] = {"min": round(mid - half, 3), "max": round(mid + half, 3)}
    if "nut_travel_max" in req:
        req["nut_travel_max"] = _scaled(req["nut_travel_max"], rng.uniform(0.7, 1.5))
    if "transmission_angle" in req:
        low, high = rng.uniform(30, 50), rng.uniform(130, 150)
        req["transmission_angle"] = {"min": f"{low:.4g} deg", "max": f"{high:.4g} deg"}
    if "rod_inclination_max" in req:
        req["rod_inclination_max"] = f"{rng.uniform(20, 40):.4g} deg"
    if "dead_length" in req:
        req["dead_length"] = _scaled(req["dead_length"], rng.uniform(0.7, 1.3))
    if "ripple_max" in req:
        req["ripple_max"] = round(float(rng.uniform(0.05, 0.3)), 4)
    for key in ("pin_bearing_pressure_max", "pin_shear_stress_max"):
        if key in req:
            req[key] = _scaled(req[key], _log_uniform(rng, 0.5, 2.0))


def _pin_options(rng: np.random.Generator, data: dict[str, Any], kind: str) -> None:
    """The pin's fit, contact model, material, shear planes and length, a backlash limit
    and fixed clearances, each within its declared input range (in place)."""
    req, variables = data["requirements"], data["variables"]
    materials = data.setdefault("materials", {})
    pin = materials.setdefault("pin", {"E": "2.1e5 MPa", "nu": 0.3})
    req["fit"] = str(rng.choice(["H7/g6", "H7/g6", "H7/f7", "H8/f7", "H9/d9", "H11/c11"]))
    req["fit_clearance"] = "min" if rng.random() < 0.15 else "max"
    if "pin_shear_planes" in req:
        req["pin_shear_planes"] = int(rng.choice([1, 2]))
    if kind != "soft":  # the soft variant keeps its polymer pin
        pin["E"] = f"{_log_uniform(rng, 2e3, 1.2e6):.4g} MPa" if rng.random() < 0.3 else pin["E"]
        pin["nu"] = round(float(rng.uniform(0.2, 0.45)), 3) if rng.random() < 0.3 else pin["nu"]
    contact = str(rng.choice(["duan2017"] * 5 + ["conforming"] * 2 + ["palmgren", "huth"]))
    if contact == "palmgren":  # an empirical law of steel (refused otherwise)
        pin["E"] = f"{rng.uniform(1.95e5, 2.15e5):.4g} MPa"
    if contact == "conforming":  # needs a gap: the fit's smallest clearance may be 0
        req["fit_clearance"] = "max"
    if contact == "huth":
        lug = {"cheek_thickness": f"{_log_uniform(rng, 1.0, 30.0):.4g} mm"}
        if rng.random() < 0.5:
            lug["thickness"] = f"{_log_uniform(rng, 1.0, 40.0):.4g} mm"
        materials["lug"] = lug
    if contact != "duan2017":
        req["pin_contact"] = contact
    if contact in ("palmgren", "huth", "duan2017") and rng.random() < 0.25:
        req["pin_contact_pressure_max"] = f"{_log_uniform(rng, 300.0, 3000.0):.4g} MPa"
    if kind != "long" and isinstance(variables.get("pin_length_ratio"), int | float):
        if rng.random() < 0.3:
            variables["pin_length_ratio"] = round(float(rng.uniform(0.5, 4.0)), 3)
    if rng.random() < 0.25:
        req["backlash_max"] = f"{_log_uniform(rng, 0.02, 5.0):.4g} deg"
    if kind != "play" and rng.random() < 0.3:
        data["clearances"] = {
            "A": f"{rng.uniform(0.0, 0.05):.4g} mm",
            "B": f"{rng.uniform(0.0, 0.05):.4g} mm",
            "O": f"{rng.uniform(0.0, 0.5):.4g} deg",
        }


def random_problem(seed: int) -> tuple[str, str, dict[str, Any]]:
    """(stem, kind, problem dict) drawn with ``numpy.random.default_rng(seed)``: a shipped
    problem, one of the variants, and its requirements, bounds, pin options, materials,
    clearances and gear ratio redrawn within their declared input ranges."""
    rng = np.random.default_rng(seed)
    stem = str(rng.choice(STEMS))
    kind = str(rng.choice(KINDS))
    data = variant(stem, kind)
    data["name"] = f"random_{seed}_{stem}_{kind}"
    tolerances = shipped(stem).get("tolerances")
    if tolerances is not None:  # the robust problem stays robust, with fewer samples
        data["tolerances"] = {**tolerances, "samples": 8}
    variables = data["variables"]
    if "d" not in variables and rng.random() < 0.5:  # a sized pin the objective ignores
        variables["d"] = {"lower": "4 mm", "upper": "30 mm"}
        variables["pin_length_ratio"] = 1.5
    for name, entry in variables.items():
        if isinstance(entry, dict) and "catalogue" not in entry and rng.random() < 0.8:
            variables[name] = _bounds(rng, entry)
    if isinstance(variables.get("i_a"), int | float) and rng.random() < 0.3:
        variables["i_a"] = round(float(variables["i_a"] * rng.uniform(0.7, 1.5)), 4)
    _requirements(rng, data["requirements"])
    if "d" in variables:
        _pin_options(rng, data, kind)
    data.pop("solver", None)  # the run sets the starts
    return stem, kind, data


# --- one problem, solved and judged -------------------------------------------------------------
def judge(problem: od.DesignProblem, result: Any) -> dict[str, Any]:
    """The verdict on ``result`` of ``problem`` (module docstring), with the by-hand
    quantities found outside their ranges and those a violated row does not name."""
    names = {r.name.split("[")[0].split(",")[0] for r in result.violated}
    design = result.design or {}
    outside: dict[str, float] = {}
    unnamed: list[str] = []
    if all(v.name in design for v in problem.free):
        x = np.array([design[v.name] for v in problem.free], dtype=float)
        for record, value in by_hand(problem, x).items():
            if not bool(record.contains(value)):
                outside[record.name] = value
                # NaN: a best point that does not assemble, which its assembly row names
                assembly = math.isnan(value) and any(n.startswith("assembly") for n in names)
                if named(record) not in names and not assembly:
                    unnamed.append(record.name)
    if result.success or result.verified is True:
        verdict = "violation" if outside else ("verified" if result.verified else "unchecked")
    elif any(is_validity(r) for r in result.violated):
        verdict = "flagged"
    else:
        verdict = "failed"
    return {
        "verdict": verdict,
        "status": result.status,
        "verified": result.verified,
        "objective": None if result.objective is None else float(result.objective),
        "outside": {k: (None if math.isnan(v) else v) for k, v in outside.items()},
        "named": sorted(n for n in names if n.startswith("validity: ")),
        "unnamed": unnamed,
    }


def run_one(seed: int, starts: int = 2) -> dict[str, Any]:
    """Draw problem ``seed``, solve it with ``starts`` starts (no ranges, no
    sensitivities) and judge the result: one JSON-able record."""
    t0 = time.perf_counter()
    stem, kind, data = random_problem(seed)
    record: dict[str, Any] = {"seed": seed, "stem": stem, "kind": kind}
    try:
        problem = od.load(copy.deepcopy(data))
    except OptDesignError as exc:
        return {**record, "verdict": "refused", "message": str(exc)[:300], "time_s": _since(t0)}
    with warnings.catch_warnings(record=True) as caught:
        # NumPy's RuntimeWarnings reach a user's terminal: none may escape (issue 35)
        warnings.simplefilter("always", RuntimeWarning)
        try:
            result = od.solve(problem, starts=starts, ranges=False, sensitivities=False)
            record.update(judge(problem, result))
        except Exception as exc:  # a crash is a finding: kept with its traceback's end
            tail = traceback.format_exc().strip().splitlines()[-3:]
            message = f"{type(exc).__name__}: {exc}"[:300]
            record.update(verdict="error", message=message, where=tail)
    found = {
        f"{Path(w.filename).name}:{w.lineno}: {w.message}"
        for w in caught
        if issubclass(w.category, RuntimeWarning)
    }
    record["warnings"] = sorted(found)
    record["formulation"] = getattr(locals().get("result"), "formulation", None)
    if record["verdict"] in ("violation", "error"):
        record["problem"] = data  # the file that shows it
    return {**record, "time_s": _since(t0)}


def _since(t0: float) -> float:
    return round(time.perf_counter() - t0, 3)


#: The verdicts of :func:`judge` and :func:`run_one`, in the order reports list them.
VERDICTS = ("verified", "unchecked", "flagged", "failed", "refused", "violation", "error")
