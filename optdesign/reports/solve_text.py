"""The plain-text summary of a solve: status, objective, the requirements as read, the
design table, what the design achieves, what limits the optimum, and for an infeasible
problem the smallest change of each conflicting requirement that makes it feasible.

Every number carries its unit, in the units the problem file wrote where that is
unambiguous (:mod:`optdesign.display.shown`); the formulation's internal rows are never
shown (:mod:`optdesign.display.limits`). Names from the user are shown one line each and
the whole text is :func:`~optdesign.text.printable`: no control character of a problem
file reaches the terminal.
"""

from __future__ import annotations

import math

from optdesign.display.limits import (
    at_bound,
    bound_limits,
    limits_of,
    objective_where,
    relaxation_limits,
    relaxation_text,
)
from optdesign.display.shown import objective_shown, requirement_echo, variable_shown
from optdesign.display.tables import format_table
from optdesign.reports.costs_text import cost_text
from optdesign.reports.facts import objective_facts, shown_facts
from optdesign.solvers.result import Result
from optdesign.text import printable
from optdesign.tolerances import FEASIBILITY_TOL
from optdesign.views.facts import design_facts


def objective_unit(problem, name: str) -> tuple[str, float]:
    """(unit shown, scale) of objective ``name``; a robust statistic such as
    ``CVaR_0.9(backlash)`` has the unit of what it is taken of."""
    s = objective_shown(problem, name, 1.0)
    return s.unit, s.value


def objective_value(result: Result) -> float:
    """The objective's physical value at the design (the independent check's), not the
    formulation's bound variable (which is not tight at an infeasible point)."""
    phys = result.objectives.get(result.objective_name)
    return float(phys) if phys is not None and math.isfinite(phys) else result.objective


def feasibility_text(result: Result) -> str:
    """What the independent check of the design found, in words: ``"verified by the
    NumPy model (every requirement within 1e-06 relative; every model within its range
    of validity)"``, ``"NOT verified: ..."`` - naming each model used outside its range
    (``"small-angle clearance: worst-case backlash 1.29e+07 deg > 5 deg at
    phi=+30.0deg"``), whose design is no answer whatever its requirements."""
    from optdesign.problem.validity import is_validity

    if result.verified is None:
        return "not checked (no design)"
    if result.verified:
        return (
            f"verified by the NumPy model (every requirement within {FEASIBILITY_TOL:g} "
            "relative; every model within its range of validity)"
        )
    outside = [r for r in result.violated if is_validity(r)]
    rows = "the NumPy model finds the requirements below violated"
    if not outside:
        return f"NOT verified: {rows}"

    def said(r) -> str:
        base, _, where = r.name.removeprefix("validity: ").partition("[")
        unit = f" {r.unit}" if r.unit else ""
        if math.isnan(r.value):
            value = "is not a number"
        elif r.upper is not None and r.value > r.upper:
            value = f"{r.value:.3g}{unit} > {r.upper:.3g}{unit}"
        elif r.lower is not None and r.value < r.lower:
            value = f"{r.value:.3g}{unit} < {r.lower:.3g}{unit}"
        else:
            value = f"{r.value:.3g}{unit}"
        return f"{base} {value}" + (f" at {where.rstrip(']')}" if where else "")

    shown = "; ".join(said(r) for r in outside[:3])
    if len(outside) > 3:
        shown += f"; and {len(outside) - 3} more"
    text = f"NOT verified: the design lies outside the range where its models hold ({shown})"
    if len(outside) < len(result.violated):
        text += f"; and {rows}"
    return printable(text)


def result_summary(result: Result) -> str:
    """Readable summary: status, objective, requirements, design, limits, diagnosis."""
    problem = result.problem_object
    label = problem.mechanism.label() if problem is not None else result.mechanism
    lines = [f"problem   {printable(result.problem)} ({printable(label)})"]
    lines.append(
        f"status    {result.status} (solver {result.solver}, {result.formulation}, "
        f"{result.message or result.termination.value})"
    )
    lines.append(f"feasible  {feasibility_text(result)}")
    if result.globality is not None and result.success:
        lines.append(f"global    {printable(result.globality.text())}")
    name = result.objective_name
    phys = result.objectives.get(name)
    if phys is not None and not math.isfinite(phys):
        # the model is undefined there (a linkage that does not assemble): the solver's
        # bound variable is no value of it
        value = "not defined at this design (the model gives NaN)"
    else:
        value = objective_shown(problem, name, objective_value(result)).text(8)
    where = ""
    if not result.success:
        met = "feasible; the solver did not converge" if result.verified else "requirements not met"
        where = f" at the best point found ({met})"
    lines.append(f"objective {printable(name)} = {value}{where}")
    lines.append(f"time      {result.wall_time_s:.3f} s")
    if result.multistart:
        ms = result.multistart
        stop = f"; stopped: {ms.stop}" if ms.stop else ""
        lines.append(
            f"starts    {ms.n_starts} run, {ms.n_converged} converged, {ms.n_at_best} at the "
            f"best value (within {ms.tolerance:g} relative; seed {ms.seed}{stop})"
        )
        if ms.polished:
            again = f"best {ms.polished} local optim{'um' if ms.polished == 1 else 'a'}"
            if not ms.n_converged:
                again = f"{ms.polished} least violated"
            lines.append(
                f"          the starts solved on {ms.search_points} of the {ms.grid_points} grid "
                f"angles; the {again} solved again on all of them"
            )
        if ms.failed:  # the starts that cost time and gave nothing: how many and why
            lines.append(f"          {ms.failure_text()}")
    for note in result.notes:
        lines.append(f"note      {note}")
    if problem is not None:
        echo = requirement_echo(problem)
        lines += ["", "requirements (as read from the file, in its units):"]
        lines += [f"  {k} = {v}" for k, v in echo]
        lines += ["", _design_table(problem, result)]
        if any(_moves(result, v.name) for v in problem.free):
            lines.append(
                "(the optimum is not unique: the variables marked above can move within their "
                "range, together, without changing the objective by more than 1e-6 relative)"
            )
    facts = shown_facts(problem, design_facts(problem, result.design)) + objective_facts(
        problem, result.objectives
    )
    if facts:
        lines += ["", "at this design:"]
        lines += [f"  {f.text()}" for f in facts]
    attained = objective_where(result.active)
    if attained:
        lines += ["", f"objective attained at: {printable(', '.join(attained))}"]
    limits = limits_of(problem, result.active) if problem is not None else []
    bounds = bound_limits(problem, result.design) if problem is not None and result.design else []
    if limits or bounds:
        head = "what limits the optimum" if result.success else "binding at the best point found"
        lines += ["", f"{head} (active requirements and bounds):"]
        lines += [f"  {lim.text()}" for lim in (limits + bounds)[:30]]
    if result.sensitivities:
        lines += ["", "what each limit costs (sensitivity of the optimum, most costly first):"]
        lines += [f"  {printable(cost_text(s))}" for s in result.sensitivities[:30]]
    if result.item_steps:
        lines += ["", "the neighbouring catalogue items (other items kept, the rest re-solved):"]
        lines += [f"  {printable(s.text())}" for s in result.item_steps]
    violated = limits_of(problem, result.violated) if problem is not None else []
    if violated:
        lines += ["", "violated requirements:"]
        lines += [f"  {lim.text()}" for lim in violated[:30]]
    elif result.violated and problem is None:
        lines += ["", "violated constraints:"]
        lines += [f"  {printable(r.describe())}" for r in result.violated[:25]]
    diagnosis = result.diagnosis
    proofs = diagnosis.impossible if diagnosis is not None else []
    if proofs:
        lines += ["", f"no design within the bounds can meet these together ({diagnosis.basis}):"]
        for proof in proofs:
            lines.append(f"  {printable(', '.join(proof.requirements))}: {printable(proof.reason)}")
            if proof.remedies:
                lines.append("  any one of these changes lifts this proof:")
                lines += [f"    - {printable(r)}" for r in proof.remedies]
    relax = diagnosis.relaxations if diagnosis is not None and problem is not None else []
    if relax:
        lines += ["", "smallest change of one requirement that makes the problem feasible:"]
        lines += [f"  {relaxation_text(lim)}" for lim in relaxation_limits(problem, relax)]
    together = diagnosis.together if relax else []
    if together:
        lines += ["", "no one of them suffices alone; the least change of them together:"]
        lines += [f"  {relaxation_text(lim)}" for lim in relaxation_limits(problem, together)]
    if relax and diagnosis.basis:
        lines.append(f"  (computed on {diagnosis.basis})")
    physical = diagnosis.physical if diagnosis is not None else []
    if physical and not together and not any(r.needed is not None for r in relax):
        lines += ["", physical_text(physical)]
    if diagnosis is not None and diagnosis.note:
        lines += ["", f"diagnosis: {diagnosis.note}"]
    if not result.success:
        if result.formulation == "fixed":
            end = "the fixed design does not meet the requirements above"
        elif result.verified:  # feasible, checked: only the optimality is missing
            end = f"a feasible design, but no optimum: the solver stopped ({result.status})"
        elif proofs:
            end = "no feasible design exists within the bounds (proved, no solve was run)"
        else:
            end = "no feasible design found"
            if result.status != "infeasible":  # not proven: the solver stopped
                end += f" (the solver stopped: {result.status})"
            elif result.violated:
                end += ": the requirements above conflict within the bounds"
        lines += ["", end]
        if proofs:
            lines.append("next: change one of the requirements or bounds named above")
        elif not relax and result.violated:
            lines.append(
                "next: relax one of the violated requirements, or widen a bound at its limit"
            )
        elif not relax:
            lines.append("next: more starts (starts=), or widen a bound at its limit")
    elif bounds:
        names = ", ".join(sorted({printable(b.name) for b in bounds}))
        lines += ["", f"next: widening the bounds of {names} may improve the objective"]
    # Our own lines break where we chose; anything else a user wrote is shown escaped.
    return printable("\n".join(lines), newlines=True)


def _moves(result: Result, name: str) -> bool:
    lo_hi = result.ranges.get(name)
    return bool(lo_hi) and lo_hi[1] - lo_hi[0] > 1e-4 * max(1.0, abs(lo_hi[1]))


def _design_table(problem, result: Result) -> str:
    rows = []
    for var in problem.variables:
        val = result.design.get(var.name, float("nan"))
        v = variable_shown(problem, var, val)
        unit = v.unit
        if var.free:
            side = at_bound(var, val)
            at = f"at {side} bound" if side else ""
            lo = variable_shown(problem, var, var.lower).value
            hi = variable_shown(problem, var, var.upper).value
            bounds = f"[{lo:.6g}, {hi:.6g}]"
        else:
            bounds, at = "fixed", ""
        lo_hi = result.ranges.get(var.name)
        moves = ""
        if _moves(result, var.name):
            a = variable_shown(problem, var, lo_hi[0]).value
            b = variable_shown(problem, var, lo_hi[1]).value
            moves = f"optimal for any value in [{a:.6g}, {b:.6g}]"
        rows.append([var.name, var.description, f"{v.value:.6g}", unit, bounds, at, moves])
    return format_table(["variable", "what", "value", "unit", "bounds", "", "optimal set"], rows)


def physical_text(names: list[str]) -> str:
    """Why the summary proposes no relaxation when the best point violates conditions of
    the physics (``Diagnosis.physical``) and relaxing the requirements found no design
    that meets them."""
    shown = ", ".join(printable(n) for n in names)
    return (
        f"the linkage itself fails at the best point found ({shown}: it passes a dead point "
        "inside the stroke or does not assemble); no requirement relaxes that: narrow the "
        "stroke (requirements.deflection) or widen the bounds of the variables"
    )
