"""A catalogue search on local workers (issue 25): each node's starts run on processes
forked once for the search, and every node keeps its serial answer, so any number of
workers gives the same nodes, values, records and optimum as one."""

from __future__ import annotations

import os
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

from optdesign.problem import problem_from_dict
from optdesign.studies.catalogue import solve_catalogue
from optdesign.studies.inherited_map import InheritedWorkers
from optdesign.studies.processes import forks_workers

ROOT = Path(__file__).resolve().parents[1]

needs_fork = pytest.mark.skipif(not forks_workers(), reason="local workers are forked (Linux)")


def _slow_first(k: int) -> tuple[int, int]:
    time.sleep(0.3 if k == 0 else 0.0)
    return k * k, os.getpid()


@needs_fork
def test_kept_workers_give_the_serial_prefix_call_after_call():
    with InheritedWorkers(_slow_first, 2) as workers:
        pids = set()
        for _ in range(3):
            # item 0 is slow, so items 1.. finish first; the answer is still 0..3
            out = workers.map(list(range(8)), lambda done: sum(v >= 4 for v, _ in done) >= 2)
            assert [v for v, _ in out] == [0, 1, 4, 9]
            pids |= {pid for _, pid in out}
            assert not workers.pool.busy  # the items past the answer were waited for
        assert os.getpid() not in pids and len(pids) == 2  # the same two processes
        assert [v for v, _ in workers.map([5, 6])] == [25, 36]
    assert workers.pool is None


def test_one_worker_maps_here():
    with InheritedWorkers(_slow_first, 1) as workers:
        assert workers.pool is None
        assert workers.map([2, 3], lambda done: True) == [(4, os.getpid())]


@pytest.fixture(scope="module")
def bnb_problem():
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    return problem_from_dict(data)


@needs_fork
def test_a_search_on_two_workers_is_the_search_on_one(bnb_problem):
    # 4 starts, the file's agree of 3: a node stopped on agreement has run a 4th start on
    # the other worker, whose result is dropped
    one = solve_catalogue(bnb_problem, method="bnb", starts=4)
    two = solve_catalogue(bnb_problem, method="bnb", starts=4, workers=2)
    assert one.success and two.success
    assert two.objective == one.objective  # bit for bit: the same starts, the same order
    assert two.design == one.design
    a, b = one.details.catalogue, two.details.catalogue
    assert (b.nlp_solves, b.nodes, b.pruned, b.infeasible) == (
        a.nlp_solves,
        a.nodes,
        a.pruned,
        a.infeasible,
    )
    assert two.multistart.objectives == one.multistart.objectives
    assert a.infeasible_boxes == b.infeasible_boxes


def test_a_search_reads_the_proofs_it_is_given(bnb_problem):
    """A front's searches share one memo of infeasible boxes: a search given the proofs
    of an earlier one skips the boxes they cover (no NLP), with the same answer."""
    from optdesign.formulations.discrete import discrete_variables
    from optdesign.studies.catalogue_bnb import InfeasibleBoxes

    dvars = discrete_variables(bnb_problem)
    memo = InfeasibleBoxes(
        {v.name: (v.lower, v.upper) for v in dvars}, {v.name: v.values for v in dvars}
    )
    first = solve_catalogue(bnb_problem, method="bnb", starts=3, memo=memo)
    assert len(memo) > 0 and first.details.catalogue.implied_infeasible == 0
    again = solve_catalogue(bnb_problem, method="bnb", starts=3, memo=memo)
    assert again.details.catalogue.implied_infeasible > 0
    assert again.details.catalogue.nlp_solves < first.details.catalogue.nlp_solves
    assert again.objective == first.objective and again.design == first.design


def test_a_box_without_an_item_is_infeasible_without_a_solve_and_names_its_solver():
    import optdesign as od
    from optdesign.studies.catalogue import NodeSolver

    ns = NodeSolver(od.load(ROOT / "problems" / "fin_actuator.toml"))
    # the catalogue's screws are d0 x lead pairs: it has no 14 mm screw of 2 mm lead
    none = ns.solve({"d0": (14.0, 14.0), "p": (2.0, 2.0)})
    assert (none.status, none.message) == ("infeasible", "no catalogue item in this box")
    assert none.solver == "ipopt" and ns.n_solves == 0


def test_a_node_solver_of_another_back_end_does_not_take_the_files_ipopt_options():
    """``[solver] ipopt = {...}`` are Ipopt's: a catalogue search on another NLP back-end
    (here CasADi's sqpmethod, which has no ``mu_strategy``) is built without them."""
    import copy

    from optdesign.studies.catalogue import NodeSolver

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data = copy.deepcopy(data)
    data.setdefault("solver", {})["ipopt"] = {"mu_strategy": "monotone"}
    problem = problem_from_dict(data)
    assert NodeSolver(problem, solver="sqpmethod").solver == "sqpmethod"
    assert NodeSolver(problem).backend.name == "ipopt"


def test_a_node_solver_leaves_its_free_rows_unbounded():
    """The diagnosis of an infeasible catalogue problem solves nodes with one
    requirement's rows dropped (``free_rows``): both their bounds go."""
    import copy

    from optdesign.studies.catalogue import NodeSolver

    data = tomllib.loads((ROOT / "problems" / "fin_actuator.toml").read_text())
    data = copy.deepcopy(data)
    data["requirements"]["nut_travel_max"] = "50 mm"  # an upper limit no design meets
    problem = problem_from_dict(data)
    items = {"d0": (25.0, 25.0), "p": (5.0, 5.0), "d": (6, 6)}
    assert not NodeSolver(problem, starts=1).solve(items).success
    rows = [i for i, n in enumerate(NodeSolver(problem).nlp.g_names) if n.startswith("nut_travel")]
    freed = NodeSolver(problem, starts=1, free_rows=tuple(rows)).solve(items)
    assert freed.success
    # its design meets every requirement but the dropped one, which it violates
    from optdesign.studies.verify import verify_design

    x = np.array([freed.design[v.name] for v in problem.free])
    ok, violated, _ = verify_design(problem, x)
    assert not ok and {v.name.split("[")[0] for v in violated} == {"nut_travel"}


def test_a_node_multistart_stops_once_agree_starts_agree(bnb_problem):
    """As the problem's own multistart (``[solver] agree``, 3 by default): a node's
    starts stop once that many agree on the best value; the answer is the same as with
    every start (``agree=0``), with fewer NLP solves."""
    from optdesign.studies import catalogue

    nodes: list = []
    solve = catalogue.NodeSolver.solve

    def recorded(self, *a, **k):
        r = solve(self, *a, **k)
        nodes.append(r.multistart)
        return r

    catalogue.NodeSolver.solve = recorded
    try:
        every = solve_catalogue(bnb_problem, method="bnb", starts=4, agree=0)
        assert not any(m.stopped_early for m in nodes if m is not None and m.n_starts > 1)
        nodes.clear()
        agreed = solve_catalogue(bnb_problem, method="bnb", starts=4)
    finally:
        catalogue.NodeSolver.solve = solve
    assert bnb_problem.spec.solver.agree == 3
    assert agreed.objective == pytest.approx(every.objective, rel=1e-9)
    assert agreed.design == every.design
    assert agreed.details.catalogue.nlp_solves < every.details.catalogue.nlp_solves
    # the nodes stopped on agreement (not at a floor): three starts of the four planned
    stopped = [m for m in nodes if m is not None and m.stopped_early and m.n_at_best >= 3]
    assert stopped and all((m.n_starts, m.n_planned) == (3, 4) for m in stopped)


def test_a_search_that_finds_no_combination_says_whether_the_relaxation_was_feasible(
    bnb_problem, monkeypatch
):
    """No catalogue design from the search: "failed" (more starts may find one) when the
    continuous relaxation has a feasible design, "infeasible" only when it has none."""
    from optdesign.studies import catalogue

    stats = {"nodes": 1, "pruned": 0, "infeasible": 0, "leaves": 0, "seeded": 0}
    monkeypatch.setattr(catalogue, "branch_and_bound", lambda *a, **k: (None, stats))
    result = solve_catalogue(bnb_problem, method="bnb", starts=2)
    assert result.status == "failed" and not result.design
    assert result.message == (
        "no catalogue combination gave a feasible design although the continuous "
        "relaxation is feasible (more starts may find one)"
    )
    assert result.details.catalogue.relaxation_status == "optimal"


def test_a_single_search_reports_the_boxes_it_proved_infeasible(bnb_problem):
    """A search without a front's memo still records its own proofs (the optimum's
    neighbouring items read them, and ``details.catalogue.infeasible_boxes`` lists them)."""
    result = solve_catalogue(bnb_problem, method="bnb", starts=3)
    boxes = result.details.catalogue.infeasible_boxes
    assert boxes and all(isinstance(box, dict) and isinstance(eps, dict) for box, eps in boxes)
    assert all(set(box) <= {"p", "d"} for box, _ in boxes)


def test_a_failed_relaxation_is_said_so_beside_the_items_found(monkeypatch):
    """Enumeration solves every combination from its own starts, so a design can come
    out although the relaxation's starts failed: the note says the relaxation failed, and
    no bound is claimed."""
    import copy
    import math

    from optdesign.solvers.result import Result
    from optdesign.studies import catalogue

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data = copy.deepcopy(data)
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "6 mm", "8 mm"]}
    problem = problem_from_dict(data)
    solve = catalogue.NodeSolver.solve

    def root_fails(self, bounds, *a, **k):
        if not bounds:
            return Result(
                status="failed",
                objective=math.nan,
                design={},
                solver="ipopt",
                formulation="nlp",
                wall_time_s=0.0,
            )
        return solve(self, bounds, *a, **k)

    monkeypatch.setattr(catalogue.NodeSolver, "solve", root_fails)
    result = solve_catalogue(problem, method="enumerate", starts=2)
    assert result.success and result.bound is None
    note = next(n for n in result.notes if n.startswith("catalogue items chosen"))
    assert "; continuous relaxation: failed; enumerate," in note and "nan" not in note
