"""The multistart's own Sobol' points against SciPy's (an independent implementation)."""

import numpy as np
import pytest

from optdesign.solvers.sobol import sobol_points


@pytest.mark.parametrize(("d", "m", "seed"), [(1, 3, 0), (4, 3, 7), (7, 4, 12), (12, 6, 3)])
def test_same_points_as_scipy(d, m, seed):
    qmc = pytest.importorskip("scipy.stats.qmc")
    expected = qmc.Sobol(d, scramble=True, seed=seed).random_base2(m)
    np.testing.assert_array_equal(sobol_points(d, m, seed), expected)


def test_points_are_balanced():
    # A (0, m, 1)-net property of Sobol' points: each of the 2^m intervals of width
    # 2^-m holds exactly one point, in every coordinate, after scrambling too.
    pts = sobol_points(5, 4, seed=1)
    for k in range(5):
        cells = np.floor(pts[:, k] * 16).astype(int)
        assert sorted(cells) == list(range(16))


def test_the_kept_points_cannot_be_changed_by_a_caller():
    from optdesign.solvers.multistart import sobol_starts

    pts = sobol_points(3, 2, seed=7)
    assert sobol_points(3, 2, seed=7) is pts  # drawn once per (d, m, seed)
    with pytest.raises(ValueError):
        pts[0, 0] = 0.5
    starts = sobol_starts(np.zeros(3), np.full(3, 2.0), 4, 7)
    starts[0, 0] = -1.0  # the caller's own scaled copy
    np.testing.assert_array_equal(sobol_points(3, 2, seed=7)[1:], pts[1:])
    assert sobol_points(3, 2, seed=7)[0, 0] == pts[0, 0] != -1.0
