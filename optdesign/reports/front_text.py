"""The plain-text summary of one or several fronts: metrics and a selection of points."""

from __future__ import annotations

from collections.abc import Sequence

from optdesign.reports.solve_text import objective_unit
from optdesign.reports.tables import format_table


def front_summary(fronts: Sequence) -> str:
    """One line per method (points, failures, metrics, time) and the first front's points."""
    main = fronts[0]
    problem = main.problem_object
    rows = []
    for f in fronts:
        m = f.metrics
        rows.append(
            [
                f.method,
                str(len(f.points)),
                str(m.get("n_failed", 0)),
                f"{m.get('hypervolume', 0.0):.6g}",
                f"{m['hypervolume_common']:.6g}" if "hypervolume_common" in m else "-",
                f"{m.get('spacing', 0.0):.3g}",
                f"{m.get('spread', 0.0):.3g}",
                f"{f.wall_time_s:.2f}",
            ]
        )
    name = problem.name if problem is not None else ""
    lines = [f"problem   {name}: objectives {', '.join(main.objectives)}", ""]
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
        "(hypervolume in internal units; reference points: nadir + 10 % of the range of the "
        "front itself (own) or of all fronts together (common))"
    )
    pts = main.points
    if not pts:
        return "\n".join(lines)
    step = max(1, len(pts) // 12)
    shown = pts[::step] + ([pts[-1]] if pts[-1] is not pts[::step][-1] else [])
    heads = []
    for k in main.objectives:
        unit, _ = objective_unit(problem, k)
        heads.append(f"{k} ({unit})" if unit else k)
    free = [v.name for v in problem.free] if problem is not None else []
    table = []
    for p in shown:
        cells = []
        for k in main.objectives:
            _, scale = objective_unit(problem, k)
            cells.append(f"{scale * p.objectives[k]:.6g}")
        cells.append(", ".join(f"{n}={p.design[n]:.4g}" for n in free))
        cells.append(p.status)
        cells.append(", ".join(sorted({a.split("[")[0] for a in p.active}))[:60])
        table.append(cells)
    lines += ["", f"{main.method} front ({len(pts)} points, every {step}th shown):"]
    lines.append(format_table([*heads, "design", "status", "active"], table))
    return "\n".join(lines)
