"""optdesign/formulations/catalogue/discrete.py as a whole: which variables are catalogue ones, how
many combinations they make, the items in a box (with its tolerance on both sides), the
nearest item and its relative distance, the branch split, and the search coordinates of
population methods (index bounds, integrality, rounding and clipping to items)."""

from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.formulations.catalogue.discrete import (
    ON_ITEM_TOL,
    CatalogueCoordinates,
    branch,
    discrete_variables,
    has_discrete,
    items_within,
    n_combinations,
    nearest_item,
)

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"
P_ITEMS = (2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0)
D_ITEMS = (4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0)


@pytest.fixture(scope="module")
def catalogue():
    return od.load(PROBLEMS / "cs_min_backlash_catalogue.toml")


@pytest.fixture(scope="module")
def continuous():
    return od.load(PROBLEMS / "cs_min_backlash.toml")


def test_the_catalogue_variables_and_their_combinations(catalogue, continuous):
    assert [v.name for v in discrete_variables(catalogue)] == ["p", "d"]
    assert has_discrete(catalogue) is True and has_discrete(catalogue, "ripple") is True
    assert n_combinations(catalogue) == 8 * 9
    assert discrete_variables(continuous) == []
    assert has_discrete(continuous) is False
    assert n_combinations(continuous) == 1


def test_items_within_a_box_with_a_relative_tolerance_at_both_ends():
    assert items_within(D_ITEMS, 5.0, 12.0) == [5.0, 6.0, 8.0, 10.0, 12.0]
    tol = ON_ITEM_TOL * 12.0
    assert items_within(D_ITEMS, 5.0 + 0.5 * tol, 12.0 - 0.5 * tol) == [5.0, 6.0, 8.0, 10.0, 12.0]
    assert items_within(D_ITEMS, 5.0 + 2 * tol, 12.0 - 2 * tol) == [6.0, 8.0, 10.0]
    # below 1 the tolerance is absolute (1e-6), not relative to a small upper end
    small = (0.1, 0.2, 0.3)
    assert items_within(small, 0.1 + 0.5e-6, 0.3 - 0.5e-6) == [0.1, 0.2, 0.3]
    assert items_within(small, 0.1 + 2e-6, 0.3 - 2e-6) == [0.2]
    assert items_within(D_ITEMS, 13.0, 15.0) == []
    # a negative upper end takes its magnitude
    assert items_within((-20.0, -10.0), -20.0 + 1e-5, -10.0) == [-20.0, -10.0]


def test_the_nearest_item_and_its_relative_distance():
    assert nearest_item(7.1, D_ITEMS) == (8.0, pytest.approx(0.9 / 8.0))
    assert nearest_item(6.9, D_ITEMS) == (6.0, pytest.approx(0.9 / 6.0))
    # a tie goes to the first item in the catalogue's order
    assert nearest_item(7.0, D_ITEMS)[0] == 6.0
    assert nearest_item(7.0, D_ITEMS[::-1])[0] == 8.0
    # below 1 the distance is absolute
    assert nearest_item(0.25, (0.2, 0.5)) == (0.2, pytest.approx(0.05))
    assert nearest_item(-3.0, (-4.0, 2.0)) == (-4.0, pytest.approx(0.25))


def test_a_branch_splits_the_items_strictly_around_the_relaxed_value():
    assert branch(7.0, list(D_ITEMS)) == ([4.0, 5.0, 6.0], [8.0, 10.0, 12.0, 16.0, 20.0, 25.0])
    # a value on an item puts it in neither side
    assert branch(8.0, list(D_ITEMS)) == ([4.0, 5.0, 6.0], [10.0, 12.0, 16.0, 20.0, 25.0])
    assert branch(1.0, [2.0, 3.0]) == ([], [2.0, 3.0])


def test_search_coordinates_index_the_catalogue_variables(catalogue):
    coords = CatalogueCoordinates(catalogue)
    assert coords.discrete == [3, 5]
    assert coords.integrality.tolist() == [False, False, False, True, False, True]
    lo, hi = catalogue.lower(), catalogue.upper()
    expected = [(float(a), float(b)) for a, b in zip(lo, hi, strict=True)]
    expected[3], expected[5] = (0.0, 7.0), (0.0, 8.0)
    assert coords.bounds == expected
    assert coords.values[3].tolist() == list(P_ITEMS)
    # the problem's own bounds are left as they were
    assert catalogue.lower()[3] == 2.0 and catalogue.upper()[5] == 25.0


def test_coordinates_map_to_the_nearest_items_clipped_to_the_catalogue(catalogue):
    coords = CatalogueCoordinates(catalogue)
    Z = np.array(
        [
            [50.0, 100.0, 10.0, 2.4, 0.1, 7.6],
            [60.0, 120.0, 20.0, -3.0, 0.2, 99.0],
            [70.0, 140.0, 30.0, 2.5, -0.1, 0.49],
        ]
    )
    X = coords.to_design(Z)
    assert X[:, [0, 1, 2, 4]].tolist() == Z[:, [0, 1, 2, 4]].tolist()
    assert X[:, 3].tolist() == [P_ITEMS[2], P_ITEMS[0], P_ITEMS[2]]  # rint(2.5) = 2 (to even)
    assert X[:, 5].tolist() == [D_ITEMS[8], D_ITEMS[8], D_ITEMS[0]]
    assert Z[0, 3] == 2.4  # the population is left as it was
    one = coords.to_design([50.0, 100.0, 10.0, 7.0, 0.0, 3.0])
    assert one.shape == (6,) and one[3] == 10.0 and one[5] == 8.0
