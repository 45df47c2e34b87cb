"""Solve times of optdesign's work under the installed casadi (and NumPy): run it in
environments that differ only in one package and compare the figures (README here).

python benchmarks/dependencies/solve_times.py [REPEATS]
"""

from __future__ import annotations

import sys
import time
import tomllib
from pathlib import Path

import casadi
import numpy as np

import optdesign as od

ROOT = Path(__file__).resolve().parents[2]


def infeasible_problem() -> od.DesignProblem:
    """cs_min_backlash with a nut travel and a mean-ratio band no design meets together."""
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash.toml").read_text())
    data["requirements"]["nut_travel_max"] = "40 mm"
    data["requirements"]["mean_ratio"] = {"min": 250, "max": 260}
    return od.load(data)


def cases() -> dict[str, tuple[od.DesignProblem, dict]]:
    shipped = {
        name: (od.load(ROOT / "problems" / f"{name}.toml"), {})
        for name in ("cs_min_ripple", "cs_min_backlash", "fin_actuator", "fin_actuator_motor")
    }
    return {**shipped, "infeasible (2 starts)": (infeasible_problem(), {"starts": 2})}


def main(repeats: int = 3) -> None:
    print(f"casadi {casadi.__version__}, numpy {np.__version__}")
    for name, (problem, options) in cases().items():
        times, values = [], set()
        for _ in range(repeats):
            t0 = time.perf_counter()
            result = od.solve(problem, ranges=False, sensitivities=False, **options)
            times.append(time.perf_counter() - t0)
            values.add(f"{result.status} {result.objective:.9g}")
        print(f"  {name:24s} median {np.median(times):6.2f} s   {' | '.join(sorted(values))}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
