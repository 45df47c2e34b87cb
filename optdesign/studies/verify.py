"""Independent check of a design on the NumPy path of the same models."""

from __future__ import annotations

import numpy as np

from optdesign.problem.design_problem import DesignProblem, relative_violation
from optdesign.solvers.result import ConstraintReport

#: A design counts as feasible when no constraint is violated by more than this,
#: relative to max(1, |bound|).
VERIFY_TOL = 1e-6


def verify_design(problem: DesignProblem, x: np.ndarray, tol: float = VERIFY_TOL):
    """Re-evaluate every constraint of ``problem`` at free-variable vector ``x``.

    Returns
    -------
    (ok, violated, objectives)
        ``ok`` if no row is violated by more than ``tol`` (relative); the violated rows
        as :class:`ConstraintReport`; the objective values on the NumPy path.
    """
    ev = problem.evaluate(np.asarray(x, dtype=float))
    violated = []
    for name, block in ev.constraints.items():
        values = np.atleast_1d(np.asarray(block.values, dtype=float))
        lo, hi = block.lower, block.upper
        rel = relative_violation(values, lo, hi)
        labels = problem.phi_labels if len(values) == len(problem.phi) else [""] * len(values)
        for k in np.flatnonzero(rel > tol):
            v = float(values[k])
            amount = max((lo - v) if lo is not None else 0.0, (v - hi) if hi is not None else 0.0)
            label = f"{name}[{labels[k]}]" if labels[k] else name
            violated.append(ConstraintReport(label, v, lo, hi, float(amount)))
    return not violated, violated, ev.objectives
