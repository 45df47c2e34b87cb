"""An independent global search on the NumPy path: scipy differential evolution.

Used to give evidence that the NLP multistart found the global optimum (tests, benchmarks,
and the ``de`` reference configuration of the solver benchmarks). It shares only the
model functions with the NLP path: no CasADi, no Ipopt, no epigraph.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import differential_evolution, minimize

from optdesign.formulations.catalogue.discrete import CatalogueCoordinates
from optdesign.problem.design_problem import DesignProblem

#: Penalty weight on the largest relative constraint violation.
PENALTY = 1e3


def penalised_objective(problem: DesignProblem, objective: str):
    """Vectorised f(x) + PENALTY * violation(x) for scipy (x: (n,) or (n, pop))."""

    def fun(X: np.ndarray) -> np.ndarray:
        pop = np.atleast_2d(X.T) if X.ndim == 2 else X[None, :]
        ev = problem.evaluate(pop)
        val = np.asarray(ev.objectives[objective], dtype=float)
        viol = np.nan_to_num(np.asarray(ev.violation, dtype=float), nan=1e3, posinf=1e3)
        out = np.where(np.isfinite(val), val, 1e3) + PENALTY * np.minimum(viol, 1e3)
        return out if X.ndim == 2 else out[0]

    return fun


def differential_evolution_optimum(
    problem: DesignProblem,
    objective: str | None = None,
    seed: int = 1,
    popsize: int = 40,
    maxiter: int = 3000,
    polish: bool = True,
) -> dict:
    """Global optimum by differential evolution (penalty), polished by SLSQP with finite
    differences on the NumPy path.

    Catalogue variables are searched over their values (integer indices with scipy's
    ``integrality``) and held at the item found while the continuous ones are polished.

    Returns
    -------
    dict
        ``x``, ``objective``, ``violation`` (relative, at x), ``nfev``, ``wall_time_s``.
    """
    objective = objective or problem.objective_names[0]
    coords = CatalogueCoordinates(problem)
    penalised = penalised_objective(problem, objective)

    def fun(Z: np.ndarray) -> np.ndarray:
        # scipy passes a population column-wise: (n, pop)
        return penalised(coords.to_design(Z.T).T if Z.ndim == 2 else coords.to_design(Z))

    t0 = time.perf_counter()
    res = differential_evolution(
        fun,
        coords.bounds,
        seed=seed,
        popsize=popsize,
        maxiter=maxiter,
        tol=1e-12,
        atol=0.0,
        vectorized=True,
        updating="deferred",
        polish=False,
        integrality=coords.integrality if coords.discrete else None,
    )
    x, nfev = coords.to_design(res.x), res.nfev
    if polish:
        bounds = list(zip(problem.lower(), problem.upper(), strict=True))
        for k in coords.discrete:  # the item found stays; the continuous variables move
            bounds[k] = (x[k], x[k])
        x = _slsqp_polish(problem, objective, x, bounds)
    ev = problem.evaluate(x)
    return {
        "x": x,
        "objective": float(ev.objectives[objective]),
        "violation": float(ev.violation),
        "nfev": int(nfev),
        "wall_time_s": time.perf_counter() - t0,
    }


def _slsqp_polish(problem, objective, x0, bounds):
    def cons(x):
        ev = problem.evaluate(x)
        rows = []
        for b in ev.constraints.values():
            values, lo, hi = b.values, b.lower, b.upper
            values = np.atleast_1d(values)
            if lo is not None:
                rows.append((values - lo) / max(1.0, abs(lo)))
            if hi is not None:
                rows.append((hi - values) / max(1.0, abs(hi)))
        return np.concatenate(rows)

    def fun(x):
        return problem.evaluate(x).objectives[objective]

    with np.errstate(invalid="ignore", divide="ignore"):
        res = minimize(
            fun,
            x0,
            method="SLSQP",
            bounds=bounds,
            constraints=[{"type": "ineq", "fun": cons}],
            options={"ftol": 1e-14, "maxiter": 500},
        )
    ok = np.all(np.isfinite(res.x)) and problem.evaluate(res.x).violation <= 1e-7
    return res.x if ok and fun(res.x) <= fun(x0) + 1e-12 else x0
