"""Impossible inputs the schema's types accept, written from the models' assumptions
(issue "No answer that cannot be true", item 1).

Each case is a shipped problem with a few values changed to something no actuator can
have - a pin softer than rubber, a lug thinner than the roughness of its bore, a joint's
play of a kilometre, a pin twice as long as its linkage, a screw whose lead angle makes
it a helical cam - yet of the right dimension and within the units' magnitudes: before
the models declared their ranges of validity most of them solved into "optimal;
verified", the others into a NaN or a failure that named no model. Each must now end
cleanly, one of:

- ``refused``: :func:`optdesign.load` raises an :class:`~optdesign.errors.OptDesignError`
  whose one-line message names the field (``names``) and the range it left
  ("is outside [...]");
- ``flagged``: the file is read, and :func:`optdesign.solve` returns no success, not
  verified, with each quantity outside its model's range reported as a violated row
  ``"validity: <model>: <quantity>"`` that names the model (``names``).

:func:`run_case` judges one case through the Python API (one start, no ranges: the
corpus stays fast); ``python tests/validity_corpus.py`` prints the verdicts.
"""

from __future__ import annotations

import copy
import sys
import time
import tomllib
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"
#: A value that deletes the key.
DELETE = object()


@dataclass(frozen=True)
class Case:
    """One impossible input: ``base`` (a shipped problem, or ``"screw"`` for the
    crank-slider with a continuous screw) with ``edits`` (path -> value), the outcome
    it must have and what its message must name."""

    name: str
    base: str
    edits: tuple[tuple[tuple[str, ...], Any], ...]
    expect: str  # "refused" or "flagged"
    names: tuple[str, ...] = ()
    why: str = ""


@dataclass
class Verdict:
    name: str
    verdict: str  # "clean", or what went wrong
    message: str
    seconds: float
    detail: dict[str, Any] = field(default_factory=dict)


@cache
def _shipped(stem: str) -> dict[str, Any]:
    return tomllib.loads((PROBLEMS / f"{stem}.toml").read_text())


def _screw_base() -> dict[str, Any]:
    """The crank-slider with a continuous ball screw (its efficiency from the lead)."""
    data = copy.deepcopy(_shipped("cs_min_backlash"))
    data["name"] = "cs_with_screw"
    data["variables"]["d0"] = {"lower": "10 mm", "upper": "40 mm"}
    data["screw"] = {"kind": "ball", "friction": 0.005}
    return data


def problem_data(case: Case) -> dict[str, Any]:
    """The problem dict of ``case`` (units as a file writes them)."""
    data = _screw_base() if case.base == "screw" else copy.deepcopy(_shipped(case.base))
    for path, value in case.edits:
        d = data
        for key in path[:-1]:
            d = d.setdefault(key, {})
        if value is DELETE:
            d.pop(path[-1], None)
        else:
            d[path[-1]] = value
    return data


def _e(*pairs) -> tuple[tuple[tuple[str, ...], Any], ...]:
    return tuple((tuple(p.split(".")), v) for p, v in pairs)


_HUTH = ("requirements.pin_contact", "huth")
_RATIO = "variables.pin_length_ratio"


def refused_cases() -> list[Case]:
    """Values outside a declared range, refused when the file is read."""
    out: list[Case] = []

    def add(name, base, edits, names, why=""):
        out.append(Case(name, base, _e(*edits), "refused", names, why))

    # elastic moduli: linear elasticity from soft polymers to diamond
    for e in ("1e-6 MPa", "1 MPa", "50 MPa", "99 MPa", "1.3e6 MPa", "1e9 MPa", "1e12 MPa"):
        add(f"pin E {e}", "cs_min_backlash", [("materials.pin.E", e)], ("materials.pin.E",))
    for e in ("1 MPa", "1e9 MPa"):
        add(f"fork pin E {e}", "fork_min_backlash", [("materials.pin.E", e)], ("E",))
    for e in ("1e-6 MPa", "10 MPa", "2e6 MPa"):
        lug = {"cheek_thickness": "5 mm", "E": e}
        add(f"lug E {e}", "cs_min_backlash", [_HUTH, ("materials.lug", lug)], ("lug.E",))
    for e in ("1 MPa", "5e6 MPa"):
        lug = {"cheek_thickness": "5 mm", "cheek_E": e}
        add(f"lug cheek_E {e}", "cs_min_backlash", [_HUTH, ("materials.lug", lug)], ("cheek_E",))
    # lug thicknesses: a micrometre (the roughness of the bore) to a metre
    for t in ("1e-9 mm", "1e-6 mm", "0.5 um", "1001 mm", "2 m", "1 km"):
        lug = {"cheek_thickness": t}
        add(
            f"lug cheek {t}",
            "cs_min_backlash",
            [_HUTH, ("materials.lug", lug)],
            ("cheek_thickness",),
        )
    for t in ("1e-9 mm", "0.0001 mm", "5 m"):
        lug = {"cheek_thickness": "5 mm", "thickness": t}
        add(
            f"lug thickness {t}", "cs_min_backlash", [_HUTH, ("materials.lug", lug)], ("thickness",)
        )
    # fixed clearances: micrometres of play, an angle within the small-angle limit
    for key, values in (
        ("A", ("1.5 mm", "10 mm", "1 m", "1 km")),
        ("B", ("2 mm", "1e6 mm")),
        ("C", ("1.01 mm", "5 mm", "1 km")),
        ("O", ("6 deg", "90 deg", "1 rad", "1 turn")),
    ):
        for v in values:
            add(f"clearance {key} {v}", "cs_min_backlash", [(f"clearances.{key}", v)], (key,))
    add("fork clearance A 1 km", "fork_min_backlash", [("clearances.A", "1 km")], ("A",))
    add("fork clearance O 10 deg", "fork_min_backlash", [("clearances.O", "10 deg")], ("O",))
    add("pivot clearance B 3 mm", "pivot_min_backlash", [("clearances.B", "3 mm")], ("B",))
    # the pin: a short stiff cylinder, L/d 0.2 to 5, d 0.1 to 500 mm
    for r in (1e9, 1e3, 10, 5.5, 5.01, 0.199, 0.15, 0.01, 1e-6):
        add(f"pin length ratio {r:g}", "cs_min_backlash", [(_RATIO, r)], ("pin_length_ratio",))
    add("fork pin length ratio 100", "fork_min_backlash", [(_RATIO, 100)], ("pin_length_ratio",))
    add("pivot pin length ratio 1e9", "pivot_min_backlash", [(_RATIO, 1e9)], ("pin_length_ratio",))
    add(
        "pin length ratio free up to 20",
        "cs_min_backlash",
        [(_RATIO, {"lower": 1, "upper": 20})],
        ("pin_length_ratio.upper",),
    )
    add(
        "pin length ratio free from 0.01",
        "cs_min_backlash",
        [(_RATIO, {"lower": 0.01, "upper": 2})],
        ("pin_length_ratio.lower",),
    )
    for length in ("1e-5 mm", "0.01 mm", "3 m", "5700 km"):
        add(
            f"pin length {length}",
            "cs_min_backlash",
            [(_RATIO, DELETE), ("variables.pin_length", length)],
            ("pin_length",),
        )
    for bounds, where in (
        ({"lower": "4 mm", "upper": "600 mm"}, "d.upper"),
        ({"lower": "4 mm", "upper": "1 m"}, "d.upper"),
        ({"lower": "0.01 mm", "upper": "30 mm"}, "d.lower"),
        ("0.001 mm", "variables.d"),
        ("1 km", "variables.d"),
        ({"values": ["0.05 mm", "4 mm"]}, "d.lower"),
    ):
        add(f"pin diameter {bounds}", "cs_min_backlash", [("variables.d", bounds)], (where,))
    add("fork pin diameter 2 m", "fork_min_backlash", [("variables.d", "2 m")], ("variables.d",))
    add(
        "reference pin 0.01 mm",
        "duan2017_redesign",
        [("reference.d", "0.01 mm")],
        ("reference.d",),
    )
    # the backlash requirement: the small-angle model holds below 5 deg
    for b in ("5.01 deg", "6 deg", "90 deg", "1 turn", "0.2 rad"):
        add(
            f"backlash_max {b}",
            "cs_min_backlash",
            [("requirements.backlash_max", b)],
            ("backlash_max",),
        )
    # the lock's friction: Coulomb friction below 1
    for mu in (1.01, 1.5, 10, 1e6):
        lock = {"kind": "friction_plate", "r1": "10 mm", "r2": "20 mm", "mu": mu}
        add(f"lock friction {mu:g}", "cs_min_backlash", [("requirements.lock", lock)], ("mu",))
    # the drive's members: 1 to 1e9 N/mm
    for k in ("1e-3 N/mm", "0.5 N/mm", "1e10 N/mm", "1e15 N/mm"):
        add(f"nut stiffness {k}", "screw", [("screw.nut_stiffness", k)], ("nut_stiffness",))
    for k in ("1e-6 N/um", "1e7 N/um"):
        add(
            f"bearing stiffness {k}",
            "screw",
            [("screw.bearing_stiffness", k)],
            ("bearing_stiffness",),
        )
    return out


def flagged_cases() -> list[Case]:
    """Values inside every input range whose designs leave a model's range: the solve
    reports them, never an optimum."""
    out: list[Case] = []

    def add(name, base, edits, names, why=""):
        out.append(Case(name, base, _e(*edits), "flagged", names, why))

    # Huth's t/d of about 0.2 to 2 (the pin of 4 to 30 mm)
    for t in ("0.001 mm", "0.01 mm", "0.3 mm", "0.79 mm", "100 mm", "900 mm"):
        add(
            f"huth cheek {t}",
            "cs_min_backlash",
            [_HUTH, ("materials.lug", {"cheek_thickness": t})],
            ("Huth",),
            "t2/d outside 0.2-2 for every pin of 4-30 mm",
        )
    for t in ("0.5 mm", "200 mm"):
        lug = {"cheek_thickness": "5 mm", "thickness": t}
        add(f"huth inner lug {t}", "cs_min_backlash", [_HUTH, ("materials.lug", lug)], ("Huth",))
    add(
        "huth fork cheek 0.05 mm",
        "fork_min_backlash",
        [_HUTH, ("materials.lug", {"cheek_thickness": "0.05 mm"})],
        ("Huth",),
    )
    # a pin softer than Hertz's half-space allows (b > d/8 under its load)
    for e in ("100 MPa", "120 MPa", "150 MPa", "200 MPa"):
        add(
            f"soft pin {e}",
            "cs_min_backlash",
            [("materials.pin.E", e)],
            ("Hertz line contact",),
            "a polymer pin carrying 500 N*m flattens beyond Hertz's range",
        )
    add("soft fork pin 100 MPa", "fork_min_backlash", [("materials.pin.E", "100 MPa")], ("Hertz",))
    add(
        "conforming soft pin 100 MPa",
        "cs_min_backlash",
        [
            ("requirements.pin_contact", "conforming"),
            ("materials.pin.E", "100 MPa"),
            ("variables.d", {"lower": "4 mm", "upper": "6 mm"}),
        ],
        ("conforming",),
        "P* above the explicit approximation's 100",
    )
    # the output shaft's play at the small-angle limit: the chain adds to it
    for o in ("5 deg", "4.99 deg", "4.98 deg", "4.97 deg"):
        add(f"output play {o}", "cs_min_backlash", [("clearances.O", o)], ("small-angle",))
    add(
        "output play 4.5 deg and bearings 1 mm",
        "cs_min_backlash",
        [("clearances.O", "4.5 deg"), ("clearances.A", "1 mm"), ("clearances.B", "1 mm")],
        ("small-angle",),
    )
    add(
        "fork output play 5 deg", "fork_min_backlash", [("clearances.O", "5 deg")], ("small-angle",)
    )
    add(
        "pivot output play 5 deg",
        "pivot_min_backlash",
        [("clearances.O", "5 deg")],
        ("small-angle",),
    )
    # a pin more than twice as long as the linkage (fork: size R)
    add(
        "fork pin more than twice the arm",
        "fork_min_backlash",
        [
            ("variables.R", {"lower": "30 mm", "upper": "40 mm"}),
            ("variables.p", {"lower": "1 mm", "upper": "10 mm"}),
            ("variables.d", {"lower": "20 mm", "upper": "30 mm"}),
            (_RATIO, 5),
        ],
        ("planar linkage",),
    )
    add(
        "free pin length up to 2 m",
        "cs_min_backlash",
        [(_RATIO, DELETE), ("variables.pin_length", {"lower": "30 mm", "upper": "2000 mm"})],
        ("pin model",),
        "a longer pin flattens less: the optimiser makes it a beam",
    )
    # a lead angle beyond 45 deg: a helical cam, no screw
    add(
        "screw of 0.5 mm",
        "screw",
        [("variables.d0", {"lower": "0.2 mm", "upper": "0.5 mm"})],
        ("screw efficiency",),
    )
    add("screw of 0.3 mm fixed", "screw", [("variables.d0", "0.3 mm")], ("screw efficiency",))
    add(
        "screw leads of 20-40 mm on 4-6 mm",
        "screw",
        [
            ("variables.d0", {"lower": "4 mm", "upper": "6 mm"}),
            ("variables.p", {"lower": "20 mm", "upper": "40 mm"}),
            ("variables.i_a", 8),
        ],
        ("screw efficiency",),
    )
    return out


def all_cases() -> list[Case]:
    return refused_cases() + flagged_cases()


def run_case(case: Case) -> Verdict:
    """Judge one case through the Python API (module docstring)."""
    import optdesign as od
    from optdesign.errors import OptDesignError
    from optdesign.problem.validity import is_validity

    t0 = time.perf_counter()
    data = problem_data(case)
    try:
        problem = od.load(data)
    except OptDesignError as exc:
        message = str(exc)
        seconds = time.perf_counter() - t0
        if case.expect != "refused":
            return Verdict(case.name, "refused, but should be read", message, seconds)
        if "\n" in message:
            return Verdict(case.name, "refused in several lines", message, seconds)
        missing = [n for n in case.names if n not in message]
        if missing or "is outside" not in message:
            return Verdict(case.name, f"message lacks {missing or 'the range'}", message, seconds)
        return Verdict(case.name, "clean", message, seconds)
    if case.expect == "refused":
        return Verdict(case.name, "read, but should be refused", "", time.perf_counter() - t0)
    result = od.solve(problem, starts=1, ranges=False)
    seconds = time.perf_counter() - t0
    outside = [r for r in result.violated if is_validity(r)]
    message = "; ".join(r.name for r in outside)
    detail = {"status": result.status, "verified": result.verified}
    if result.success or result.verified is not False:
        return Verdict(case.name, f"{result.status}, verified {result.verified}", message, seconds)
    if not outside:
        return Verdict(case.name, "not verified, no model named", message, seconds, detail)
    missing = [n for n in case.names if n not in message]
    if missing:
        return Verdict(case.name, f"flagged without {missing}", message, seconds, detail)
    return Verdict(case.name, "clean", message, seconds, detail)


def run_case_cli(case: Case, json_mode: bool, out: Path) -> Verdict:
    """Judge one case through ``optdesign solve`` (``--json`` on stdout, or the summary
    and files under ``out``): a refused case exits 2 with one line on stderr naming the
    field and the range; a flagged one exits 1 and names each model it leaves, in the
    JSON document's violated rows or in the summary."""
    from hostile_corpus import dumps, run_main

    out.mkdir(parents=True, exist_ok=True)
    path = out / "problem.toml"
    path.write_text(dumps(problem_data(case)))
    argv = ["solve", str(path), "--starts", "1", "--no-ranges"]
    argv += ["--json"] if json_mode else ["--no-plot", "--out", str(out / "run")]
    code, stdout, stderr, seconds = run_main(argv, timeout=60)
    lines = [ln for ln in stderr.strip().splitlines() if ln.strip()]
    if case.expect == "refused":
        message = lines[0] if lines else ""
        if code != 2 or len(lines) != 1 or stdout:
            return Verdict(case.name, f"exit {code}, {len(lines)} lines", stderr[-300:], seconds)
        missing = [n for n in case.names if n not in message]
        if missing or "is outside" not in message:
            return Verdict(case.name, f"message lacks {missing or 'the range'}", message, seconds)
        return Verdict(case.name, "clean", message, seconds)
    if code != 1:
        return Verdict(case.name, f"exit {code}", (stderr or stdout)[-300:], seconds)
    if json_mode:
        import json

        doc = json.loads(stdout)
        shown = "; ".join(str(r.get("name", "")) for r in doc.get("violated", []))
        if doc.get("verified") is not False or doc.get("status") == "optimal":
            return Verdict(case.name, f"json says {doc.get('status')}", shown, seconds)
    else:
        shown = stdout
    missing = [n for n in case.names if n not in shown]
    if "validity: " not in shown or missing:
        return Verdict(case.name, f"flagged without {missing or 'a model'}", shown[-300:], seconds)
    return Verdict(case.name, "clean", "", seconds)


if __name__ == "__main__":  # pragma: no cover - a report for a person
    sys.path.insert(0, str(ROOT))
    for c in all_cases():
        v = run_case(c)
        print(f"{v.verdict:40s} {v.seconds:6.2f}s  {c.expect:8s} {c.name}: {v.message[:150]}")
