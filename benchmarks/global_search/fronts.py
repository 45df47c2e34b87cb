"""Fronts and sweeps on a linkage with several local optima (the knee of
tests/multimodal_mechanisms), against its reference and against cold solves:

- the default ripple/backlash front (10 points, epsilon method), with 1 and 2 workers:
  its ends against the reference's single-objective optima (knee_optimum.json), and the
  two fronts point for point;
- a hinge-moment sweep (250-450 N*m, 5 points), with 1 and 2 workers: every point
  against a cold ``od.solve`` of the problem at that moment (seed 0), and the two sweeps.

Each part's records go to ``benchmarks/global_search/fronts.jsonl`` as they finish; a
rerun skips the parts already there. Run from the repository root:

    python benchmarks/global_search/fronts.py
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))

from multimodal_mechanisms import knee  # noqa: E402

import optdesign as od  # noqa: E402

RECORDS = Path(__file__).resolve().parent / "fronts.jsonl"
REFERENCE = json.loads((ROOT / "tests/multimodal_mechanisms/knee_optimum.json").read_text())
MOMENTS_NMM = [250e3, 300e3, 350e3, 400e3, 450e3]


def _done() -> dict:
    if not RECORDS.exists():
        return {}
    recs = [json.loads(line) for line in RECORDS.read_text().splitlines()]
    return {r["part"]: r for r in recs}


def _write(rec: dict) -> None:
    with RECORDS.open("a") as fh:
        fh.write(json.dumps(rec) + "\n")
    print(json.dumps(rec)[:400], flush=True)


def front(workers: int) -> dict:
    problem = od.load(knee.problem("backlash"))
    with tempfile.TemporaryDirectory() as out:
        t = time.perf_counter()
        f = od.pareto(problem, ["ripple", "backlash"], workers=workers, out=out + "/f")
        dt = time.perf_counter() - t
    pts = sorted((p.objectives["ripple"], p.objectives["backlash"]) for p in f.points)
    return {"part": f"front-{workers}", "time_s": dt, "points": pts}


def sweep(workers: int) -> dict:
    problem = od.load(knee.problem("backlash"))
    with tempfile.TemporaryDirectory() as out:
        t = time.perf_counter()
        s = od.sweep(
            problem,
            {"requirements.hinge_moment": (f"{MOMENTS_NMM[0]} N*mm", f"{MOMENTS_NMM[-1]} N*mm", 5)},
            workers=workers,
            out=out + "/s",
        )
        dt = time.perf_counter() - t
    values = [p.objective if p.success else None for p in s.points]
    return {"part": f"sweep-{workers}", "time_s": dt, "values": values}


def cold() -> dict:
    values = []
    for moment in MOMENTS_NMM:
        data = knee.problem("backlash")
        data["requirements"]["hinge_moment"] = f"{moment} N*mm"
        r = od.solve(od.load(data), seed=0, ranges=False, diagnose=False, sensitivities=False)
        values.append(r.objective if r.success else None)
    return {"part": "cold", "values": values}


def summary(done: dict) -> str:
    lines = []
    ref = {k: REFERENCE[k]["value"] for k in ("ripple", "backlash")}
    for w in (1, 2):
        rec = done.get(f"front-{w}")
        if rec:
            pts = rec["points"]
            lo_ripple, lo_backlash = pts[0][0], min(b for _, b in pts)
            lines.append(
                f"front, {w} worker(s): {len(pts)} points in {rec['time_s']:.0f} s; least ripple "
                f"{lo_ripple:.10g} (reference {ref['ripple']:.10g}, gap "
                f"{(lo_ripple - ref['ripple']) / ref['ripple']:.1e}); least backlash "
                f"{lo_backlash:.10g} (reference {ref['backlash']:.10g}, gap "
                f"{(lo_backlash - ref['backlash']) / ref['backlash']:.1e})"
            )
    if "front-1" in done and "front-2" in done:
        same = done["front-1"]["points"] == done["front-2"]["points"]
        lines.append(f"fronts of 1 and 2 workers identical: {same}")
    if "cold" in done:
        for w in (1, 2):
            rec = done.get(f"sweep-{w}")
            if rec:
                gaps = [
                    None if a is None or b is None else (a - b) / b
                    for a, b in zip(rec["values"], done["cold"]["values"], strict=True)
                ]
                shown = ", ".join("n/a" if g is None else f"{g:.1e}" for g in gaps)
                lines.append(
                    f"sweep, {w} worker(s), {rec['time_s']:.0f} s: gap to the cold solve "
                    f"at 250..450 N*m: {shown}"
                )
    if "sweep-1" in done and "sweep-2" in done:
        same = done["sweep-1"]["values"] == done["sweep-2"]["values"]
        lines.append(f"sweeps of 1 and 2 workers identical: {same}")
    return "\n".join(lines)


def main() -> None:
    done = _done()
    for part, run in [
        ("front-1", lambda: front(1)),
        ("front-2", lambda: front(2)),
        ("cold", cold),
        ("sweep-1", lambda: sweep(1)),
        ("sweep-2", lambda: sweep(2)),
    ]:
        if part not in done:
            done[part] = run()
            _write(done[part])
    print(summary(done))


if __name__ == "__main__":
    main()
