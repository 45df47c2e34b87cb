"""pandas views of results and fronts, and the rows of ``front.csv``, in the units the
summary shows (pandas is imported only here).

One source of display units: a variable's value is shown as
:func:`~optdesign.display.shown.variable_shown` shows it (the unit the file wrote it in;
an angle in degrees unless the file wrote radians), an objective's as
:func:`~optdesign.display.shown.objective_shown` (its ``display_unit``: ripple in %, a
motor torque in N*m). Every such conversion is a factor, so a column's values are the
internal values times the scale of :func:`display_column`. A front's columns carry the
unit in their name (``"ripple [%]"``, ``"R [mm]"``; a dimensionless one only its name),
and ``frame.attrs["units"]`` maps each column to its unit; a result's frame has one row
per variable and objective with the unit in its ``unit`` column.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Column:
    """A column in display units: ``header`` (``"name [unit]"``), ``unit``, ``scale``
    (display value = internal value * scale)."""

    name: str
    header: str
    unit: str
    scale: float

    def value(self, internal: Any) -> Any:
        """``internal`` in the shown unit (None and NaN kept)."""
        return None if internal is None else float(internal) * self.scale

    def bound(self, internal: Any) -> Any:
        """A bound as the file wrote it: ``-30`` deg, not ``-29.999999999999996``."""
        from optdesign.display.shown import _tidy

        shown = self.value(internal)
        return shown if shown is None or not math.isfinite(shown) else _tidy(shown)


def header(name: str, unit: str) -> str:
    """``"ripple [%]"``; a dimensionless column is its name alone."""
    return f"{name} [{unit}]" if unit else name


def variable_column(problem: Any, var: Any) -> Column:
    """Design variable ``var`` as the summary shows it."""
    from optdesign.display.shown import variable_shown

    s = variable_shown(problem, var, 1.0)
    return Column(var.name, header(var.name, s.unit), s.unit, float(s.value))


def objective_column(problem: Any, name: str) -> Column:
    """Objective ``name`` as the summary shows it."""
    from optdesign.display.shown import objective_shown

    s = objective_shown(problem, name, 1.0)
    return Column(name, header(name, s.unit), s.unit, float(s.value))


def result_frame(result):
    """One row per variable (value, unit, bounds, range) then per objective (value,
    unit), every number in the unit the summary shows (the row's ``unit``)."""
    import pandas as pd

    problem = result.problem_object
    rows = []
    if problem is not None:
        for v in problem.variables:
            col = variable_column(problem, v)
            lo_hi = result.ranges.get(v.name, (None, None))
            rows.append(
                {
                    "kind": "variable",
                    "name": v.name,
                    "value": col.value(result.design.get(v.name)),
                    "unit": col.unit,
                    # bounds as the file wrote them (-30 deg, not -29.999999999999996)
                    "lower": col.bound(v.lower),
                    "upper": col.bound(v.upper),
                    "free": v.free,
                    "range_min": col.value(lo_hi[0]),
                    "range_max": col.value(lo_hi[1]),
                    "description": v.description,
                }
            )
    infos = problem.objectives if problem is not None else {}
    for name, value in result.objectives.items():
        info = infos.get(name)
        col = objective_column(problem, name)
        rows.append(
            {
                "kind": "objective",
                "name": name,
                "value": col.value(value),
                "unit": col.unit,
                "description": info.description if info else "",
            }
        )
    return pd.DataFrame(rows).set_index(["kind", "name"])


def front_columns(front: Any, problem: Any) -> list[Column]:
    """The number columns of a front's table: its objectives, then the free variables."""
    cols = [objective_column(problem, k) for k in front.objectives]
    if problem is not None:
        cols += [variable_column(problem, v) for v in problem.free]
    return cols


def front_table(front: Any, problem: Any, rejected: bool = False) -> list[dict[str, Any]]:
    """One dict per point (``front.csv``'s rows, the frame's): method, id, objectives
    and free variables in display units under ``"name [unit]"``, status, verified,
    on_front, active."""
    cols = front_columns(front, problem)
    n_obj = len(front.objectives)
    rows = []
    for p in front.points + (front.rejected if rejected else []):
        row: dict[str, Any] = {"method": p.method, "id": p.id}
        for k, c in enumerate(cols):
            source = p.objectives if k < n_obj else p.design
            row[c.header] = c.value(source.get(c.name, float("nan")))
        row["status"] = p.status
        row["verified"] = p.verified
        row["on_front"] = not p.rejected
        row["active"] = ";".join(p.active)
        rows.append(row)
    return rows


def front_frame(front, rejected: bool = False):
    """One row per point: method, id, objectives and free variables in the summary's
    units (``"ripple [%]"``), status, verification; ``frame.attrs["units"]``: column ->
    unit."""
    import pandas as pd

    problem = front.problem_object
    cols = front_columns(front, problem)
    names = ["method", "id", *(c.header for c in cols), "status", "verified", "on_front"]
    frame = pd.DataFrame(front_table(front, problem, rejected), columns=[*names, "active"])
    frame.attrs["units"] = {c.header: c.unit for c in cols}
    return frame
