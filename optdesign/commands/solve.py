"""``optdesign solve FILE``: the optimal design of a problem file, with its evidence."""

from __future__ import annotations

from pathlib import Path

from optdesign.cli import command, default_out


@command("solve")
def _solve(sub):
    p = sub.add_parser("solve", help="find the optimal design of a problem file")
    p.add_argument("file", type=Path, help="problem file (TOML)")
    p.add_argument("--out", type=Path, default=None, help="output folder (default: new one)")
    p.add_argument("--json", action="store_true", help="print the result JSON to stdout")
    p.add_argument(
        "--formulation", default="auto", help="auto (default), nlp, gp, catalogue, robust"
    )
    p.add_argument("--solver", default="ipopt", help="solver back-end (default ipopt)")
    p.add_argument("--objective", default=None, help="objective to minimise (default: file's)")
    p.add_argument("--starts", type=int, default=None, help="multistart count (default: file's)")
    p.add_argument("--seed", type=int, default=None, help="multistart seed (default: file's)")
    p.add_argument("--workers", type=int, default=1, help="local processes for the starts")
    p.add_argument("--no-plot", action="store_true", help="skip the PNG plot")
    p.add_argument(
        "--no-ranges",
        action="store_true",
        help="skip the ranges of the variables over the optimal set (2 solves per variable)",
    )
    p.set_defaults(func=run_solve)


def run_solve(args) -> int:
    from optdesign.api import solve
    from optdesign.problem import load_problem

    problem = load_problem(args.file)
    result = solve(
        problem,
        formulation=args.formulation,
        objective=args.objective,
        starts=args.starts,
        seed=args.seed,
        workers=args.workers,
        solver=args.solver,
        ranges=not args.no_ranges,
    )
    write_files = args.out is not None or not args.json
    out = args.out or default_out(f"solve-{problem.name}")
    if write_files:
        out.mkdir(parents=True, exist_ok=True)
        (out / "result.json").write_text(result.to_json())
        if not args.no_plot and result.design:
            from optdesign.plots import save_figure

            save_figure(result.plot(), out / "solution.png")
    if args.json:
        print(result.to_json())
    else:
        print(result.summary())
        if write_files:
            print(
                f"\nwrote {out / 'result.json'}"
                + ("" if args.no_plot else f" and {out / 'solution.png'}")
            )
    return 0 if result.success else 1
