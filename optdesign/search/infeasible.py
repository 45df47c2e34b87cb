"""The global search's verdict on a problem with no feasible design: starts that agree on
a positive least violation, counted as the starts of an optimum are.

A start that fails before any start reached a feasible design is followed by a phase-1
solve from its point (the least violation of the rows,
:class:`~optdesign.solvers.phase_one.PhaseOneSolver`). Its positive minimum says no
feasible design lies near that start; the next starts then solve that cheaper problem
alone (:func:`phase_one_starts`) until the search can stop:

- the phase-1 solves settle a verdict (:class:`VerdictRule`) by the count an optimum
  needs: ``agree`` starts at the least positive least violation found (within
  :data:`LEAST_VIOLATION_TIE`), the counted starts a search of that dimension reads its
  odds after (two per free variable), and Boender and Rinnooy Kan's odds of a lower
  minimum, over the distinct positive minima certified, settled. The search's answer is
  then infeasible (stop ``"least violation"``): local solves from independent starts
  agreeing on one value, the evidence the odds give an optimum, never a proof. Fewer do
  not suffice: a ten-variable knee linkage at 350 N*m had three starts agree on a least
  violation of 0.0194, yet a quarter of its starts reach feasible designs; and starts
  that end at different positive minima do not agree (Watt's six-bar for its least
  ripple, seed 2: 0.200, 0.147 and 18.8, then a fourth start met every row);
- one of them met every row: a feasible design exists, and the search goes back to the
  full solves of the starts it skipped (its starts are those of a search without phase 1);
- the search's cap on starts or the time limit, unsettled: stop
  ``"no feasible start"``.

The decisions read the starts in their order (each map returns the shortest prefix on
which its stop rule holds), so the answer does not depend on the number of workers.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from optdesign.search.odds import distinct_optima, odds, settled
from optdesign.search.starts import CHUNK
from optdesign.solvers.deadline import passed
from optdesign.solvers.multistart import tie_width
from optdesign.solvers.phase_one import LeastViolation
from optdesign.solvers.result import Odds, Result, SolutionStatus, TerminationCondition

#: Two least violations closer than this (relative) are one minimum: a phase-1 solve
#: converges to Ipopt's tight tolerance, so starts at one minimum agree far closer.
LEAST_VIOLATION_TIE = 1e-4

#: The outcome of a start that solved only its least violation, by what it found.
CERTIFIED = "least violation above 0 (phase 1)"
UNSETTLED = "phase 1 did not converge"


@dataclass
class PhaseOne:
    """What the phase-1 solves of a search found.

    ``found``: the phase-1 solves in start order, from the failed start ``first`` on;
    ``feasible``: the index of the start whose phase 1 met every row (None: none);
    ``end``: the index after the last start solved; ``stop``: why the search stops
    (``""``: it goes on with full solves)."""

    first: int
    found: list[LeastViolation] = field(default_factory=list)
    feasible: int | None = None
    stop: str = ""

    @property
    def end(self) -> int:
        return self.first + len(self.found)

    @property
    def proved(self) -> bool:
        return self.stop == "least violation"

    @property
    def least(self) -> float:
        """The least positive least violation found (NaN: none)."""
        values = [v.value for v in self.found if v.certified]
        return min(values) if values else float("nan")

    @property
    def certified(self) -> int:
        """Phase-1 solves that certified a positive least violation."""
        return sum(v.certified for v in self.found)

    @property
    def agreeing(self) -> int:
        """Phase-1 solves at the least positive least violation."""
        least = self.least
        return sum(
            v.certified and v.value <= least + tie_width(least, LEAST_VIOLATION_TIE)
            for v in self.found
        )

    @property
    def minima(self) -> list[float]:
        """The distinct positive least violations certified, least first."""
        values = [v.value for v in self.found if v.certified]
        return distinct_optima(values, LEAST_VIOLATION_TIE)

    @property
    def odds(self) -> Odds:
        """The odds of a lower positive minimum, from the certified solves."""
        return odds(self.certified, len(self.minima))

    @property
    def outcomes(self) -> list[str]:
        """The outcomes of the starts that solved only their least violation."""
        return [CERTIFIED if v.certified else UNSETTLED for v in self.found[1:]]


@dataclass(frozen=True)
class VerdictRule:
    """When phase-1 solves settle a verdict of infeasibility: the count an optimum needs
    (:class:`~optdesign.search.global_phase.StopRule`).

    ``agree``: solves at the least positive least violation; ``min_counted``: solves that
    certified a positive least violation before the odds are read; ``target``: the
    estimated probability of a lower minimum the odds must also reach (None: Boender and
    Rinnooy Kan's rule alone). At the search's cap on starts the odds are not asked (as an
    optimum's search ends there, "all starts run"); unsettled there, the search stops
    ``"no feasible start"``."""

    agree: int
    min_counted: int = 0
    target: float | None = None

    def settles(self, verdict: PhaseOne, at_cap: bool = False) -> bool:
        """Whether these phase-1 solves settle the verdict (``at_cap``: the search can
        run no more starts)."""
        if verdict.agreeing < self.agree or verdict.certified < self.min_counted:
            return False
        return at_cap or settled(verdict.odds, self.target)


def no_feasible_end(results: Sequence[Result]) -> bool:
    """No start so far converged or ended at a feasible design, and there is one."""
    return bool(results) and not any(r.success or r.verified for r in results)


LeastViolationFrom = Callable[[np.ndarray, Result | None], LeastViolation]


def after_failure(
    least_violation: LeastViolationFrom,
    x0: np.ndarray,
    failed: Result,
    found: LeastViolation | None = None,
) -> LeastViolation:
    """The least violation from a start whose full solve failed: from its start point
    (``found``, when already solved), else (that phase 1 did not converge) from where the
    full solve ended - often Ipopt's own restoration point, a local minimum of the
    violation already."""
    found = found if found is not None else least_violation(x0, None)
    if found.converged or not failed.design:
        return found
    again = least_violation(x0, failed)
    return again if again.converged else found


def phase_one_attempt(
    least_violation: LeastViolationFrom, solve: Callable[[np.ndarray], Result]
) -> Callable[[np.ndarray], LeastViolation]:
    """A start of the phase-1 mode: its least violation alone; where that does not
    converge, its full solve, then the least violation from the full solve's end. A full
    solve that converges or ends feasible is a feasible design found (value 0)."""

    def attempt(x0: np.ndarray) -> LeastViolation:
        found = least_violation(x0, None)
        if found.converged:
            return found
        full = solve(x0)
        if full.success or full.verified:
            return LeastViolation(0.0, "Solve_Succeeded", found.z, full)
        return after_failure(least_violation, x0, full, found)

    return attempt


def phase_one_starts(
    least_violation: LeastViolationFrom,
    solve: Callable[[np.ndarray], Result],
    starts_between: Callable[[int, int], np.ndarray],
    results: Sequence[Result],
    cap: int,
    rule: VerdictRule,
    workers: int = 1,
    parallel_map: Callable[..., list] | None = None,
) -> PhaseOne:
    """The phase-1 solves from the last of ``results`` (a start that failed with no
    feasible design seen) and, while they certify a positive least violation, from the
    next starts (``starts_between(a, b)``: starts ``a`` to ``b - 1``;
    :func:`phase_one_attempt`), until they settle the verdict (``rule``), one finds a
    feasible design, the cap ``cap`` (starts in all, the failed full solve's included) or
    the time limit."""
    failed = len(results) - 1
    x_failed = starts_between(failed, failed + 1)[0]
    out = PhaseOne(failed, [after_failure(least_violation, x_failed, results[-1])])
    attempt = phase_one_attempt(least_violation, solve)
    if out.found[0].feasible:
        out.feasible = failed
    if not out.found[0].certified:
        return out

    def done(found: list[LeastViolation]) -> bool:
        return found[-1].feasible or rule.settles(PhaseOne(failed, found))

    while not done(out.found) and out.end < cap and not passed():
        batch = list(starts_between(out.end, min(cap, out.end + CHUNK)))
        before = list(out.found)

        def stop(tail: list[LeastViolation], before=before) -> bool:
            return done(before + tail)

        if workers > 1 and len(batch) > 1 and parallel_map is not None:
            out.found = before + parallel_map(attempt, batch, workers, stop=stop)
        else:
            for x0 in batch:
                out.found.append(attempt(x0))
                if stop(out.found[len(before) :]):
                    break
    if out.found[-1].feasible:
        out.feasible = out.end - 1
    elif rule.settles(out, at_cap=out.end >= cap):
        out.stop = "least violation"
    elif passed():
        out.stop = "time limit"
    else:
        out.stop = "no feasible start"
    return out


def mark_infeasible(best: Result, verdict: PhaseOne) -> None:
    """Mark the search's answer infeasible, saying what the phase-1 solves agree on."""
    best.status = "infeasible"
    best.termination = TerminationCondition.INFEASIBLE
    best.solution_status = SolutionStatus.INFEASIBLE
    n, least, at_least = verdict.certified, verdict.least, verdict.agreeing
    found = verdict.odds
    odds_said = (
        f"{found.optima} distinct positive minima, a lower one unseen with an estimated "
        f"probability of {found.p_better:.2g}"
        if settled(found)
        else "the cap on starts came before the odds of a lower minimum settled"
    )
    best.message = (best.message + "; " if best.message else "") + (
        f"least violation {least:.3g} (phase 1, {n} starts)"
    )
    best.notes.append(
        f"no feasible design found from {n} starts (a local verdict, not a proof): the "
        f"violation of the requirements (the largest, each row scaled by its limit) "
        f"minimised from each stays positive, at least {least:.3g} ({at_least} of them "
        f"reached it; {odds_said}); a positive local minimum says no feasible design lies "
        "near its start, not that none exists within the bounds"
    )
