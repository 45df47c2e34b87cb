"""``solvers.base.on_every_row``: a solve of the NLP on a subset of its rows taken as a
solve of the NLP itself only when every row left out is met at its point."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.formulations.catalogue.thinned_grid import thinned_rows
from optdesign.programs.nlp import build_nlp, with_rows
from optdesign.solvers.base import on_every_row
from optdesign.solvers.registry import make_solver
from optdesign.tolerances import LEFT_OUT_ROW_TOL, OBJECTIVE_TIE_TOL

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def fin():
    problem = od.load(ROOT / "problems" / "fin_actuator.toml")
    nlp = build_nlp(problem, ["backlash", "backlash_rss", "ripple"])
    return problem, nlp, make_solver(nlp, "ipopt")


#: fin_actuator's optimal items (a leaf of the catalogue search)
LEAF = {"d0": (25.0, 25.0), "p": (5.0, 5.0), "d": (6.0, 6.0)}


def _solve(problem, nlp, rows, objective):
    """The thinned NLP solved on the leaf from the problem's start, with the leaf's
    bounds on every row (those of the whole NLP)."""
    bounds = nlp.bounds(box=LEAF, parameters=problem.parameter_values(LEAF))
    sub = with_rows(nlp, rows)
    sub_bounds = replace(bounds, lbg=np.asarray(bounds.lbg)[rows], ubg=np.asarray(bounds.ubg)[rows])
    target = nlp.target(objective)
    start = sub.start(x0=problem.start(), parameters=bounds.parameters)
    return make_solver(sub, "ipopt").solve(start, target, sub_bounds), target, bounds


def test_a_point_that_meets_the_rows_left_out_is_the_whole_nlps_solve(fin):
    """The RSS backlash binds no row between the kept angles: the thinned optimum meets
    every row, and is the whole NLP's optimum from the same start (its value, no row
    violated, zero multipliers on the rows left out)."""
    problem, nlp, whole = fin
    rows = np.asarray(thinned_rows(problem, nlp))
    first, target, bounds = _solve(problem, nlp, rows, "backlash_rss")
    lifted, met = on_every_row(first, nlp, rows, target, bounds)
    assert first.success and met
    assert lifted.success and not lifted.violated
    left_out = np.setdiff1d(np.arange(len(nlp.g_names)), rows)
    assert np.all(lifted.raw["lam_g"][left_out] == 0.0)
    assert len(lifted.raw["lam_g"]) == len(nlp.g_names)
    direct = whole.solve(
        nlp.start(x0=problem.start(), parameters=bounds.parameters), target, bounds
    )
    assert direct.success
    assert lifted.objective == pytest.approx(direct.objective, rel=OBJECTIVE_TIE_TOL)


def test_a_point_that_misses_a_row_left_out_is_not_kept(fin):
    """Ripple peaks between the kept angles: the thinned optimum misses a row of a left
    -out angle, by more than the back-end's tolerance."""
    problem, nlp, _ = fin
    rows = np.asarray(thinned_rows(problem, nlp))
    first, target, bounds = _solve(problem, nlp, rows, "ripple")
    lifted, met = on_every_row(first, nlp, rows, target, bounds)
    assert first.success and not met
    theta = nlp.parameter_values(bounds.parameters)
    g = np.asarray(nlp.g_fun(lifted.raw["z"], theta), dtype=float).ravel()
    miss = np.maximum(np.asarray(bounds.lbg) - g, g - np.asarray(bounds.ubg))
    left_out = np.setdiff1d(np.arange(len(nlp.g_names)), rows)
    assert miss[left_out].max() > LEFT_OUT_ROW_TOL
    assert miss[rows].max() <= LEFT_OUT_ROW_TOL  # the kept rows are met: the solve's own


def test_a_solve_with_no_point_is_passed_through(fin):
    problem, nlp, _ = fin
    from optdesign.solvers.base import failed_result

    rows = np.asarray(thinned_rows(problem, nlp))
    target = nlp.target("backlash")
    failed = failed_result("ipopt", nlp, target, "evaluation error", 0.0)
    lifted, met = on_every_row(failed, nlp, rows, target, nlp.bounds())
    assert lifted is failed and not met
