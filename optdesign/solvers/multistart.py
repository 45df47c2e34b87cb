"""Multistart: seeded Sobol starts inside the bounds, solved locally, best kept.

Reports how many starts reached the best objective (evidence of a global optimum). Starts
run in-process, or through the ``parallel_map`` a study passes (the studies' process
engine, :func:`optdesign.runtime.inherited_map.map_inherited`: local worker processes that
inherit the solver built once in this process). The solver layer knows no process pool.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence

import numpy as np

from optdesign.solvers.blas import one_blas_thread
from optdesign.solvers.deadline import deadline, passed
from optdesign.solvers.result import MultistartInfo, Result, TerminationCondition
from optdesign.tolerances import OBJECTIVE_TIE_TOL


def sobol_starts(lower: np.ndarray, upper: np.ndarray, n: int, seed: int) -> np.ndarray:
    """``n`` scrambled-Sobol points in the box [lower, upper] (reproducible from ``seed``)."""
    from optdesign.solvers.sobol import sobol_points

    m = max(0, math.ceil(math.log2(max(n, 1))))
    pts = sobol_points(len(lower), m, seed)[:n]
    return lower + pts * (upper - lower)


def best_of(results: Sequence[Result], rel_tol: float = OBJECTIVE_TIE_TOL) -> tuple[Result, int]:
    """The best successful result and how many reached it within ``rel_tol``.

    Ties are decided by value, then by index, never by rounding: every successful result
    within ``rel_tol`` of the least objective reached the best, and the first of them (the
    lowest start index) wins. A strict minimum would let a 1e-14 difference - another BLAS
    thread count, another machine - pick another start, and with it another design when
    the optimum is not unique. With no successful result, the least violated one is
    returned (the first of those within ``rel_tol`` of the least violation).
    """
    ok = [r for r in results if r.success and math.isfinite(r.objective)]
    if not ok:
        # No feasible start: report the least violated one.
        viol = [violation(r) for r in results]
        least = min(viol)
        first = next(k for k, v in enumerate(viol) if v <= least + tie_width(least, rel_tol))
        return results[first], 0
    least = min(r.objective for r in ok)
    tol = tie_width(least, rel_tol)
    at_best = [r for r in ok if r.objective <= least + tol]
    return at_best[0], len(at_best)


def violation(r: Result) -> float:
    """A result's largest violation, inf where it has none to compare (NaN)."""
    return r.max_violation if math.isfinite(r.max_violation) else math.inf


def tie_width(value: float, rel_tol: float = OBJECTIVE_TIE_TOL) -> float:
    """The absolute width of a tie at ``value``: ``rel_tol`` relative to the larger of
    |value| and 1e-12 (0 for a value that is not finite)."""
    return rel_tol * max(abs(value), 1e-12) if math.isfinite(value) else 0.0


#: The reason counted for the starts a time limit left unrun.
NOT_STARTED = "not started (time limit)"


def start_outcome(result: Result) -> str:
    """How one start ended, in the summary's words: ``"converged"`` or why not.

    ``"restoration failed"`` (Ipopt's feasibility restoration found no way back),
    ``"iteration limit"``, ``"time limit"``, ``"not assembling"`` (a NaN or an infinity
    in the model: a design where the linkage cannot be put together, such as a rod
    shorter than the gap it must span), ``"locally infeasible"``, ``"evaluation error"``
    (the back-end could not evaluate the model), else the result's status.
    """
    if result.success:
        return "converged"
    message = result.message or ""
    term = result.termination
    if "Restoration_Failed" in message:
        return "restoration failed"
    if "(bound not tight" in message:
        return "bound not tight"
    if "(independent check failed)" in message:
        return "independent check failed"
    if term == TerminationCondition.MAX_ITERATIONS:
        return "iteration limit"
    if term == TerminationCondition.MAX_TIME:
        return "time limit"
    if "Invalid_Number" in message:
        return "not assembling"
    if term == TerminationCondition.INFEASIBLE:
        return "locally infeasible"
    if term == TerminationCondition.ERROR:
        return "evaluation error"
    return str(result.status or "failed")


def outcome_counts(outcomes: Sequence[str]) -> dict[str, int]:
    """The starts that did not converge, counted by reason: most frequent first, a tie
    in the order the reasons first occur (never by timing)."""
    counts: dict[str, int] = {}
    for o in outcomes:
        if o != "converged":
            counts[o] = counts.get(o, 0) + 1
    order = {o: k for k, o in enumerate(counts)}
    return dict(sorted(counts.items(), key=lambda kv: (-kv[1], order[kv[0]])))


def improves(value: float, best: float, rel_tol: float = OBJECTIVE_TIE_TOL) -> bool:
    """Whether ``value`` is better than ``best`` by more than a tie (``rel_tol``
    relative): a search keeps its earlier incumbent on a tie, as :func:`best_of` does."""
    return value < best - tie_width(best, rel_tol)


def multistart(
    solve: Callable[[np.ndarray], Result],
    starts: np.ndarray,
    workers: int = 1,
    rel_tol: float = OBJECTIVE_TIE_TOL,
    seed: int = 0,
    agree: int | None = None,
    time_limit: float | None = None,
    parallel_map: Callable[..., list[Result]] | None = None,
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
        ``rel_tol``); None runs every start. The starts considered are always the
        shortest prefix of ``starts`` (in their order) on which that many agree, whatever
        the number of workers and whichever start finishes first: the same starts, the
        same winner (:func:`best_of`) and the same record as a run on one worker.
    time_limit
        Wall-clock seconds for the whole multistart (:mod:`optdesign.solvers.deadline`):
        no start begins after it (the first start always runs), a solve built with
        :data:`~optdesign.solvers.deadline.DEADLINE_OPTION` stops at it; the starts not
        begun count as failed, "not started (time limit)", and a note says so.
    parallel_map
        ``parallel_map(solve, starts, workers, stop=...)`` -> the results of the shortest
        prefix of ``starts`` for which ``stop`` holds, in their order; needed when
        ``workers > 1``.
    """
    if workers > 1 and parallel_map is None:
        raise ValueError("multistart: workers > 1 needs a parallel_map")
    t0 = time.perf_counter()
    starts = list(np.atleast_2d(starts))
    results: list[Result] = []
    # One BLAS thread in this process as in the workers (a back-end of the user's own
    # gets it too): the same arithmetic whatever the number of workers.
    with one_blas_thread(), deadline(time_limit):
        stop = _stop_rule(rel_tol, agree)
        if workers > 1 and len(starts) > 1:
            results = parallel_map(solve, starts, workers, stop=stop)
        else:
            for x0 in starts:
                results.append(solve(x0))
                if stop(results):
                    break
        timed_out = passed()
    best, n_at_best = best_of(results, rel_tol)
    outcomes = [start_outcome(r) for r in results]
    not_started = len(starts) - len(results) if timed_out else 0
    failed = outcome_counts(outcomes + [NOT_STARTED] * not_started)
    if timed_out:
        stopped = sum(o == "time limit" for o in outcomes)
        best.notes.append(
            f"time limit of {time_limit:g} s reached: {len(results)} of {len(starts)} starts "
            f"run ({stopped} stopped at the limit), {not_started} not started"
        )
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
        outcomes=outcomes,
        failed=failed,
    )
    best.wall_time_s = time.perf_counter() - t0
    return best


def _stop_rule(rel_tol: float, agree: int | None) -> Callable[[list[Result]], bool]:
    def stop(results: list[Result]) -> bool:
        if passed():  # the time limit: no further start
            return True
        return bool(agree) and best_of(results, rel_tol)[1] >= agree

    return stop
