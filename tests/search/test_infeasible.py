"""optdesign.search.infeasible through the global search: a search whose starts fail
stops once the phase-1 solves of ``min(agree, max_starts)`` starts certify the same
positive least violation, marked infeasible with its outcomes; a phase-1 solve that meets every
row sends it back to the full solves, whose starts are then those of a search without
phase 1; a search that converges never asks for one."""

from __future__ import annotations

import numpy as np

from optdesign.search.global_phase import global_search
from optdesign.search.infeasible import CERTIFIED, UNSETTLED
from optdesign.search.starts import TiltedStarts
from optdesign.solvers.phase_one import LeastViolation
from optdesign.solvers.result import Result, TerminationCondition


def _starts():
    def sample(points):
        return np.linalg.norm(points - 0.5, axis=1), np.zeros(len(points))

    return TiltedStarts(sample, np.zeros(2), np.ones(2), 0)


def _failed(x0):
    return Result(
        status="max_iterations",
        objective=float("nan"),
        formulation="test",
        termination=TerminationCondition.MAX_ITERATIONS,
        design={"x": float(x0[0])},
        max_violation=0.3,
    )


def _least(value, status="Solve_Succeeded"):
    point = Result(status="infeasible", objective=float("nan"), formulation="test")
    return LeastViolation(value, status, np.zeros(2), point)


class Calls:
    """A solve and a least violation that count their calls."""

    def __init__(self, solve, least):
        self.solves, self.phase_ones = 0, 0
        self._solve, self._least = solve, least

    def solve(self, x0):
        self.solves += 1
        return self._solve(x0)

    def least_violation(self, x0, end):
        self.phase_ones += 1
        return self._least(self.phase_ones, end)


def test_starts_that_agree_on_a_positive_least_violation_stop_the_search_as_infeasible():
    # the same minimum to within the tie (1e-4 relative) from three starts
    calls = Calls(_failed, lambda k, end: _least(0.2 * (1 + 1e-6 * k)))
    best = global_search(
        calls.solve, _starts(), max_starts=32, agree=3, least_violation=calls.least_violation
    )
    ms = best.multistart
    assert best.status == "infeasible" and not best.success
    assert ms.stop == "least violation"
    # one full solve, then its phase 1 and those of the next two starts alone
    assert calls.solves == 1 and calls.phase_ones == 3
    assert ms.outcomes == ["iteration limit", CERTIFIED, CERTIFIED]
    assert ms.n_starts == 3 and ms.n_converged == 0
    assert "least violation 0.2 (phase 1, 3 starts)" in best.message
    assert any("3 of them reached it" in note for note in best.notes)


def test_starts_at_different_positive_minima_do_not_agree_on_infeasibility():
    """Each start certifies a positive least violation, but not the same one (a
    violation with several local minima, where another start may reach zero): the
    search runs on to its limit of failed starts and says no start was feasible, never
    that the problem is infeasible."""
    calls = Calls(_failed, lambda k, end: _least(0.2 if k == 1 else 0.3 + 0.1 * k))
    best = global_search(
        calls.solve, _starts(), max_starts=32, agree=3, least_violation=calls.least_violation
    )
    assert best.multistart.stop == "no feasible start"
    assert best.status == "max_iterations" and "phase 1" not in best.message
    assert calls.phase_ones == 8  # FAILED_LIMIT starts, each certified, none agreeing


def test_a_later_start_at_the_least_violation_completes_the_agreement():
    values = iter([0.2, 0.35, 0.2, 0.5, 0.2])
    calls = Calls(_failed, lambda k, end: _least(next(values)))
    best = global_search(
        calls.solve, _starts(), max_starts=32, agree=3, least_violation=calls.least_violation
    )
    assert best.multistart.stop == "least violation" and best.status == "infeasible"
    assert calls.phase_ones == 5
    assert any("3 of them reached it" in note for note in best.notes)


def test_the_agreement_needed_is_capped_by_the_starts_allowed():
    calls = Calls(_failed, lambda k, end: _least(0.2))
    best = global_search(
        calls.solve, _starts(), max_starts=2, agree=3, least_violation=calls.least_violation
    )
    assert best.status == "infeasible" and best.multistart.stop == "least violation"
    assert (calls.solves, calls.phase_ones) == (1, 2)


def test_a_phase_one_that_does_not_converge_falls_back_on_the_full_solve_of_its_start():
    # phase 1 from the second start does not converge; its full solve fails, and the
    # phase 1 from where that ended certifies
    answers = iter([_least(0.2), _least(np.nan, "Maximum_Iterations_Exceeded"), _least(0.2)])
    calls = Calls(_failed, lambda k, end: next(answers))
    best = global_search(
        calls.solve, _starts(), max_starts=2, agree=3, least_violation=calls.least_violation
    )
    assert best.multistart.stop == "least violation"
    assert (calls.solves, calls.phase_ones) == (2, 3)


def test_a_phase_one_meeting_every_row_sends_the_search_back_to_its_full_solves():
    """The third start's phase 1 finds a feasible design: the starts it skipped are
    solved in full, and the search's record is the one a search without phase 1 gives."""

    def solve(x0):
        k = int(np.argmin(np.linalg.norm(_starts().first(32) - x0, axis=1)))
        if k < 2:
            return _failed(x0)
        return Result(status="optimal", objective=1.0, formulation="test", verified=True)

    def least(k, end):
        return _least(0.2 if k < 3 else -1e-9)

    calls = Calls(solve, least)
    best = global_search(
        calls.solve, _starts(), max_starts=32, least_violation=calls.least_violation
    )
    plain = global_search(solve, _starts(), max_starts=32)
    assert best.success and best.objective == plain.objective == 1.0
    assert best.multistart.outcomes == plain.multistart.outcomes
    assert best.multistart.stop == plain.multistart.stop == "odds"
    assert calls.phase_ones == 3


def test_a_search_whose_first_start_converges_never_solves_a_phase_one():
    calls = Calls(
        lambda x0: Result(status="optimal", objective=1.0, formulation="test", verified=True),
        lambda k, end: _least(0.2),
    )
    best = global_search(
        calls.solve, _starts(), max_starts=32, least_violation=calls.least_violation
    )
    assert best.success and calls.phase_ones == 0


def test_phase_ones_that_never_certify_leave_the_search_as_it_was():
    calls = Calls(_failed, lambda k, end: _least(np.nan, "Maximum_Iterations_Exceeded"))
    best = global_search(
        calls.solve, _starts(), max_starts=32, least_violation=calls.least_violation
    )
    plain = global_search(_failed, _starts(), max_starts=32)
    assert best.status == plain.status == "max_iterations"
    assert best.multistart.stop == plain.multistart.stop == "no feasible start"
    assert best.multistart.outcomes == plain.multistart.outcomes
    assert UNSETTLED not in best.multistart.outcomes
