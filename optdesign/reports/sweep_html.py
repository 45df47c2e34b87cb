"""``sweep.html``: the design chart of a sweep in the interactive page of ``report.html``.

The chart is the objective against the (first) parameter, one trace per value of a
second one, the points where the binding set or a catalogue item changes marked; the
table below it is the sweep's (:func:`~optdesign.reports.sweep_text.sweep_rows`, in the
summary's units). Hovering or clicking a point of the chart, or a row of the table,
shows that point's design as ``report.html`` shows a front's: its values, sketch, curves
and what binds, evaluated on the point's own problem (the swept requirement at the
point's value). The page is :mod:`optdesign.reports.html_page`'s: every string of the
data (a problem's or a variable's name, a binding row's label) is embedded by
:func:`~optdesign.reports.html_page.to_json` and inserted as text.
"""

from __future__ import annotations

import math
from typing import Any

from optdesign.display.shown import objective_shown
from optdesign.reports.costs_text import cost_text
from optdesign.reports.html import _header, design_json
from optdesign.reports.html_page import render
from optdesign.reports.sweep_text import _cell, sweep_rows
from optdesign.solvers.result import Sensitivity
from optdesign.views.design import design_view

#: What the page says of a point's sensitivities when the sweep did not compute them
#: (an empty list would read "none": nothing binds).
NOT_COMPUTED = "not computed (od.sweep(..., sensitivities=True), optdesign sweep --sensitivities)"


def _shown_value(axis: Any, value: float) -> float:
    table = dict(zip(axis.values, axis.shown, strict=True))
    return float(table.get(value, value))


def _cost(problem: Any, objective: str, name: str, log: float) -> str:
    """The line of a point's log-sensitivity ``log`` to the limit ``name``, with the
    limit's value on the point's ``problem`` (which way 1 % moves it, where to)."""
    from optdesign.problem.parameters import limit_shown, limit_value

    try:
        limit = limit_shown(problem, name, limit_value(problem, name))
    except (KeyError, IndexError, ValueError, AttributeError):  # a name it lacks
        return f"{name}: 1.01 x the limit -> {objective} {log:+.3g} %"
    record = Sensitivity(name, objective, limit.value, limit.unit, math.nan, "", log)
    return cost_text(record)


def sweep_report(sweep: Any) -> str:
    """The page of ``sweep``: the design chart, the table, the design of each point."""
    from optdesign.problem.parameters import at_values, linked_values

    problem = sweep.problem
    paths = [a.path for a in sweep.axes]
    linked = {path: a.path for a in sweep.axes for path in a.linked}
    first = sweep.axes[0]
    designs: list[dict[str, Any]] = []
    of_point: dict[int, int] = {}
    for p in sweep.points:
        if not p.design:
            continue
        at = at_values(problem, linked_values(dict(zip(paths, p.values, strict=True)), linked))
        where = ", ".join(
            f"{a.label} = {_shown_value(a, v):.6g}"
            for a, v in zip(sweep.axes, p.values, strict=True)
        )
        label = f"point {p.index}: {where}" + ("" if p.success else f" ({p.status}, best found)")
        view = design_json(at, design_view(at, {**p.design, **at.fixed_values}), label)
        view["sensitivities"] = [
            _cost(at, sweep.objective, name, value)
            for name, value in sorted(p.sensitivities.items(), key=lambda kv: -abs(kv[1]))
        ] or [NOT_COMPUTED]
        of_point[p.index] = len(designs)
        designs.append(view)
    groups: dict[tuple[float, ...], list[Any]] = {}
    for p in sweep.points:
        groups.setdefault(tuple(p.values[1:]), []).append(p)

    def trace(name: str, points: list[Any], mode: str | None = None) -> dict[str, Any]:
        shown = [p for p in points if p.success and p.index in of_point]
        coords = [
            [_shown_value(first, p.values[0]) for p in shown],
            [objective_shown(problem, sweep.objective, p.objective).value for p in shown],
        ]
        out = {"method": name, "coords": coords, "index": [of_point[p.index] for p in shown]}
        if mode:
            out["mode"] = mode
        return out

    traces = []
    for key, points in groups.items():
        if len(sweep.axes) > 1:
            name = f"{sweep.axes[1].label} = {_shown_value(sweep.axes[1], key[0]):.6g}"
        else:
            name = "optimum"
        traces.append(trace(name, points))
    changes = [p for p in sweep.points if p.active_change]
    if changes:
        traces.append(trace("binding set or item changes", changes, "markers"))
    unit = objective_shown(problem, sweep.objective, 1.0).unit
    headers, rows = sweep_rows(sweep)
    solved = sum(p.success for p in sweep.points)
    data = {
        **_header(problem),
        "kind": "sweep",
        "status": f"{solved} of {len(sweep.points)} points solved",
        "objective": sweep.objective,
        "designs": designs,
        "reference": None,
        "selected": next(iter(of_point.values()), None),
        "front": {
            "axes": [first.label, f"{sweep.objective} ({unit})" if unit else sweep.objective],
            "traces": traces,
            "title": "design chart: hover or click a point (or a row of the table)",
        },
        "table": {
            "headers": headers,
            "rows": [[_cell(v) for v in row] for row in rows],
            "design": [of_point.get(p.index) for p in sweep.points],
        },
    }
    return render(data, f"optdesign sweep: {problem.name}")
