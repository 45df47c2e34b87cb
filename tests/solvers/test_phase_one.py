"""optdesign/solvers/phase_one.py on the crank-slider: the least violation is the largest
scaled violation of the rows at the point it returns (checked by evaluating the rows), zero
on a feasible problem and positive on one whose nut travel no design meets; weighted on one
requirement's rows it is that requirement's relaxation with the other rows held."""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.formulations.nlp.solve import formulation_for
from optdesign.solvers.phase_one import CERTIFY_ABOVE, PhaseOneSolver

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"


def _problem(travel: str):
    text = (PROBLEMS / "cs_min_backlash.toml").read_text()
    text = text.replace('nut_travel_max = "110 mm"', f'nut_travel_max = "{travel}"')
    return od.load(tomllib.loads(text.replace("points = 61", "points = 13")))


def _scaled_violation(nlp, z, rows=None):
    g = np.asarray(nlp.g_fun(z, nlp.parameter_values(None)), dtype=float).ravel()
    over = np.maximum(g - nlp.ubg, nlp.lbg - g)
    return float(np.max(over if rows is None else over[rows]))


@pytest.fixture(scope="module")
def tight():
    problem = _problem("5 mm")
    nlp = formulation_for(problem)
    return problem, nlp, PhaseOneSolver(nlp)


def test_a_feasible_problems_least_violation_is_zero_at_a_design_meeting_every_row():
    problem = _problem("110 mm")
    nlp = formulation_for(problem)
    found = PhaseOneSolver(nlp).solve(nlp.z_from_x(problem.midpoint()))
    assert found.converged and found.feasible and not found.certified
    assert abs(found.value) <= CERTIFY_ABOVE
    assert _scaled_violation(nlp, found.z) <= 1e-8
    assert not found.result.violated


def test_an_infeasible_problems_least_violation_is_the_largest_scaled_violation_there(tight):
    problem, nlp, solver = tight
    found = solver.solve(nlp.z_from_x(problem.midpoint()))
    assert found.certified and not found.feasible
    assert found.value == pytest.approx(_scaled_violation(nlp, found.z), rel=1e-6)
    # the nut travel cannot be met at 5 mm: it is among the rows at the least violation
    assert "nut_travel" in {r.name.split("[", 1)[0] for r in found.result.violated}
    assert found.result.status == "infeasible"


def test_the_least_violation_on_sqpmethod_is_ipopts(tight):
    """The phase-1 problem on sqpmethod (a catalogue node's first solver certifies its
    failed starts with it) reaches Ipopt's least violation from the same start, and its
    solves do not depend on the solves before (a memory each)."""
    from optdesign.solvers.registry import SQPMETHOD_NODE, nlpsol_options

    problem, nlp, ipopt = tight
    sqp = PhaseOneSolver(nlp, nlpsol_options("sqpmethod", SQPMETHOD_NODE), plugin="sqpmethod")
    z0 = nlp.z_from_x(problem.midpoint())
    a, b = ipopt.solve(z0), sqp.solve(z0)
    assert a.certified and b.certified and b.result.solver == "sqpmethod"
    assert b.value == pytest.approx(a.value, rel=1e-6)
    assert b.value == pytest.approx(_scaled_violation(nlp, b.z), rel=1e-6)
    sqp.solve(nlp.z_from_x(problem.lower() + 0.3 * (problem.upper() - problem.lower())))
    again = sqp.solve(z0)
    assert np.array_equal(again.z, b.z) and again.value == b.value


def test_weights_on_one_requirement_give_its_relaxation_with_the_others_held(tight):
    problem, nlp, solver = tight
    rows = np.array([k for k, g in enumerate(nlp.g_names) if g == "nut_travel"])
    scale = np.asarray(nlp.g_scale, dtype=float)[rows]
    found = solver.solve(nlp.z_from_x(problem.midpoint()), rows=rows, per_row=1.0 / scale)
    assert found.converged
    others = np.setdiff1d(np.arange(len(nlp.g_names)), rows)
    assert _scaled_violation(nlp, found.z, others) <= 1e-8  # the others hold
    g = np.asarray(nlp.g_fun(found.z, nlp.parameter_values(None)), dtype=float).ravel()
    travel = float(g[rows][0] * scale[0])
    assert 5.0 + found.value == pytest.approx(travel, rel=1e-6)  # t in mm: the travel needed
    # the hand bound of a mean ratio >= 200 over +-30 deg with p >= 2 mm, i_a = 2, within
    # what the 13 grid angles' mean ratio allows
    assert travel == pytest.approx(200 * (np.pi / 3) * 2 / (2 * np.pi * 2), rel=0.01)


def test_an_epsilon_limit_on_an_objective_is_a_row_the_least_violation_holds():
    # The backlash (an objective, in deg) has no upper limit in the NLP; NLP.bounds(eps=...)
    # gives it one per call. Below its least value (0.0362 deg at these 13 angles'
    # optimum) no design meets it: the least violation is positive there, and the row of
    # the limit is violated; at 0.05 deg a design meets every row.
    problem = _problem("110 mm")
    nlp = formulation_for(problem, ("backlash",))
    solver = PhaseOneSolver(nlp)
    z0 = nlp.z_from_x(problem.midpoint())
    row = nlp.eps_rows["backlash"]
    tight = solver.solve(z0, nlp.bounds(eps={"backlash": 0.03}))
    assert tight.certified
    assert nlp.g_names[row] in {r.name for r in tight.result.violated}
    g = np.asarray(nlp.g_fun(tight.z, nlp.parameter_values(None)), dtype=float).ravel()
    assert g[row] * nlp.g_scale[row] > 0.03
    loose = solver.solve(z0, nlp.bounds(eps={"backlash": 0.05}))
    assert loose.feasible


def test_a_lower_limit_a_call_adds_to_a_row_is_held():
    # nut_travel has an upper limit only (110 mm); a call that also asks for at least
    # 100 mm gets a phase-1 problem holding both sides, and a design within them (the
    # NLP's own phase-1 problem, which ignores it, ends at 80 mm from this start).
    problem = _problem("110 mm")
    nlp = formulation_for(problem)
    (row,) = [k for k, g in enumerate(nlp.g_names) if g == "nut_travel"]
    assert not np.isfinite(nlp.lbg[row])
    bounds = nlp.bounds()
    lbg = np.array(bounds.lbg, dtype=float)
    lbg[row] = 100.0 / nlp.g_scale[row]
    found = PhaseOneSolver(nlp).solve(nlp.z_from_x(problem.midpoint()), replace(bounds, lbg=lbg))
    assert found.feasible
    g = np.asarray(nlp.g_fun(found.z, nlp.parameter_values(None)), dtype=float).ravel()
    assert 100.0 * (1 - 1e-6) <= g[row] * nlp.g_scale[row] <= 110.0 * (1 + 1e-6)
