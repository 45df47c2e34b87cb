"""cvxpy back-end for geometric programs (DGP, solved in log space by an interior point).

Takes a generic :class:`~optdesign.programs.gp.GPData` (variables, bounds, posynomial
rows) and returns the common :class:`Result`. The certificate is a Lagrange dual bound
computed from the solver's multipliers, independent of the solver's own stopping test:

    with y = log x, f_i(y) = log posy_i(e^y) (convex), multipliers lambda_k >= 0 of the
    objective rows normalised to sum 1 and mu_i >= 0 of the constraint rows,
    g = min over the variable box of  sum_k lambda_k f_k(y) + sum_i mu_i f_i(y)
    is a lower bound of log(optimum) (weak duality; sum_k lambda_k f_k <= max_k f_k).

g is a smooth convex minimisation over a box (SLSQP); ``gap_rel = 1 - exp(g - log p)``
says how far the returned objective p can be above the true global optimum.

Both calls run inside :func:`optdesign.interrupts.solver_call`: a signal during them is
raised as the interrupt once they return (the conic solvers do not look at Python's
signals; the CLI's watchdog ends a call that would not return within a second).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from scipy.optimize import minimize
from scipy.special import logsumexp

from optdesign.interrupts import solver_call
from optdesign.programs.gp import GPData, GPRow, to_cvxpy
from optdesign.solvers.blas import one_blas_thread
from optdesign.solvers.details import Details, GPBackEndDetails, GPDual, GPTiming
from optdesign.solvers.result import (
    Certificate,
    ConstraintReport,
    Result,
    SolutionStatus,
    TerminationCondition,
)
from optdesign.solvers.solved_point import SOLVED_STATUSES

#: cvxpy status -> (termination, status word).
_STATUS = {
    "optimal": (TerminationCondition.CONVERGED, "optimal"),
    "optimal_inaccurate": (TerminationCondition.ACCEPTABLE, "feasible"),
    "infeasible": (TerminationCondition.INFEASIBLE, "infeasible"),
    "infeasible_inaccurate": (TerminationCondition.INFEASIBLE, "infeasible"),
    "unbounded": (TerminationCondition.UNBOUNDED, "failed"),
    "unbounded_inaccurate": (TerminationCondition.UNBOUNDED, "failed"),
    "user_limit": (TerminationCondition.MAX_ITERATIONS, "max_iterations"),
    "solver_error": (TerminationCondition.ERROR, "failed"),
}


_OPTIONS = {"ftol": 1e-15, "gtol": 1e-12, "maxfun": 500}
#: A multiplier above this marks the row active in reports.
ACTIVE_DUAL = 1e-6


def _log_posy(row: GPRow, y: np.ndarray) -> tuple[float, np.ndarray]:
    """f(y) = log sum_k c_k exp(A_k y) and its gradient."""
    z = row.A @ y + np.log(row.c)
    f = logsumexp(z)
    w = np.exp(z - f)
    return float(f), row.A.T @ w


def dual_bound(
    gp: GPData, lam_obj: np.ndarray, mu: list[float], rows: list[GPRow]
) -> tuple[float, bool]:
    """Lower bound on log(optimum) from multipliers (see module docstring).

    Returns
    -------
    (g, converged)
    """
    lam = np.clip(np.asarray(lam_obj, dtype=float), 0.0, None)
    if lam.sum() <= 0:
        lam = np.full(len(gp.objective_rows), 1.0 / max(len(gp.objective_rows), 1))
    lam = lam / lam.sum()
    mu = [max(float(m), 0.0) for m in mu]

    def L(y):
        total, grad = 0.0, np.zeros_like(y)
        for w, row in zip(lam, gp.objective_rows, strict=True):
            f, g = _log_posy(row, y)
            total += w * f
            grad += w * g
        for w, row in zip(mu, rows, strict=True):
            if w > 0:
                f, g = _log_posy(row, y)
                total += w * f
                grad += w * g
        return total, grad

    lo, hi = np.log(gp.lower), np.log(gp.upper)
    y0 = 0.5 * (lo + hi)
    # L is convex: one local minimisation from the box centre is the minimum. SLSQP
    # (bounds) is used because L-BFGS-B was much slower per call here.
    with solver_call():
        best = minimize(
            L,
            y0,
            jac=True,
            method="SLSQP",
            bounds=list(zip(lo, hi, strict=True)),
            options={"ftol": 1e-15, "maxiter": 500},
        )
    return float(best.fun), bool(best.success)


def solve_gp(gp: GPData, solver: str = "CLARABEL", options: dict[str, Any] | None = None) -> Result:
    """Solve the GP with cvxpy (``gp=True``) and certify it with a dual bound.

    Parameters
    ----------
    gp
        The GP (must be DGP: ``gp.is_gp``).
    solver
        cvxpy conic solver (CLARABEL default; SCS also handles exponential cones).
    options
        Solver keyword options passed to ``cvxpy.Problem.solve``.
    """
    import cvxpy as cp

    t0 = time.perf_counter()
    prob, xs, _t, cons = to_cvxpy(gp)
    t_build = time.perf_counter() - t0
    error = ""
    try:
        with solver_call():
            prob.solve(gp=True, solver=solver, **(options or {}))
    except cp.error.SolverError as exc:
        error = str(exc).splitlines()[0]
    wall = time.perf_counter() - t0
    stats = prob.solver_stats
    status_text = str(prob.status) if prob.status is not None else "solver_error"
    term, status = _STATUS.get(status_text, (TerminationCondition.UNKNOWN, "failed"))
    common = {
        "solver": f"cvxpy-{solver.lower()}",
        "formulation": "gp",
        "wall_time_s": wall,
        "termination": term,
        "message": error or status_text,
    }
    timing = GPTiming(
        build_s=t_build,
        compile_s=float(getattr(prob, "compilation_time", None) or float("nan")),
        solver_s=float(stats.solve_time) if stats and stats.solve_time else float("nan"),
        total_s=wall,
    )
    if status not in SOLVED_STATUSES or xs[0].value is None:
        return Result(
            status=status,
            objective=float("nan"),
            design={},
            solution_status=SolutionStatus.INFEASIBLE
            if status == "infeasible"
            else SolutionStatus.NO_SOLUTION,
            details=Details(gp=GPBackEndDetails(timing=timing)),
            **common,
        )
    t_cert = time.perf_counter()
    x = np.array([float(v.value) for v in xs])
    y = np.log(x)
    objective = float(max(row.c @ np.exp(row.A @ y) for row in gp.objective_rows))
    # Multipliers: objective rows first, then constraint rows, then bounds (to_cvxpy order).
    n_obj = len(gp.objective_rows)
    duals = [float(np.asarray(c.dual_value if c.dual_value is not None else 0.0)) for _, c in cons]
    rows = [r for r, _ in cons[n_obj:]]
    # The bounds are the box of the dual minimisation itself: their multipliers are not
    # needed for the bound (the box is enforced directly).
    keep = [k for k, r in enumerate(rows) if not r.name.startswith("bound:")]
    g, conv = dual_bound(
        gp, np.array(duals[:n_obj]), [duals[n_obj + k] for k in keep], [rows[k] for k in keep]
    )
    timing.certificate_s = time.perf_counter() - t_cert
    log_p = float(np.log(objective))
    gap_log = log_p - g
    lower = float(np.exp(g))
    certificate = Certificate(
        "gp-dual: Lagrange dual bound from the GP multipliers (log space, box of the bounds)",
        lower,
        objective,
        float(1.0 - np.exp(-gap_log)),
    )
    dual_info = GPDual(
        dual_bound_converged=conv,
        multipliers={
            f"{r.name}[{r.label}]" if r.label else r.name: d
            for (r, _), d in zip(cons, duals, strict=True)
            if d > ACTIVE_DUAL
        },
    )
    active = []
    for (r, _c), d in zip(cons[n_obj:], duals[n_obj:], strict=True):
        if d <= ACTIVE_DUAL:
            continue
        posy = float(r.c @ np.exp(r.A @ y))
        if r.name.startswith("bound:"):
            continue
        value = posy * r.bound if r.kind == "upper" else r.bound / posy
        label = f"{r.name}[{r.label}]" if r.label else r.name
        lo = r.bound if r.kind == "lower" else None
        hi = r.bound if r.kind == "upper" else None
        active.append(ConstraintReport(label, value, lo, hi, 0.0, r.unit))
    return Result(
        status=status,
        objective=objective,
        design=dict(zip(gp.names, x.tolist(), strict=True)),
        solution_status=SolutionStatus.OPTIMAL if status == "optimal" else SolutionStatus.FEASIBLE,
        iterations=int(stats.num_iters) if stats and stats.num_iters is not None else None,
        active=active,
        max_violation=0.0,
        bound=lower,
        certificate=certificate,
        details=Details(gp=GPBackEndDetails(dual=dual_info, timing=timing)),
        **common,
    )


class GPSolver:
    """The solver contract for a GP: built for one :class:`GPData`, ``solve()`` any
    number of times (cvxpy builds its problem per call; the GP has no start)."""

    def __init__(self, gp: GPData, solver: str = "CLARABEL", options: dict[str, Any] | None = None):
        self.gp = gp
        self.solver = solver.upper()
        self.options = dict(options or {})

    @property
    def name(self) -> str:
        return f"cvxpy-{self.solver.lower()}"

    @one_blas_thread()
    def solve(self, *_args, **_kwargs) -> Result:
        return solve_gp(self.gp, self.solver, self.options)
