"""optdesign/problem/evaluation.py: a population's evaluation on the NumPy path, and the
screened rows (checks of the NumPy path alone, computed in a population only for the
designs that pass every other row) against each design evaluated alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.problem.evaluation import RowsOnDemand
from optdesign.tolerances import FEASIBILITY_TOL

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"

#: fin_actuator_loop's optimum (16 mm pins), and designs that each fail another row.
OPTIMUM = {"R": 105.5714658, "l": 59.7942416, "n": 102.0869895, "phi0": 0.2292040,
           "d0": 25.0, "p": 5.0, "d": 16.0}  # fmt: skip
DESIGNS = {
    "optimum": OPTIMUM,
    "arm 2 % longer (mean ratio)": dict(OPTIMUM, R=OPTIMUM["R"] * 1.02),
    "10 mm pins (resonance margin)": dict(OPTIMUM, d=10.0),
    "folds inside the stroke": dict(OPTIMUM, R=30.0, l=40.0, n=150.0),
    "rod 1 % longer (lock force)": dict(OPTIMUM, l=OPTIMUM["l"] * 1.01),
}
SCREENED = ("loop_stable", "limit_cycle_amplitude")


@pytest.fixture(scope="module")
def problem():
    return od.load(PROBLEMS / "fin_actuator_loop.toml")


@pytest.fixture(scope="module")
def population(problem):
    return np.array([[d[v.name] for v in problem.free] for d in DESIGNS.values()])


def test_a_populations_verdicts_equal_each_designs_alone(problem, population):
    """Every design is feasible in the population exactly when it is alone; a passing
    design's violation and screened rows are its own to the last bit, and a failing one's
    violation is its other rows' (here the optimum passes, the four others fail)."""
    ev = problem.evaluate(population)
    alone = [problem.evaluate(x) for x in population]
    passing = [a.violation <= FEASIBILITY_TOL for a in alone]
    assert passing == [True, False, False, False, False]
    for j, a in enumerate(alone):
        assert (ev.violation[j] <= FEASIBILITY_TOL) == passing[j]
        if passing[j]:
            assert ev.violation[j] == a.violation
            for name in SCREENED:
                np.testing.assert_array_equal(
                    ev.constraints[name].values[j], np.ravel(a.constraints[name].values)
                )
        else:
            assert ev.violation[j] == pytest.approx(a.violation, rel=1e-12) or (
                ev.violation[j] > FEASIBILITY_TOL
            )
    for name in SCREENED:
        block = ev.constraints[name]
        np.testing.assert_array_equal(block.unchecked, [not p for p in passing])
        assert np.all(np.isnan(block.values[1:]))


def test_a_failing_designs_violation_is_its_other_rows_largest(problem, population):
    """The screened rows never raise a failing design's violation: it is the largest of
    its other rows' (the 10 mm pins' resonance margin: 1.19 %)."""
    ev = problem.evaluate(population)
    alone = problem.evaluate(population[2])
    others = max(
        float(np.nanmax(od_rel(v))) for k, v in alone.constraints.items() if k not in SCREENED
    )
    assert ev.violation[2] == pytest.approx(others, rel=1e-12)
    assert ev.violation[2] == pytest.approx(0.01193, rel=1e-3)


def od_rel(block):
    from optdesign.problem.evaluation import relative_violation

    return np.atleast_1d(relative_violation(block.values, block.lower, block.upper))


def test_screened_rows_read_as_an_array_are_every_designs(problem, population):
    """A reader that takes the block as an array (the front's costs, the sensitivities)
    gets every design's rows, the failing ones' too: equal to each design's alone."""
    ex = problem.expressions(problem.design_dict(population))
    blocks = {b.name: b for b in ex.constraints}
    for name in SCREENED:
        assert isinstance(blocks[name].expr, RowsOnDemand)
        rows = np.asarray(blocks[name].expr)
        for j, x in enumerate(population):
            own = np.ravel(problem.evaluate(x).constraints[name].values)
            np.testing.assert_array_equal(rows[j], own)
        assert np.all(np.isfinite(rows[:3])) and np.all(np.isnan(rows[3]))


def test_a_front_search_population_marks_unchecked_rows_as_no_violation(problem, population):
    """pymoo's constraint matrix reads an unchecked screened block as no violation, so a
    design failing another row is ranked by that row alone, not by a placeholder."""
    from optdesign.formulations.catalogue.discrete import CatalogueCoordinates
    from optdesign.studies.pareto.methods import pymoo_problem

    coords = CatalogueCoordinates(problem)
    Z = population.copy()
    for k, values in coords.values.items():  # the search's coordinates: item indices
        Z[:, k] = [int(np.flatnonzero(values == v)[0]) for v in population[:, k]]
    np.testing.assert_array_equal(coords.to_design(Z), population)
    out: dict = {}
    pymoo_problem(problem, ["backlash", "motor_peak_torque"])._evaluate(Z, out)
    G = out["G"]
    names = list(problem.evaluate(population).constraints)
    for name in SCREENED:
        column = G[:, names.index(name)]
        assert column[0] < 0 and np.all(column[1:] == 0.0), name
    assert G[0].max() <= FEASIBILITY_TOL
    assert G[2].max() == pytest.approx(0.01193, rel=1e-3)  # the resonance margin's


def test_a_populations_costly_objective_is_computed_when_read(problem, population, monkeypatch):
    """The loop's bandwidth (a root finding per design and angle) is not computed for a
    population until its objective is read, and then equals each design's alone; reading
    another objective (the start sample ranks by one) computes none of it."""
    from optdesign.problem import loop_bandwidth

    calls = []
    exact = loop_bandwidth._bandwidth.__wrapped__

    def counted(plant, loop):
        calls.append(plant.angle)
        return exact(plant, loop)

    monkeypatch.setattr(loop_bandwidth, "_bandwidth", counted)
    ev = problem.evaluate(population)
    backlash = ev.objectives["backlash"]
    assert calls == [] and backlash.shape == (len(population),)
    periods = ev.objectives["bandwidth_period"]
    assert len(calls) == 4 * 7  # the four designs that are plants, at the seven angles
    for j, x in enumerate(population):
        alone = problem.evaluate(x).objectives["bandwidth_period"]
        if j == 3:  # folds inside the stroke: no plant
            assert np.isnan(periods[j])
        else:
            assert periods[j] == alone
