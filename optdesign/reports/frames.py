"""pandas views of results and fronts (pandas is imported only here)."""

from __future__ import annotations


def result_frame(result):
    """One row per variable (value, unit, bounds, range) then per objective (value, unit)."""
    import pandas as pd

    problem = result.problem_object
    rows = []
    if problem is not None:
        for v in problem.variables:
            lo_hi = result.ranges.get(v.name, (None, None))
            rows.append(
                {
                    "kind": "variable",
                    "name": v.name,
                    "value": result.design.get(v.name),
                    "unit": v.unit,
                    "lower": v.lower,
                    "upper": v.upper,
                    "free": v.free,
                    "range_min": lo_hi[0],
                    "range_max": lo_hi[1],
                    "description": v.description,
                }
            )
    infos = problem.objectives if problem is not None else {}
    for name, value in result.objectives.items():
        info = infos.get(name)
        rows.append(
            {
                "kind": "objective",
                "name": name,
                "value": value,
                "unit": info.unit if info else "",
                "description": info.description if info else "",
            }
        )
    return pd.DataFrame(rows).set_index(["kind", "name"])


def front_frame(front, rejected: bool = False):
    """One row per point: objectives, free variables, status, verification, method."""
    import pandas as pd

    problem = front.problem_object
    free = [v.name for v in problem.free] if problem is not None else []
    rows = []
    for p in front.points + (front.rejected if rejected else []):
        row = {"id": p.id, "method": p.method}
        row.update({k: p.objectives.get(k) for k in front.objectives})
        row.update({k: p.design.get(k) for k in free})
        row.update(
            status=p.status, verified=p.verified, on_front=not p.rejected, active=";".join(p.active)
        )
        rows.append(row)
    return pd.DataFrame(rows)
