"""Multistart: seeded Sobol starts inside the bounds, solved locally, best kept.

Reports how many starts reached the best objective (evidence of a global optimum). Starts
run in-process, or on local worker processes (each builds its own solver once) when
``workers > 1``.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy.stats import qmc

from optdesign.solvers.result import MultistartInfo, Result


def sobol_starts(lower: np.ndarray, upper: np.ndarray, n: int, seed: int) -> np.ndarray:
    """``n`` scrambled-Sobol points in the box [lower, upper] (reproducible from ``seed``)."""
    d = len(lower)
    sampler = qmc.Sobol(d, scramble=True, seed=seed)
    m = max(0, math.ceil(math.log2(max(n, 1))))
    pts = sampler.random_base2(m)[:n]
    return lower + pts * (upper - lower)


def best_of(results: list[Result], rel_tol: float = 1e-6) -> tuple[Result, int]:
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


# --- process pool plumbing: each worker builds its solver once --------------------------
_WORKER_SOLVE: Callable | None = None


def _init_worker(factory: Callable, args: tuple) -> None:
    global _WORKER_SOLVE
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    _WORKER_SOLVE = factory(*args)


def _solve_in_worker(x0: np.ndarray) -> Result:
    assert _WORKER_SOLVE is not None
    return _WORKER_SOLVE(x0)


def multistart(
    solve: Callable[[np.ndarray], Result],
    starts: np.ndarray,
    workers: int = 1,
    factory: Callable | None = None,
    factory_args: tuple = (),
    rel_tol: float = 1e-6,
    seed: int = 0,
) -> Result:
    """Solve from every start and return the best result with its multistart record.

    Parameters
    ----------
    solve
        x0 -> Result, used in-process.
    starts
        One start per row.
    workers
        Local processes; >1 needs ``factory(*factory_args)`` returning such a ``solve``
        (picklable, built once per worker).
    """
    t0 = time.perf_counter()
    if workers > 1 and factory is not None and len(starts) > 1:
        with ProcessPoolExecutor(
            max_workers=workers, initializer=_init_worker, initargs=(factory, factory_args)
        ) as pool:
            results = list(pool.map(_solve_in_worker, list(starts)))
    else:
        results = [solve(x0) for x0 in starts]
    best, n_at_best = best_of(results, rel_tol)
    best.multistart = MultistartInfo(
        n_starts=len(results),
        n_converged=sum(r.success for r in results),
        n_at_best=n_at_best,
        tolerance=rel_tol,
        objectives=[r.objective if r.success else math.nan for r in results],
        seed=seed,
        workers=workers,
    )
    best.wall_time_s = time.perf_counter() - t0
    return best
