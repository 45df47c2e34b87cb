"""GP vs NLP on fork_min_backlash (issue 4): optimum, gap, certificate, times, ratio.

    /work/venv/bin/python benchmarks/bench_gp.py [--repeat 7] [--out benchmarks/results/bench_gp.json]

Times are measured in this run, on this machine, so their *ratios* are the figure:
- GP end to end: trace the models + build + cvxpy compile + Clarabel solve (fresh problem),
  and separately the dual-bound certificate (a post-processing step);
- GP solver only: Clarabel's own solve time;
- NLP: one Ipopt solve (exact Hertz) from the problem's start, NLP built once outside the
  timer; and the default 8-start multistart.
Best of ``--repeat`` for each.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from optdesign.formulations.nlp.solve import solve_nlp, solver_for
from optdesign.problem import load_problem
from optdesign.programs.gp import build_gp
from optdesign.solvers import make_solver

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--problem", default=str(ROOT / "problems" / "fork_min_backlash.toml"))
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "bench_gp.json")
    args = ap.parse_args()
    problem = load_problem(args.problem)

    gp_total, gp_solver, gp_cert, gp_all, gp_obj, cert = [], [], [], [], None, None
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        gp = build_gp(problem)
        t_trace = time.perf_counter() - t0
        r = make_solver(gp, "clarabel").solve()
        gp_all.append(time.perf_counter() - t0)
        timing = r.details.gp.timing
        gp_total.append(t_trace + timing.total_s)  # without the certificate
        gp_solver.append(timing.solver_s)
        gp_cert.append(timing.certificate_s)
        gp_obj, cert = r.objective, r.certificate

    backend = solver_for(problem)

    def solve(x0):
        return backend.solve(x0)

    nlp_one, nlp_obj = [], None
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        rn = solve(problem.start())
        nlp_one.append(time.perf_counter() - t0)
        nlp_obj = rn.objective if nlp_obj is None else min(nlp_obj, rn.objective)
    nlp_ms = []
    for _ in range(max(1, args.repeat // 3)):
        t0 = time.perf_counter()
        rm = solve_nlp(problem, starts=8)
        nlp_ms.append(time.perf_counter() - t0)
        nlp_obj = min(nlp_obj, rm.objective)

    fig = {
        "problem": problem.name,
        "gp_objective": gp_obj,
        "nlp_exact_objective": nlp_obj,
        "gap_gp_vs_nlp_rel": (gp_obj - nlp_obj) / nlp_obj,
        "gp_certificate_lower_bound": cert.lower_bound,
        "gp_certificate_gap_rel": cert.gap_rel,
        "gp_end_to_end_s": min(gp_total),
        "gp_solver_only_s": min(gp_solver),
        "gp_certificate_s": min(gp_cert),
        "gp_with_certificate_s": min(gp_all),
        "nlp_one_ipopt_solve_s": min(nlp_one),
        "nlp_multistart_8_s": min(nlp_ms),
        "ratio_gp_end_to_end_over_nlp_one": min(gp_total) / min(nlp_one),
        "ratio_gp_solver_over_nlp_one": min(gp_solver) / min(nlp_one),
        "ratio_gp_end_to_end_over_nlp_multistart": min(gp_total) / min(nlp_ms),
        "repeat": args.repeat,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(fig, indent=2))
    for k, v in fig.items():
        print(f"{k:45s} {v:.6g}" if isinstance(v, float | np.floating) else f"{k:45s} {v}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
