"""optdesign.search.starts: each start the best of its own Sobol' group, reproducible
and stable under more draws."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.search.starts import (
    CHUNK,
    NEAR_FEASIBLE,
    TiltedStarts,
    merit_order,
    problem_evaluator,
    tilt,
    tilted_chunk,
)
from optdesign.solvers.sobol import sobol_points


def _bowl(points):
    # objective: distance to (0.7, 0.2); violation: how far x0 + x1 exceeds 1.2
    f = np.hypot(points[:, 0] - 0.7, points[:, 1] - 0.2)
    v = np.maximum(0.0, points[:, 0] + points[:, 1] - 1.2)
    return f, v


def test_merit_puts_nearly_feasible_designs_first_by_objective():
    f = np.array([5.0, 1.0, np.nan, 0.5, 3.0, 2.0])
    v = np.array([0.0, 0.2, 0.0, NEAR_FEASIBLE, np.nan, 0.01])
    # nearly feasible by objective: 3 (0.5), 5 (2.0), 0 (5.0); then violated: 1; then NaN
    # (the NaN objective counts as unusable, with its finite violation 0: before 4)
    assert list(merit_order(f, v)) == [3, 5, 0, 2, 1, 4]


def test_each_start_is_the_best_of_its_group():
    lower, upper = np.zeros(2), np.ones(2)
    starts = tilted_chunk(_bowl, lower, upper, seed=3, chunk=1, size=8, per_start=16)
    assert starts.shape == (8, 2)
    # the same points, drawn here by hand: 8 groups of 16
    from optdesign.search.starts import chunk_seed

    pts = sobol_points(2, 7, chunk_seed(3, 1))[:128]
    for k in range(8):
        group = pts[16 * k : 16 * (k + 1)]
        f, v = _bowl(group)
        ok = v <= NEAR_FEASIBLE
        best = group[ok][np.argmin(f[ok])] if ok.any() else group[np.argmin(v)]
        np.testing.assert_array_equal(starts[k], best)


def test_starts_are_reproducible_and_a_prefix_never_changes():
    a = TiltedStarts(_bowl, np.zeros(2), np.ones(2), seed=5)
    b = TiltedStarts(_bowl, np.zeros(2), np.ones(2), seed=5)
    first = a.first(3).copy()
    many = a.first(CHUNK + 5)
    np.testing.assert_array_equal(many[:3], first)
    np.testing.assert_array_equal(b.first(CHUNK + 5), many)
    other = TiltedStarts(_bowl, np.zeros(2), np.ones(2), seed=6).first(CHUNK)
    assert not np.array_equal(other, many[:CHUNK])


def test_tilted_starts_sit_lower_than_uniform_points():
    starts = TiltedStarts(_bowl, np.zeros(2), np.ones(2), seed=0).first(64)
    uniform = sobol_points(2, 6, 11)
    assert np.median(_bowl(starts)[0]) < 0.5 * np.median(_bowl(uniform)[0])


@pytest.mark.parametrize(("d", "m"), [(1, 4), (2, 8), (3, 16), (7, 32), (9, 64)])
def test_points_per_start_grow_with_the_dimension(d, m):
    assert tilt(d) == m


def test_problem_evaluator_scores_objective_and_violation():
    problem = od.load(Path(__file__).resolve().parents[2] / "problems/cs_min_backlash.toml")
    evaluate = problem_evaluator(problem, "backlash")
    X = np.vstack([problem.midpoint(), problem.lower()])
    f, v = evaluate(X)
    ev = problem.evaluate(X)
    np.testing.assert_array_equal(f, ev.objectives["backlash"])
    np.testing.assert_array_equal(v, ev.violation)
    f0, _ = problem_evaluator(problem, None)(X)
    assert np.all(f0 == 0.0)
