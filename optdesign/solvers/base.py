"""The solver contract: one protocol for every NLP back-end, and what they share.

A back-end is built once for one :class:`~optdesign.programs.nlp.NLP` and solved many
times; each call passes its own :class:`Start`, :class:`Target` (what to minimise) and
:class:`Bounds` (epsilon limits, catalogue sub-boxes), so no back-end ever changes a
shared NLP. The status mapping and the constraint reports are written once here
(:func:`make_result`); a back-end maps its own return status to a
:class:`~optdesign.solvers.result.TerminationCondition` and a status word, and hands over
the final point and multipliers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from optdesign.programs.nlp import NLP, Bounds, Start, Target
from optdesign.solvers.result import (
    ConstraintReport,
    Result,
    SolutionStatus,
    TerminationCondition,
)
from optdesign.solvers.solved_point import SOLVED_STATUSES
from optdesign.tolerances import FEASIBILITY_TOL, LEFT_OUT_ROW_TOL


@dataclass
class MINLPSolution:
    """What a MINLP back-end returns (:attr:`~optdesign.solvers.registry.SolverHints.
    minlp`): its return status, whether it found an integer-feasible point, the point
    (None when not) and its objective (in the formulation's scaling), the algorithm it ran.
    """

    status: str
    found: bool
    x: np.ndarray | None
    objective: float | None
    algorithm: str


@runtime_checkable
class NLPSolver(Protocol):
    """What every NLP back-end offers (see :func:`optdesign.solvers.make_solver`)."""

    name: str
    nlp: NLP

    def solve(
        self, start: Start, target: Target | None = None, bounds: Bounds | None = None
    ) -> Result:
        """Solve from ``start`` for ``target`` (default: the NLP's) within ``bounds``
        (default: the NLP's); never raises for solver trouble (a failed Result)."""
        ...


def constraint_reports(
    nlp: NLP, g: np.ndarray, bounds: Bounds
) -> tuple[list[ConstraintReport], list[ConstraintReport]]:
    """Violated and active constraint rows at ``g``, in the constraints' own units."""
    g = np.asarray(g, dtype=float).ravel()
    lo_all = np.asarray(bounds.lbg, dtype=float)
    hi_all = np.asarray(bounds.ubg, dtype=float)
    # Vectorised screening (a Python loop over every row was a visible part of a solve);
    # reports are built only for the violated and active rows, in row order.
    flo, fhi, fg = np.isfinite(lo_all), np.isfinite(hi_all), np.isfinite(g)
    with np.errstate(invalid="ignore"):
        amounts = np.maximum(np.where(flo, lo_all - g, 0.0), np.where(fhi, g - hi_all, 0.0))
        is_viol = ~fg | (amounts > FEASIBILITY_TOL)
        is_act = ~is_viol & (
            (flo & (g - lo_all < FEASIBILITY_TOL)) | (fhi & (hi_all - g < FEASIBILITY_TOL))
        )
    violated, active = [], []
    for k in np.flatnonzero(is_viol | is_act):
        s = nlp.g_scale[k]
        lo, hi = lo_all[k], hi_all[k]
        amount = amounts[k]
        rep = ConstraintReport(
            nlp.g_names[k],
            float(g[k] * s),
            None if not np.isfinite(lo) else float(lo * s),
            None if not np.isfinite(hi) else float(hi * s),
            float(max(amount, 0.0) * s) if amount > FEASIBILITY_TOL else 0.0,
            nlp.g_units[k],
        )
        if is_viol[k]:
            if not fg[k]:
                rep.amount = float("inf")
            violated.append(rep)
        else:
            active.append(rep)
    return violated, active


def _bound_scale(report: ConstraintReport) -> float:
    """max(1, |bound|) of a violated row; 1 for a row without bounds (violated because
    its value is NaN)."""
    bound = report.upper if report.upper is not None else report.lower
    return max(1.0, abs(bound)) if bound is not None else 1.0


def make_result(
    solver: str,
    nlp: NLP,
    target: Target,
    bounds: Bounds,
    z: np.ndarray,
    lam_x: np.ndarray,
    lam_g: np.ndarray,
    status: str,
    termination: TerminationCondition,
    message: str,
    iterations: int | None,
    n_evals: dict[str, int],
    wall: float,
) -> Result:
    """The :class:`Result` of a finished solve, whatever the back-end.

    A point the back-end calls optimal but that violates a row is ``infeasible``; a point
    of a stopped solve (iterations, time) that violates nothing is a feasible solution.
    """
    z = np.asarray(z, dtype=float).ravel()
    theta = nlp.parameter_values(bounds.parameters)
    g = np.asarray(nlp.g_fun(z, theta), dtype=float).ravel()
    violated, active = constraint_reports(nlp, g, bounds)
    max_viol = max((r.amount / _bound_scale(r) for r in violated), default=0.0)
    if status in SOLVED_STATUSES and violated:
        status, termination = "infeasible", TerminationCondition.INFEASIBLE
    if status in ("max_iterations", "time_limit", "failed") and not violated:
        sol_status = SolutionStatus.FEASIBLE
    elif status == "optimal":
        sol_status = SolutionStatus.OPTIMAL
    elif status == "feasible":
        sol_status = SolutionStatus.FEASIBLE
    else:
        sol_status = SolutionStatus.INFEASIBLE if violated else SolutionStatus.NO_SOLUTION
    values = np.asarray(nlp.values_fun(z, theta), dtype=float).ravel()
    n_obj = len(nlp.objective_values)
    x = nlp.x_from_z(z)
    return Result(
        status=status,
        objective=nlp.objective_of(target, values),
        design=dict(zip(nlp.design_names, x.tolist(), strict=True)),
        solver=solver,
        formulation=f"nlp-{nlp.form}",
        wall_time_s=wall,
        termination=termination,
        solution_status=sol_status,
        message=message,
        objectives=dict(zip(nlp.objective_values, values[:n_obj].tolist(), strict=True)),
        objective_name=target.name,
        iterations=iterations,
        n_evals=n_evals,
        violated=violated,
        active=active,
        max_violation=float(max_viol),
        raw={"z": z, "lam_x": np.asarray(lam_x, dtype=float).ravel(), "lam_g": lam_g},
    )


def row_misses(nlp: NLP, z: np.ndarray, bounds: Bounds) -> np.ndarray:
    """How far the point ``z`` misses each row of ``nlp`` under ``bounds`` (scaled, as
    the solver sees the rows; <= 0 met, NaN where a row is not a number)."""
    theta = nlp.parameter_values(bounds.parameters)
    g = np.asarray(nlp.g_fun(z, theta), dtype=float).ravel()
    lo, hi = np.asarray(bounds.lbg, dtype=float), np.asarray(bounds.ubg, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.maximum(lo - g, g - hi)


def on_every_row(
    result: Result,
    nlp: NLP,
    rows: np.ndarray,
    target: Target,
    bounds: Bounds,
    tol: float = LEFT_OUT_ROW_TOL,
) -> tuple[Result, bool]:
    """A solve of ``with_rows(nlp, rows)`` as a solve of ``nlp`` itself.

    The point, its multipliers (zero on every row left out) and its reports on every row
    of ``nlp`` under ``bounds`` (the whole problem's); True when every row left out is met
    within ``tol`` at the point. Then the point is a KKT point of ``nlp`` to the solver's
    tolerances (the rows left out are inactive there, with zero multipliers), i.e. what a
    solve of ``nlp`` could have returned; otherwise the result is not one (a solved
    status then reads ``infeasible``, as :func:`make_result` calls a point that misses a
    row)."""
    z = result.raw.get("z")
    if z is None:  # nothing solved (an evaluation error): no point to lift
        return result, False
    rows = np.asarray(rows, dtype=int)
    lam_g = np.zeros(len(nlp.g_names))
    if result.raw.get("lam_g") is not None:
        lam_g[rows] = np.asarray(result.raw["lam_g"], dtype=float).ravel()
    miss = row_misses(nlp, z, bounds)
    left_out = np.ones(miss.size, dtype=bool)
    left_out[rows] = False
    met = bool(np.all(miss[left_out] <= tol))  # NaN: not met
    lifted = make_result(
        result.solver,
        nlp,
        target,
        bounds,
        z,
        result.raw.get("lam_x", np.zeros_like(z)),
        lam_g,
        result.status,
        result.termination,
        result.message,
        result.iterations,
        dict(result.n_evals),
        result.wall_time_s,
    )
    return lifted, met


def failed_result(
    solver: str,
    nlp: NLP,
    target: Target,
    message: str,
    wall: float,
    n_evals: dict[str, int] | None = None,
) -> Result:
    """A solve that produced no point (an evaluation error the back-end cannot recover)."""
    return Result(
        status="failed",
        objective=float("nan"),
        design={},
        solver=solver,
        formulation=f"nlp-{nlp.form}",
        wall_time_s=wall,
        termination=TerminationCondition.ERROR,
        solution_status=SolutionStatus.NO_SOLUTION,
        message=message,
        objective_name=target.name,
        n_evals=dict(n_evals or {}),
    )


def resolve(
    nlp: NLP, start: Start | Any, target, bounds: Bounds | None
) -> tuple[Start, Target, Bounds]:
    """Normalise the arguments of a solve (a design vector is accepted as the start)."""
    bounds = bounds if bounds is not None else nlp.bounds()
    if not isinstance(start, Start):
        start = nlp.start(x0=start, parameters=bounds.parameters)
    return start, nlp.target(target), bounds
