"""Edge values in every field of the drive sections (issue 21, classes 4 and 7).

Four problems that use every drive section between them - ``fin_actuator`` (catalogue
screw, duty cycle, life, stiffness, lock), a crank-slider with a continuous trapezoidal
screw (efficiency, back-drive, critical speed, DN, friction-plate lock, clearances), the
robust crank-slider (tolerances) and the pivoting screw (legacy screw sizing, pin lock,
motor torque, backlash and contact-pressure limits, clearances, materials) - each get,
leaf by leaf, zero, a tiny and a huge magnitude (1e-300, 1e300), a small and a large one
that are still in range (1e-11, 1e12), the negative, NaN, a 400-digit integer and values
of the wrong type. Every case must end as one of:

- ``refused``: exit 2, one line naming the field (or a field it contradicts);
- ``infeasible``: exit 1 with the violated requirements named (or the diagnosis' note);
- ``success``: exit 0 with a finite objective;

never an internal error, a traceback, a hang, a NaN result or an infeasibility that names
nothing. ``python tests/drive_corpus.py [json|text]`` runs them all and prints the counts.
"""

from __future__ import annotations

import copy
import json
import math
import re
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hostile_corpus import Case, _prepare, _Raw, dumps, run_main

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"
#: Seconds a case may take before it counts as a hang (a catalogue problem that is
#: infeasible everywhere takes a minute or two on a loaded machine, diagnosis included).
CASE_TIMEOUT = 300


def _load(name: str) -> dict[str, Any]:
    return tomllib.loads((PROBLEMS / f"{name}.toml").read_text())


def bases() -> dict[str, tuple[dict[str, Any], tuple[str, ...]]]:
    """name -> (problem data, the sections whose leaves are mutated)."""
    fin = _load("fin_actuator")
    cont = _load("cs_min_backlash")
    cont["name"] = "continuous_drive"
    cont["variables"]["d0"] = {"lower": "10 mm", "upper": "40 mm"}
    cont["screw"] = {
        "kind": "trapezoidal",
        "friction": 0.1,
        "root_ratio": 0.8,
        "mounting": "fixed-supported",
        "length": "300 mm",
        "nut_offset": "40 mm",
        "nut_stiffness": "500 N/um",
        "bearing_stiffness": "400 N/um",
        "gear_efficiency": 0.96,
        "gear_back_efficiency": 0.94,
    }
    cont["requirements"].update(
        efficiency_min=0.2,
        back_drive="forbidden",
        deflection_rate="60 deg/s",
        critical_speed=True,
        dn_max=70000,
        stiffness_min="50 kN*m/rad",
        lock={
            "kind": "friction_plate",
            "r1": "10 mm",
            "r2": "20 mm",
            "mu": 0.3,
            "eta_screw_back": 0.9,
            "eta_gear_back": 0.9,
            "force_max": "3000 N",
        },
    )
    cont["clearances"] = {"A": "0.01 mm", "B": "0.01 mm", "C": "0.01 mm", "O": "0.01 deg"}
    rob = _load("cs_min_backlash_robust")
    rob["tolerances"]["samples"] = 8
    rob["requirements"]["deflection"]["points"] = 21
    piv = _load("pivot_min_backlash")
    piv["requirements"].update(
        screw={"root_diameter": "12 mm", "buckling_length": "400 mm", "mounting": "fixed-free"},
        lock={
            "kind": "pin",
            "radius": "20 mm",
            "eta_screw_back": 0.9,
            "eta_gear_back": 0.95,
            "force_max": "3000 N",
        },
        motor_torque_max="20 N*m",
        backlash_max="1 deg",
        pin_contact_pressure_max="3000 MPa",
    )
    piv["clearances"] = {"A": "0.01 mm", "B": "0.01 mm", "O": "0.01 deg"}
    return {
        "fin": (fin, ("screw", "requirements", "variables.d0", "variables.p")),
        "cont": (cont, ("screw", "requirements.", "clearances", "variables.d0")),
        "rob": (rob, ("tolerances",)),
        "piv": (piv, ("requirements.", "clearances", "materials", "variables")),
    }


#: Requirements every base shares: mutated on ``fin`` only ("requirements." above).
_SHARED = {
    "deflection",
    "hinge_moment",
    "mean_ratio",
    "nut_travel_max",
    "transmission_angle",
    "rod_inclination_max",
    "pin_bearing_pressure_max",
    "pin_shear_stress_max",
    "pin_shear_planes",
    "fit",
    "fit_clearance",
}
_TEXT = {"name", "description", "label", "mechanism"}
_NUMBER = re.compile(r"^\s*([+-]?[\d.]+(?:[eE][+-]?\d+)?)\s*(.*)$")


def _leaves(d: Any, path: tuple = ()):
    for k, v in d.items():
        here = (*path, k)
        if isinstance(v, dict):
            yield from _leaves(v, here)
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for i, x in enumerate(v):
                yield from _leaves(x, (*here, i))
        else:
            yield here, v


def _set(data: dict[str, Any], path: tuple, value: Any) -> dict[str, Any]:
    new = copy.deepcopy(data)
    d = new
    for k in path[:-1]:
        d = d[k]
    d[path[-1]] = value
    return new


def edge_values(v: Any) -> dict[str, Any]:
    """Label -> edge value for a leaf whose shipped value is ``v``."""
    big = _Raw("9" * 400)
    if isinstance(v, bool):
        return {"string": "yes", "int": 3}
    if isinstance(v, int | float):
        return {
            "zero": 0,
            "tiny": 1e-300,
            "small": 1e-11,
            "large": 1e12,
            "huge": 1e300,
            "negative": -abs(v) if v else -1.0,
            "nan": float("nan"),
            "big_int": big,
            "string": "abc",
            "table": {"a": 1},
        }
    m = _NUMBER.match(v) if isinstance(v, str) else None
    if m:
        u = m.group(2)
        return {
            "zero": f"0 {u}",
            "tiny": f"1e-300 {u}",
            "small": f"1e-11 {u}",
            "large": f"1e12 {u}",
            "huge": f"1e300 {u}",
            "negative": f"-{m.group(1).lstrip('-')} {u}",
            "big_int": f"{'9' * 400} {u}",
            "table": {"a": 1},
            "bool": True,
        }
    if isinstance(v, str):
        return {"other": "zzz", "int": 5, "empty": ""}
    return {}


def _selected(path: tuple, sections: tuple[str, ...]) -> bool:
    dotted = ".".join(map(str, path))
    for s in sections:
        if s.endswith(".") and dotted.startswith(s) and path[1] not in _SHARED:
            return True
        if not s.endswith(".") and (dotted == s or dotted.startswith(s + ".")):
            return True
    return False


def drive_cases() -> list[Case]:
    """Every leaf of the drive sections of the four bases, with every edge value."""
    out = []
    for tag, (data, sections) in bases().items():
        for path, value in _leaves(data):
            if path[-1] in _TEXT or not _selected(path, sections):
                continue
            # the leaf's key and its table's (a bound names its variable, a band its
            # requirement, a contradiction the field it contradicts)
            keys = [str(k) for k in path if not isinstance(k, int)]
            names = tuple(keys[-2:])
            for label, bad in edge_values(value).items():
                out.append(
                    Case(
                        f"{tag}:{'.'.join(map(str, path))}={label}",
                        ["solve", "{file}", "--starts", "1", "--no-ranges"],
                        dumps(_set(data, path, bad)),
                        codes=(0, 1, 2),
                        names=names,
                    )
                )
    return out


@dataclass
class Verdict:
    name: str
    code: Any
    verdict: str
    message: str
    seconds: float


def run(case: Case, tmp: Path, json_mode: bool) -> Verdict:
    """Run one case through ``optdesign.cli.main`` (``--json``, or the default mode with
    an output folder) and judge it."""
    extra = ["--json"] if json_mode else ["--no-plot", "--out", "{tmp}/out"]
    case = copy.copy(case)
    case.argv = [*case.argv, *extra]
    code, o, e, seconds = run_main(_prepare(case, tmp), CASE_TIMEOUT)
    lines = [ln for ln in e.strip().splitlines() if ln.strip() and "WARNING(" not in ln]
    message = lines[-1] if lines else ""
    verdict = _judge(case, code, o, e, json_mode)
    return Verdict(case.name, code, verdict, message[:300], round(seconds, 2))


def _judge(case: Case, code: Any, out: str, err: str, json_mode: bool) -> str:
    if code == "hang":
        return "hang"
    if "Traceback" in err + out or "internal error" in err or code == "exception":
        return "internal error"
    if code == 2:
        lines = [ln for ln in err.strip().splitlines() if "WARNING(" not in ln]
        if not any(n.lower() in err.lower() for n in case.names):
            return "refused naming another field"
        return "refused" if len(lines) == 1 else "refused in several lines"
    if code not in (0, 1):
        return f"exit {code}"
    if json_mode:
        doc = json.loads(out)
        value = doc["objective"]["value"]
        if code == 0:
            return "success" if value is not None and math.isfinite(value) else "NaN success"
        diagnosis = doc.get("diagnosis") or {}
        # violated rows at the best point, the diagnosis's relaxations, or a proof before
        # any solve that names the requirements no design can meet together
        named = (
            doc.get("violated")
            or diagnosis.get("note")
            or any(entry.get("requirements") for entry in diagnosis.get("impossible") or [])
        )
        return "infeasible" if named else "infeasible naming nothing"
    if code == 0:
        return "success" if re.search(r"^objective \S+ = [-0-9.]", out, re.M) else "NaN success"
    named = (
        "violated requirements:" in out
        or "diagnosis:" in out
        or "no design within the bounds can meet these together" in out
    )
    return "infeasible" if named else "infeasible naming nothing"


#: Verdicts that are fine.
CLEAN = ("refused", "infeasible", "success")


def main(argv: list[str] | None = None) -> int:
    """``python tests/drive_corpus.py [json|text] [OUT.json]``: run every case, print the
    counts of each verdict."""
    import tempfile
    from collections import Counter

    argv = sys.argv[1:] if argv is None else argv
    json_mode = (argv[0] if argv else "json") == "json"
    with tempfile.TemporaryDirectory() as tmp:
        verdicts = [run(c, Path(tmp) / f"c{k}", json_mode) for k, c in enumerate(drive_cases())]
    counts = Counter(v.verdict for v in verdicts)
    if len(argv) > 1:
        Path(argv[1]).write_text(json.dumps([v.__dict__ for v in verdicts], indent=1))
    print(json.dumps(dict(counts)), file=sys.__stdout__)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())
