"""``report.html``: an interactive, self-contained report of a solve or a front.

The page needs no network: plotly's JavaScript is inlined, and the data of every design
shown (its values with units, its linkage sketch, its ratio and backlash over the
stroke, what limits it) is evaluated by :mod:`optdesign.views` and embedded here as
JSON; the page only draws it (:mod:`optdesign.reports.html_page`). For a front,
hovering or clicking a point shows that design; for a solve, the optimum is shown
against the initial design.

Any text in the data may come from a user (a problem's name, a label, a constraint's
name): :func:`~optdesign.reports.html_page.to_json` embeds it so that no string can end or re-open the ``<script>``
element that carries it, and the page inserts every string as text (see
:mod:`optdesign.reports.html_page`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from optdesign.display.limits import binding_angles, bound_limits, limits_of
from optdesign.display.shown import (
    angle_unit,
    objective_shown,
    requirement_echo,
    variable_shown,
)
from optdesign.reports.costs_text import cost_text, front_point_costs
from optdesign.reports.facts import objective_facts, shown_facts
from optdesign.reports.html_page import render
from optdesign.reports.solve_text import feasibility_text, objective_value
from optdesign.reports.time_response_html import time_response_json
from optdesign.views.curves import StrokeCurves
from optdesign.views.design import DesignView, design_view
from optdesign.views.sketches import SketchFrame
from optdesign.views.time_response import time_response_view


def design_json(problem: Any, view: DesignView, label: str) -> dict[str, Any]:
    """Everything the page shows of one design (JSON-ready), from its evaluated ``view``
    (:func:`optdesign.views.design.design_view`)."""
    design = view.design
    active, violated = list(view.rows.active), list(view.rows.violated)
    rows = []
    for var in problem.variables:
        v = variable_shown(problem, var, design[var.name])
        row = {"name": var.name, "description": var.description, "value": v.value, "unit": v.unit}
        if var.free:
            row["lower"] = variable_shown(problem, var, var.lower).value
            row["upper"] = variable_shown(problem, var, var.upper).value
        rows.append(row)
    return {
        "label": label,
        "design": rows,
        "facts": [
            {"text": f.text(), **f.to_json(), "name": f.name}
            for f in shown_facts(problem, view.facts)
        ],
        "objectives": [
            {"name": f.name, "text": f.text(), **f.value.to_json()}
            for f in objective_facts(problem, dict(view.objectives))
        ],
        "limits": [
            lim.text() for lim in limits_of(problem, active) + bound_limits(problem, design)
        ],
        "violated": [lim.text() for lim in limits_of(problem, violated)],
        "active_angles": binding_angles(active),
        "sketch": _sketch(view.frames),
        "curves": _curves(problem, view.curves),
    }


def _sketch(frames: Sequence[SketchFrame]) -> list[dict[str, Any]]:
    """The sketch's frames as the page draws them ([]: the mechanism draws none)."""
    if any(frame.sketch is None for frame in frames):
        return []
    out = []
    for frame in frames:
        sk = frame.sketch
        out.append(
            {
                "phi": _plotted(math.degrees(frame.phi)),
                "links": [[[_plotted(x), _plotted(y)] for x, y in link] for link in sk.links],
                "pivots": [[_plotted(x), _plotted(y)] for x, y in sk.pivots],
                "slider": None if sk.slider is None else [_plotted(c) for c in sk.slider],
                "axis": None if sk.axis is None else [[_plotted(c) for c in p] for p in sk.axis],
            }
        )
    return out


def _curves(problem: Any, curves: StrokeCurves) -> dict[str, Any]:
    return {
        "phi": [_plotted(v) for v in np.degrees(problem.phi)],
        "ratio": [_plotted(v) for v in curves.ratio],
        "backlash": None if curves.backlash is None else [_plotted(v) for v in curves.backlash],
    }


def _plotted(v: float) -> float | None:
    """A number that is only drawn (a curve's point, a sketch's joint) at 7 significant
    digits, finer than any plot shows it: ``-29.999999999999996`` took 19 characters of
    the page for each of the ~200 numbers of every design (None: not finite)."""
    v = float(v)
    return float(f"{v:.7g}") if math.isfinite(v) else None


def _bands(problem: Any) -> dict[str, Any]:
    """Requirement limits drawn over the curves: the mean-ratio band, the backlash limit."""
    req = problem.spec.requirements
    out: dict[str, Any] = {}
    if req.mean_ratio is not None:
        out["mean_ratio"] = [req.mean_ratio.min, req.mean_ratio.max]
    if req.backlash_max is not None:
        out["backlash_max"] = math.degrees(req.backlash_max)
    return out


def _header(problem: Any) -> dict[str, Any]:
    return {
        "problem": problem.name,
        "mechanism": problem.mechanism.label(),
        "size": problem.mechanism.size_description,
        "requirements": [f"{k} = {v}" for k, v in requirement_echo(problem)],
        "angle_unit": angle_unit(problem),
        "bands": _bands(problem),
    }


def solve_report(result: Any) -> str:
    """The report of a solve: the optimum against the initial design."""
    problem = result.problem_object
    if problem is None or not result.design:
        raise ValueError("report: the result carries no problem or no design")
    start = problem.design_dict(problem.start())
    initial = design_json(problem, design_view(problem, start), "initial design")
    if initial["violated"]:
        initial["label"] = "initial design (violates the requirements)"
    label = "optimum" if result.success else "best point found"
    best = design_json(problem, design_view(problem, result.design), label)
    best["sensitivities"] = [cost_text(s) for s in result.sensitivities]
    best["item_steps"] = [s.text() for s in result.item_steps]
    time_response = time_response_view(problem, result.design)
    name = result.objective_name
    data = {
        **_header(problem),
        "kind": "solve",
        "status": result.status + _starts_text(result.multistart),
        "objective": f"{name} = {objective_shown(problem, name, objective_value(result)).text(8)}",
        "claims": _claims(result),
        "designs": [initial, best],
        "reference": 0,
        "selected": 1,
        "front": None,
    }
    if time_response is not None:  # a [loop]: the optimum's step response and cycle
        data["time_response"] = time_response_json(time_response)
    return render(data, title=f"optdesign: {problem.name}")


def _claims(result: Any) -> list[str]:
    """What the result claims, as the summary's ``feasible`` and ``global`` lines say it."""
    lines = [f"feasible: {feasibility_text(result)}"]
    if result.globality is not None and result.success:
        lines.append(f"global: {result.globality.text()}")
    return lines


def _starts_text(ms: Any) -> str:
    """`` (5 of 8 starts converged; 3 failed: 2 restoration failed, 1 iteration limit)``:
    the starts as the summary counts them; "" without a multistart."""
    if ms is None:
        return ""
    failed = ms.failure_text()
    return f" ({ms.n_converged} of {ms.n_starts} starts converged" + (
        f"; {failed})" if failed else ")"
    )


def front_report(problem: Any, fronts: Sequence[Any]) -> str:
    """The report of fronts: the objective space; hover or click a point for its design."""
    from optdesign.plots.front import pick_points

    main = fronts[0]
    objectives = list(main.objectives)
    designs: list[dict[str, Any]] = []
    traces = []
    for f in fronts:
        idx = []
        coords: list[list[float]] = [[] for _ in objectives]
        # what each limit costs at each point, from the point's own solve (or why unknown)
        costs = f.point_costs(problem)
        for k, p in enumerate(f.points):
            label = f"{f.method} point {k + 1}"
            view = design_json(problem, design_view(problem, p.design), label)
            view.update(front_point_costs(problem, f.objectives, p, costs[k]))
            designs.append(view)
            idx.append(len(designs) - 1)
            for j, o in enumerate(objectives):
                coords[j].append(objective_shown(problem, o, p.objectives[o]).value)
        traces.append({"method": f.method, "coords": coords, "index": idx})
    axes = []
    for o in objectives:
        unit = objective_shown(problem, o, 1.0).unit
        axes.append(f"{o} ({unit})" if unit else o)
    picks = pick_points(main.F) if len(main.points) else []
    data = {
        **_header(problem),
        "kind": "front",
        "status": f"{sum(len(f.points) for f in fronts)} points on {len(fronts)} front(s)",
        "objective": ", ".join(objectives),
        "designs": designs,
        "reference": None,
        "selected": picks[-1] if picks else (0 if designs else None),
        "front": {"axes": axes, "traces": traces},
    }
    return render(data, title=f"optdesign: {problem.name} front")
