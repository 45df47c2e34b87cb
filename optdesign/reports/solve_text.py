"""The plain-text summary of a solve: status, objective, design table, what limits the
optimum, and the ranges of a non-unique optimum."""

from __future__ import annotations

import numpy as np

from optdesign.reports.tables import format_table
from optdesign.solvers.result import Result


def objective_unit(problem, name: str) -> tuple[str, float]:
    """(unit shown, scale) of objective ``name``; a robust statistic such as
    ``CVaR_0.9(backlash)`` has the unit of what it is taken of."""
    if problem is None:
        return "", 1.0
    infos = problem.objectives
    info = infos.get(name) or next((i for k, i in infos.items() if f"({k})" in name), None)
    if info is None:
        return "", 1.0
    return info.shown_unit, info.display_scale


def result_summary(result: Result) -> str:
    """Readable summary: status, objective, design table, active and violated constraints."""
    problem = result.problem_object
    lines = [f"problem   {result.problem} ({result.mechanism})"]
    check = {True: "passed", False: "FAILED", None: "n/a"}[result.verified]
    lines.append(
        f"status    {result.status} (solver {result.solver}, {result.formulation}, "
        f"{result.message or result.termination.value}); independent check: {check}"
    )
    name = result.objective_name
    unit, scale = objective_unit(problem, name)
    lines.append(f"objective {name} = {scale * result.objective:.8g} {unit}".rstrip())
    lines.append(f"time      {result.wall_time_s:.3f} s")
    if result.multistart:
        ms = result.multistart
        lines.append(
            f"multistart {ms.n_at_best} of {ms.n_starts} starts reached the best point "
            f"(within {ms.tolerance:g} relative; {ms.n_converged} converged; seed {ms.seed})"
        )
    for note in result.notes:
        lines.append(f"note      {note}")
    if problem is not None:
        lines += ["", _design_table(problem, result)]
        if any(_moves(result, v.name) for v in problem.free):
            lines.append(
                "(the optimum is not unique: the variables marked above can move within their "
                "range, together, without changing the objective by more than 1e-6 relative)"
            )
    if result.objectives:
        shown = []
        for k, v in result.objectives.items():
            u, s = objective_unit(problem, k)
            shown.append(f"{k} = {s * v:.6g} {u}".rstrip())
        lines += ["", "objectives at this design: " + ", ".join(shown)]
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


def _moves(result: Result, name: str) -> bool:
    lo_hi = result.ranges.get(name)
    return bool(lo_hi) and lo_hi[1] - lo_hi[0] > 1e-4 * max(1.0, abs(lo_hi[1]))


def _design_table(problem, result: Result) -> str:
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
        lo_hi = result.ranges.get(var.name)
        moves = (
            f"optimal for any value in [{lo_hi[0]:.6g}, {lo_hi[1]:.6g}]"
            if _moves(result, var.name)
            else ""
        )
        rows.append([var.name, var.description, shown, var.unit, bounds, at, moves])
    return format_table(["variable", "what", "value", "unit", "bounds", "", "optimal set"], rows)
