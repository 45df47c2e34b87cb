"""Independent check of a design on the NumPy path of the same models."""

from __future__ import annotations

import numpy as np

from optdesign.problem.design_problem import DesignProblem, relative_violation
from optdesign.solvers.result import ConstraintReport
from optdesign.tolerances import FEASIBILITY_TOL


def verify_design(problem: DesignProblem, x: np.ndarray, tol: float = FEASIBILITY_TOL):
    """Re-evaluate every constraint of ``problem`` at free-variable vector ``x``.

    Returns
    -------
    (ok, violated, objectives)
        ``ok`` if no row is violated by more than ``tol`` (relative) and no objective
        is NaN; the violated rows (and the NaN objectives) as
        :class:`ConstraintReport`; the objective values on the NumPy path.
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
    for name, value in ev.objectives.items():
        # e.g. a user's objective that is NaN here: the design is no verified result
        if np.isnan(value):
            violated.append(ConstraintReport(f"objective {name}", float(value), None, None, np.inf))
    return not violated, violated, ev.objectives


def nan_notes(problem: DesignProblem, objectives: dict[str, float], violated) -> list[str]:
    """Notes for the objectives and user constraints that are NaN at a design: which
    function returns NaN there (a user's: its name, file and line)."""
    from optdesign.user_code import describe_function, is_users, location_of

    def whose(kind: str, name: str, fn) -> str:
        if fn is None:
            return f"{kind} {name!r} is NaN at this design"
        where = location_of(fn)
        at = f" (defined at {where})" if where else ""
        return (
            f"{kind} {name!r} is NaN at this design: its function {describe_function(fn)}{at} "
            "returns NaN there, so the design is not a verified result"
        )

    notes = []
    for name, value in objectives.items():
        if np.isnan(value):
            info = problem.objectives.get(name)
            user = info is not None and is_users(info.fn)
            notes.append(whose("objective", name, info.fn if user else None))
    user = {c.name: c for c in problem.user_constraints}
    for name in dict.fromkeys(r.name.split("[", 1)[0] for r in violated if np.isnan(r.value)):
        if name in user:
            notes.append(whose("constraint", name, user[name].fn))
    return notes


def constraint_rows(problem: DesignProblem, design, rel: float = 1e-5, ev=None):
    """(active, violated) constraint reports of any design on the NumPy path: a row is
    active within ``rel`` of its bound (relative to max(1, |bound|)), violated beyond.

    ``design``: a full design dict (name -> value) or the free-variable vector; ``ev``:
    the design's ``problem.evaluate`` when the caller has it already.
    """
    import math

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
                amount = max(
                    (lo - v) if lo is not None else 0.0, (v - hi) if hi is not None else 0.0
                )
                violated.append(ConstraintReport(label, float(v), lo, hi, float(amount)))
            elif gap <= rel:
                active.append(ConstraintReport(label, float(v), lo, hi, 0.0))
    return active, violated
