"""Issue 24: what a robust optimum depends on - the sensitivities of the sample-average
NLP (a requirement's multipliers summed over its samples), checked against
finite-difference re-solves of the robust problem on the same samples."""

import json
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.formulations.robust.program import draw_samples
from optdesign.formulations.robust.solve import solve_robust
from optdesign.problem.parameters import limit_value, perturbed
from optdesign.reports.costs_text import cost_text
from optdesign.reports.result_json import result_document

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"
FILE = PROBLEMS / "cs_min_backlash_robust.toml"


def _check_against_resolves(problem, result, samples, constrain_samples=False, rel=0.01):
    """Each sensitivity equals the central difference of two robust re-solves (the limit
    0.1 % to both sides, the same samples, warm from the optimum)."""
    x = np.array([result.design[v.name] for v in problem.free])
    assert result.sensitivities
    for s in result.sensitivities:
        p = limit_value(problem, s.name)
        h = 1e-3 * abs(p)
        values = []
        for q in (p + h, p - h):
            other = solve_robust(
                perturbed(problem, s.name, q),
                x0=x,
                samples=samples,
                constrain_samples=constrain_samples,
            )
            assert other.success, s.name
            values.append(other.objective)
        fd_log = (values[0] - values[1]) / (2 * h) * p / result.objective
        assert s.log_sensitivity == pytest.approx(fd_log, rel=rel), s.name


@pytest.fixture(scope="module")
def small():
    """The shipped robust problem on 4 of its samples (a quick SAA)."""
    problem = od.load(FILE)
    nominal = od.solve(problem, formulation="nlp", ranges=False)
    x0 = np.array([nominal.design[v.name] for v in problem.free])
    return problem, draw_samples(problem, 4, 0), x0


def test_robust_sensitivities_equal_resolves(small):
    problem, samples, x0 = small
    result = solve_robust(problem, x0=x0, samples=samples, sensitivities=True)
    names = [s.name for s in result.sensitivities]
    assert names[0] == "requirements.nut_travel_max" and "requirements.hinge_moment" in names
    assert all(s.objective == "CVaR_0.9(backlash)" for s in result.sensitivities)
    assert result.sensitivities[0].objective_unit == "deg"
    _check_against_resolves(problem, result, samples)


@pytest.mark.slow
def test_requirements_on_every_sample(small):
    # the requirements imposed on every sample too: their rows' multipliers summed
    problem, samples, x0 = small
    result = solve_robust(
        problem, x0=x0, samples=samples, sensitivities=True, constrain_samples=True
    )
    _check_against_resolves(problem, result, samples, constrain_samples=True)


def test_a_one_value_objective_is_not_covered(small):
    problem, samples, x0 = small
    result = solve_robust(problem, x0=x0, samples=samples, objective="size", sensitivities=True)
    assert result.success and result.sensitivities == []
    assert any("sensitivities not computed: a one-value objective" in n for n in result.notes)


def test_no_sensitivities_unless_asked(small):
    problem, samples, x0 = small
    assert solve_robust(problem, x0=x0, samples=samples).sensitivities == []


@pytest.mark.slow
def test_shipped_robust_problem(tmp_path):
    # od.solve's robust formulation, the file's 32 samples
    problem = od.load(FILE)
    result = od.solve(problem, formulation="robust", ranges=False)
    assert result.formulation == "robust-saa" and result.sensitivities
    tol = problem.spec.tolerances
    _check_against_resolves(problem, result, draw_samples(problem, tol.samples, tol.seed, tol))
    first = result.sensitivities[0]
    assert cost_text(first) in result.summary()
    assert result_document(result)["sensitivities"][0]["name"] == first.name
    assert json.loads(result.to_json())["sensitivities"][0]["name"] == first.name
