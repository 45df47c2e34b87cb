"""Independent check of a design on the NumPy path of the same models: every
requirement, every objective a number, and every model within its range of validity."""

from __future__ import annotations

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.evaluation import relative_violation
from optdesign.problem.validity import OutsideRange, outside_ranges
from optdesign.solvers.constraint_rows import violation_amount
from optdesign.solvers.result import ConstraintReport
from optdesign.tolerances import FEASIBILITY_TOL


def verify_design(problem: DesignProblem, x: np.ndarray, tol: float = FEASIBILITY_TOL):
    """Re-evaluate every constraint of ``problem`` at free-variable vector ``x``, and the
    quantities that the models' ranges of validity bound.

    Returns
    -------
    (ok, violated, objectives)
        ``ok`` if no row is violated by more than ``tol`` (relative), no objective is
        NaN and no model is used outside its range; the violated rows (the NaN
        objectives, and each quantity outside its model's range as a row named
        ``"validity: <model>: <quantity>[<angle>]"``, :func:`validity_report`) as
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
            amount = violation_amount(v, lo, hi)
            label = f"{name}[{labels[k]}]" if labels[k] else name
            violated.append(ConstraintReport(label, v, lo, hi, float(amount)))
    for name, value in ev.objectives.items():
        # e.g. a user's objective that is NaN here: the design is no verified result
        if np.isnan(value):
            violated.append(ConstraintReport(f"objective {name}", float(value), None, None, np.inf))
    # a design whose models are used outside their ranges is no answer, whatever its rows
    violated += [validity_report(o) for o in outside_ranges(problem, np.asarray(x, dtype=float))]
    return not violated, violated, ev.objectives


def validity_report(found: OutsideRange) -> ConstraintReport:
    """The row of a quantity outside its model's range, in the unit messages show it
    (``validity: small-angle clearance: worst-case backlash[phi=+30.0deg] = 1.29e+07 deg
    (<= 5), violated by ...``); the amount is inf for a NaN."""
    record = found.record

    def shown(v: float | None) -> float | None:
        return None if v is None else float(v) * record.scale

    value = shown(found.value)
    lower, upper = shown(record.lower), shown(record.upper)
    if np.isnan(value):
        amount = np.inf
    else:
        amount = violation_amount(value, lower, upper)
    name = found.name + (f"[{found.where}]" if found.where else "")
    return ConstraintReport(name, value, lower, upper, float(amount), record.display_unit)


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
