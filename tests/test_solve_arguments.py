"""od.solve's arguments that change what the global search and the evidence do
(optdesign/api.py, optdesign/studies/solve.py), and what a result then claims in its
summary, result.json and report (optdesign/reports)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

import optdesign as od
from optdesign.reports.html import solve_report
from optdesign.reports.result_json import result_document

ROOT = Path(__file__).resolve().parents[1]
RIPPLE = ROOT / "problems" / "cs_min_ripple.toml"


@pytest.fixture(scope="module")
def ripple():
    return od.solve(RIPPLE, seed=0)


def test_sensitivities_false_leaves_them_out_and_true_computes_them(ripple):
    without = od.solve(RIPPLE, seed=0, sensitivities=False, ranges=False)
    assert without.sensitivities == [] and ripple.sensitivities
    assert without.objective == pytest.approx(ripple.objective, rel=1e-9)


def test_slsqp_back_end_solves_and_prices_its_limits():
    # the run reports its label (scipy-slsqp-...), not the registered name: the evidence
    # after the optimum must still find the back-end's hints
    result = od.solve(RIPPLE, solver="slsqp", seed=0, ranges=False)
    assert result.success and result.solver.startswith("scipy-slsqp")
    assert result.objective == pytest.approx(0.012111423, rel=1e-5)
    assert not any("not computed" in n for n in result.notes), result.notes


def test_target_odds_keeps_the_search_going_until_its_estimate_is_below_it(ripple):
    # one optimum: the rule alone stops at 10 counted starts (2 per free variable), with
    # an estimate 2 / (10 * 9); a target of 0.5 % needs n (n - 1) >= 400, n = 21
    assert ripple.multistart.counted == 10
    assert ripple.multistart.odds.p_better == pytest.approx(2 / 90)
    strict = od.solve(RIPPLE, seed=0, target_odds=0.005, ranges=False, sensitivities=False)
    assert strict.multistart.counted == 21 and strict.multistart.stop == "odds"
    assert strict.multistart.odds.p_better == pytest.approx(2 / (21 * 20))
    assert strict.objective == pytest.approx(ripple.objective, rel=1e-9)


def test_result_json_and_the_report_state_what_was_checked(ripple):
    doc = json.loads(json.dumps(result_document(ripple)))
    assert doc["globality"]["proved"] is False
    assert doc["globality"]["odds"]["starts"] == 10 and doc["globality"]["odds"]["optima"] == 1
    assert "estimated probability that a better one exists: 2.2 %" in doc["globality"]["text"]
    page = solve_report(ripple)
    assert "feasible: verified by the NumPy model" in page
    assert "global: not proved; 1 local optimum seen in 10 counted starts" in page


def test_a_feasible_point_where_the_solver_stopped_is_not_called_infeasible(ripple):
    stopped = replace(ripple, status="max_iterations", globality=None)
    stopped.verified = True
    text = stopped.summary()
    assert "(feasible; the solver did not converge)" in text
    assert "a feasible design, but no optimum: the solver stopped (max_iterations)" in text
    assert "no feasible design found" not in text
