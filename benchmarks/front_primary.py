"""A front's primary back-end: CasADi's sqpmethod with qpOASES (the default) against
SciPy's SLSQP, on the same fronts, one process per run.

Why: each worker of a front imported ``scipy.optimize`` for SLSQP (~0.3 s), the largest
fixed cost of the pareto command's front after the interpreter's start-up
(benchmarks/README.md, "The pareto command's fixed cost"). CasADi's own SQP needs no
SciPy. ``--options`` (JSON) are added to sqpmethod's sweep options
(``optdesign.solvers.registry.SQPMETHOD_SWEEP``) for the run.

For each run it prints one JSON line: CPU seconds of the front (one worker, no files),
points, NLP solves, starts the primary failed (solved again by Ipopt), failed points,
whether ``scipy.optimize`` was imported, and each point's gap to Ipopt solving it again
from the point at the same epsilon (``(f_point - f_ipopt) / |f_ipopt|``: how far short of
a KKT point the primary stopped). Run from the repository root:

    python benchmarks/front_primary.py --primary slsqp --case cs_min_backlash:ripple,backlash
    python benchmarks/front_primary.py --primary sqpmethod --case knee:backlash,ripple

A case is ``PROBLEM:OBJ1,OBJ2`` with PROBLEM a file of problems/ (without .toml) or one of
the user-written linkages of tests/multimodal_mechanisms (knee, six_bar, double_rocker).
"""

from __future__ import annotations

import argparse
import collections
import importlib
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--primary", default="sqpmethod", choices=("sqpmethod", "slsqp"))
    ap.add_argument("--options", default="{}", help="sqpmethod options (JSON)")
    ap.add_argument("--case", action="append", required=True, help="PROBLEM:OBJ1,OBJ2")
    ap.add_argument("--points", type=int, default=30)
    args = ap.parse_args()

    import optdesign as od
    import optdesign.studies.pareto.eps_solver as eps_solver
    from optdesign.solvers import registry

    if args.primary == "sqpmethod":
        registry.SQPMETHOD_SWEEP.update(json.loads(args.options))
    sys.path.insert(0, str(ROOT / "tests"))
    for case in args.case:
        name, _, objectives = case.partition(":")
        objs = objectives.split(",")
        if name in ("knee", "six_bar", "double_rocker"):
            module = importlib.import_module(f"multimodal_mechanisms.{name}")
            problem = od.load(module.problem(objs[0]))
        else:
            problem = od.load(ROOT / "problems" / f"{name}.toml")
        t0 = time.process_time()
        front = od.pareto(
            problem, objs, points=args.points, workers=1, files=False, solver=args.primary
        )
        cpu = time.process_time() - t0
        again = eps_solver.EpsSolver(problem, objs)
        gaps = []
        for pt in front.points:
            if not pt.success or pt.target is None:
                continue
            start = again.nlp.start(x0=np.asarray(pt.x))
            res = again.solve(pt.target, pt.eps or {}, start, use="fallback")
            if res.success:
                best = res.objectives[pt.target]
                gaps.append((pt.objectives[pt.target] - best) / max(abs(best), 1e-12))
        fallbacks = collections.Counter(str(p.fallback) for p in front.points if p.fallback)
        line = {
            "case": case,
            "primary": args.primary,
            "options": json.loads(args.options) if args.primary == "sqpmethod" else {},
            "cpu_s": round(cpu, 3),
            "points": len(front.points),
            "nlp_solves": front.n_solves,
            "primary_failed": dict(fallbacks),
            "failed_points": sum(1 for p in front.points if not p.success),
            "scipy_optimize_imported": "scipy.optimize" in sys.modules,
            "gap_max": max(gaps) if gaps else None,
            "front": [[p.objectives[o] for o in objs] for p in front.points],
        }
        print(json.dumps(line), flush=True)


if __name__ == "__main__":
    main()
