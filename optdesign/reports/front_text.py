"""The plain-text summary of one or several fronts: metrics and a selection of points
(names from the user one line each, the whole text :func:`~optdesign.text.printable`)."""

from __future__ import annotations

from collections.abc import Sequence

from optdesign.display.limits import bound_limits, is_internal
from optdesign.display.shown import variable_shown
from optdesign.display.tables import format_table
from optdesign.reports.solve_text import objective_unit
from optdesign.text import printable


def front_summary(fronts: Sequence) -> str:
    """One line per method (points, failures, metrics, time) and the first front's points."""
    main = fronts[0]
    problem = main.problem_object
    hv_scale, hv_unit = hypervolume_unit(problem, main.objectives)
    rows = []
    for f in fronts:
        m = f.metrics
        rows.append(
            [
                f.method,
                str(len(f.points)),
                str(m.get("n_failed", 0)),
                f"{hv_scale * m.get('hypervolume', 0.0):.6g}",
                f"{hv_scale * m['hypervolume_common']:.6g}" if "hypervolume_common" in m else "-",
                f"{m.get('spacing', 0.0):.3g}",
                f"{m.get('spread', 0.0):.3g}",
                f"{f.wall_time_s:.2f}",
            ]
        )
    name = problem.name if problem is not None else ""
    objectives = ", ".join(printable(o) for o in main.objectives)
    lines = [f"problem   {printable(name)}: objectives {objectives}", ""]
    lines.append(
        format_table(
            [
                "method",
                "non-dominated",
                "failed",
                "HV own ref",
                "HV common ref",
                "spacing",
                "spread",
                "time s",
            ],
            rows,
        )
    )
    lines.append(
        f"(hypervolume in {printable(hv_unit)}; reference points: nadir + 10 % of the range of the "
        "front itself (own) or of all fronts together (common))"
    )
    lines += [f"note      {f.method}: {note}" for f in fronts for note in f.notes]
    pts = main.points
    if not pts:
        return printable("\n".join(lines), newlines=True)
    step = max(1, len(pts) // 12)
    shown = pts[::step] + ([pts[-1]] if pts[-1] is not pts[::step][-1] else [])
    heads = []
    for k in main.objectives:
        unit, _ = objective_unit(problem, k)
        heads.append(f"{k} ({unit})" if unit else k)
    free = list(problem.free) if problem is not None else []
    table = []
    for p in shown:
        cells = []
        for k in main.objectives:
            _, scale = objective_unit(problem, k)
            cells.append(f"{scale * p.objectives[k]:.6g}")
        cells.append(", ".join(_design_cell(problem, v, p.design[v.name]) for v in free))
        cells.append(p.status)
        cells.append(", ".join(point_limits(problem, main.objectives, p))[:70])
        table.append(cells)
    lines += ["", f"{printable(main.method)} front ({len(pts)} points, {_shown(step)}):"]
    lines.append(format_table([*heads, "design", "status", "what limits it"], table))
    return printable("\n".join(lines), newlines=True)


def _shown(step: int) -> str:
    """Which points the table shows: "all shown", "every 2nd shown", "every 11th..."."""
    if step <= 1:
        return "all shown"
    suffix = "th" if 10 <= step % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(step % 10, "th")
    return f"every {step}{suffix} shown"


def _design_cell(problem, var, value: float) -> str:
    v = variable_shown(problem, var, value)
    return f"{var.name}={v.value:.4g}" + (f" {v.unit}" if v.unit else "")


def point_limits(problem, objectives: Sequence[str], point) -> list[str]:
    """What limits a front point: its active requirements (not the front's own epsilon
    rows nor internal rows), then its variables at a bound."""
    own = {f"{o}_max" for o in objectives}
    names = sorted({a.split("[")[0] for a in point.active if not is_internal(a)} - own)
    if problem is not None:
        names += [f"{b.name} at {b.side} bound" for b in bound_limits(problem, point.design)]
    return names


def hypervolume_unit(problem, objectives: Sequence[str]) -> tuple[float, str]:
    """(scale, unit) of a hypervolume of ``objectives`` in the units users read them."""
    scale, units = 1.0, []
    for k in objectives:
        unit, s = objective_unit(problem, k)
        scale *= s
        units.append(unit or "1")
    return scale, " x ".join(units)
