"""optdesign/studies/pareto/metrics.py as a whole, against independent computations: the
non-dominated mask by brute force (with its rule for duplicates), the 2-objective
hypervolume as a sum of rectangles, Schott's spacing and Deb's spread written out by
loops, the reference point by hand, and the edge cases (fewer than 3 points, flat
objectives, non-finite rows)."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from optdesign.studies.pareto.metrics import (
    front_metrics,
    hypervolume,
    non_dominated,
    reference_point,
    spacing,
    spread,
)


def _brute_non_dominated(F):
    """Rows no other row dominates; among rows equal to 1e-9 relative, the first stays."""
    n = len(F)
    keep = []
    for i in range(n):
        if not np.isfinite(F[i]).all():
            keep.append(False)
            continue
        dup_before = any(
            np.isfinite(F[j]).all() and np.allclose(F[j], F[i], rtol=1e-9, atol=0.0)
            for j in range(i)
        )
        dominated = any(
            np.isfinite(F[j]).all()
            and not np.allclose(F[j], F[i], rtol=1e-9, atol=0.0)
            and (F[j] <= F[i]).all()
            and (F[j] < F[i]).any()
            for j in range(n)
        )
        keep.append(not dominated and not dup_before)
    return np.array(keep)


def _hv2(F, ref):
    """2-objective hypervolume: rectangles of the staircase, sorted by the first."""
    P = sorted(tuple(p) for p in F if (p < ref).all())
    total, best_y = 0.0, ref[1]
    for x, y in P:
        if y < best_y:
            total += (ref[0] - x) * (best_y - y)
            best_y = y
    return total


points = st.lists(st.tuples(st.integers(0, 6), st.integers(0, 6)), min_size=1, max_size=9).map(
    lambda rows: np.array(rows, dtype=float)
)


@given(points)
def test_the_mask_equals_brute_force(F):
    assert non_dominated(F).tolist() == _brute_non_dominated(F).tolist()


@given(points)
def test_the_hypervolume_equals_the_sum_of_rectangles(F):
    ref = np.array([7.0, 7.5])
    assert hypervolume(F, ref) == pytest.approx(_hv2(F, ref), abs=1e-12)


def test_the_mask_by_hand_with_duplicates_and_non_finite_rows():
    F = np.array(
        [
            [1.0, 5.0],
            [2.0, 2.0],
            [2.0 * (1 + 1e-12), 2.0],  # a rounding duplicate: the first of them stays
            [3.0, 3.0],  # dominated by (2, 2)
            [math.nan, 0.0],  # never on the front
            [0.0, math.inf],
            [4.0, 1.0],
            [4.0, 1.0 * (1 + 1e-6)],  # no duplicate at 1e-6: dominated by (4, 1)
        ]
    )
    assert non_dominated(F).tolist() == [True, True, False, False, False, False, True, False]
    # the duplicate that comes first stays, whichever it is
    assert non_dominated(F[[2, 1]]).tolist() == [True, False]
    assert non_dominated(np.zeros((0, 2))).tolist() == []


def test_the_reference_point_is_the_nadir_plus_a_tenth_of_the_range():
    F = np.array([[1.0, 8.0], [3.0, 4.0], [5.0, 2.0]])
    assert reference_point(F).tolist() == pytest.approx([5.4, 8.6])
    assert reference_point(F, margin=0.5).tolist() == pytest.approx([7.0, 11.0])
    # a flat objective takes its own size (or 1e-12 at zero) as its range
    flat = np.array([[2.0, -3.0], [4.0, -3.0]])
    assert reference_point(flat).tolist() == pytest.approx([4.2, -2.7])
    zero = np.array([[0.0, 1.0], [0.0, 2.0]])
    assert reference_point(zero)[0] == pytest.approx(1e-13)


def test_the_hypervolume_by_hand():
    F = np.array([[1.0, 3.0], [2.0, 1.0]])
    assert hypervolume(F, np.array([4.0, 4.0])) == pytest.approx(3 * 1 + 2 * 2)
    assert hypervolume(F, [4, 4]) == pytest.approx(7.0)
    assert hypervolume(np.zeros((0, 2))) == 0.0
    # default reference point: (2.1, 3.2)
    assert hypervolume(F) == pytest.approx(1.1 * 0.2 + 0.1 * 2.2 - 0.1 * 0.2)


def _spacing_by_loop(F):
    Z = (F - F.min(axis=0)) / np.where(np.ptp(F, axis=0) > 0, np.ptp(F, axis=0), 1.0)
    d = []
    for i in range(len(Z)):
        d.append(min(np.abs(Z[i] - Z[j]).sum() for j in range(len(Z)) if j != i))
    d = np.array(d)
    return math.sqrt(((d - d.mean()) ** 2).sum() / (len(d) - 1))


@pytest.mark.parametrize(
    "F",
    [
        np.array([[0.0, 4.0], [1.0, 2.0], [3.0, 1.0], [6.0, 0.0]]),
        np.array([[0.0, 1.0, 5.0], [1.0, 0.0, 2.0], [2.0, 2.0, 0.0], [0.5, 0.5, 0.5]]),
        np.array([[0.0, 1.0], [1.0, 1.0], [3.0, 1.0]]),  # a flat objective
    ],
)
def test_the_spacing_equals_schotts_formula_by_loop(F):
    assert spacing(F) == pytest.approx(_spacing_by_loop(F), rel=1e-12)


def test_spacing_and_spread_of_fewer_than_three_points_are_zero():
    two = np.array([[0.0, 1.0], [1.0, 0.0]])
    assert spacing(two) == 0.0 and spread(two) == 0.0
    even = np.array([[0.0, 2.0], [1.0, 1.0], [2.0, 0.0]])
    assert spacing(even) == pytest.approx(0.0, abs=1e-15)
    assert spread(even) == pytest.approx(0.0, abs=1e-15)


def test_the_spread_by_hand():
    # gaps after normalising to [0, 1]^2: sqrt(2)/4 * (1, 3) from the points below
    F = np.array([[0.0, 4.0], [1.0, 3.0], [4.0, 0.0]])
    d = np.array([math.hypot(0.25, 0.25), math.hypot(0.75, 0.75)])
    mean = d.mean()
    assert spread(F) == pytest.approx(np.abs(d - mean).sum() / (2 * mean), rel=1e-12)
    # in any row order
    assert spread(F[[2, 0, 1]]) == pytest.approx(spread(F), rel=1e-12)
    # the true extremes add their distances to the front's ends (in either order)
    E = np.array([[4.4, -0.4], [-0.4, 4.4]])
    Z_e = (E - [0.0, 0.0]) / 4.0
    d_f = float(np.linalg.norm(np.array([0.0, 1.0]) - Z_e[1]))
    d_l = float(np.linalg.norm(np.array([1.0, 0.0]) - Z_e[0]))
    expected = (d_f + d_l + np.abs(d - mean).sum()) / (d_f + d_l + 2 * mean)
    assert spread(F, extremes=E) == pytest.approx(expected, rel=1e-12)
    assert spread(F, extremes=E[::-1]) == pytest.approx(expected, rel=1e-12)
    assert expected > spread(F)  # extremes beyond the ends widen it (they were ignored)
    # bounds given: normalised by them, not by the front's range
    bounds = (np.array([0.0, 0.0]), np.array([8.0, 8.0]))
    assert spread(F, bounds=bounds) == pytest.approx(spread(F), rel=1e-12)
    assert spacing(F, bounds=bounds) == pytest.approx(spacing(F) / 2, rel=1e-12)


def test_the_spread_of_three_objectives_uses_nearest_neighbours():
    F = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.2, 0.2, 0.2]])
    Z = F  # already spans [0, 1] in each objective
    d = np.array([min(np.linalg.norm(Z[i] - Z[j]) for j in range(4) if j != i) for i in range(4)])
    expected = np.abs(d - d.mean()).sum() / (len(d) * d.mean())
    assert spread(F) == pytest.approx(expected, rel=1e-12)


def test_the_spread_of_coincident_points_is_zero():
    assert spread(np.ones((4, 2))) == 0.0


def test_front_metrics_measure_the_non_dominated_points_only():
    F = np.array([[0.0, 4.0], [1.0, 2.0], [2.0, 2.5], [4.0, 0.0]])  # (2, 2.5) is dominated
    P = F[[0, 1, 3]]
    m = front_metrics(F)
    assert (m["n_points"], m["n_nondominated"]) == (4, 3)
    assert m["reference_point"] == pytest.approx(reference_point(P).tolist())
    assert m["hypervolume"] == pytest.approx(_hv2(P, reference_point(P)), rel=1e-12)
    assert m["spacing"] == pytest.approx(spacing(P)) and m["spread"] == pytest.approx(spread(P))
    given_ref = front_metrics(F, ref=[5.0, 5.0])
    assert given_ref["reference_point"] == [5.0, 5.0]
    assert given_ref["hypervolume"] == pytest.approx(_hv2(P, np.array([5.0, 5.0])))
    assert front_metrics(np.zeros((0, 2))) == {
        "n_points": 0,
        "n_nondominated": 0,
        "hypervolume": 0.0,
    }


def test_every_pair_of_a_front_is_mutually_non_dominated():
    F = np.array(list(itertools.product(range(4), range(4))), dtype=float)
    P = F[non_dominated(F)]
    assert P.tolist() == [[0.0, 0.0]]


# --- metrics ------------------------------------------------------------------------------
def test_the_spread_of_coincident_or_evenly_spaced_points_is_zero():
    """Points that all coincide have no uneven gap: their spread is 0, not NaN."""
    from optdesign.studies.pareto.metrics import spread

    F = np.array([[1.0, 2.0], [1.0, 2.0], [1.0, 2.0]])
    assert spread(F) == 0.0
    assert spread(np.array([[0.0, 2.0], [1.0, 1.0], [2.0, 0.0]])) == 0.0  # even gaps
