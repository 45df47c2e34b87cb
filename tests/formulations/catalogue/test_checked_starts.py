"""A catalogue node's starts solved on every other grid angle first
(``NodeSolver._solve_checked``): the point kept only when it meets every row, solved
again on the whole grid otherwise, and the same node value as on the whole grid."""

from __future__ import annotations

from pathlib import Path

import pytest

import optdesign as od
from optdesign.formulations.catalogue.bnb import InfeasibleBoxes
from optdesign.formulations.catalogue.discrete import discrete_variables
from optdesign.formulations.catalogue.node_solver import (
    MAX_REGRIDS,
    MISSED_ANGLES,
    THINNED_START,
    NodeSolver,
)
from optdesign.formulations.catalogue.search import solve_catalogue
from optdesign.formulations.catalogue.thinned_grid import _angle_label, thinned_rows
from optdesign.runtime.processes import forks_workers
from optdesign.solvers.result import Result
from optdesign.tolerances import OBJECTIVE_TIE_TOL

ROOT = Path(__file__).resolve().parents[3]
LEAF = {"d0": (25.0, 25.0), "p": (5.0, 5.0), "d": (6.0, 6.0)}
OTHER_LEAF = {"d0": (20.0, 20.0), "p": (5.0, 5.0), "d": (6.0, 6.0)}


@pytest.fixture(scope="module")
def fin():
    return od.load(ROOT / "problems" / "fin_actuator.toml")


@pytest.fixture(scope="module")
def first_stage(fin):
    """The first stage of a front's motor-torque anchor (``ties=False``), 4 starts a node."""
    return solve_catalogue(fin, objective="motor_torque", ties=False, starts=4)


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
    """Ripple peaks between the kept angles (at +-15 deg) at every start: each start
    costs two solves, its point meets every row, and the search learns those angles:
    the next node's thinned grid keeps them, and its thinned points are kept (the
    same verdict as on the whole grid)."""
    checked = NodeSolver(fin, objective="ripple", starts=3)
    whole = NodeSolver(fin, objective="ripple", starts=3, checked=False)
    a, b = checked.solve(LEAF), whole.solve(LEAF)
    assert a.raw[THINNED_START] == "solved again"
    assert sorted(a.raw[MISSED_ANGLES]) == ["phi=+15.0deg", "phi=-15.0deg"]
    assert (checked.n_checked, checked.n_resolved, checked.n_solves) == (0, 3, 6)
    assert a.success and not a.violated
    assert a.objective == pytest.approx(b.objective, rel=OBJECTIVE_TIE_TOL)
    assert checked.learned_angles == {"phi=+15.0deg", "phi=-15.0deg"}
    assert {"phi=+15.0deg", "phi=-15.0deg"} <= {
        _angle_label(checked.nlp.g_names[k])
        for k in thinned_rows(fin, checked.nlp, checked.learned_angles)
    }
    nxt, ref = checked.solve(OTHER_LEAF), whole.solve(OTHER_LEAF)
    assert nxt.raw[THINNED_START] == "kept" and checked.n_resolved == 3
    assert nxt.status == ref.status == "infeasible"  # d0 = 20 mm cannot carry it


def test_a_search_learns_the_angles_of_missed_rows_a_bounded_number_of_times(fin):
    """Every node missing rows at new angles: the thinned grid changes MAX_REGRIDS
    times, then the checks are counted as before (more solved again than kept: the
    whole grid)."""
    ns = NodeSolver(fin, objective="ripple", starts=1)
    labels = iter(fin.phi_labels[1::2])  # angles the thinned grid leaves out
    for _ in range(MAX_REGRIDS + 2):
        ns._note_checks([_resolved({next(labels)})])
    assert len(ns.learned_angles) == MAX_REGRIDS
    assert ns._mode(ns.backend) == "whole"


def test_the_search_finds_the_same_items_and_value_either_way(fin):
    on = solve_catalogue(fin)
    off = solve_catalogue(fin, thinned_starts=False)
    assert on.details.catalogue.items == off.details.catalogue.items
    assert on.objective == pytest.approx(off.objective, rel=OBJECTIVE_TIE_TOL)
    assert on.details.catalogue.checked_starts > 0 and off.details.catalogue.checked_starts == 0
    assert on.details.catalogue.nlp_solves == off.details.catalogue.nlp_solves


def _resolved(angles: set[str]) -> Result:
    """A start solved again after its thinned point missed rows at ``angles``."""
    r = Result(status="optimal", objective=1.0, solver="ipopt", formulation="catalogue")
    r.raw[THINNED_START] = "solved again"
    r.raw[MISSED_ANGLES] = sorted(angles)
    return r


def test_a_first_stage_keeps_checked_starts_once_it_learnt_the_missed_angles(fin, first_stage):
    """The first stage of a front's anchor (``ties=False``): its root's thinned points
    miss the lock force's peak between the kept angles; with those angles learnt, its
    later nodes keep their thinned points, and it finds the whole grid's value."""
    on = first_stage
    off = solve_catalogue(fin, objective="motor_torque", ties=False, starts=4, thinned_starts=False)
    info = on.details.catalogue
    assert info.resolved_starts > 0 and info.checked_starts > info.resolved_starts
    # the summary names the angles the thinned grid kept besides every other one
    assert info.learned_angles and all(a.startswith("phi=") for a in info.learned_angles)
    note = next(n for n in on.notes if n.startswith("catalogue items chosen"))
    assert f"(on every other grid angle and at {', '.join(info.learned_angles)}: " in note
    # the value, and the screw; a stage that prunes ties may end on any pin that ties
    # (the motor torque does not depend on it), whichever path its nodes took
    assert on.objective == pytest.approx(off.objective, rel=OBJECTIVE_TIE_TOL)
    screw = ("d0", "p")
    assert {k: info.items[k] for k in screw} == {k: off.details.catalogue.items[k] for k in screw}


def test_a_fronts_next_search_starts_with_the_angles_its_memo_learnt(fin, first_stage):
    """The searches of a front share a memo: the angles one learnt (here the motor-torque
    anchor's first stage's) are the next one's thinned grid from its root on (one solver
    for both), with the same answer as a search that learns them itself."""
    dvars = discrete_variables(fin)
    memo = InfeasibleBoxes(
        {v.name: (v.lower, v.upper) for v in dvars}, {v.name: v.values for v in dvars}
    )
    learnt = frozenset(first_stage.details.catalogue.learned_angles)
    memo.learned_angles = learnt
    second = solve_catalogue(fin, objective="backlash", ties=False, memo=memo)
    alone = solve_catalogue(fin, objective="backlash", ties=False)
    assert learnt and learnt <= set(second.details.catalogue.learned_angles)
    assert learnt <= memo.learned_angles
    assert not learnt <= set(alone.details.catalogue.learned_angles)
    assert second.details.catalogue.items == alone.details.catalogue.items
    assert second.objective == pytest.approx(alone.objective, rel=OBJECTIVE_TIE_TOL)


@pytest.mark.skipif(not forks_workers(), reason="local workers are forked (Linux)")
def test_a_search_that_learns_angles_on_two_workers_is_the_search_on_one(fin, first_stage):
    """The starts carry the thinned grid's rows to the worker processes (each builds
    that grid's solver once): the same angles learnt, nodes, solves and optimum as on
    one worker, bit for bit."""
    one = first_stage
    two = solve_catalogue(fin, objective="motor_torque", ties=False, starts=4, workers=2)
    a, b = one.details.catalogue, two.details.catalogue
    assert a.learned_angles and b.learned_angles == a.learned_angles
    assert (b.nlp_solves, b.nodes, b.checked_starts, b.resolved_starts) == (
        a.nlp_solves,
        a.nodes,
        a.checked_starts,
        a.resolved_starts,
    )
    assert two.objective == one.objective and two.design == one.design
