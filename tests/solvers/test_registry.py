"""Solver capabilities declared in the registry (issue 22): a study asks the registry for
a back-end's hints (warm-start, node, restart, sweep, iteration, deadline and time-limit
options, the problem file's table of options), for the default back-end of a formulation
kind and for the back-ends of a front's roles - never names one. A new back-end is one
module and one registration line."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import optdesign as od
from optdesign.errors import InputError
from optdesign.solvers import registry
from optdesign.solvers.casadi_nlp import CasadiNLPSolver
from optdesign.solvers.ipopt_options import IPOPT_NODE, IPOPT_TIE, IPOPT_WARM
from optdesign.solvers.registry import (
    FRONT_SOLVERS,
    default_solver,
    register_solver,
    solver_entry,
    solver_for_kind,
    solver_hints,
    solver_names,
)

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "optdesign"


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


def test_the_registry_holds_each_back_ends_hints_and_the_defaults():
    ipopt = solver_hints("ipopt")
    assert ipopt.restart_options == IPOPT_TIE and ipopt.node_options == IPOPT_NODE
    assert ipopt.file_options == "ipopt" and ipopt.deadline_options
    assert ipopt.time_limit(2) == {"max_wall_time": 2.0, "max_cpu_time": 2.0}
    assert solver_hints("slsqp").sweep_options == {"maxiter": 200}
    assert solver_hints("sqpmethod").sweep_options["hessian_approximation"] == "limited-memory"
    assert solver_hints("scs", "gp").time_limit(3) == {"time_limit_secs": 3.0}
    assert solver_hints("sqpmethod").time_limit(3) == {}  # none: the hard timeout covers it
    assert solver_hints(None) is ipopt  # None: the default NLP back-end's
    assert (default_solver("nlp"), default_solver("gp")) == ("ipopt", "clarabel")
    assert solver_for_kind("slsqp", "gp") == "clarabel" and solver_for_kind("scs", "gp") == "scs"
    assert (FRONT_SOLVERS.primary, FRONT_SOLVERS.fallback, FRONT_SOLVERS.tie) == (
        "sqpmethod",
        "ipopt",
        "ipopt",
    )
    with pytest.raises(InputError, match="unknown nlp solver 'knitro'"):
        solver_hints("knitro")
    with pytest.raises(InputError, match="expected a SolverHints"):
        register_solver("bad-hints", lambda nlp, o: None, hints={"warm": 1})


def _quoted_solver_names(path: Path) -> list[tuple[int, str]]:
    """Lines of ``path`` whose code (not a docstring) holds a registered back-end's name
    as a string."""
    tree = ast.parse(path.read_text())
    docstrings = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef)
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    # the benchmark's list of its configurations is data: which back-end each one runs
    skip = {
        id(n)
        for node in ast.walk(tree)
        if isinstance(node, ast.FunctionDef) and node.name == "_register_defaults"
        for n in ast.walk(node)
    }
    names = set(solver_names())
    return [
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and node.value in names
        and id(node) not in docstrings
        and id(node) not in skip
    ]


def test_no_study_command_or_api_names_a_solver():
    # Solver names and their options live in optdesign/solvers (the registry); the
    # studies, the API and the commands ask it. A study naming "ipopt" again fails here.
    files = [
        *sorted((PACKAGE / "studies").rglob("*.py")),
        *sorted((PACKAGE / "commands").rglob("*.py")),
        PACKAGE / "api.py",
        PACKAGE / "validation.py",
    ]
    found = {str(f.relative_to(ROOT)): hits for f in files if (hits := _quoted_solver_names(f))}
    assert found == {}


@pytest.fixture
def lbfgs_back_end():
    from backend_example import HINTS, lbfgs_ipopt

    # The one registration line of a new back-end:
    register_solver("ipopt-lbfgs-example", lbfgs_ipopt, hints=HINTS)
    yield HINTS
    registry._SOLVERS.pop("ipopt-lbfgs-example")


def test_a_new_back_end_is_one_module_and_one_registration_line(lbfgs_back_end):
    problem = od.load(ROOT / "problems" / "fork_min_backlash.toml")
    assert "ipopt-lbfgs-example" in od.solver_names("nlp")
    result = od.solve(problem, "nlp", solver="ipopt-lbfgs-example", starts=2, ranges=False)
    assert result.status == "optimal" and result.solver == "ipopt"
    assert result.objective == pytest.approx(0.0194989, rel=1e-4)
    # its declared hints reach the studies: a catalogue node gets its node options
    from optdesign.formulations.catalogue.search import NodeSolver

    cat = od.load(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
    node = NodeSolver(cat, solver="ipopt-lbfgs-example")
    ipopt = node.backend.options["ipopt"]
    assert ipopt["expect_infeasible_problem"] == "yes"
    assert ipopt["hessian_approximation"] == "limited-memory"
    with pytest.raises(InputError, match=r"unknown solver 'nope' \(known: ipopt, .*ipopt-lbfgs"):
        od.solve(problem, solver="nope")
