"""optdesign.search.infeasible through the global search: a search whose starts fail
stops once its phase-1 solves settle a verdict by the count an optimum needs (``agree``
of them at the least positive least violation, two per free variable certified, the odds
of a lower minimum settled; at the cap on starts, the first two), marked infeasible with
its outcomes; a phase-1 solve that meets every row, or the problem itself solved from the
verdict's point, sends it back to the full solves, whose starts are then those of a search
without phase 1; a search that converges never asks for one."""

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
    """One minimum (to within the tie, 1e-4 relative) from every start: the odds of a
    lower one settle after 8 starts (Boender and Rinnooy Kan: 2 / (n - 3) < 1/2 unseen),
    more than ``agree`` and than the 4 a two-variable search counts."""
    calls = Calls(_failed, lambda k, end: _least(0.2 * (1 + 1e-6 * k)))
    best = global_search(
        calls.solve, _starts(), max_starts=32, agree=3, least_violation=calls.least_violation
    )
    ms = best.multistart
    assert best.status == "infeasible" and not best.success
    assert ms.stop == "least violation"
    # one full solve, then its phase 1 and those of the next seven starts alone
    assert calls.solves == 1 and calls.phase_ones == 8
    assert ms.outcomes == ["iteration limit"] + [CERTIFIED] * 7
    assert ms.n_starts == 8 and ms.n_converged == 0
    assert "least violation 0.2 (phase 1, 8 starts)" in best.message
    assert any(
        "8 of them reached it; 1 distinct positive minima, a lower one unseen with an "
        "estimated probability of 0.036" in note
        for note in best.notes
    )


def test_three_agreeing_starts_are_not_a_verdict_in_ten_dimensions():
    """A ten-variable search needs 20 certified starts, as it needs 20 converged starts
    before it reads an optimum's odds: a knee linkage had three starts agree on a least
    violation of 0.0194 where a quarter of its starts reach a feasible design. Here the
    20th start is feasible: the search goes back to its full solves."""
    lower, upper = np.zeros(10), np.ones(10)
    starts = TiltedStarts(lambda p: (np.zeros(len(p)), np.zeros(len(p))), lower, upper, 0)
    calls = Calls(_failed, lambda k, end: _least(0.0194 if k < 20 else -1e-9))
    best = global_search(
        calls.solve, starts, max_starts=120, agree=3, least_violation=calls.least_violation
    )
    assert best.status != "infeasible" and best.multistart.stop != "least violation"
    assert calls.phase_ones == 20


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
    assert calls.phase_ones == 32  # every start allowed, each certified, none agreeing


def test_a_later_start_at_the_least_violation_completes_the_agreement():
    """Two minima, 0.2 and 0.35: the odds of a third settle after 17 starts (w = 2:
    2 (n - 1) / (n - 4) - 2 < 1/2)."""
    values = iter([0.2, 0.35] * 20)
    calls = Calls(_failed, lambda k, end: _least(next(values)))
    best = global_search(
        calls.solve, _starts(), max_starts=32, agree=3, least_violation=calls.least_violation
    )
    assert best.multistart.stop == "least violation" and best.status == "infeasible"
    assert calls.phase_ones == 17
    assert any("9 of them reached it; 2 distinct positive minima" in n for n in best.notes)


def test_the_agreement_needed_is_capped_by_the_starts_allowed():
    """At the cap the odds are not asked (an optimum's search ends there too), and the
    note says they had not settled."""
    calls = Calls(_failed, lambda k, end: _least(0.2))
    best = global_search(
        calls.solve, _starts(), max_starts=2, agree=3, least_violation=calls.least_violation
    )
    assert best.status == "infeasible" and best.multistart.stop == "least violation"
    assert (calls.solves, calls.phase_ones) == (1, 2)
    assert any("the cap on starts came before the odds" in n for n in best.notes)


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


def test_a_verdict_the_problem_itself_refutes_sends_the_search_back_to_its_full_solves():
    """A stand-in search (``polish`` solves the problem itself) whose phase-1 starts agree:
    the problem solved from the verdict's point meets every row, so the answer is that
    design, never "infeasible" with a design that meets the requirements."""

    def polish(x0, end):
        return Result(
            status="optimal",
            objective=2.0,
            formulation="test",
            termination=TerminationCondition.CONVERGED,
            verified=True,
        )

    calls = Calls(_failed, lambda k, end: _least(0.2))
    best = global_search(
        calls.solve,
        _starts(),
        max_starts=32,
        agree=3,
        least_violation=calls.least_violation,
        polish=polish,
    )
    assert best.status == "optimal" and best.objective == 2.0
    assert best.multistart.stop == "no feasible start"  # the full solves all failed
    assert calls.phase_ones == 8 and calls.solves > 1
    assert any("met every row: the search went on" in n for n in best.notes)
    assert "phase 1" not in best.message
