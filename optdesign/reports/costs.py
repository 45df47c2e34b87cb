"""What each limit costs, in words: the lines of the summary and of the pages.

A sensitivity's number is the change of the optimum when its limit is multiplied by
1.01 (the log-sensitivity, % per %). For a negative limit that moves it *down*: "+1 %"
alone read as a step up, and for a bound it said nothing of whether the box of designs
grows. Each line says which way the limit moves, where to, and for a variable's bound
whether that widens or narrows the bounds::

    hinge_moment 500 N*m: raising it by 1 % to 505 N*m -> backlash +0.235 %
    deflection.min -30 deg: lowering it by 1 % to -30.3 deg -> backlash +0.666 %
    variables.gx.lower -150 mm: lowering it by 1 % to -151.5 mm (widens the bounds)
        -> backlash -1.2 %

A limit at 0 (where 1 % is no move) or an objective at 0 (no % of it) gives the
derivative per unit instead, with the limit raised.

A front's point shows the costs of its own solve (:mod:`optdesign.studies.pareto.costs`):
of its target objective with the others held at the point's epsilon bounds, or why they
cannot be known.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from optdesign.reports.display_units import objective_shown
from optdesign.solvers.result import Sensitivity

#: What the page says when no limit moves the optimum (nothing binds, or only by less
#: than :data:`optdesign.studies.sensitivity.NEGLIGIBLE`).
NOTHING_BINDS = "none: no requirement or bound moves this optimum (by 1e-6 of it or more)"


def _number(value: float, unit: str) -> str:
    return f"{value:.6g} {unit}".rstrip()


def _bound_move(name: str, up: bool) -> str:
    """`` (widens the bounds)`` or `` (narrows the bounds)`` for a variable's bound
    moved up (``up``) or down; "" for a requirement (which way is looser depends on
    what it limits: a stroke's lower end moved down asks for more)."""
    if not name.startswith("variables."):
        return ""
    upper = name.endswith(".upper")
    return " (widens the bounds)" if up == upper else " (narrows the bounds)"


def cost_text(s: Sensitivity) -> str:
    """One line of what the limit of ``s`` costs, saying which way the limit moves."""
    what = s.name.removeprefix("requirements.")
    limit = _number(s.limit, s.unit)
    log = s.log_sensitivity
    if log is not None and s.limit != 0 and math.isfinite(s.limit):
        up = s.limit > 0  # 1.01 x the limit: up for a positive limit, down for a negative
        move = f"{'raising' if up else 'lowering'} it by 1 % to {_number(1.01 * s.limit, s.unit)}"
        return f"{what} {limit}: {move}{_bound_move(s.name, up)} -> {s.objective} {log:+.3g} %"
    d = s.d_objective_d_limit
    if not math.isfinite(d):  # a sweep keeps the log-sensitivity only
        return f"{what} {limit}: its cost per {s.unit or 'unit'} is not kept here"
    per = f"{s.objective_unit}/{s.unit}" if s.unit else s.objective_unit
    return (
        f"{what} {limit}: raising it{_bound_move(s.name, True)} -> "
        f"d{s.objective}/d{what} = {d:+.3g} {per}".rstrip()
    )


def front_point_costs(problem: Any, objectives: Sequence[str], point: Any) -> dict[str, Any]:
    """What the page shows of a front point's costs: ``sensitivities`` (lines, most
    costly first) and ``costs_note`` (what they are of, or why they cannot be known)."""
    from optdesign.studies.pareto.costs import point_costs

    costs = point_costs(problem, objectives, point)
    if costs.why:
        return {"sensitivities": [], "costs_note": f"not known for this point: {costs.why}"}
    held = [
        f"{name} <= {objective_shown(problem, name, value).text(6)}"
        for name, value in sorted(costs.held.items())
    ]
    note = f"costs in {costs.target}, from this point's own solve" + (
        f", with {', '.join(held)} held (its epsilon bound{'s' if len(held) > 1 else ''})"
        if held
        else ""
    )
    lines = [cost_text(s) for s in costs.sensitivities]
    return {"sensitivities": lines or [NOTHING_BINDS], "costs_note": note}
