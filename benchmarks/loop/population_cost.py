"""The CPU time of one NumPy evaluation of a population of `fin_actuator_loop` designs
(a global search's start sample): 256 Sobol designs within the file's bounds, the least
of ``--rounds`` evaluations, then the same evaluation with the bandwidth objective read
(which computes its roots). Runs the optdesign found on PYTHONPATH, so two trees are
compared with the same script:

    PYTHONPATH=. python benchmarks/loop/population_cost.py
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from scipy.stats import qmc

import optdesign as od

ROOT = Path(__file__).resolve().parents[2]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=256)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    problem = od.load(ROOT / "problems" / "fin_actuator_loop.toml")
    lo, hi = problem.lower(), problem.upper()
    X = lo + (hi - lo) * qmc.Sobol(len(lo), seed=0).random(args.designs)
    problem.evaluate(X[:2])  # imports and caches outside the timing

    def timed(read_bandwidth: bool) -> float:
        best = np.inf
        for k in range(args.rounds):
            Y = X * (1 + 1e-12 * (k + 1))  # new plants: no cached root answers
            start = time.process_time()
            ev = problem.evaluate(Y)
            _ = ev.objectives["backlash"]
            if read_bandwidth and "bandwidth_period" in ev.objectives:
                _ = ev.objectives["bandwidth_period"]
            best = min(best, time.process_time() - start)
        return best

    feasible = int(np.sum(np.asarray(problem.evaluate(X).violation) <= 1e-6))
    print(f"optdesign from {Path(od.__file__).parent}")
    print(f"{args.designs} designs ({feasible} feasible), least of {args.rounds} rounds (CPU s):")
    print(f"  evaluation, backlash read:              {timed(False):.3f}")
    print(f"  evaluation, backlash and bandwidth read: {timed(True):.3f}")


if __name__ == "__main__":
    main()
