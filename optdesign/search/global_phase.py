"""The global search: local solves from tilted independent starts until the odds of a
better optimum say stop.

:func:`global_search` runs a local solver (an NLP back-end's ``solve``: anything
``x0 -> Result``) from

1. the caller's own starts, if any (a declared start, a neighbour's design): solved
   first, never counted by the odds, since they are no random draw;
2. starts drawn a chunk at a time from :class:`~optdesign.search.starts.TiltedStarts`.

After each start it asks the stopping rule (:class:`StopRule`), on the starts so far in
their order: stop once the counted starts' odds are settled (Boender and Rinnooy Kan's
rule, :func:`optdesign.search.odds.settled`) and at least ``agree`` starts reached the best
value; after :data:`FAILED_LIMIT` starts without a feasible end (no design to compare);
at the time limit; or when ``max_starts`` have run. The rule reads the starts in their
order, so the answer is the one a serial run gives whatever the number of workers
(:func:`optdesign.runtime.inherited_map.map_inherited`'s prefix contract).

Local optima are told apart by value alone (:func:`distinct_optima`): two starts whose
objectives differ by less than the tie tolerance (relative), or by less than what the
local solver resolves on the objective's scale (absolute), reached the same optimum as far
as the search is concerned, even where a flat valley lets them end at different designs.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from optdesign.search.infeasible import (
    LeastViolationFrom,
    PhaseOne,
    VerdictRule,
    mark_infeasible,
    no_feasible_end,
    phase_one_starts,
)
from optdesign.search.odds import distinct_optima, odds, settled
from optdesign.search.starts import CHUNK, TiltedStarts
from optdesign.solvers.blas import one_blas_thread
from optdesign.solvers.deadline import deadline, passed
from optdesign.solvers.multistart import (
    NOT_STARTED,
    best_of,
    outcome_counts,
    start_outcome,
    tie_width,
    violation,
)
from optdesign.solvers.result import Globality, MultistartInfo, Result
from optdesign.tolerances import OBJECTIVE_TIE_TOL

#: Starts in a row without a feasible end after which a search stops (the problem may
#: have no feasible design; the diagnosis takes it from there).
FAILED_LIMIT = 8

#: Most starts per free variable that a search with no cap of its own may run.
STARTS_PER_DIMENSION = 12

#: Fewest starts a search with no cap of its own may run.
MIN_MAX_STARTS = 32


#: Two starts whose values are closer than this (relative) are a tie when the search
#: picks its answer (the first of them wins, :func:`~optdesign.solvers.multistart.best_of`);
#: tighter than the tie that counts them as one optimum (``rel_tol``), so that of the starts
#: at one optimum that a solver resolves only to ~1e-6 (a ripple of 1e-4 held by its
#: epigraph rows to their constraint tolerance) the least is the answer, while starts that
#: differ by round-off alone still keep the first.
CHOICE_TOL = 1e-9

#: Counted starts per free variable that must converge before the odds may stop a search.
COUNTED_PER_DIMENSION = 2


def min_counted_starts(dimension: int) -> int:
    """The converged counted starts a search needs before its odds are read:
    :data:`COUNTED_PER_DIMENSION` per free variable. Boender and Rinnooy Kan's rule alone
    stops after 8 starts that agree, whatever the dimension; but the share of the starts
    that reach the best optimum shrinks as the design space grows (a ten-variable knee
    linkage's best basin takes a fifth to a quarter of them), and 8 starts then miss it in
    one search of ten."""
    return COUNTED_PER_DIMENSION * int(dimension)


def default_max_starts(dimension: int) -> int:
    """The cap on a search's starts when the caller gives none: grows with the number of
    free variables (:data:`STARTS_PER_DIMENSION` each, at least :data:`MIN_MAX_STARTS`)."""
    return max(MIN_MAX_STARTS, STARTS_PER_DIMENSION * int(dimension))


@dataclass(frozen=True)
class StopRule:
    """When a search stops, read from its results so far, in start order.

    ``counted_from``: the index of the first counted start (the caller's own starts come
    before it); ``agree``: starts that must reach the best value before the odds may stop
    the search (0: the odds never stop it, every start runs); ``target``: an estimated
    probability of a better optimum the odds must also reach (None: Boender and Rinnooy
    Kan's rule alone); ``rel_tol``, ``abs_tol``: two values closer than these are one
    optimum (:func:`distinct_optima`); ``min_counted``: counted starts that must converge
    before the odds are read (:func:`min_counted_starts`).
    """

    counted_from: int
    agree: int
    target: float | None = None
    rel_tol: float = OBJECTIVE_TIE_TOL
    abs_tol: float = 0.0
    min_counted: int = 0

    def reason(self, results: Sequence[Result]) -> str:
        """Why a search with these results stops (``""``: it goes on)."""
        if passed():
            return "time limit"
        if not self.agree:
            return ""
        if not any(_converged(r) for r in results):
            # a failed start that ended at a feasible design shows one exists: go on
            hopeless = len(results) >= FAILED_LIMIT and not any(r.verified for r in results)
            return "no feasible start" if hopeless else ""
        if best_of(results, self.rel_tol)[1] < self.agree:
            return ""
        counted = [r.objective for r in results[self.counted_from :] if _converged(r)]
        if len(counted) < self.min_counted:
            return ""
        found = odds(len(counted), len(self.optima(counted)))
        return "odds" if settled(found, self.target) else ""

    def __call__(self, results: Sequence[Result]) -> bool:
        return bool(self.reason(results))

    def optima(self, values: Sequence[float]) -> list[float]:
        """The distinct optima among ``values`` (:func:`distinct_optima`)."""
        return distinct_optima(values, self.rel_tol, self.abs_tol)


def _converged(r: Result) -> bool:
    return bool(r.success) and math.isfinite(r.objective)


MapFunction = Callable[..., list[Result]]


def global_search(
    solve: Callable[[np.ndarray], Result],
    starts: TiltedStarts,
    own: Sequence[np.ndarray] = (),
    max_starts: int | None = None,
    agree: int = 3,
    target: float | None = None,
    workers: int = 1,
    seed: int = 0,
    time_limit: float | None = None,
    parallel_map: MapFunction | None = None,
    rel_tol: float = OBJECTIVE_TIE_TOL,
    abs_tol: float = 0.0,
    polish: Callable[[np.ndarray, Result], Result] | None = None,
    least_violation: LeastViolationFrom | None = None,
) -> Result:
    """The best result of local solves from ``own`` then tilted starts, with its record.

    Parameters
    ----------
    solve
        x0 -> Result (a solver built once; forked workers inherit it).
    starts
        The tilted draws (:class:`~optdesign.search.starts.TiltedStarts`).
    own
        The caller's starts, solved first and never counted by the odds.
    max_starts
        The most starts in all, ``own`` included (None: :func:`default_max_starts`).
    agree, target
        The stopping rule's (:class:`StopRule`).
    workers, parallel_map
        Local processes and the map that runs starts on them (``parallel_map(solve,
        starts, workers, stop=...)`` -> the shortest prefix on which ``stop`` holds).
    time_limit
        Wall-clock seconds for the whole search: no start begins after it.
    rel_tol, abs_tol
        Values closer than these are one optimum when the optima are counted (the best
        start is chosen with ``rel_tol`` alone, :func:`~optdesign.solvers.multistart.
        best_of`).
    polish
        (start point, its result) -> the problem itself solved again from the result's end
        (a converged start) or from the start point (a failed one), when ``solve`` solves
        a cheaper stand-in (the problem on fewer grid angles): the answer is then the best
        of the polished starts (:func:`polish_optima`), never a stand-in's result.
    least_violation
        (start point, a failed full solve from it or None) -> the least violation of the
        rows solved from the start (from the full solve's end when given; a phase-1
        solve, :class:`~optdesign.solvers.phase_one.PhaseOneSolver`). Given, a start that fails
        before any start reached a feasible design is followed by it, and while each
        certifies a positive least violation the next starts solve it alone
        (:func:`optdesign.search.infeasible.phase_one_starts`): once they settle a
        verdict by the count an optimum needs (:class:`~optdesign.search.infeasible.
        VerdictRule`) the search stops, its answer marked infeasible (stop ``"least
        violation"``); a phase-1 solve that meets every row, or (with ``polish``) the
        problem itself solved from the verdict's point meeting every row, sends the
        search back to the full solves of the starts it skipped, so a feasible problem's
        starts are those of a search without it.

    Returns
    -------
    Result
        The best start's result (:func:`~optdesign.solvers.multistart.best_of`) with its
        :class:`~optdesign.solvers.result.MultistartInfo`: counts, outcomes, the distinct
        optima, the odds and why it stopped.
    """
    if workers > 1 and parallel_map is None:
        raise ValueError("global_search: workers > 1 needs a parallel_map")
    t0 = time.perf_counter()
    own = [np.asarray(x, dtype=float) for x in own]
    cap = max_starts if max_starts is not None else default_max_starts(len(starts.lower))
    cap = max(1, int(cap))
    dimension = len(starts.lower)
    rule = StopRule(
        min(len(own), cap), agree, target, rel_tol, abs_tol, min_counted_starts(dimension)
    )
    verdict_rule = VerdictRule(min(agree, cap), min(rule.min_counted, cap), target)
    results: list[Result] = []
    points: list[np.ndarray] = []  # each start's point, in start order
    planned = 0
    watch = least_violation is not None and agree > 0
    verdict: PhaseOne | None = None
    polished: Polished | None = None
    refuted: Result | None = None
    with one_blas_thread(), deadline(time_limit):
        while len(results) < cap and (not results or not rule(results)):
            n = min(cap, len(results) + (CHUNK if results or not own else len(own)))
            batch = _starts_between(own, starts, len(results), n)
            planned = n
            before = list(results)

            def stop(tail: list[Result], before=before, watch=watch) -> bool:
                # a failed start with no feasible design seen yet: its phase 1 decides
                return rule(before + tail) or (watch and no_feasible_end(before + tail))

            if workers > 1 and len(batch) > 1:
                results = before + parallel_map(solve, list(batch), workers, stop=stop)
            else:
                for x0 in batch:
                    results.append(solve(x0))
                    if stop(results[len(before) :]):
                        break
            points = (points + list(batch))[: len(results)]
            if watch and no_feasible_end(results) and not rule(results):
                verdict = phase_one_starts(
                    least_violation,
                    solve,
                    lambda a, b: _starts_between(own, starts, a, b),
                    results,
                    cap,
                    verdict_rule,
                    workers,
                    parallel_map,
                )
                planned = max(planned, verdict.end)
                watch = verdict.feasible is None  # a feasible design seen: never again
                if verdict.proved and polish is not None:
                    # the verdict's point to report: the problem itself, which may refute it
                    polished = _polish(results, points, polish, rule, 1)
                    if _feasible(polished.best):
                        refuted, polished, watch = polished.best, None, False
                        verdict.stop = ""
                if verdict.stop:
                    break
        why = (verdict.stop if verdict else "") or rule.reason(results) or "all starts run"
    if polish is not None and polished is None:
        polished = _polish(results, points, polish, rule, MAX_POLISHED)
    if refuted is not None:
        polished = _with_refuting(polished, refuted)
    best = _best_with_record(
        results,
        rule,
        why,
        planned,
        cap,
        seed,
        workers,
        time_limit,
        t0,
        polished,
        verdict.outcomes if verdict is not None and verdict.stop else (),
    )
    if verdict is not None and verdict.proved:
        mark_infeasible(best, verdict)
    return best


#: Most local optima of a stand-in search solved again on the problem itself.
MAX_POLISHED = 4


def _feasible(r: Result) -> bool:
    return _converged(r) or bool(r.verified)


def _polish(
    results: Sequence[Result],
    points: Sequence[np.ndarray],
    polish: Callable[[np.ndarray, Result], Result],
    rule: StopRule,
    limit: int,
) -> Polished:
    return polish_optima(results, lambda k: polish(points[k], results[k]), rule, limit)


def _with_refuting(polished: Polished | None, refuting: Result) -> Polished:
    """The answer of a search whose verdict of infeasibility the problem itself refuted
    (a stand-in's least violated start, solved again, met every row): the better of that
    design and the search's own answer, noted."""
    refuting.notes.append(
        "the stand-in's phase-1 starts agreed on a positive least violation, but the "
        "problem itself, solved from the least violated of them, met every row: the "
        "search went on with full solves"
    )
    if polished is None or not _feasible(polished.best):
        return Polished(refuting, (polished.count if polished else 0) + 1)
    if refuting.objective < polished.best.objective - tie_width(
        polished.best.objective, CHOICE_TOL
    ):
        return Polished(refuting, polished.count + 1)
    polished.best.notes.append(refuting.notes[-1])
    return Polished(polished.best, polished.count + 1)


#: How far (relative) above the best polished value a stand-in optimum may lie, beyond
#: the largest rise seen from stand-in to problem, and still be polished: the stand-in's
#: values are not an exact lower bound where an objective averages over the grid.
POLISH_SLACK = 1e-3


@dataclass
class Polished:
    """The answer of a stand-in search: the best polished result and how many of the
    stand-in's local optima were polished."""

    best: Result
    count: int


def polish_optima(
    results: Sequence[Result],
    polish: Callable[[int], Result],
    rule: StopRule,
    max_failed: int = MAX_POLISHED,
) -> Polished:
    """The stand-in search's local optima solved again on the problem itself, best first,
    until the next one cannot beat the best polished value: its stand-in value lies above
    that value by more than the largest rise from stand-in to problem seen so far (a
    stand-in on a subset of the grid angles is a relaxation, so its value is below the
    problem's near each optimum), plus :data:`POLISH_SLACK`; at most :data:`MAX_POLISHED`.
    Starts at an optimum already polished (within the rule's tie) are skipped. No start
    converged: the least violated starts (at most :data:`MAX_POLISHED`) are solved again
    and the least violated of those is the answer, so that it belongs to the problem
    (``max_failed`` of them: 1 when the search has already proved infeasibility and only
    the point to report is wanted). ``polish(k)`` solves again from start ``k``."""
    order = sorted(range(len(results)), key=lambda k: results[k].objective)
    ok = [k for k in order if _converged(results[k])]
    if not ok:  # no optimum: the least violated starts, solved again
        least = sorted(range(len(results)), key=lambda k: violation(results[k]))
        again = [polish(k) for k in least[:max_failed]]
        return Polished(best_of(again, CHOICE_TOL)[0], len(again))
    best: Result | None = None
    first: Result | None = None
    rise, seen = 0.0, []
    for k in ok:
        r = results[k]
        if any(abs(r.objective - v) <= max(tie_width(v, rule.rel_tol), rule.abs_tol) for v in seen):
            continue
        if best is not None:
            reach = best.objective + rise + tie_width(best.objective, POLISH_SLACK)
            if len(seen) >= MAX_POLISHED or r.objective > reach:
                break
        fine = polish(k)
        seen.append(r.objective)
        first = first or fine
        if _converged(fine):
            rise = max(rise, fine.objective - r.objective)
            if best is None or fine.objective < best.objective - tie_width(
                best.objective, CHOICE_TOL
            ):
                best = fine
    return Polished(best or first, len(seen))


def _starts_between(own: list[np.ndarray], tilted: TiltedStarts, a: int, b: int) -> np.ndarray:
    """Starts ``a`` to ``b - 1`` of the search: the caller's, then the tilted draws."""
    rows = [own[k] for k in range(a, min(b, len(own)))]
    if b > len(own):
        drawn = tilted.first(b - len(own))
        rows += list(drawn[max(0, a - len(own)) :])
    return np.array(rows)


def _best_with_record(
    results: list[Result],
    rule: StopRule,
    why: str,
    planned: int,
    cap: int,
    seed: int,
    workers: int,
    time_limit: float | None,
    t0: float,
    polished: Polished | None = None,
    skipped: Sequence[str] = (),
) -> Result:
    """The best result with the search's record; ``skipped``: the outcomes of the starts
    that solved only their least violation (after the full solves' starts)."""
    _, n_at_best = best_of(results, rule.rel_tol)
    best = polished.best if polished is not None else best_of(results, CHOICE_TOL)[0]
    outcomes = [start_outcome(r) for r in results] + list(skipped)
    timed_out = why == "time limit"
    not_started = max(0, planned - len(results)) if timed_out else 0
    counted = [r.objective for r in results[rule.counted_from :] if _converged(r)]
    found = odds(len(counted), len(rule.optima(counted))) if counted else None
    if timed_out:
        stopped = sum(o == "time limit" for o in outcomes)
        best.notes.append(
            f"time limit of {time_limit:g} s reached: {len(results)} of {planned} starts run "
            f"({stopped} stopped at the limit), {not_started} not started; the odds count "
            "only the starts that converged"
        )
    best.multistart = MultistartInfo(
        n_starts=len(outcomes),
        n_converged=sum(r.success for r in results),
        n_at_best=n_at_best,
        tolerance=rule.rel_tol,
        objectives=[r.objective if r.success else math.nan for r in results]
        + [math.nan] * len(skipped),
        seed=seed,
        workers=workers,
        n_planned=cap,
        stopped_early=len(outcomes) < cap,
        outcomes=outcomes,
        failed=outcome_counts(outcomes + [NOT_STARTED] * not_started),
        optima=rule.optima([r.objective for r in results if _converged(r)]),
        counted=len(counted),
        odds=found,
        stop=why,
        polished=polished.count if polished is not None else 0,
    )
    best.wall_time_s = time.perf_counter() - t0
    return best


def search_globality(info: MultistartInfo | None) -> Globality:
    """What a search's record says of its best value: never proved; its odds, and why
    the search stopped where that limits them."""
    if info is None:
        return Globality(basis="no search")
    if info.odds is None:
        if info.n_converged:
            return Globality(basis="only the caller's own starts converged: no random start")
        return Globality(basis="no start converged")
    basis = {
        "time limit": "the time limit stopped the search",
        "all starts run": (
            f"the search ran all {info.n_starts} starts it was allowed"
            + ("" if settled(info.odds) else " before the odds settled")
        ),
    }.get(info.stop, "")
    return Globality(basis=basis, odds=info.odds)
