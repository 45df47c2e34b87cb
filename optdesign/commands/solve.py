"""``optdesign solve FILE``: the optimal design of a problem file, with its evidence."""

from __future__ import annotations

import contextlib
from pathlib import Path

from optdesign import validation as check
from optdesign.cli import (
    as_options,
    checked,
    command,
    flags,
    literal,
    output_folder,
    time_limit_option,
)

#: Options spelt otherwise than their API argument (optdesign.solve).
RENAMED = {"ranges": "--no-ranges", "problem": "file"}


@command("solve")
def _solve(sub):
    p = sub.add_parser("solve", help="find the optimal design of a problem file")
    p.add_argument("file", type=Path, help="problem file (TOML)")
    p.add_argument(
        "--out", type=checked(check.out_path), default=None, help="output folder (default: new one)"
    )
    p.add_argument("--json", action="store_true", help="print the result JSON to stdout")
    p.add_argument(
        "--formulation",
        type=checked(check.formulation),
        default="auto",
        help="auto (default), nlp, gp, catalogue, robust",
    )
    p.add_argument(
        "--solver",
        type=checked(check.solver),
        default=None,
        help="solver back-end (default: the formulation's, ipopt for an NLP, clarabel for a GP)",
    )
    p.add_argument("--objective", default=None, help="objective to minimise (default: file's)")
    p.add_argument(
        "--starts",
        type=checked(check.starts, literal),
        default=None,
        help=f"multistart count, 1..{check.MAX_STARTS} (default: file's)",
    )
    p.add_argument(
        "--seed",
        type=checked(check.seed, literal),
        default=None,
        help="multistart seed (default: file's)",
    )
    p.add_argument(
        "--workers",
        type=checked(check.workers, literal),
        default=1,
        help="local processes for the starts (of each node, on a catalogue problem)",
    )
    time_limit_option(
        p,
        "wall-clock limit of the multistart, s (default: none); the summary says when it "
        "stopped the solve",
    )
    p.add_argument("--no-plot", action="store_true", help="skip the PNG plot")
    p.add_argument("--no-report", action="store_true", help="skip the interactive report.html")
    p.add_argument(
        "--no-diagnosis",
        action="store_true",
        help="on an infeasible problem, skip the smallest relaxation of each requirement",
    )
    p.add_argument(
        "--no-ranges",
        action="store_true",
        help="skip the ranges of the variables over the optimal set (2 solves per variable)",
    )
    p.add_argument(
        "--contact-models",
        action="store_true",
        help="also the backlash of the optimum under each pin contact model (the spread)",
    )
    p.set_defaults(func=run_solve)


def run_solve(args) -> int:
    from optdesign import storage
    from optdesign.problem import load_problem

    problem = load_problem(args.file)
    with as_options(RENAMED):  # before the output folder is made
        check.objective_of(problem, args.objective)
        # what needs no solve, before the folder is made
        check.solve_plan(problem, args.formulation, args.objective)
    write_files = args.out is not None or not args.json
    if not write_files:
        return _solve_and_report(args, problem, None, None)
    from optdesign.plots.figure_process import FigureProcess

    # One writer per folder, and a folder we cannot write to is refused before solving.
    with output_folder(args.out, f"solve-{problem.name}") as out, storage.lock_folder(out):
        storage.ensure_writable(out)
        with FigureProcess() if not args.no_plot else contextlib.nullcontext() as figures:
            return _solve_and_report(args, problem, out, figures)


def _solve_and_report(args, problem, out: Path | None, figures) -> int:
    from optdesign.api import solve
    from optdesign.cli import stdout_to_stderr
    from optdesign.text import printable

    # With --json, stdout carries the JSON only: a solver's log goes to stderr.
    quiet = stdout_to_stderr() if args.json else contextlib.nullcontext()
    with quiet, as_options(RENAMED):
        result = solve(
            problem,
            formulation=args.formulation,
            objective=args.objective,
            starts=args.starts,
            seed=args.seed,
            workers=args.workers,
            solver=args.solver,
            ranges=not args.no_ranges,
            diagnose=not args.no_diagnosis,
            contact_models=args.contact_models,
            time_limit=args.time_limit,
        )
    from optdesign.reports.result_json import result_json

    text = result_json(result)
    wrote = []
    if out is not None:
        from optdesign.errors import OptDesignError
        from optdesign.reports.html import solve_report
        from optdesign.storage import atomic_write_text

        # result.json first: whatever fails after it, the result is kept.
        atomic_write_text(out / "result.json", text)
        wrote.append(out / "result.json")
        # the figure is drawn (in the figure process) while the page is made here
        drawn = figures is not None and bool(result.design)
        if drawn:
            from optdesign.plots.solution import result_figure

            figures.submit(
                "optdesign.plots.solution:draw_solution",
                out / "solution.png",
                lambda: result_figure(result),
            )
        page, failed_page = None, None
        if not args.no_report and result.design:
            try:
                page = solve_report(result)
            except OptDesignError as exc:  # a user's mechanism that cannot draw itself
                failed_page = f"report.html not written: {exc}"
        failed = figures.outcome() if drawn else None
        if drawn and failed is None:
            wrote.append(out / "solution.png")
        elif failed is not None:  # said in the summary, in result.json and on the page
            result.notes.append(failed)
            if page is not None:
                page = solve_report(result)
        if failed_page is not None:
            result.notes.append(failed_page)
        if failed is not None or failed_page is not None:
            text = result_json(result)
            atomic_write_text(out / "result.json", text)
        if page is not None:
            atomic_write_text(out / "report.html", page)
            wrote.append(out / "report.html")
    if args.json:
        print(text)
    else:
        print(flags(result.summary()))
        if wrote:
            print("\nwrote " + ", ".join(printable(w) for w in wrote))
    return 0 if result.success else 1
