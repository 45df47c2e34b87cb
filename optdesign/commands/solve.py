"""``optdesign solve FILE``: the optimal design of a problem file, with its evidence."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from optdesign.cli import command, default_out
from optdesign.report import format_table
from optdesign.solvers.result import Result

#: formulation name -> function(problem, args) -> Result. "auto" picks among them.
FORMULATIONS: dict = {}


def formulation(name: str):
    """Register a formulation's solve function for ``--formulation NAME``."""

    def deco(fn):
        FORMULATIONS[name] = fn
        return fn

    return deco


@formulation("nlp")
def _solve_nlp(problem, args) -> Result:
    from optdesign.studies.solve import solve_nlp

    if any(v.discrete for v in problem.free):  # never solve catalogue variables as continuous
        from optdesign.errors import ProblemError

        raise ProblemError(
            "--formulation nlp: variables "
            + ", ".join(v.name for v in problem.free if v.discrete)
            + " take catalogue values; use --formulation catalogue (or auto)"
        )
    return solve_nlp(
        problem,
        starts=args.starts,
        seed=args.seed,
        workers=args.workers,
        plugin=args.solver,
        objective=args.objective,
    )


@formulation("robust")
def _solve_robust(problem, args) -> Result:
    from optdesign.studies.robust import solve_robust_cli

    return solve_robust_cli(problem, args)


def choose_formulation(problem, requested: str) -> str:
    """The formulation to use: the requested one, or for ``auto`` the first that applies
    (see :data:`AUTO_ORDER`)."""
    if requested != "auto":
        return requested
    for name, applies in AUTO_ORDER:
        if applies(problem):
            return name
    return "nlp"


#: (formulation, predicate) tried in order by ``--formulation auto``. A file with
#: ``[tolerances]`` asks for a robust design; tolerances are never ignored silently.
AUTO_ORDER: list = [("robust", lambda problem: problem.spec.tolerances is not None)]


@command("solve")
def _solve(sub):
    p = sub.add_parser("solve", help="find the optimal design of a problem file")
    p.add_argument("file", type=Path, help="problem file (TOML)")
    p.add_argument("--out", type=Path, default=None, help="output folder (default: new one)")
    p.add_argument("--json", action="store_true", help="print the result JSON to stdout")
    p.add_argument("--formulation", default="auto", help="auto (default), nlp, ...")
    p.add_argument("--solver", default="ipopt", help="CasADi nlpsol plugin (default ipopt)")
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
    from optdesign.errors import ProblemError
    from optdesign.problem import load_problem

    problem = load_problem(args.file)
    name = choose_formulation(problem, args.formulation)
    if name not in FORMULATIONS:
        raise ProblemError(
            f"--formulation: unknown formulation {name!r} (known: auto, {', '.join(FORMULATIONS)})"
        )
    result = FORMULATIONS[name](problem, args)
    # Ranges of the optimal set: for continuous NLP optima only (a GP optimum is of the
    # first-order model, a catalogue optimum of fixed items).
    continuous_nlp = result.formulation.startswith("nlp") and not any(
        v.discrete for v in problem.free
    )
    if result.success and continuous_nlp and not args.no_ranges and result.design:
        from optdesign.studies.solve import optimal_ranges

        try:
            result.extra["optimal_ranges"] = optimal_ranges(
                problem, result, objective=result.extra.get("objective_name")
            )
        except Exception as exc:  # a report, not the result: never lose the optimum
            result.extra["optimal_ranges_error"] = str(exc)
    write_files = args.out is not None or not args.json
    out = args.out or default_out(f"solve-{problem.name}")
    if write_files:
        from optdesign.storage import atomic_output, atomic_write_text

        atomic_write_text(out / "result.json", result.to_json())
        if not args.no_plot and result.design:
            from optdesign.plots.solution import plot_solution

            start = problem.design_dict(problem.start())
            with atomic_output(out / "solution.png") as tmp:
                plot_solution(problem, {"initial design": start, "optimum": result.design}, tmp)
    if args.json:
        print(result.to_json())
    else:
        print(summary(problem, result))
        if write_files:
            print(
                f"\nwrote {out / 'result.json'}"
                + ("" if args.no_plot else f" and {out / 'solution.png'}")
            )
    return 0 if result.success else 1


def summary(problem, result: Result) -> str:
    """Readable summary: status, objective, design table, active and violated constraints."""
    lines = [f"problem   {problem.name} ({problem.mechanism_kind})"]
    lines.append(
        f"status    {result.status} (solver {result.solver}, {result.formulation}, "
        f"{result.message or result.termination.value}); independent check: "
        f"{'passed' if result.verified else 'FAILED' if result.verified is False else 'n/a'}"
    )
    obj_name = result.extra.get("objective_name", problem.objective_names[0])
    units = {
        "backlash_rss": "deg",
        "backlash": "deg",
        "size": "mm",
        "nut_travel": "mm",
        "motor_torque": "N*mm",
        "lock_force": "N",
    }
    # a robust objective such as "CVaR_0.9(backlash)" has the unit of what it is taken of
    unit = next((u for name, u in units.items() if name in obj_name), "")
    lines.append(f"objective {obj_name} = {result.objective:.8g} {unit}".rstrip())
    lines.append(f"time      {result.wall_time_s:.3f} s")
    if result.multistart:
        ms = result.multistart
        lines.append(
            f"multistart {ms.n_at_best} of {ms.n_starts} starts reached the best point "
            f"(within {ms.tolerance:g} relative; {ms.n_converged} converged; seed {ms.seed})"
        )
    for k, v in result.extra.items():
        if k.startswith("note"):
            lines.append(f"note      {v}")
    rows = []
    for var in problem.variables:
        val = result.design.get(var.name, float("nan"))
        if var.free:
            at = ""
            tol = 1e-6 * max(1.0, abs(var.upper - var.lower))
            if abs(val - var.lower) < tol:
                at = "at lower bound"
            elif abs(val - var.upper) < tol:
                at = "at upper bound"
            bounds = f"[{var.lower:g}, {var.upper:g}]"
        else:
            bounds, at = "fixed", ""
        shown = f"{val:.6g}" if var.unit != "rad" else f"{val:.6g} ({np.degrees(val):.3f} deg)"
        rows.append([var.name, var.description, shown, var.unit, bounds, at])
    ranges = result.extra.get("optimal_ranges", {})
    for row in rows:
        lo_hi = ranges.get(row[0])
        if lo_hi and lo_hi[1] - lo_hi[0] > 1e-4 * max(1.0, abs(lo_hi[1])):
            row.append(f"optimal for any value in [{lo_hi[0]:.6g}, {lo_hi[1]:.6g}]")
        else:
            row.append("")
    lines += [
        "",
        format_table(["variable", "what", "value", "unit", "bounds", "", "optimal set"], rows),
    ]
    if any(r[-1] for r in rows):
        lines.append(
            "(the optimum is not unique: the variables marked above can move within their range,"
            " together, without changing the objective by more than 1e-6 relative)"
        )
    if result.objectives:
        lines += [
            "",
            "objectives at this design: "
            + ", ".join(f"{k} = {v:.6g}" for k, v in result.objectives.items()),
        ]
    envelope = [r for r in result.active if "_envelope[" in r.name]
    limits = [r for r in result.active if "_envelope[" not in r.name]
    if envelope:
        where = sorted({r.name.split("[", 1)[1].rstrip("]") for r in envelope})
        lines += ["", f"objective attained at: {', '.join(where)}"]
    if limits:
        lines += ["", "active constraints (what limits the optimum):"]
        lines += [f"  {r.describe()}" for r in limits[:25]]
        if len(limits) > 25:
            lines.append(f"  ... and {len(limits) - 25} more")
    if result.violated:
        lines += ["", "violated constraints:"]
        lines += [f"  {r.describe()}" for r in result.violated[:25]]
        if len(result.violated) > 25:
            lines.append(f"  ... and {len(result.violated) - 25} more")
    if not result.success:
        lines += [
            "",
            "no feasible design found"
            + (": the requirements above conflict within the bounds" if result.violated else ""),
        ]
    return "\n".join(lines)
