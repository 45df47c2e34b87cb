"""A sweep read by a user: its table (``sweep.csv``, :meth:`Sweep.to_frame`) and its
plain-text summary, every number in the units the summary of a solve shows."""

from __future__ import annotations

import csv
import io
from typing import Any

from optdesign.display.frames import objective_column, variable_column
from optdesign.text import csv_cell, printable


def sweep_columns(sweep: Any) -> list[tuple[str, str, Any]]:
    """(header, unit, value-of-point) of every column of the table."""
    problem = sweep.problem
    cols: list[tuple[str, str, Any]] = [("point", "", lambda p: p.index)]
    for k, axis in enumerate(sweep.axes):
        cols.append((axis.label, axis.unit, _axis_value(sweep, k)))
    obj = objective_column(problem, sweep.objective)
    cols.append((obj.header, obj.unit, lambda p: obj.value(p.objective)))
    for var in problem.free:
        c = variable_column(problem, var)
        cols.append((c.header, c.unit, lambda p, c=c: c.value(p.design.get(c.name))))
    cols += [
        ("status", "", lambda p: p.status),
        ("binding", "", lambda p: ";".join(p.active)),
        ("active_change", "", lambda p: p.active_change),
        ("global_search", "", lambda p: p.checked),
        ("found_by", "", lambda p: p.found_by),
        ("jump", "", lambda p: p.jump),
        ("what_fails", "", lambda p: "; ".join(p.violated)),
    ]
    return cols


def _axis_value(sweep: Any, k: int):
    axis = sweep.axes[k]
    table = dict(zip(axis.values, axis.shown, strict=True))
    return lambda p: table.get(p.values[k], p.values[k])


def sweep_rows(sweep: Any) -> tuple[list[str], list[list[Any]]]:
    """Headers and rows of the table, points in grid order (first parameter fastest)."""
    cols = sweep_columns(sweep)
    return [c[0] for c in cols], [[c[2](p) for c in cols] for p in sweep.points]


def sweep_frame(sweep: Any):
    """The table as a pandas DataFrame; ``frame.attrs["units"]``: column -> unit."""
    import pandas as pd

    headers, rows = sweep_rows(sweep)
    frame = pd.DataFrame(rows, columns=headers)
    frame.attrs["units"] = {c[0]: c[1] for c in sweep_columns(sweep) if c[1]}
    return frame


def sweep_csv(sweep: Any) -> str:
    """``sweep.csv``: the table, units in the headers (``"hinge_moment [N*m]"``); a text
    cell a spreadsheet would read as a formula (a user's name starting with ``=``) gets
    a leading ``'``, as in ``front.csv``."""
    headers, rows = sweep_rows(sweep)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([csv_cell(printable(h)) for h in headers])
    for row in rows:
        w.writerow([csv_cell(printable(v)) if isinstance(v, str) else _num(v) for v in row])
    return buf.getvalue()


def _num(v: Any) -> Any:
    return f"{v:.10g}" if isinstance(v, float) else v


def sweep_summary(sweep: Any) -> str:
    """The summary: what was swept, the table, the points where the binding set changes,
    the jumps (points a warm start from the point before would have left on a worse
    branch), and the infeasible points with what fails."""
    problem = sweep.problem
    n = len(sweep.points)
    solved = [p for p in sweep.points if p.success]
    what = ", ".join(
        f"{a.label} {a.shown[0]:.6g}..{a.shown[-1]:.6g} ({len(a.values)} points"
        + (f"; {', '.join(a.linked)} with it)" if a.linked else ")")
        for a in sweep.axes
    )
    how = (
        "each point's own global search, then warm starts from its neighbours until none improves"
        if sweep.continuation
        else "each solved by its formulation"
    )
    lines = [
        f"problem   {printable(problem.name)}",
        f"sweep     {printable(what)}; minimise {printable(sweep.objective)}",
        f"points    {len(solved)} of {n} solved; {how}",
        f"time      {sweep.wall_time_s:.3f} s",
    ]
    lines += [f"note      {printable(n)}" for n in sweep.notes]
    headers, rows = sweep_rows(sweep)
    hidden = ("what_fails", "active_change", "jump", "found_by", "global_search")
    keep = [i for i, h in enumerate(headers) if h not in hidden]
    from optdesign.display.tables import format_table

    # an infeasible point's numbers are of the best design found, not an optimum: "-"
    first = 1 + len(sweep.axes)  # the point and the parameters are shown for every point
    cells = [
        [_cell(r[i]) if p.success or i < first or headers[i] in _ALWAYS else "-" for i in keep]
        for r, p in zip(rows, sweep.points, strict=True)
    ]
    lines += ["", format_table([headers[i] for i in keep], cells)]
    changes = [p for p in sweep.points if p.active_change]
    if changes:
        lines += ["", "binding set changes at:"]
        lines += [f"  point {p.index}: {printable(';'.join(p.active))}" for p in changes]
    jumps = [p for p in sweep.points if p.jump]
    if jumps:
        lines += [
            "",
            "jumps (a warm start from the point before would have stayed on a worse branch):",
        ]
        lines += [f"  point {p.index}: found {printable(p.found_by)}" for p in jumps]
    bad = [p for p in sweep.points if not p.success]
    if bad:
        lines += ["", "infeasible points (what fails at the best design found):"]
        for p in bad:
            lines.append(f"  point {p.index} ({p.status}): {printable('; '.join(p.violated))}")
    if sweep.store is not None:
        lines += ["", f"store     {printable(sweep.store)}"]
    return "\n".join(lines)


#: Columns shown for an infeasible point too.
_ALWAYS = ("status",)


def _cell(v: Any) -> str:
    if isinstance(v, bool):
        return "yes" if v else ""
    if isinstance(v, float):
        return f"{v:.6g}"
    return printable(v)


def sweep_document(sweep) -> dict:
    """``sweep.json``: the axes, the table's columns with their units, the rows."""
    from optdesign.solvers.result import clean_json

    headers, rows = sweep_rows(sweep)
    return clean_json(
        {
            "schema": "optdesign.sweep/1",
            "problem": sweep.problem.name,
            "objective": sweep.objective,
            "continuation": sweep.continuation,
            "axes": [
                {
                    "path": a.path,
                    "unit": a.unit,
                    "values": list(a.shown),
                    **({"linked": list(a.linked)} if a.linked else {}),
                }
                for a in sweep.axes
            ],
            "units": {c[0]: c[1] for c in sweep_columns(sweep) if c[1]},
            "points": [dict(zip(headers, r, strict=True)) for r in rows],
            "sensitivities": [p.sensitivities for p in sweep.points]
            if any(p.sensitivities for p in sweep.points)
            else None,
            "wall_time": {"value": sweep.wall_time_s, "unit": "s"},
            "notes": sweep.notes,
        }
    )
