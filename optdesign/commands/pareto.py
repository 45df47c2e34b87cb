"""``optdesign pareto FILE --objectives A,B[,C]``: the Pareto front of a problem file.

Writes ``front.csv``, ``front.json``, ``front.png``, ``report.html`` and one JSONL store per method (the
points as they finish; ``--resume`` continues from them) to the output folder.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

from optdesign import validation as check
from optdesign.cli import as_options, checked, command, literal, output_folder
from optdesign.errors import InputError

METHOD_NAMES = ("epsilon", "uniform", "weighted_sum", "nsga2")
#: Options spelt otherwise than their API argument (optdesign.pareto).
RENAMED = {"pop_size": "--pop"}


@command("pareto")
def _pareto(sub):
    p = sub.add_parser("pareto", help="Pareto front of two or three objectives")
    p.add_argument("file", type=Path, help="problem file (TOML)")
    p.add_argument(
        "--objectives", required=True, help="two or three objectives, e.g. ripple,backlash"
    )
    p.add_argument(
        "--points",
        type=checked(check.points, literal),
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
        type=checked(check.workers, literal),
        default=os.cpu_count() or 1,
        help="local processes (default: the CPU count)",
    )
    p.add_argument("--scheduler", default=None, help="address of a Dask distributed scheduler")
    p.add_argument(
        "--starts",
        type=checked(check.starts, literal),
        default=None,
        help="anchor multistarts (default: file's)",
    )
    p.add_argument(
        "--seed", type=checked(check.seed, literal), default=None, help="seed (default: file's)"
    )
    p.add_argument(
        "--pop",
        type=checked(check.pop_size, literal),
        default=100,
        help="NSGA-II population (default 100)",
    )
    p.add_argument(
        "--generations",
        type=checked(check.generations, literal),
        default=500,
        help="NSGA-II generations",
    )
    p.add_argument(
        "--time-limit",
        type=checked(check.seconds, literal),
        default=None,
        help="epsilon fronts: wall-clock seconds of the whole front; no point begins after "
        "it (the points left out are named; --resume computes them)",
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
    with as_options(RENAMED):  # the checks of optdesign.pareto, before any work
        objectives = check.front_objectives(problem, args.objectives)
        methods = list(METHOD_NAMES) if args.method == "all" else check.names("method", args.method)
        for m in methods:
            check.method("method", m)
            check.method_for(problem, m)  # refused before the output folder is made
        check.run_folder(args.out, args.resume, args.overwrite)
    if args.time_limit is not None:
        from optdesign.studies.pareto.catalogue_front import has_catalogue

        other = [m for m in methods if m not in ("epsilon", "uniform")]
        if other or has_catalogue(problem):
            what = f"the {other[0]} method" if other else "a catalogue front"
            raise InputError(
                "--time-limit",
                f"not applied by {what}: only a continuous epsilon sweep stops at a time limit",
            )
    # One run per folder for the whole command (the runner re-enters the lock per store),
    # checked before any solving.
    with output_folder(args.out, f"pareto-{problem.name}") as out, storage.lock_folder(out):
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
        overwrite=args.overwrite,
        progress=not args.no_progress,
    )
    if args.time_limit is not None:
        run["time_limit"] = args.time_limit
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
    wrote = [out / "front.csv", out / "front.json"]
    notes = []
    if not args.no_plot:
        from optdesign.plots import write_figure
        from optdesign.plots.front import plot_fronts

        failed = write_figure(lambda: plot_fronts(problem, fronts), out / "front.png")
        if failed is None:
            wrote.append(out / "front.png")
        else:  # the front's files are written; the report and the summary follow
            notes.append(failed)
    if not args.no_report and any(f.points for f in fronts):
        from optdesign.errors import OptDesignError
        from optdesign.reports.html import front_report
        from optdesign.storage import atomic_write_text

        try:
            page = front_report(problem, fronts)
        except OptDesignError as exc:  # a user's mechanism that cannot draw itself
            notes.append(f"report.html not written: {exc}")
        else:
            atomic_write_text(out / "report.html", page)
            wrote.append(out / "report.html")
    from optdesign.reports.front_text import front_summary
    from optdesign.text import printable

    print(front_summary(fronts))
    for note in notes:
        print(f"note: {printable(note)}")
    print("\nwrote " + ", ".join(printable(w) for w in wrote))
    for front in fronts:
        if not front.points and front.notes and not front.rejected:
            # the time limit left every point out: not an infeasible front
            line = printable(f"{front.method}: {front.notes[0]}")
            print(f"optdesign: {line}", file=sys.stderr)
        elif not front.points:
            line = printable(_no_point(problem, front))
            print(f"optdesign: infeasible: {line}", file=sys.stderr)
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
