"""Pareto front of cs_min_backlash (ripple vs backlash): quality and cost, in one run.

- hypervolume of the default 50-point epsilon-constraint front, of the uniform-epsilon
  front and of NSGA-II (population 100, 500 generations, 3 seeds) as a fraction of the
  dense reference front's (benchmarks/data/cs_min_backlash_reference_front.csv, made by
  benchmarks/reference_front.py); reference point: the reference front's nadir + 10 % of
  its range in each objective;
- wall time of the epsilon front over NSGA-II's (solver builds included: the per-process
  solver cache is emptied before each timed run);
- wall time of the epsilon front with 1 and with 2 local worker processes: ``--repeats``
  interleaved pairs (1 worker, then 2), each from an empty solver cache; the speed-up is
  the ratio of the medians (a single front takes ~1-1.5 s and single timings vary by
  +-20 % on the 2-core machine), every timing is written too.

    /work/venv/bin/python benchmarks/bench_pareto.py [--points 50] [--seeds 0 1 2] [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

# One BLAS thread, as in the workers, and set before NumPy loads its BLAS (NSGA-II and the
# 1-worker run then use one core, like each of the 2 workers).
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from optdesign.formulations.nlp import solve as solve_study
from optdesign.problem import load_problem
from optdesign.reports.front_files import read_front_csv
from optdesign.studies.pareto import NSGA2, EpsilonConstraint, compute_front
from optdesign.studies.pareto.metrics import hypervolume, non_dominated, reference_point

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "benchmarks" / "data" / "cs_min_backlash_reference_front.csv"
OBJECTIVES = ["ripple", "backlash"]


def timed_front(problem, points, workers, tag, **kw):
    # include the formulation and solver builds in every timed run
    solve_study._NLPS.clear()
    solve_study._SOLVERS.clear()
    out = Path(tempfile.mkdtemp(prefix=f"bench-pareto-{tag}-"))
    t0 = time.perf_counter()
    method = EpsilonConstraint(points=points, **kw)
    front = compute_front(problem, OBJECTIVES, method=method, out=out, workers=workers)
    return front, time.perf_counter() - t0


def _solver_counts(front) -> dict:
    """How the epsilon front's records were solved (from its store): solver of each
    record, Ipopt fallbacks, and the anchors' multistart evidence."""
    from optdesign.runtime.runner import read_store

    _, recs = read_store(front.store)
    solvers: dict[str, int] = {}
    for r in recs.values():
        solvers[r.get("solver", "?")] = solvers.get(r.get("solver", "?"), 0) + 1
    return {
        "records_by_solver": solvers,
        "fallbacks": sum(1 for r in recs.values() if r.get("fallback")),
        "anchors": {k: r.get("multistart") for k, r in recs.items() if r.get("kind") == "anchor"},
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=50)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--pop", type=int, default=100)
    ap.add_argument("--generations", type=int, default=500)
    ap.add_argument("--repeats", type=int, default=5, help="1-vs-2-worker pairs")
    ap.add_argument(
        "--deterministic",
        action="store_true",
        help="time the 1-vs-2-worker pairs with chains that meet in the middle",
    )
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "data" / "bench_pareto.json")
    args = ap.parse_args()
    problem = load_problem(ROOT / "problems" / "cs_min_backlash.toml")
    R = read_front_csv(REFERENCE, OBJECTIVES, problem)  # internal units
    R = R[non_dominated(R)]
    ref = reference_point(R)
    hv_ref = hypervolume(R, ref)
    print(f"reference front: {len(R)} points, HV {hv_ref:.6g} (reference point {ref})")
    results: dict = {"reference": {"points": len(R), "hv": hv_ref, "ref_point": ref.tolist()}}

    eps, t_eps = timed_front(problem, args.points, 1, "eps")
    hv = hypervolume(eps.F, ref)
    results["epsilon"] = {
        "points": len(eps.points),
        "failed": eps.metrics["n_failed"],
        "hv_ratio": hv / hv_ref,
        "time_s": t_eps,
        "n_solves": eps.n_solves,
        "n_retried": eps.n_retried,
        "spacing": eps.metrics["spacing"],
        "solvers": _solver_counts(eps),
    }
    print(
        f"epsilon ({args.points} pts, 1 worker): HV {100 * hv / hv_ref:.3f} % of reference, "
        f"{t_eps:.2f} s, {eps.n_solves} solves, {eps.metrics['n_failed']} failed; "
        f"{results['epsilon']['solvers']}"
    )

    uni, t_uni = timed_front(problem, args.points, 1, "uniform", spacing="uniform", name="uniform")
    results["uniform"] = {"hv_ratio": hypervolume(uni.F, ref) / hv_ref, "time_s": t_uni}
    print(
        f"uniform epsilon ({args.points} pts): HV "
        f"{100 * results['uniform']['hv_ratio']:.3f} %, {t_uni:.2f} s"
    )

    ns = []
    for seed in args.seeds:
        t0 = time.perf_counter()
        method = NSGA2(args.pop, args.generations, seed=seed)
        f = compute_front(problem, OBJECTIVES, method=method)
        t = time.perf_counter() - t0
        ns.append({"seed": seed, "hv_ratio": hypervolume(f.F, ref) / hv_ref, "time_s": t})
        print(
            f"NSGA-II seed {seed}: HV {100 * ns[-1]['hv_ratio']:.3f} %, {t:.2f} s, "
            f"{len(f.points)} non-dominated"
        )
    results["nsga2"] = ns
    t_ns = float(np.mean([r["time_s"] for r in ns]))
    results["time_ratio_eps_over_nsga2"] = t_eps / t_ns
    print(f"time epsilon / NSGA-II (mean of seeds): {t_eps / t_ns:.3f}")

    t1s, t2s = [], []
    for _ in range(args.repeats):
        det = {"deterministic": args.deterministic}
        f1, t1 = timed_front(problem, args.points, 1, "w1", **det)
        f2, t2 = timed_front(problem, args.points, 2, "w2", **det)
        # The parallel front is the same computation: same points within the tolerance.
        assert len(f1.points) == len(f2.points), (len(f1.points), len(f2.points))
        t1s.append(t1)
        t2s.append(t2)
    t1, t2 = float(np.median(t1s)), float(np.median(t2s))
    results["workers"] = {
        "deterministic": args.deterministic,
        "t1_s": t1,
        "t2_s": t2,
        "speedup": t1 / t2,
        "t1_all_s": t1s,
        "t2_all_s": t2s,
        "hv_ratio_2_workers": hypervolume(f2.F, ref) / hv_ref,
    }
    print(
        f"workers ({args.repeats} interleaved pairs, medians): 1 -> {t1:.2f} s, "
        f"2 -> {t2:.2f} s, speed-up {t1 / t2:.2f}x "
        f"(1: {', '.join(f'{t:.2f}' for t in t1s)}; 2: {', '.join(f'{t:.2f}' for t in t2s)}); "
        f"HV with 2 workers {100 * results['workers']['hv_ratio_2_workers']:.3f} %"
    )
    results["load_average"] = os.getloadavg()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=1))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
