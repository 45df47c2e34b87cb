"""``optdesign pareto FILE --objectives A,B[,C]``: the Pareto front of a problem file.

Writes ``front.csv``, ``front.json``, ``front.png``, ``report.html`` and one JSONL store per method (the
points as they finish; ``--resume`` continues from them) to the output folder.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from optdesign.cli import (
    MAX_POINTS,
    MAX_SEED,
    MAX_STARTS,
    MAX_WORKERS,
    bounded_int,
    command,
    default_out,
)
from optdesign.errors import InputError

METHOD_NAMES = ("epsilon", "uniform", "weighted_sum", "nsga2")


@command("pareto")
def _pareto(sub):
    p = sub.add_parser("pareto", help="Pareto front of two or three objectives")
    p.add_argument("file", type=Path, help="problem file (TOML)")
    p.add_argument(
        "--objectives", required=True, help="two or three objectives, e.g. ripple,backlash"
    )
    p.add_argument(
        "--points",
        type=bounded_int(2, MAX_POINTS),
        default=50,
        help="points of the front (default 50)",
    )
    p.add_argument(
        "--method",
        default="epsilon",
        help="comma list of epsilon (default; evenly spread along the front), uniform "
        "(epsilon evenly spaced), weighted_sum, nsga2; or 'all'",
    )
    p.add_argument("--out", type=Path, default=None, help="output folder (default: new one)")
    p.add_argument("--resume", action="store_true", help="continue the run stored in --out")
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="start afresh in an --out folder that holds a previous run's stores",
    )
    p.add_argument(
        "--workers",
        type=bounded_int(1, MAX_WORKERS),
        default=os.cpu_count() or 1,
        help="local processes (default: the CPU count)",
    )
    p.add_argument("--scheduler", default=None, help="address of a Dask distributed scheduler")
    p.add_argument(
        "--starts",
        type=bounded_int(1, MAX_STARTS),
        default=None,
        help="anchor multistarts (default: file's)",
    )
    p.add_argument(
        "--seed", type=bounded_int(0, MAX_SEED), default=None, help="seed (default: file's)"
    )
    p.add_argument(
        "--pop", type=bounded_int(4, 100_000), default=100, help="NSGA-II population (default 100)"
    )
    p.add_argument(
        "--generations", type=bounded_int(1, 100_000), default=500, help="NSGA-II generations"
    )
    p.add_argument(
        "--deterministic",
        action="store_true",
        help="epsilon fronts: the two chains meet in the middle, so the front is the same "
        "for any --workers and a resumed run equals an uninterrupted one (slower with "
        "several workers); by default they meet where timing makes them meet",
    )
    p.add_argument("--no-plot", action="store_true", help="skip the PNG plot")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--no-report", action="store_true", help="skip the interactive report.html")
    p.set_defaults(func=run_pareto)


def run_pareto(args) -> int:
    from optdesign import storage
    from optdesign.problem import load_problem
    from optdesign.studies.pareto.methods import check_front_problem
    from optdesign.studies.solve import solver_options

    problem = load_problem(args.file)
    check_front_problem(problem)  # before the output folder is made
    solver_options(problem, "ipopt")
    objectives = [s.strip() for s in args.objectives.split(",") if s.strip()]
    methods = (
        list(METHOD_NAMES)
        if args.method == "all"
        else [s.strip() for s in args.method.split(",") if s.strip()]
    )
    for m in methods:
        if m not in METHOD_NAMES:
            raise InputError("--method", f"unknown method {m!r} (known: {', '.join(METHOD_NAMES)})")
    if "weighted_sum" in methods:
        from optdesign.studies.pareto.catalogue_front import has_catalogue

        if has_catalogue(problem):  # refused before the output folder is made
            raise InputError(
                "--method",
                "weighted_sum would leave the catalogue: with catalogue variables use "
                "epsilon or nsga2",
            )
    if args.points < 2:
        raise InputError("--points", "need at least 2 points")
    if args.resume and args.out is None:
        raise InputError("--resume", "give the --out folder of the run to resume")
    if args.resume and args.overwrite:
        raise InputError("--overwrite", "excludes --resume (start over, or continue)")
    out = args.out or default_out(f"pareto-{problem.name}")
    # One run per folder for the whole command (the runner re-enters the lock per store),
    # checked before any solving.
    with storage.lock_folder(out):
        storage.ensure_writable(out)
        for m in methods:
            if m == "nsga2":
                continue
            store = out / f"{m}.jsonl"
            if args.overwrite:
                storage.discard_store(store)
            elif not args.resume:
                storage.check_new_store(store)
        return _run_locked(args, problem, objectives, methods, out)


def _run_locked(args, problem, objectives, methods, out: Path) -> int:
    from optdesign.studies import pareto as pa
    from optdesign.studies.pareto.catalogue_front import has_catalogue

    seed = args.seed if args.seed is not None else problem.spec.solver.seed
    run = dict(
        out=out,
        workers=args.workers,
        scheduler=args.scheduler,
        resume=args.resume,
        progress=not args.no_progress,
    )
    fronts = []
    for m in methods:
        if m == "nsga2":
            method = pa.NSGA2(pop_size=args.pop, generations=args.generations, seed=seed)
        elif m == "weighted_sum":
            method = pa.WeightedSum(points=args.points, starts=args.starts, seed=seed)
        elif has_catalogue(problem):
            # the name: compute_front turns it into the catalogue front (every point a
            # catalogue design)
            method = m
        else:
            method = pa.EpsilonConstraint(
                points=args.points,
                spacing="arc" if m == "epsilon" else "uniform",
                name=m,
                starts=args.starts,
                seed=seed,
                deterministic=args.deterministic,
            )
        named = {"points": args.points, "starts": args.starts, "seed": seed}
        extra = named if isinstance(method, str) else {}
        fronts.append(pa.compute_front(problem, objectives, method=method, **extra, **run))
    if len(fronts) > 1:
        # Hypervolumes of different methods are comparable only with one reference point.
        pa.common_hypervolumes(fronts)
    pa.write_front_csv(fronts, problem, out / "front.csv")
    pa.write_front_json(
        fronts,
        out / "front.json",
        problem=problem.name,
        objectives=objectives,
        points=args.points,
        created=time.strftime("%Y-%m-%d %H:%M:%S"),
    )
    if not args.no_plot:
        from optdesign.plots import save_figure
        from optdesign.plots.front import plot_fronts
        from optdesign.storage import atomic_output

        fig = plot_fronts(problem, fronts)
        with atomic_output(out / "front.png") as tmp:
            save_figure(fig, tmp)
    wrote = [out / "front.csv", out / "front.json"] + ([] if args.no_plot else [out / "front.png"])
    if not args.no_report and any(f.points for f in fronts):
        from optdesign.reports.html import front_report
        from optdesign.storage import atomic_write_text

        atomic_write_text(out / "report.html", front_report(problem, fronts))
        wrote.append(out / "report.html")
    from optdesign.reports.front_text import front_summary

    print(front_summary(fronts))
    print("\nwrote " + ", ".join(str(w) for w in wrote))
    for front in fronts:
        if not front.points:
            print(f"optdesign: infeasible: {_no_point(problem, front)}", file=sys.stderr)
    return 0 if all(f.points for f in fronts) else 1


def _no_point(problem, front) -> str:
    """Why a front has no point: the requirements its least violating design violates."""
    import numpy as np

    from optdesign.studies.diagnosis import violated_text

    head = f"{front.method}: no feasible design"
    designs = [p.design for p in front.rejected if p.design]
    if not designs:
        return head
    X = np.array([[d[v.name] for v in problem.free] for d in designs])
    worst = np.asarray(problem.evaluate(X).violation, dtype=float)
    best = X[int(np.argmin(np.where(np.isfinite(worst), worst, np.inf)))]
    shown = violated_text(problem, best)
    return f"{head} among {len(designs)} designs; the least violating one: {shown or 'none'}"
