"""A sweep by continuation against independent solves (issue 24).

On one problem, one parameter over ``--points`` evenly spaced values: the wall time of
``od.sweep`` (continuation: warm starts from the neighbour, a full multistart every
``--check-every`` points, at the ends and where the binding set changes) against
``--points`` independent ``od.solve`` calls on the same values (each the default
multistart, ranges and sensitivities included: what a user runs per value), in one
process, one after the other, on the same machine. Every point's objective is compared
with the independent multistart's (relative difference; the target is 1e-6), and the
binding set changes are listed. Results go to ``benchmarks/sweep/results.json`` under
``--label``, the design chart to ``benchmarks/sweep/<problem>.png``.

    PYTHONPATH=$PWD python benchmarks/sweep/bench_sweep.py --label after
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problem", default="cs_min_backlash")
    ap.add_argument("--vary", default="requirements.hinge_moment")
    ap.add_argument("--start", default="200 N*m")
    ap.add_argument("--stop", default="1000 N*m")
    ap.add_argument("--points", type=int, default=50)
    ap.add_argument("--check-every", type=int, default=10)
    ap.add_argument("--label", default="run")
    args = ap.parse_args()

    import optdesign as od
    from optdesign.problem.parameters import at_values

    problem = od.load(ROOT / "problems" / f"{args.problem}.toml")
    od.solve(problem)  # imports and first-use costs paid before either side is timed
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as out:
        sweep = od.sweep(
            problem,
            {args.vary: (args.start, args.stop, args.points)},
            out=out,
            check_every=args.check_every,
        )
    t_sweep = time.perf_counter() - t0
    t0 = time.perf_counter()
    alone = [od.solve(at_values(problem, {args.vary: p.values[0]})) for p in sweep.points]
    t_alone = time.perf_counter() - t0
    diffs = []
    for p, r in zip(sweep.points, alone, strict=True):
        if p.success and r.success:
            diffs.append(abs(p.objective - r.objective) / max(abs(r.objective), 1e-300))
        elif p.success != r.success:
            diffs.append(float("inf"))
    row = {
        "problem": args.problem,
        "vary": f"{args.vary} {args.start}..{args.stop}",
        "points": args.points,
        "check_every": args.check_every,
        "sweep_s": round(t_sweep, 3),
        "independent_solves_s": round(t_alone, 3),
        "ratio": round(t_sweep / t_alone, 4),
        "solved": sum(p.success for p in sweep.points),
        "multistart_checks": sum(p.checked for p in sweep.points),
        "jumps": sum(p.jump for p in sweep.points),
        "binding_set_changes": [
            {"point": p.index, "value": p.values[0], "binding": p.active}
            for p in sweep.points
            if p.active_change
        ],
        "max_rel_objective_difference": max(diffs) if diffs else None,
        "points_within_1e-6": sum(d <= 1e-6 for d in diffs),
        "compared": len(diffs),
    }
    print(json.dumps(row, indent=2))
    fig = sweep.plot()
    fig.savefig(HERE / f"{args.problem}.png", dpi=100)
    path = HERE / "results.json"
    data = json.loads(path.read_text()) if path.exists() else {}
    data.setdefault(args.label, {})[args.problem] = row
    path.write_text(json.dumps(data, indent=2) + "\n")


if __name__ == "__main__":
    main()
