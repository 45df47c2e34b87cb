"""A design's constraint rows as :class:`~optdesign.solvers.result.ConstraintReport`
records, on the NumPy path of the models: which rows bind and which are violated, with
their values.

Below the studies so that the pages and plots that show a design's binding and violated
rows (:mod:`optdesign.reports.html`, :mod:`optdesign.plots.solution`) and the studies that
check a design (:mod:`optdesign.formulations.verify`, :mod:`optdesign.formulations.diagnosis`) read
one rule.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.evaluation import relative_violation
from optdesign.solvers.result import ConstraintReport


def violation_amount(value: float, lower: float | None, upper: float | None) -> float:
    """How far ``value`` lies outside ``[lower, upper]`` (either may be None: no bound),
    in the row's own unit; 0 or less inside."""
    return max(
        (lower - value) if lower is not None else 0.0,
        (value - upper) if upper is not None else 0.0,
    )


def constraint_rows(
    problem: DesignProblem, design: Any, rel: float = 1e-5, ev: Any = None
) -> tuple[list[ConstraintReport], list[ConstraintReport]]:
    """(active, violated) constraint reports of any design on the NumPy path: a row is
    active within ``rel`` of its bound (relative to max(1, |bound|)), violated beyond.

    Parameters
    ----------
    problem
        The problem whose rows are evaluated.
    design
        A full design dict (name -> value) or the free-variable vector.
    rel
        The relative distance to a bound within which a row binds.
    ev
        The design's ``problem.evaluate`` when the caller has it already.

    Returns
    -------
    (active, violated)
        The binding rows (amount 0) and the violated ones (amount: how far outside).
    """
    if ev is None:
        if isinstance(design, dict):
            design = [design[v.name] for v in problem.free]
        ev = problem.evaluate(np.asarray(design, dtype=float))
    active, violated = [], []
    for name, block in ev.constraints.items():
        values = np.atleast_1d(np.asarray(block.values, dtype=float))
        lo, hi = block.lower, block.upper
        labels = problem.phi_labels if len(values) == len(problem.phi) else [""] * len(values)
        viol = relative_violation(values, lo, hi)
        for k, v in enumerate(values):
            label = f"{name}[{labels[k]}]" if labels[k] else name
            gap = min(
                abs(v - lo) / max(1.0, abs(lo)) if lo is not None else math.inf,
                abs(v - hi) / max(1.0, abs(hi)) if hi is not None else math.inf,
            )
            if viol[k] > rel:
                amount = violation_amount(v, lo, hi)
                violated.append(ConstraintReport(label, float(v), lo, hi, float(amount)))
            elif gap <= rel:
                active.append(ConstraintReport(label, float(v), lo, hi, 0.0))
    return active, violated
