"""Issue 3 benchmark: one Ipopt solve vs multistart vs differential evolution.

Measures, in one run on this machine, for ``problems/cs_min_ripple.toml``:
- the median wall time of one Ipopt solve from the declared start (model built once);
- the wall time of the default multistart (8 Sobol starts) to the global optimum;
- the wall time of scipy differential evolution on the NumPy path until its best
  feasible point is within 1e-4 (relative) of that optimum;
and prints the ratios. Usage::

    python benchmarks/bench_solve.py [--problem problems/cs_min_ripple.toml] [--repeats 15]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import differential_evolution

from optdesign.formulations.nlp.solve import solve_nlp
from optdesign.problem import load_problem
from optdesign.programs.nlp import build_nlp
from optdesign.solvers.casadi_nlp import CasadiNLPSolver
from optdesign.solvers.registry import solver_hints
from optdesign.solvers.scipy_nlp import ScipyNLPSolver

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the independent global search lives with the tests
from independent_global import penalised_objective  # noqa: E402


def _target_callback(problem, objective, target, t_start, reached):
    """DE callback stopping when the best point is feasible and within 1e-4 of target."""

    def callback(intermediate_result):
        ev = problem.evaluate(intermediate_result.x)
        f = ev.objectives[objective]
        if ev.violation <= 1e-6 and f <= target * (1 + 1e-4):
            reached["t"] = time.perf_counter() - t_start
            reached["f"] = f
            return True
        return False

    return callback


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problem", default=str(ROOT / "problems" / "cs_min_ripple.toml"))
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--de-seeds", type=int, default=3)
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "bench_solve.json"))
    args = ap.parse_args()
    problem = load_problem(args.problem)
    objective = problem.objective_names[0]

    t0 = time.perf_counter()
    solver = CasadiNLPSolver(build_nlp(problem))
    build_time = time.perf_counter() - t0
    times, results = [], []
    for _ in range(args.repeats):
        r = solver.solve(problem.start())
        times.append(r.wall_time_s)
        results.append(r)
    one_solve = float(np.median(times))
    # the same NLP by SLSQP with exact CasADi derivatives (the Pareto sweeps' solver)
    sweep = dict(solver_hints("slsqp").sweep_options or {})
    slsqp = ScipyNLPSolver(solver.nlp, "SLSQP", "exact", sweep)
    slsqp_runs = [slsqp.solve(problem.start()) for _ in range(args.repeats)]
    one_slsqp = float(np.median([r.wall_time_s for r in slsqp_runs]))

    t0 = time.perf_counter()
    ms = solve_nlp(problem)
    multistart_time = time.perf_counter() - t0
    target = ms.objective

    de_times, de_evals, de_values = [], [], []
    fun = penalised_objective(problem, objective)
    bounds = list(zip(problem.lower(), problem.upper(), strict=True))
    for seed in range(args.de_seeds):
        reached: dict = {}
        t_start = time.perf_counter()
        callback = _target_callback(problem, objective, target, t_start, reached)

        res = differential_evolution(
            fun,
            bounds,
            seed=seed,
            popsize=40,
            maxiter=20000,
            tol=0,
            atol=0,
            vectorized=True,
            updating="deferred",
            polish=False,
            callback=callback,
        )
        de_times.append(reached.get("t", float("nan")))
        de_evals.append(int(res.nfev))
        de_values.append(reached.get("f", float(res.fun)))
    de_time = float(np.nanmedian(de_times))
    figures = {
        "problem": problem.name,
        "optimum": target,
        "build_time_s": build_time,
        "one_ipopt_solve_median_s": one_solve,
        "one_ipopt_solve_iterations": results[0].iterations,
        "one_solve_reaches_optimum": bool(abs(results[0].objective - target) <= 1e-6 * target),
        "one_slsqp_solve_median_s": one_slsqp,
        "one_slsqp_solve_objective": slsqp_runs[0].objective,
        "multistart_time_s": multistart_time,
        "multistart_starts": ms.multistart.n_starts,
        "multistart_at_best": ms.multistart.n_at_best,
        "de_time_to_target_s": de_time,
        "de_times_s": de_times,
        "de_nfev": de_evals,
        "de_reached_target": [not np.isnan(t) for t in de_times],
        "ratio_de_over_one_solve": de_time / one_solve,
        "ratio_de_over_one_slsqp_solve": de_time / one_slsqp,
        "ratio_de_over_multistart": de_time / multistart_time,
    }
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(figures, indent=2))
    for k, v in figures.items():
        print(f"{k:32s} {v}")


if __name__ == "__main__":
    main()
