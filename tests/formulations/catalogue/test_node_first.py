"""A catalogue node's first solver (``NodeFirst``, Ipopt's: CasADi's sqpmethod;
optdesign.formulations.catalogue.first_solver): it tries each start of a node of several
item combinations on the thinned grid, its converged points kept; where it does not
converge, its phase 1 (least violation) from the same start certifies the start locally
infeasible, or the node back-end (Ipopt) solves the start again; a leaf, whose design may
be reported, is its only after its first start, which is Ipopt's alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.formulations.catalogue.first_solver import CERTIFIED, FIRST_SOLVER, KEPT, first_try
from optdesign.formulations.catalogue.node_solver import NodeSolver
from optdesign.solvers.registry import SQPMETHOD_NODE, solver_hints

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def fin():
    return od.load(ROOT / "problems" / "fin_actuator.toml")


def test_ipopt_declares_sqpmethod_as_the_first_solver_of_its_nodes():
    first = solver_hints("ipopt").node_first
    assert first is not None and first.solver == "sqpmethod"
    assert first.options == SQPMETHOD_NODE and SQPMETHOD_NODE["tol_du"] <= 1e-9
    assert solver_hints("slsqp").node_first is None


@pytest.mark.parametrize("box", [{"d": (6.0, 10.0)}, {"d0": (20.0, 25.0), "p": (5.0, 10.0)}])
def test_a_node_of_several_combinations_keeps_the_first_solvers_optimum(fin, box):
    """Its value is the one Ipopt reaches from the same starts (the node's bound), to
    well inside the search's tie tolerance (1e-6)."""
    quick = NodeSolver(fin, starts=3)
    alone = NodeSolver(fin, starts=3, first=False)
    a, b = quick.solve(box, relaxed=True), alone.solve(box, relaxed=True)
    assert a.success and b.success
    assert a.raw[FIRST_SOLVER] == "kept" and FIRST_SOLVER not in b.raw
    assert a.objective == pytest.approx(b.objective, rel=1e-8)
    assert quick.n_first == a.multistart.n_starts and quick.n_first_failed == 0
    assert alone.n_first == 0


LEAF = {"d0": (25.0, 25.0), "p": (5.0, 5.0), "d": (6.0, 6.0)}


def test_a_leafs_first_start_is_the_node_back_ends_and_its_design_is_reported(fin):
    """A leaf's first start (from the hint: the design reported unless another start
    beats it) is Ipopt's alone; its other starts, which confirm the value, are tried by
    sqpmethod first and reach the same value."""
    ns = NodeSolver(fin, starts=3)
    leaf = ns.solve(LEAF)
    assert leaf.success and FIRST_SOLVER not in leaf.raw and "ipopt" in leaf.solver
    assert ns.n_first == 2 and ns.n_polished == 0
    # the shipped optimum's items: the design the search reports (benchmarks/README.md)
    assert leaf.objective == pytest.approx(0.034839253179819264, rel=1e-9)
    assert all(v == pytest.approx(leaf.objective, rel=1e-8) for v in leaf.multistart.objectives)


def test_a_leafs_best_start_found_by_the_first_solver_is_solved_again_by_ipopt(fin):
    """Where an sqpmethod start beats the leaf's own first start, the node back-end
    solves it again from its point: the design reported is Ipopt's, at the same value."""
    ns = NodeSolver(fin, starts=3)
    nlp = ns.backend.nlp
    node = {k: v for k, v in LEAF.items()}
    box = nlp.bounds(eps=ns.eps, box=LEAF, parameters=fin.parameter_values(node))
    every_row = list(range(len(nlp.g_names)))
    x0 = np.clip(fin.start(), fin.lower(), fin.upper())
    for k, name in enumerate(ns.names):
        if name in LEAF:
            x0[k] = LEAF[name][0]
    found = first_try(ns.backend, ns.first, every_row, box, x0, ns.target)
    assert found is not None and found.raw[FIRST_SOLVER] == KEPT
    polished = ns._polished(found, box)
    assert polished.success and FIRST_SOLVER not in polished.raw and "ipopt" in polished.solver
    assert polished.objective == pytest.approx(found.objective, rel=1e-8)
    assert (ns.n_polished, ns.n_solves) == (1, 1)


def test_an_infeasible_box_is_decided_by_two_certified_least_violations(fin):
    """Pins of 4 and 5 mm cannot carry the hinge moment: the first solver does not
    converge from either start, and its phase 1 from each certifies a positive least
    violation - the two verdicts that decide a node, as Ipopt's two did without the first
    solver (the same node, the same outcome). Each such start is two NLP solves."""
    ns = NodeSolver(fin, starts=3)
    r = ns.solve({"d": (4.0, 5.0)}, relaxed=True)
    assert not r.success
    assert r.multistart.outcomes == ["locally infeasible"] * 2
    assert ns.n_first == ns.n_first_failed == ns.n_first_certified == 2
    assert ns.n_solves == 4
    assert r.raw[FIRST_SOLVER] == CERTIFIED and "least violation" in r.message
    alone = NodeSolver(fin, starts=3, first=False)
    r = alone.solve({"d": (4.0, 5.0)}, relaxed=True)
    assert r.multistart.outcomes == ["locally infeasible"] * 2
    assert r.message == "Infeasible_Problem_Detected" and alone.n_solves == 2


def test_a_callers_node_options_leave_out_the_first_solver(fin):
    """A cap or a tolerance the caller asks of the node back-end is not the first
    solver's: with options of its own, the back-end solves every start."""
    ns = NodeSolver(fin, starts=2, options={"max_iter": 300})
    assert ns.first is None
    r = ns.solve({"d": (6.0, 10.0)}, relaxed=True)
    assert r.success and FIRST_SOLVER not in r.raw and ns.n_first == 0
