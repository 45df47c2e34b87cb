"""Starts stuck at a linkage's singular position, against Ipopt's cap on the Hessian's
regularisation (``max_hessian_perturbation``): the first 8 starts of seed 0 of
``cs_min_backlash`` with the deflection widened to +-120 deg (no feasible design), each
cap in one process, one line per cap. Run from the repository root:

    python benchmarks/global_search/stuck_starts.py --caps 1e4 1e6 1e20
"""

from __future__ import annotations

import argparse
import time
import tomllib
from pathlib import Path

import optdesign as od
from optdesign.formulations.nlp.solve import _objective_set, solver_for, tilted_starts

ROOT = Path(__file__).resolve().parents[2]


def infeasible_problem() -> od.DesignProblem:
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash.toml").read_text())
    data["requirements"]["deflection"].update({"min": "-120 deg", "max": "120 deg"})
    return od.load(data)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--caps", type=float, nargs="+", default=[1e4, 1e6, 1e20])
    parser.add_argument("--starts", type=int, default=8)
    args = parser.parse_args()
    problem = infeasible_problem()
    objective = problem.objective_names[0]
    starts = tilted_starts(problem, objective, 0).first(args.starts)
    for cap in args.caps:
        backend = solver_for(
            problem, None, {"max_hessian_perturbation": cap}, _objective_set(problem, objective)
        )
        target = backend.nlp.target(objective)
        t0 = time.perf_counter()
        ends = []
        for x0 in starts:
            t = time.perf_counter()
            r = backend.solve(x0, target)
            ends.append(f"{r.iterations} it {r.message[:24]} {time.perf_counter() - t:.2f}s")
        print(f"cap {cap:g}: {time.perf_counter() - t0:.2f} s for {len(starts)} starts")
        for line in ends:
            print("   ", line)


if __name__ == "__main__":
    main()
