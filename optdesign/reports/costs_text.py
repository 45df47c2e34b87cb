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

A front's point shows the costs of its own solve (:meth:`~optdesign.studies.pareto.front.
FrontPoint.costs`, :mod:`optdesign.studies.pareto.costs`):
of its target objective with the others held at the point's epsilon bounds, or why they
cannot be known.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from optdesign.display.shown import objective_shown
from optdesign.solvers.result import Sensitivity

#: What the page says when no limit moves the optimum (nothing binds, or only by less
#: than :data:`optdesign.formulations.nlp.sensitivities.NEGLIGIBLE`).
NOTHING_BINDS = "none: no requirement or bound moves this optimum (by 1e-6 of it or more)"


def cost_text(s: Sensitivity) -> str:
    """One line of what the limit of ``s`` costs (:meth:`Sensitivity.text`: one wording
    for the summary, the pages and the API)."""
    return s.text()


def front_point_costs(
    problem: Any, objectives: Sequence[str], point: Any, costs: Any = None
) -> dict[str, Any]:
    """What the page shows of a front point's costs: ``sensitivities`` (lines, most
    costly first) and ``costs_note`` (what they are of, or why they cannot be known).
    ``costs``: the point's, when the caller has them (``Front.point_costs``)."""
    if costs is None:
        costs = point.costs(problem, objectives)  # the study's, through the record
    if costs.why:
        return {"sensitivities": [], "costs_note": f"not known for this point: {costs.why}"}
    held = [
        f"{name} <= {objective_shown(problem, name, value).text(6)}"
        for name, value in sorted(costs.held.items())
    ]
    note = f"costs in {costs.target}, from {costs.basis}" + (
        f", with {', '.join(held)} held (its epsilon bound{'s' if len(held) > 1 else ''})"
        if held
        else ""
    )
    lines = [cost_text(s) for s in costs.sensitivities]
    return {"sensitivities": lines or [NOTHING_BINDS], "costs_note": note}
