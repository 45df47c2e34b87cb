"""optdesign.search.global_phase: the search on a made-up landscape whose regions of
attraction are known - what it finds, when it stops, what it counts - and the same
answer on one or two workers."""

from __future__ import annotations

import time

import numpy as np
import pytest

from optdesign.runtime.inherited_map import map_inherited
from optdesign.search.global_phase import (
    FAILED_LIMIT,
    MAX_POLISHED,
    StopRule,
    default_max_starts,
    distinct_optima,
    global_search,
    min_counted_starts,
    search_globality,
)
from optdesign.search.odds import odds
from optdesign.search.starts import TiltedStarts
from optdesign.solvers.result import Result

#: Centres of the regions of attraction (nearest centre wins) and their optimum values.
CENTRES = np.array([[0.1, 0.1], [0.9, 0.2], [0.5, 0.8], [0.95, 0.95]])
VALUES = np.array([3.0, 2.0, 1.5, 1.0])  # the best optimum has the smallest region


def _region(x):
    return int(np.argmin(np.linalg.norm(CENTRES - np.asarray(x), axis=1)))


def local_solve(x0):
    """The local solver of the landscape: the optimum of the start's region."""
    k = _region(x0)
    return Result(
        status="optimal",
        objective=float(VALUES[k]),
        design={"x": float(CENTRES[k, 0]), "y": float(CENTRES[k, 1])},
        formulation="test",
        verified=True,
    )


def failing_solve(x0):
    return Result(status="failed", objective=float("nan"), formulation="test")


def sample(points):
    """The NumPy path's view of the landscape: a bowl around each centre, rising to the
    region's edge, at the region's optimum value."""
    d = np.linalg.norm(points[:, None, :] - CENTRES[None], axis=2)
    k = np.argmin(d, axis=1)
    return VALUES[k] + d[np.arange(len(points)), k], np.zeros(len(points))


def starts(seed=0):
    return TiltedStarts(sample, np.zeros(2), np.ones(2), seed)


def test_uniform_starts_see_every_region_and_stop_on_their_odds():
    uniform = TiltedStarts(sample, np.zeros(2), np.ones(2), 0, per_start=1)
    best = global_search(local_solve, uniform, max_starts=200)
    ms = best.multistart
    assert best.objective == 1.0
    assert ms.stop == "odds"
    assert ms.optima == [1.0, 1.5, 2.0, 3.0]
    assert ms.counted == ms.n_starts  # no start of the caller's
    assert ms.odds == odds(ms.counted, 4)
    assert ms.odds.expected_unseen < 0.5
    assert ms.n_at_best == ms.objectives.count(1.0) >= 3


def test_tilted_starts_reach_the_best_region_more_often_than_uniform_ones():
    uniform = TiltedStarts(sample, np.zeros(2), np.ones(2), 0, per_start=1).first(256)
    tilted = starts().first(256)
    share = [np.mean([_region(x) == 3 for x in pts]) for pts in (uniform, tilted)]
    assert share[0] < 0.15 and share[1] > 2 * share[0]
    best = global_search(local_solve, starts(), max_starts=200)
    assert best.objective == 1.0 and best.multistart.stop == "odds"
    assert best.multistart.optima[0] == 1.0


def test_the_callers_starts_come_first_and_are_not_counted():
    own = [np.array([0.96, 0.96]), np.array([0.9, 0.9])]
    best = global_search(local_solve, starts(), own=own, max_starts=40)
    ms = best.multistart
    assert ms.objectives[:2] == [1.0, 1.0]
    assert ms.counted == ms.n_starts - 2


def test_agree_zero_runs_every_start():
    best = global_search(local_solve, starts(), max_starts=21, agree=0)
    assert best.multistart.n_starts == 21 and best.multistart.stop == "all starts run"
    assert not best.multistart.stopped_early


def test_a_search_with_no_feasible_end_stops():
    best = global_search(failing_solve, starts(), max_starts=100)
    assert best.multistart.n_starts == FAILED_LIMIT
    assert best.multistart.stop == "no feasible start"
    assert best.multistart.odds is None
    assert "no start converged" in search_globality(best.multistart).text()


def test_a_time_limit_stops_the_search():
    def slow(x0):
        time.sleep(0.02)
        return local_solve(x0)

    best = global_search(slow, starts(), max_starts=500, agree=0, time_limit=0.1)
    ms = best.multistart
    assert ms.stop == "time limit" and ms.n_starts < 20
    assert "time limit" in search_globality(ms).text()
    assert any("time limit of 0.1 s" in n for n in best.notes)


def test_a_cap_reached_before_the_odds_settle_is_said():
    best = global_search(local_solve, starts(), max_starts=6)
    text = search_globality(best.multistart).text()
    assert text.startswith("not proved; ")
    assert "ran all 6 starts it was allowed before the odds settled" in text


def test_one_and_two_workers_give_the_same_search():
    one = global_search(local_solve, starts(3), max_starts=200)
    two = global_search(
        local_solve, starts(3), max_starts=200, workers=2, parallel_map=map_inherited
    )
    a, b = one.multistart, two.multistart
    assert (a.n_starts, a.objectives, a.optima, a.odds, a.stop) == (
        b.n_starts,
        b.objectives,
        b.optima,
        b.odds,
        b.stop,
    )
    assert one.design == two.design


def test_distinct_optima_chain_ties():
    values = [1.0, 1.0 + 5e-7, 1.0 + 1.2e-6, 2.0, float("nan"), 2.0 - 1e-9]
    assert distinct_optima(values) == [1.0, 1.0 + 1.2e-6, 2.0 - 1e-9]


def test_the_stop_rule_needs_agreement_and_settled_odds():
    rule = StopRule(counted_from=0, agree=3)
    same = [local_solve(CENTRES[3])] * 7
    assert rule.reason(same) == ""  # 2 / (7 - 3) = 0.5 optima expected unseen: not yet
    assert rule.reason([*same, local_solve(CENTRES[3])]) == "odds"
    assert StopRule(counted_from=0, agree=9).reason(same + same[:1]) == ""
    assert StopRule(counted_from=0, agree=0).reason(same * 5) == ""


@pytest.mark.parametrize(("d", "cap"), [(1, 32), (2, 32), (5, 60), (7, 84)])
def test_the_cap_grows_with_the_dimension(d, cap):
    assert default_max_starts(d) == cap


def test_the_stop_rule_waits_for_two_counted_starts_per_variable():
    # ten free variables: the odds alone would stop after 8 agreeing starts
    rule = StopRule(counted_from=0, agree=3, min_counted=min_counted_starts(10))
    same = [local_solve(CENTRES[3])] * 19
    assert min_counted_starts(10) == 20
    assert rule.reason(same) == ""
    assert rule.reason([*same, local_solve(CENTRES[3])]) == "odds"


def test_failed_starts_at_a_feasible_design_keep_the_search_going():
    # a start may stop on its iteration limit at a design the NumPy model finds
    # feasible: a feasible design exists, the search must not call it hopeless
    def stopped_at_a_feasible_design(x0):
        return Result(status="max_iterations", objective=2.0, formulation="test", verified=True)

    best = global_search(stopped_at_a_feasible_design, starts(), max_starts=20)
    assert best.multistart.n_starts == 20 and best.multistart.stop == "all starts run"
    rule = StopRule(counted_from=0, agree=3)
    assert rule.reason([failing_solve(None)] * FAILED_LIMIT) == "no feasible start"


def test_agree_zero_runs_every_start_even_when_none_converges():
    best = global_search(failing_solve, starts(), max_starts=12, agree=0)
    assert best.multistart.n_starts == 12 and best.multistart.stop == "all starts run"


# --- a search on a stand-in (the grid thinned), its optima polished on the problem -----
#: The stand-in's optimum in each region: at or below the problem's (a relaxation), and
#: ranked otherwise - its best region (1) is the problem's third.
STAND_IN = np.array([3.0, 0.9, 1.5, 0.99])
PROBLEM = np.array([3.0, 2.0, 1.5, 1.0])


def stand_in_solve(x0):
    result = local_solve(x0)
    result.objective = float(STAND_IN[_region(x0)])
    return result


def polish_in_region(x0, end):
    """The problem solved again from a start's end (converged) or its point (failed)."""
    point = [end.design["x"], end.design["y"]] if end.success else x0
    result = local_solve(point)
    result.objective = float(PROBLEM[_region(point)])
    return result


def test_polishing_reaches_the_problems_best_optimum_where_the_stand_in_ranks_another_first():
    polished = []

    def polish(x0, end):
        polished.append(_region([end.design["x"], end.design["y"]]))
        return polish_in_region(x0, end)

    uniform = TiltedStarts(sample, np.zeros(2), np.ones(2), 1, per_start=1)
    r = global_search(stand_in_solve, uniform, max_starts=60, agree=0, polish=polish)
    assert r.objective == 1.0 and r.design == {"x": 0.95, "y": 0.95}
    # best stand-in first (0.9, region 1: rises by 1.1 to 2.0), then 0.99 (to 1.0, the
    # best), then 1.5 (still below 1.0 + 1.1); region 0's 3.0 is above that reach
    assert polished == [1, 3, 2] and r.multistart.polished == 3
    # the record's values are the stand-in's
    assert min(r.multistart.objectives) == 0.9 and r.multistart.optima[0] == 0.9


def test_polishing_stops_after_the_best_when_the_stand_in_equals_the_problem():
    # the next optimum (1.5) lies above the best (1.0) by more than the slack: not polished
    def exact(x0, end):
        return local_solve([end.design["x"], end.design["y"]])

    r = global_search(local_solve, starts(2), max_starts=60, agree=0, polish=exact)
    assert r.objective == 1.0 and r.multistart.polished == 1


def test_with_no_converged_start_the_least_violated_starts_are_solved_again_from_their_points():
    seen, again = [], []

    def failed_near(x0):
        result = failing_solve(x0)
        result.max_violation = float(np.linalg.norm(np.asarray(x0) - CENTRES[2]))
        return result

    def polish(x0, end):
        seen.append((tuple(x0), end.max_violation))
        again.append(polish_in_region(x0, end))
        return again[-1]

    r = global_search(failed_near, starts(0), max_starts=10, agree=0, polish=polish)
    assert len(seen) == MAX_POLISHED == r.multistart.polished
    # the four least violated, least first, each from its own start point
    violations = [v for _, v in seen]
    assert violations == sorted(violations)
    assert all(v == pytest.approx(np.linalg.norm(np.array(x) - CENTRES[2])) for x, v in seen)
    assert r.success and r.objective == min(a.objective for a in again)


def test_a_stand_in_search_gives_the_same_answer_on_one_and_two_workers():
    one = global_search(stand_in_solve, starts(4), max_starts=40, polish=polish_in_region)
    two = global_search(
        stand_in_solve,
        starts(4),
        max_starts=40,
        polish=polish_in_region,
        workers=2,
        parallel_map=map_inherited,
    )
    assert (one.objective, one.design, one.multistart.polished) == (
        two.objective,
        two.design,
        two.multistart.polished,
    )
