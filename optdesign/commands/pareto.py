"""``optdesign pareto FILE --objectives A,B[,C]``: the Pareto front of a problem file.

Writes ``front.csv``, ``front.json``, ``front.png``, ``report.html`` and one JSONL store per method (the
points as they finish; ``--resume`` continues from them) to the output folder.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from optdesign import validation as check
from optdesign.cli import (
    as_options,
    checked,
    command,
    flags,
    literal,
    output_folder,
    progress_bar,
    time_limit_option,
)

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
        default=check.DEFAULT_FRONT_POINTS,
        help=f"points of the front (default {check.DEFAULT_FRONT_POINTS})",
    )
    p.add_argument(
        "--method",
        default="epsilon",
        help="comma list of epsilon (default; evenly spread along the front), uniform "
        "(epsilon evenly spaced), weighted_sum, nsga2; or 'all'",
    )
    p.add_argument(
        "--out", type=checked(check.out_path), default=None, help="output folder (default: new one)"
    )
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
    p.add_argument(
        "--scheduler",
        type=checked(check.scheduler),
        default=None,
        help="address of a Dask distributed scheduler (tcp://HOST:PORT)",
    )
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
    time_limit_option(
        p,
        "epsilon fronts: wall-clock seconds of the whole front; no point begins after it "
        "(the points left out are named; --resume computes them)",
    )
    p.add_argument(
        "--deterministic",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="epsilon fronts: the two chains meet in the middle, so the front is the same "
        "for any --workers and a resumed run equals an uninterrupted one (the default); "
        "--no-deterministic lets them meet where timing makes them meet (faster with "
        "several workers, the front may depend on them)",
    )
    p.add_argument("--no-plot", action="store_true", help="skip the PNG plot")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--no-report", action="store_true", help="skip the interactive report.html")
    p.set_defaults(func=run_pareto)


def run_pareto(args) -> int:
    from optdesign import storage
    from optdesign.problem import load_problem

    problem = load_problem(args.file)
    with as_options(RENAMED):  # the checks of optdesign.pareto, before any work
        check.front_problem(problem)  # before the output folder is made
        objectives = check.front_objectives(problem, args.objectives)
        methods = list(METHOD_NAMES) if args.method == "all" else check.names("method", args.method)
        for m in methods:
            check.method("method", m)
            check.method_for(problem, m, objectives=objectives)  # before the folder is made
        check.front_time_limit(problem, methods, args.time_limit)
        check.run_folder(args.out, args.resume, args.overwrite)
    # One run per folder for the whole command (the runner re-enters the lock per store),
    # checked before any solving.
    with output_folder(args.out, f"pareto-{problem.name}") as out, storage.lock_folder(out):
        storage.ensure_writable(out)
        for m in methods:
            name = check.front_store(problem, m)
            if name is None:
                continue
            store = out / name
            if args.overwrite:
                storage.discard_store(store)
            elif not args.resume:
                storage.check_new_store(store)
        if args.no_plot:
            return _run_locked(args, problem, objectives, methods, out, None)
        from optdesign.plots.figure_process import FigureProcess
        from optdesign.reports.front_files import FRONT_FIGURE
        from optdesign.runtime.processes import when_a_worker_idles

        # Forked before the fronts (one thread yet); it draws front.png while this
        # process makes the page. It imports matplotlib at once where the fronts leave a
        # core free, else when one of their workers first idles (a chain waiting for the
        # other's anchor): importing it beside two busy workers only slows them.
        free_core = args.scheduler is not None or args.workers < (os.cpu_count() or 1)
        figures = FigureProcess(warm=free_core, draws=(FRONT_FIGURE,))
        with figures, when_a_worker_idles(figures.warm_up):
            return _run_locked(args, problem, objectives, methods, out, figures)


def _method_options(args, method: str, seed: int) -> dict:
    """The options of ``optdesign.pareto`` for ``method`` from the command's arguments."""
    if method == "nsga2":
        return {"pop_size": args.pop, "generations": args.generations, "seed": seed}
    if method == "weighted_sum":
        return {"starts": args.starts, "seed": seed}
    # an epsilon front; on a catalogue problem the catalogue front (every point a
    # catalogue design), which takes the starts and the seed
    return {"starts": args.starts, "seed": seed, "deterministic": args.deterministic}


def _run_locked(args, problem, objectives, methods, out: Path, figures) -> int:
    from optdesign.api import front_outputs, pareto

    seed = args.seed if args.seed is not None else problem.spec.solver.seed
    run = dict(
        out=out,
        workers=args.workers,
        scheduler=args.scheduler,
        resume=args.resume,
        overwrite=args.overwrite,
        progress=progress_bar(args),
    )
    if args.time_limit is not None:
        run["time_limit"] = args.time_limit
    fronts = []
    for m in methods:
        with as_options(RENAMED):
            # the files of all the methods together are written below, once
            front = pareto(
                problem,
                objectives,
                args.points,
                m,
                **run,
                **_method_options(args, m, seed),
                files=False,
            )
        fronts.append(front)
    wrote, notes = front_outputs(
        fronts,
        problem,
        out,
        objectives,
        args.points,
        plot=not args.no_plot,
        report=not args.no_report,
        figures=figures,
    )
    from optdesign.reports.front_text import front_summary
    from optdesign.text import printable

    print(flags(front_summary(fronts)))
    for note in notes:
        print(f"note: {printable(flags(note))}")
    print("\nwrote " + ", ".join(printable(w) for w in wrote))
    for front in fronts:
        if not front.points and front.notes and not front.rejected:
            # the time limit left every point out: not an infeasible front
            line = printable(flags(f"{front.method}: {front.notes[0]}"))
            print(f"optdesign: {line}", file=sys.stderr)
        elif not front.points:
            line = printable(flags(front.no_point_text(problem)))
            print(f"optdesign: infeasible: {line}", file=sys.stderr)
    return 0 if all(f.points for f in fronts) else 1
