"""Multistart: seeded Sobol starts inside the bounds, solved locally, best kept.

Reports how many starts reached the best objective (evidence of a global optimum). Starts
run in-process, or on local worker processes that inherit the solver built once in this
process (:mod:`optdesign.studies.runner`'s process engine).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence

import numpy as np

from optdesign.solvers.result import MultistartInfo, Result


def sobol_starts(lower: np.ndarray, upper: np.ndarray, n: int, seed: int) -> np.ndarray:
    """``n`` scrambled-Sobol points in the box [lower, upper] (reproducible from ``seed``)."""
    from optdesign.solvers.sobol import sobol_points

    m = max(0, math.ceil(math.log2(max(n, 1))))
    pts = sobol_points(len(lower), m, seed)[:n]
    return lower + pts * (upper - lower)


def best_of(results: Sequence[Result], rel_tol: float = 1e-6) -> tuple[Result, int]:
    """The best successful result and how many reached it within ``rel_tol``."""
    ok = [r for r in results if r.success and math.isfinite(r.objective)]
    if not ok:
        # No feasible start: report the least violated one.
        worst = min(
            results, key=lambda r: r.max_violation if math.isfinite(r.max_violation) else math.inf
        )
        return worst, 0
    best = min(ok, key=lambda r: r.objective)
    tol = rel_tol * max(abs(best.objective), 1e-12)
    n_at_best = sum(1 for r in ok if r.objective <= best.objective + tol)
    return best, n_at_best


def multistart(
    solve: Callable[[np.ndarray], Result],
    starts: np.ndarray,
    workers: int = 1,
    rel_tol: float = 1e-6,
    seed: int = 0,
    agree: int | None = None,
) -> Result:
    """Solve from every start and return the best result with its multistart record.

    Parameters
    ----------
    solve
        x0 -> Result (a solver built once; local workers inherit it).
    starts
        One start per row.
    workers
        Local processes (the starts are split among them).
    agree
        Stop once this many successful starts agree on the best value (within
        ``rel_tol``); None runs every start. With several workers the starts run in
        rounds of ``workers``.
    """
    t0 = time.perf_counter()
    starts = list(np.atleast_2d(starts))
    results: list[Result] = []
    if workers > 1 and len(starts) > 1:
        from optdesign.studies.runner import map_inherited

        results = map_inherited(solve, starts, workers, stop=_stop_rule(rel_tol, agree))
    else:
        stop = _stop_rule(rel_tol, agree)
        for x0 in starts:
            results.append(solve(x0))
            if stop(results):
                break
    best, n_at_best = best_of(results, rel_tol)
    best.multistart = MultistartInfo(
        n_starts=len(results),
        n_converged=sum(r.success for r in results),
        n_at_best=n_at_best,
        tolerance=rel_tol,
        objectives=[r.objective if r.success else math.nan for r in results],
        seed=seed,
        workers=workers,
        n_planned=len(starts),
        stopped_early=len(results) < len(starts),
    )
    best.wall_time_s = time.perf_counter() - t0
    return best


def _stop_rule(rel_tol: float, agree: int | None) -> Callable[[list[Result]], bool]:
    def stop(results: list[Result]) -> bool:
        return bool(agree) and best_of(results, rel_tol)[1] >= agree

    return stop
