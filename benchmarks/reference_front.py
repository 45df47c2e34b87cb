"""Dense reference Pareto front of cs_min_backlash (ripple vs backlash), computed once.

Epsilon-constraint with points evenly spread along the front (arc length), every point
solved from its neighbour's warm start *and* from several seeded Sobol starts (best
kept), anchors from 32 starts each. The non-dominated, independently verified points go
to ``benchmarks/data/cs_min_backlash_reference_front.csv``, which bench_pareto.py reads.

    /work/venv/bin/python benchmarks/reference_front.py [--points 240] [--workers 2]

Resumable: the run's store is in ``--out`` (default optdesign-out/reference-front);
rerun with ``--resume`` after an interruption.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from optdesign.problem import load_problem
from optdesign.reports.front_files import write_front_csv
from optdesign.studies.pareto import EpsilonConstraint, compute_front

ROOT = Path(__file__).resolve().parents[1]
CSV = ROOT / "benchmarks" / "data" / "cs_min_backlash_reference_front.csv"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=240)
    ap.add_argument("--extra-starts", type=int, default=3)
    ap.add_argument("--anchor-starts", type=int, default=32)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=Path("optdesign-out/reference-front"))
    ap.add_argument("--resume", action="store_true")
    args = ap.parse_args()
    problem = load_problem(ROOT / "problems" / "cs_min_backlash.toml")
    t0 = time.perf_counter()
    method = EpsilonConstraint(
        points=args.points,
        starts=args.anchor_starts,
        agree=None,  # every anchor start runs (no early stop): a reference, not a race
        extra_starts=args.extra_starts,
        name="reference",
    )
    front = compute_front(
        problem,
        ["ripple", "backlash"],
        method=method,
        out=args.out,
        workers=args.workers,
        resume=args.resume,
        progress=True,
    )
    write_front_csv(front, problem, CSV)
    print(
        f"{len(front.points)} non-dominated verified points of {args.points} "
        f"({front.metrics['n_failed']} failed) in {time.perf_counter() - t0:.1f} s "
        f"-> {CSV.relative_to(ROOT)}"
    )
    print(f"anchors: {front.anchors}")


if __name__ == "__main__":
    main()
