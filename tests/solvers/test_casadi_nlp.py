"""CasADi's nlpsol back-ends (optdesign.solvers.casadi_nlp, through
optdesign.solvers.nlpsol_call): a solve of sqpmethod depends on its own start only, not on
what the same back-end solved before."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.formulations.nlp.solve import formulation_for
from optdesign.solvers import nlpsol_call
from optdesign.solvers.casadi_nlp import CasadiNLPSolver
from optdesign.solvers.registry import SQPMETHOD_SWEEP, make_solver

ROOT = Path(__file__).resolve().parents[2]
OBJECTIVES = ("backlash", "ripple")


@pytest.fixture(scope="module")
def nlp():
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    return problem, formulation_for(problem, OBJECTIVES)


def _start(problem, nlp, seed: int):
    """The problem's start, each design variable moved by up to 10 % (seeded)."""
    x0 = np.asarray(problem.start(), dtype=float)
    x0 = x0 * (1 + 0.1 * np.random.default_rng(seed).uniform(-1, 1, len(x0)))
    return nlp.start(x0=np.clip(x0, problem.lower(), problem.upper()))


def _sqp(nlp):
    return make_solver(nlp, "sqpmethod", dict(SQPMETHOD_SWEEP))


def test_an_sqpmethod_solve_is_the_same_after_other_solves_as_on_a_new_back_end(nlp, capfd):
    """qpOASES starts each QP from the working set it ended the last one with, across the
    solves of a Function: this solve's design differed in its 15th digit after one other
    solve, and a front in its 16th between 1 and 2 workers. Each solve gets a memory of
    its own, so the result is bit for bit the new back-end's."""
    problem, formulation = nlp
    alone = _sqp(formulation).solve(_start(problem, formulation, 2), "backlash")
    used = _sqp(formulation)
    for seed, target in ((1, "ripple"), (3, "backlash"), (4, "ripple")):
        used.solve(_start(problem, formulation, seed), target)
    after = used.solve(_start(problem, formulation, 2), "backlash")
    assert alone.success and after.success
    assert np.array_equal(after.raw["z"], alone.raw["z"])
    assert after.iterations == alone.iterations
    assert np.array_equal(after.raw["lam_g"], alone.raw["lam_g"])
    # qpOASES prints its licence banner through CasADi to sys.stdout at each new memory
    assert "qpOASES" not in capfd.readouterr().out


def test_an_sqpmethod_back_end_is_built_again_once_its_retired_memories_reach_the_cap(
    nlp, monkeypatch
):
    """The memories that solves retire are freed by building the Function again every
    RETIRED_MEMORIES solves; the solves on either side agree bit for bit."""
    problem, formulation = nlp
    monkeypatch.setattr(nlpsol_call, "RETIRED_MEMORIES", 2)
    solver = _sqp(formulation)
    first = solver.function.function
    start = _start(problem, formulation, 5)
    results = [solver.solve(start, "ripple") for _ in range(3)]
    assert solver.function.function is not first  # built again after the second solve
    assert all(np.array_equal(r.raw["z"], results[0].raw["z"]) for r in results)
    assert len(solver.function.retired) == 1


def test_an_ipopt_solve_goes_straight_to_its_function(nlp):
    """Ipopt keeps no state between solves: no call node, no retired memory."""
    problem, formulation = nlp
    solver = CasadiNLPSolver(formulation)
    result = solver.solve(_start(problem, formulation, 2), "backlash")
    assert result.success and not solver.function.keeps_state
    assert solver.function.wrapped is None and solver.function.retired == []
