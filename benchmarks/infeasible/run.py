"""Verdicts on impossible problems: the time from ``od.solve`` to its answer (the search
and the diagnosis) on a corpus of infeasible variants of the shipped problems, for the
code on ``sys.path`` - run it once per tree to compare two trees - and, with ``--check``,
each relaxation the diagnosis names solved again: the problem with that requirement (or,
when none suffices alone, the set named together) moved to the limit the diagnosis gives
(0.1 % further, as a user would write it) must have a feasible design.

    PYTHONPATH=/work/base_inf python benchmarks/infeasible/run.py --out old.json
    PYTHONPATH=. python benchmarks/infeasible/run.py --check --out new.json
    python benchmarks/infeasible/run.py --table old.json new.json

A relaxation is checked on the problem file when its rows hold the requirement's own
value (``nut_travel_max``, ``mean_ratio.min``...); otherwise (an angle's rows hold its
cosine) on the problem's NLP with those rows widened, solved from 8 starts.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import tomllib
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "problems"

#: name: (shipped problem, requirement edits: path below [requirements] -> value).
CORPUS: dict[str, tuple[str, dict[str, Any]]] = {
    "backlash stroke +-120 deg": (
        "cs_min_backlash",
        {"deflection": {"min": "-120 deg", "max": "120 deg", "points": 61}},
    ),
    "backlash stroke +-90 deg": (
        "cs_min_backlash",
        {"deflection": {"min": "-90 deg", "max": "90 deg", "points": 61}},
    ),
    "backlash band 250-260, travel 40 mm": (
        "cs_min_backlash",
        {"mean_ratio": {"min": 250, "max": 260}, "nut_travel_max": "40 mm"},
    ),
    "backlash travel 5 mm": ("cs_min_backlash", {"nut_travel_max": "5 mm"}),
    "backlash travel 20 mm": ("cs_min_backlash", {"nut_travel_max": "20 mm"}),
    "backlash band 1500-1510": ("cs_min_backlash", {"mean_ratio": {"min": 1500, "max": 1510}}),
    "backlash hinge 50 kN*m": ("cs_min_backlash", {"hinge_moment": "50000 N*m"}),
    "backlash pin pressure 2 MPa": ("cs_min_backlash", {"pin_bearing_pressure_max": "2 MPa"}),
    "backlash transmission 85-95 deg": (
        "cs_min_backlash",
        {"transmission_angle": {"min": "85 deg", "max": "95 deg"}},
    ),
    "ripple travel 5 mm": ("cs_min_ripple", {"nut_travel_max": "5 mm"}),
    "ripple stroke +-120 deg": (
        "cs_min_ripple",
        {"deflection": {"min": "-120 deg", "max": "120 deg", "points": 61}},
    ),
    "ripple band 1500-1510": ("cs_min_ripple", {"mean_ratio": {"min": 1500, "max": 1510}}),
    "fork travel 5 mm": ("fork_min_backlash", {"nut_travel_max": "5 mm"}),
    "fork pin pressure 1 MPa": ("fork_min_backlash", {"pin_bearing_pressure_max": "1 MPa"}),
    "pivot travel 5 mm": ("pivot_min_backlash", {"nut_travel_max": "5 mm"}),
    "pivot band 1500-1510": ("pivot_min_backlash", {"mean_ratio": {"min": 1500, "max": 1510}}),
    "pivot hinge 50 kN*m": ("pivot_min_backlash", {"hinge_moment": "50000 N*m"}),
    "robust travel 5 mm": ("cs_min_backlash_robust", {"nut_travel_max": "5 mm"}),
    "duan travel 20 mm": ("duan2017_redesign", {"nut_travel_max": "20 mm"}),
    "duan ripple 0.001": ("duan2017_redesign", {"ripple_max": 0.001}),
    "catalogue hinge 50 kN*m": ("fin_actuator", {"hinge_moment": "50000 N*m"}),
    "fork band 10-30": ("fork_min_backlash", {"mean_ratio": {"min": 10, "max": 30}}),
}


def problem_data(name: str) -> dict[str, Any]:
    """The case's problem file as a dict, its requirements edited."""
    base, edits = CORPUS[name]
    data = tomllib.loads((PROBLEMS / f"{base}.toml").read_text())
    data["requirements"].update(edits)
    if base == "cs_min_backlash_robust":  # the robust statistic's samples: a short run
        data["tolerances"]["samples"] = 8
    return data


def verdict(name: str) -> dict[str, Any]:
    """Solve one case (the search and its diagnosis) and time it."""
    import optdesign as od

    problem = od.load(problem_data(name))
    t0 = time.perf_counter()
    result = od.solve(problem, ranges=False)
    wall = time.perf_counter() - t0
    diagnosis = result.diagnosis
    alone = [] if diagnosis is None else diagnosis.relaxations
    together = getattr(diagnosis, "together", []) if diagnosis is not None else []
    ms = result.multistart
    return {
        "case": name,
        "seconds": round(wall, 2),
        "status": result.status,
        "stop": ms.stop if ms is not None else "",
        "starts": ms.n_starts if ms is not None else 0,
        "violated": sorted({v.name.split("[", 1)[0] for v in result.violated}),
        "alone": [_relaxation(r) for r in alone],
        "together": [_relaxation(r) for r in together],
        "note": diagnosis.note if diagnosis is not None else "",
        "impossible": [] if diagnosis is None else [p.to_json() for p in diagnosis.impossible],
    }


def _relaxation(r: Any) -> dict[str, Any]:
    return {"name": r.name, "upper": r.upper, "written": r.written, "needed": r.needed}


def check(name: str, relaxations: list[dict[str, Any]]) -> bool:
    """Whether the problem with every relaxation of ``relaxations`` applied (0.1 % beyond
    the needed limit) has a feasible design."""
    import optdesign as od
    from optdesign.problem.parameters import requirement_paths

    problem = od.load(problem_data(name))
    paths = dict(requirement_paths(problem))
    rows = []
    for r in relaxations:
        slack = 1e-3 * max(abs(r["needed"] - r["written"]), abs(r["written"]), 1e-9)
        value = r["needed"] + (slack if r["upper"] else -slack)
        side = "max" if r["upper"] else "min"
        path = next(
            (
                p
                for p in (f"{r['name']}_{side}", f"{r['name']}.{side}", r["name"])
                if p in paths and abs(paths[p] - r["written"]) <= 1e-9 * max(1.0, abs(r["written"]))
            ),
            None,
        )
        if path is None:
            rows.append((r["name"], value - r["written"]))
        else:
            problem = problem.with_requirement(path, value)
    if not rows:
        return bool(od.solve(problem, ranges=False, diagnose=False).success)
    return _feasible_with_rows(problem, rows)


def _feasible_with_rows(problem: Any, rows: list[tuple[str, float]]) -> bool:
    """A feasible point of the NLP with each named block of rows widened by its amount."""
    from dataclasses import replace

    import numpy as np

    from optdesign.formulations.nlp.solve import solver_for, tilted_starts

    backend = solver_for(problem)
    nlp = backend.nlp
    bounds = nlp.bounds()
    lbg, ubg = np.array(bounds.lbg), np.array(bounds.ubg)
    base = [g.split("[", 1)[0] for g in nlp.g_names]
    for name, t in rows:
        idx = [k for k, b in enumerate(base) if b == name]
        lbg[idx] -= abs(t) / nlp.g_scale[idx]
        ubg[idx] += abs(t) / nlp.g_scale[idx]
    widened = replace(bounds, lbg=lbg, ubg=ubg)
    for x in tilted_starts(problem, problem.objective_names[0], 0).first(8):
        r = backend.solve(nlp.start(x0=x), None, widened)
        if r.success and not r.violated:
            return True
    return False


def table(old_path: Path, new_path: Path) -> str:
    """The markdown table of two runs, case by case."""
    old = {r["case"]: r for r in json.loads(old_path.read_text())}
    new = {r["case"]: r for r in json.loads(new_path.read_text())}
    lines = [
        "| case | before (s) | after (s) | status before / after | stop after | relaxations named after | checked |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in CORPUS:
        o, n = old.get(name, {}), new.get(name, {})
        named = [f"{r['name']} -> {_g(r['needed'])}" for r in n.get("alone", [])]
        if n.get("together"):
            named.append(
                "together: " + ", ".join(f"{r['name']} -> {_g(r['needed'])}" for r in n["together"])
            )
        for proof in n.get("impossible", []):
            named.append(
                f"proved before any solve: {', '.join(proof['requirements'])} "
                f"(lifted by: {'; '.join(proof['remedies'])})"
            )
        if not named and n.get("note"):
            named = [n["note"].split(":", 1)[0]]
        lines.append(
            f"| {name} | {o.get('seconds', '-')} | {n.get('seconds', '-')} | "
            f"{o.get('status', '-')} / {n.get('status', '-')} | {n.get('stop', '')} | "
            f"{'; '.join(named)} | {n.get('checked', '-')} |"
        )
    return "\n".join(lines)


def _g(value: float | None) -> str:
    return "alone: none" if value is None else f"{value:.5g}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, help="write the measured records (JSON)")
    parser.add_argument("--check", action="store_true", help="solve each relaxed problem")
    parser.add_argument("--only", nargs="*", help="cases to run (default: all)")
    parser.add_argument("--table", nargs=2, type=Path, metavar=("OLD", "NEW"))
    args = parser.parse_args(argv)
    if args.table:
        print(table(*args.table))
        return 0
    import optdesign

    print(f"optdesign from {Path(optdesign.__file__).parent}", file=sys.stderr)
    records = []
    for name in args.only or CORPUS:
        rec = verdict(name)
        if args.check:
            alone = [r for r in rec["alone"] if r["needed"] is not None]
            checks = [check(name, [r]) for r in alone]
            if rec["together"]:
                checks.append(check(name, rec["together"]))
            rec["checked"] = f"{sum(checks)}/{len(checks)}" if checks else "-"
        print(json.dumps(rec), file=sys.stderr)
        records.append(rec)
    if args.out:
        args.out.write_text(json.dumps(records, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
