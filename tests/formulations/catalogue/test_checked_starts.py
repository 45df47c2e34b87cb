"""A catalogue node's starts solved on every other grid angle first
(``NodeSolver._solve_checked``): the point kept only when it meets every row, solved
again on the whole grid otherwise, and the same node value as on the whole grid."""

from __future__ import annotations

from pathlib import Path

import pytest

import optdesign as od
from optdesign.formulations.catalogue.node_solver import THINNED_START, NodeSolver
from optdesign.formulations.catalogue.search import solve_catalogue
from optdesign.tolerances import OBJECTIVE_TIE_TOL

ROOT = Path(__file__).resolve().parents[3]
LEAF = {"d0": (25.0, 25.0), "p": (5.0, 5.0), "d": (6.0, 6.0)}
OTHER_LEAF = {"d0": (20.0, 20.0), "p": (5.0, 5.0), "d": (6.0, 6.0)}


@pytest.fixture(scope="module")
def fin():
    return od.load(ROOT / "problems" / "fin_actuator.toml")


def test_a_leaf_whose_rows_are_met_keeps_the_thinned_points(fin):
    checked = NodeSolver(fin, starts=3)
    whole = NodeSolver(fin, starts=3, checked=False)
    a, b = checked.solve(LEAF), whole.solve(LEAF)
    assert a.raw[THINNED_START] == "kept" and THINNED_START not in b.raw
    assert (checked.n_checked, checked.n_resolved, checked.n_solves) == (3, 0, 3)
    assert a.success and not a.violated
    assert a.objective == pytest.approx(b.objective, rel=OBJECTIVE_TIE_TOL)
    for name, value in b.design.items():
        assert a.design[name] == pytest.approx(value, rel=1e-5, abs=1e-8), name


def test_a_leaf_whose_peak_falls_between_the_kept_angles_is_solved_again(fin):
    """Ripple peaks between the kept angles at every start: each start costs two
    solves, its point meets every row, and the next node is solved on the whole grid."""
    checked = NodeSolver(fin, objective="ripple", starts=3)
    whole = NodeSolver(fin, objective="ripple", starts=3, checked=False)
    a, b = checked.solve(LEAF), whole.solve(LEAF)
    assert a.raw[THINNED_START] == "solved again"
    assert (checked.n_checked, checked.n_resolved, checked.n_solves) == (0, 3, 6)
    assert a.success and not a.violated
    assert a.objective == pytest.approx(b.objective, rel=OBJECTIVE_TIE_TOL)
    nxt = checked.solve(OTHER_LEAF)
    assert THINNED_START not in nxt.raw
    assert (checked.n_checked, checked.n_resolved) == (0, 3)  # one NLP solve per start


def test_the_search_finds_the_same_items_and_value_either_way(fin):
    on = solve_catalogue(fin)
    off = solve_catalogue(fin, thinned_starts=False)
    assert on.details.catalogue.items == off.details.catalogue.items
    assert on.objective == pytest.approx(off.objective, rel=OBJECTIVE_TIE_TOL)
    assert on.details.catalogue.checked_starts > 0 and off.details.catalogue.checked_starts == 0
    assert on.details.catalogue.nlp_solves == off.details.catalogue.nlp_solves
