"""Solver capabilities declared in the registry (issue 22 part 3): a study asks a
back-end's entry for its warm-start options and its iteration cap, never its name."""

from __future__ import annotations

from pathlib import Path

import pytest

import optdesign as od
from optdesign.solvers.casadi_nlp import CasadiNLPSolver
from optdesign.solvers.ipopt_options import IPOPT_WARM
from optdesign.solvers.registry import register_solver, solver_entry

ROOT = Path(__file__).resolve().parents[1]


def test_ipopt_declares_its_warm_start_and_iteration_options():
    ipopt = solver_entry("ipopt")
    assert ipopt.warm_options == IPOPT_WARM and ipopt.iteration_option == "max_iter"
    slsqp = solver_entry("slsqp")
    assert slsqp.warm_options is None and slsqp.iteration_option is None


def test_a_registered_back_end_gets_its_declared_warm_options_for_the_ranges():
    seen: list[dict] = []

    def factory(nlp, options):
        seen.append(dict(options))
        return CasadiNLPSolver(nlp, "ipopt", options)

    warm = {**IPOPT_WARM, "mu_init": 1e-7}
    register_solver("ipopt-warm-test", factory, warm_options=warm, iteration_option="max_iter")
    problem = od.load(ROOT / "problems" / "fork_min_backlash.toml")
    result = od.solve(problem, "nlp", solver="ipopt-warm-test", starts=1)
    assert result.status == "optimal" and result.ranges
    # the multistart's back-end without them, the ranges' back-end with them
    assert {} in seen and warm in seen
    assert result.objective == pytest.approx(0.0194989, rel=1e-4)
