"""Nominal vs robust optimum of a problem with ``[tolerances]``, judged by an independent
Monte Carlo (another seed, many more samples, the same draws for both designs) with a
paired bootstrap of the difference (:func:`optdesign.formulations.robust.solve.compare_nominal_robust`).

Run:  python benchmarks/robust_compare.py problems/cs_min_backlash_robust.toml
      [--mc 20000] [--mc-seed S] [--q 0.95] [--starts N] [--robust-starts N]

The robust optimum alone is ``optdesign solve FILE --formulation robust`` (or
``od.solve(problem, formulation="robust")``); this script prints the comparison table.
"""

from __future__ import annotations

import argparse
import time

from optdesign.formulations.robust.solve import MC_SAMPLES, MC_SEED, compare_nominal_robust
from optdesign.problem import load_problem


def main(argv: list[str] | None = None) -> int:
    """Print the nominal-vs-robust table; exit 0 when the robust solve succeeded."""
    ap = argparse.ArgumentParser(prog="python benchmarks/robust_compare.py")
    ap.add_argument("file")
    ap.add_argument("--mc", type=int, default=MC_SAMPLES, help="independent MC samples")
    ap.add_argument("--mc-seed", type=int, default=MC_SEED)
    ap.add_argument("--q", type=float, default=0.95, help="quantile level reported")
    ap.add_argument("--starts", type=int, default=None, help="nominal multistart count")
    ap.add_argument("--robust-starts", type=int, default=1)
    args = ap.parse_args(argv)
    problem = load_problem(args.file)
    t0 = time.perf_counter()
    cmp = compare_nominal_robust(
        problem, args.mc, args.mc_seed, args.q, args.starts, args.robust_starts
    )
    print(cmp.table())
    print(
        f"\nnominal {cmp.nominal.status}, robust {cmp.robust.status} "
        f"(independent check {'passed' if cmp.robust.verified else 'FAILED'}); "
        f"SAA statistic recomputed on the NumPy path: {cmp.robust.details.robust.saa_check:.6g}; "
        f"total {time.perf_counter() - t0:.1f} s"
    )
    return 0 if cmp.robust.success else 1


if __name__ == "__main__":
    raise SystemExit(main())
