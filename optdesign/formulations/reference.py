"""Compare an optimum with a reference design declared in the problem file.

``[reference]`` holds a label and a value (with unit) for every free variable; fixed
variables take the problem's values. The comparison evaluates both designs on the NumPy
path of the same models (ripple, backlash, the ratio band, ...) and says whether the
reference meets the problem's requirements.
"""

from __future__ import annotations

import numpy as np

from optdesign.display.tables import format_table
from optdesign.errors import ProblemError
from optdesign.formulations.verify import verify_design
from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.details import ReferenceComparison
from optdesign.solvers.result import Result
from optdesign.text import printable
from optdesign.tolerances import FEASIBILITY_TOL

#: Quantities of the side-by-side table: (objective name, label, unit, scale).
QUANTITIES = (
    ("ripple", "ratio ripple", "%", 100.0),
    ("backlash", "worst-case backlash", "deg", 1.0),
    ("backlash_rss", "RSS backlash", "deg", 1.0),
    ("nut_travel", "nut travel", "mm", 1.0),
    ("motor_torque", "peak motor torque", "N*m", 1e-3),
    ("size", "size", "mm", 1.0),
)


def reference_design(problem: DesignProblem) -> tuple[str, dict[str, float]] | None:
    """(label, full design) of the file's ``[reference]``, or None when there is none.

    Raises ProblemError naming ``reference.FIELD`` for a variable the problem does not
    declare, a fixed one, or a free one left out (units were parsed with the file).
    """
    ref = problem.spec.reference
    if ref is None:
        return None
    design: dict[str, float] = dict(problem.fixed_values)
    for name, value in ref.values().items():
        field = f"reference.{name}"
        if name not in problem.by_name:
            raise ProblemError(
                f"{field}: not a variable of this problem "
                f"(free: {', '.join(v.name for v in problem.free)})"
            )
        if not problem.by_name[name].free:
            raise ProblemError(f"{field}: {name} is fixed by the problem; give free variables only")
        design[name] = value
    missing = [v.name for v in problem.free if v.name not in design]
    if missing:
        raise ProblemError(f"reference.{missing[0]}: missing (every free variable needs a value)")
    return ref.label, design


def compare_reference(problem: DesignProblem, result: Result) -> ReferenceComparison | None:
    """Evaluate reference and optimum; None when the problem has no reference (or the
    result no design).

    Returns
    -------
    ReferenceComparison
        label, reference design, and per quantity (reference, optimum); also whether
        the reference meets the requirements (its largest relative violation).
    """
    ref = reference_design(problem)
    if ref is None or not result.design:
        return None
    label, design = ref
    x_ref = np.array([design[v.name] for v in problem.free])
    x_opt = np.array([result.design[v.name] for v in problem.free])
    ev_ref, ev_opt = problem.evaluate(x_ref), problem.evaluate(x_opt)
    rows = {}
    for name, _text, _unit, scale in QUANTITIES:
        if name in ev_ref.objectives:
            rows[name] = (
                scale * float(ev_ref.objectives[name]),
                scale * float(ev_opt.objectives[name]),
            )
    ratio_ref = np.atleast_1d(ev_ref.constraints["ratio_positive"].values)
    ratio_opt = np.atleast_1d(ev_opt.constraints["ratio_positive"].values)
    rows["ratio_min"] = (float(ratio_ref.min()), float(ratio_opt.min()))
    rows["ratio_max"] = (float(ratio_ref.max()), float(ratio_opt.max()))
    return ReferenceComparison(
        label=label,
        design={v.name: design[v.name] for v in problem.free},
        quantities=rows,
        reference_violation=float(ev_ref.violation),
        reference_violated=sorted({r.name.split("[")[0] for r in verify_design(problem, x_ref)[1]}),
        optimum_violation=float(ev_opt.violation),
        optimum_design={v.name: result.design[v.name] for v in problem.free},
    )


def comparison_text(problem: DesignProblem, comparison: ReferenceComparison) -> str:
    """Side-by-side table of a :func:`compare_reference` result."""
    label = printable(comparison.label)  # one line: it heads the table
    texts = {name: (text, unit) for name, text, unit, _ in QUANTITIES}
    texts["ratio_min"] = ("ratio min", "")
    texts["ratio_max"] = ("ratio max", "")
    opt_design = comparison.optimum_design
    table = []
    for v in problem.free:
        table.append(
            [
                f"{v.name} ({v.description})",
                v.unit,
                comparison.design[v.name],
                opt_design.get(v.name, float("nan")),
                "",
            ]
        )
    for name, (a, b) in comparison.quantities.items():
        text, unit = texts[name]
        change = f"{100 * (b - a) / abs(a):+.1f} %" if a else "-"
        table.append([text, unit, a, b, change])
    ok = comparison.reference_violation <= FEASIBILITY_TOL
    state = (
        "meets the requirements"
        if ok
        else "violates " + printable(", ".join(comparison.reference_violated))
    )
    head = f"{label} vs optimum, same models ({label} {state}):"
    return head + "\n" + format_table(["quantity", "unit", label, "optimum", "change"], table)


def attach_reference(problem: DesignProblem, result: Result) -> Result:
    """Add the reference comparison to ``result`` (``details.reference`` and a summary
    note)."""
    comparison = compare_reference(problem, result)
    if comparison is None:
        return result
    result.details.reference = comparison
    result.notes.append(comparison_text(problem, comparison))
    return result
