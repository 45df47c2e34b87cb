"""Tests written from the fifth mutation sample's survivors (issue 21, mutmut, SEED=24)
in studies/pareto, storage, units and reports.

Each test names the behaviour it pins, not the mutant it was written from (the mutants
and their verdicts go to the fifth sample's table in docs/testing.md). Every test was
checked to fail on its mutant (``MUTANT_UNDER_TEST=<name> pytest`` in a copy of the
run's ``mutants/``) and to pass on the code.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

import optdesign as od
from optdesign.errors import InputError
from optdesign.studies.pareto import FrontMethod, compute_front
from optdesign.studies.pareto.front import FrontPoint, make_front
from optdesign.studies.pareto.io import write_front_csv
from optdesign.studies.pareto.records import AnchorStarts, PointRecord, record_problem

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


def _front_of_midpoints(problem, objectives=("backlash", "size")):
    """A two-point front over the problem's mid-box design (no solve): enough to draw."""
    design = problem.design_dict(problem.midpoint())
    points = [
        FrontPoint(
            id=f"eps-{k}",
            kind="eps",
            target="backlash",
            objectives=dict(zip(objectives, values, strict=True)),
            design=dict(design),
            status="optimal",
            verified=True,
            method="epsilon",
        )
        for k, values in enumerate([(0.1, 30.0), (0.2, 20.0)])
    ]
    return make_front(points, list(objectives), "epsilon", problem=problem)


# --- the front's plot ---------------------------------------------------------------------
def test_a_fronts_plot_on_a_given_axes_draws_there_without_sketches(cs_min_backlash):
    """``front.plot(ax=...)`` draws the objective space on the caller's axes and returns
    the caller's figure, with no sketch axes added."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    front = _front_of_midpoints(cs_min_backlash)
    fig, ax = plt.subplots()
    try:
        assert front.plot(ax=ax) is fig
        assert fig.axes == [ax]
        x, y = ax.lines[0].get_data()
        assert list(y) == pytest.approx([30.0, 20.0])
        assert len(x) == 2
    finally:
        plt.close("all")


# --- the front's back-ends ----------------------------------------------------------------
def test_an_ipopt_front_warm_starts_its_sweep_solves(cs_min_backlash):
    """With Ipopt throughout (``solver="ipopt"``) the sweep's solves are warm-started
    (primal and dual, a small barrier); the plain fallback is not."""
    from optdesign.studies.pareto.eps_solver import EpsSolver

    eps = EpsSolver(cs_min_backlash, ["backlash", "size"], "ipopt")
    assert not eps.has_fallback
    for use in ("primary", "warm"):
        options = eps.backend(use).options["ipopt"]
        assert options["warm_start_init_point"] == "yes"
        assert options["mu_init"] == 1e-6
    assert "warm_start_init_point" not in eps.backend("fallback").options["ipopt"]


def test_a_front_solvers_back_end_is_its_primary_by_default(cs_min_backlash):
    """``EpsSolver.backend()`` with no use named is the primary back-end (the registry's
    front primary, SLSQP), the one every sweep solve tries first."""
    from optdesign.studies.pareto.eps_solver import EpsSolver

    eps = EpsSolver(cs_min_backlash, ["backlash", "size"])
    assert eps.has_fallback
    assert eps.backend() is eps.backend("primary")
    assert eps.backend().name == "scipy-slsqp-exact"
    assert eps.backend("fallback").name == "ipopt"


# --- the front's objectives ---------------------------------------------------------------
def test_a_library_front_of_a_repeated_objective_is_refused_naming_the_field(cs_min_backlash):
    """``compute_front`` (below the API's own check) refuses an objective given twice,
    naming the field and the list, before any solve."""
    with pytest.raises(InputError) as caught:
        compute_front(cs_min_backlash, ["backlash", "backlash"], 3)
    assert caught.value.field == "objectives"
    assert str(caught.value) == "objectives: repeated objective in ['backlash', 'backlash']"


def test_a_library_front_of_an_unknown_method_is_refused_naming_the_known_ones(cs_min_backlash):
    """``compute_front`` refuses a method name it does not know, listing the known ones."""
    with pytest.raises(InputError) as caught:
        compute_front(cs_min_backlash, ["backlash", "size"], 3, method="simplex")
    assert caught.value.field == "method"
    assert str(caught.value).startswith("method: unknown method 'simplex' (known: epsilon, ")


# --- the sweep's solves -------------------------------------------------------------------
def test_an_epsilon_point_that_needs_no_retry_is_solved_once(cs_min_backlash, tmp_path):
    """Without extra starts, a point whose warm start succeeds (not worse than its
    neighbour, no jump) costs one solve, and its record says so."""
    od.pareto(cs_min_backlash, ["backlash", "size"], 5, out=tmp_path, starts=1)
    lines = (tmp_path / "epsilon.jsonl").read_text().splitlines()[1:]
    eps = [r for r in map(json.loads, lines) if r["kind"] == "eps" and "polish" not in r["id"]]
    plain = [r for r in eps if not r["retried"]]
    assert len(eps) == 5 and len(plain) >= 3
    assert [r["n_solves"] for r in plain] == [1] * len(plain)


# --- files of a front ---------------------------------------------------------------------
def test_an_empty_fronts_csv_has_the_heading_every_front_csv_starts_with(cs_min_backlash, tmp_path):
    """A front with no point still writes front.csv: the one heading ``method``, the
    first heading of a front with points."""
    empty = make_front([], ["backlash", "size"], "epsilon", problem=cs_min_backlash)
    path = write_front_csv(empty, cs_min_backlash, tmp_path / "empty.csv")
    assert path.read_text() == "method\n"
    full = _front_of_midpoints(cs_min_backlash)
    text = write_front_csv(full, cs_min_backlash, tmp_path / "full.csv").read_text()
    assert text.split(",")[0] == "method"


# --- stored records -----------------------------------------------------------------------
def test_a_stored_anchor_whose_multistart_is_not_a_multistart_record_is_not_trusted(
    cs_min_backlash,
):
    """A stored record's ``multistart`` is null or the anchor's multistart record (every
    field); anything else is named as the reason the record cannot be trusted."""
    record = PointRecord(
        id="anchor-backlash-ms",
        kind="anchor-multistart",
        target="backlash",
        status="failed",
        multistart=AnchorStarts(
            n_starts=2, n_planned=2, n_at_best=0, agree=None, stopped_early=False
        ),
    ).to_dict()
    assert record_problem(cs_min_backlash, record) is None
    for broken in ({"n_starts": 2}, [2, 2, 0, None, False], "2 starts"):
        why = record_problem(cs_min_backlash, {**record, "multistart": broken})
        assert why == "field 'multistart' is not a multistart record"


def test_a_stored_record_whose_lists_are_not_lists_of_names_is_not_trusted(cs_min_backlash):
    """A stored record's ``active``, ``violated`` and ``order`` are lists of names; a
    number among them is named as the reason the record cannot be trusted."""
    record = PointRecord(
        id="epsilon-0001", kind="eps", target="size", status="failed", active=["backlash"]
    ).to_dict()
    assert record_problem(cs_min_backlash, record) is None
    for name in ("active", "violated", "order"):
        why = record_problem(cs_min_backlash, {**record, name: ["backlash", 5]})
        assert why == f"field {name!r} is not a list of names"


def test_a_failed_points_record_keeps_the_names_of_its_first_twenty_violated_rows(
    cs_min_backlash,
):
    """A front's record names at most 20 violated rows (the first ones, in the
    solver's order): a point violating a whole grid does not fill the store."""
    import math

    from optdesign.solvers.result import ConstraintReport, Result
    from optdesign.studies.pareto.records import record_from_result

    rows = [
        ConstraintReport(name=f"deflection[{i}]", value=1.0, lower=None, upper=0.5, amount=0.5)
        for i in range(25)
    ]
    result = Result(
        status="infeasible", solver="ipopt", objective=math.nan, formulation="nlp", violated=rows
    )
    rec = record_from_result(cs_min_backlash, result, "eps", "size", {"backlash": 0.01}, "e-1")
    assert rec.violated == [f"deflection[{i}]" for i in range(20)]
    assert not rec.success


# --- catalogue fronts ---------------------------------------------------------------------
def test_a_catalogue_front_of_fewer_than_two_points_is_refused_naming_the_count():
    """A catalogue front needs two points at least: ``points=1`` is refused, naming the
    field and the count, before any search."""
    problem = od.load(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
    with pytest.raises(InputError) as caught:
        compute_front(problem, ["backlash", "motor_torque"], 1)
    assert caught.value.field == "points"
    assert str(caught.value) == "points: a front needs at least 2 points, got 1"


# --- the catalogue refusal of the front-method template -----------------------------------
@dataclass
class _CatalogueOnly(FrontMethod):
    """A plug-in front method that needs catalogue variables."""

    name: str = "catalogue-only"
    designs: ClassVar[str] = "catalogue"


def test_a_front_method_that_needs_catalogue_variables_refuses_a_continuous_problem(
    cs_min_backlash, tmp_path
):
    """A method declaring ``designs = "catalogue"`` is refused on a problem without
    catalogue variables, naming the field and the method, before any store is written."""
    with pytest.raises(InputError) as caught:
        compute_front(cs_min_backlash, ["backlash", "size"], 3, _CatalogueOnly(), out=tmp_path)
    assert caught.value.field == "method"
    assert str(caught.value) == "method: catalogue-only: no variable takes catalogue values"
    assert list(tmp_path.iterdir()) == []


def test_a_catalogue_front_of_a_problem_without_catalogue_variables_is_refused_first(
    cs_min_backlash, tmp_path
):
    """``CatalogueEpsilon`` given to ``od.pareto`` on a continuous problem is refused
    naming the field, before its store is opened (it used to write the store and fail in
    its first task on a message naming ``--formulation catalogue``)."""
    from optdesign.studies.pareto import CatalogueEpsilon

    with pytest.raises(InputError) as caught:
        od.pareto(cs_min_backlash, ["backlash", "size"], method=CatalogueEpsilon(), out=tmp_path)
    assert str(caught.value) == "method: epsilon-catalogue: no variable takes catalogue values"
    assert list(tmp_path.iterdir()) == []


# --- the work a front reports ---------------------------------------------------------------
def test_a_weighted_sum_front_counts_the_solves_of_its_points_and_anchors(
    cs_min_backlash, tmp_path
):
    """A weighted-sum front's ``n_solves`` is one solve a point plus every solve behind its
    anchors (their multistarts and tie-breaks), as its store records them."""
    front = od.pareto(
        cs_min_backlash, ["backlash", "size"], 4, method="weighted_sum", out=tmp_path, starts=1
    )
    lines = (tmp_path / "weighted_sum.jsonl").read_text().splitlines()[1:]
    records = list(map(json.loads, lines))
    points = [r for r in records if r["kind"] == "weighted_sum"]
    anchors = [r for r in records if r["kind"] == "anchor"]
    assert len(points) == 4 and len(anchors) == 2
    assert all(r["n_solves"] >= 2 for r in anchors)  # the multistart's solve and the tie's
    assert front.n_solves == 4 + sum(r["n_solves"] for r in anchors)


def test_a_weighted_sum_point_whose_neighbour_failed_restarts_from_its_chains_anchor(
    cs_min_backlash, tmp_path, monkeypatch
):
    """The weighted-sum chain starts at the last objective's anchor (weight 0 on the
    first); a point whose neighbour failed starts again from that anchor's design."""
    from optdesign.studies.pareto import tasks

    real = tasks.TASK_KINDS["weighted_sum"]
    given = {}

    def weighted(task, deps):
        given[task["id"]] = task["x0"]
        if task["id"] == "ws-0001":  # a failed point: the next one starts without it
            return PointRecord(
                id=task["id"], kind="weighted_sum", target="backlash", status="failed"
            ).to_dict()
        return real(task, deps)

    monkeypatch.setitem(tasks.TASK_KINDS, "weighted_sum", weighted)
    front = od.pareto(
        cs_min_backlash, ["backlash", "size"], 3, method="weighted_sum", out=tmp_path, starts=1
    )
    lines = (tmp_path / "weighted_sum.jsonl").read_text().splitlines()[1:]
    anchors = {r["id"]: r["x"] for r in map(json.loads, lines) if r["kind"] == "anchor"}
    assert anchors["anchor-size"] != anchors["anchor-backlash"]
    assert given == {f"ws-000{i}": anchors["anchor-size"] for i in range(3)}
    assert "ws-0002" in {p.id for p in front.points}


def test_nsga2_runs_the_generations_it_is_given(cs_min_backlash, monkeypatch):
    """NSGA-II evaluates one population a generation, for exactly ``generations``."""
    from optdesign.studies.pareto import methods

    calls = []
    real = methods.pymoo_problem

    def counted(problem, objectives):
        inner = real(problem, objectives)
        evaluate = inner._evaluate

        def _evaluate(X, out, *args, **kwargs):
            calls.append(len(X))
            if len(calls) > 10:
                raise RuntimeError("NSGA-II ran past the generations it was given")
            return evaluate(X, out, *args, **kwargs)

        inner._evaluate = _evaluate
        return inner

    monkeypatch.setattr(methods, "pymoo_problem", counted)
    front = od.pareto(
        cs_min_backlash, ["backlash", "size"], method="nsga2", pop_size=8, generations=3, seed=1
    )
    assert calls == [8, 8, 8]
    assert front.settings == {"pop_size": 8, "generations": 3, "seed": 1}


# --- the chains of an epsilon front -------------------------------------------------------
def _record(id_, kind, objectives):
    return PointRecord(
        id=id_,
        kind=kind,
        target="size",
        status="optimal",
        verified=True,
        objectives=objectives,
    ).to_dict()


def _arc_chain():
    """The first two tasks of a 5-point arc sweep between anchor A (backlash 1, size 10)
    and B's multistart optimum (backlash 5, size 2)."""
    from optdesign.studies.pareto.chains import TwoChains

    chains = TwoChains(["backlash", "size"], 5, "epsilon", {}, "arc", None)
    done = {
        "anchor-backlash": _record("anchor-backlash", "anchor", {"backlash": 1.0, "size": 10.0}),
        "anchor-size-ms": _record(
            "anchor-size-ms", "anchor-multistart", {"backlash": 5.0, "size": 2.0}
        ),
    }
    (first,) = chains({"id": "anchor-size-ms"}, done["anchor-size-ms"], done)
    (second,) = chains(first, {}, done)
    return first, second


def test_an_arc_point_whose_neighbour_failed_takes_the_evenly_spaced_limit():
    """An arc-spaced point whose neighbour has no design cannot predict its limit from
    the neighbour: it takes its place on an even spacing between the frame's ends."""
    from optdesign.studies.pareto.tasks import ANCHOR_SLACK, arc_eps

    first, second = _arc_chain()
    assert second["index"] == 1 and second["eps_name"] == "backlash"
    lo = 1.0 * (1 + ANCHOR_SLACK) + 1e-12
    assert first["eps"] == {"backlash": lo}
    failed = PointRecord(id=first["id"], kind="eps", target="size", status="failed")
    assert arc_eps(second, failed) == {"backlash": pytest.approx(lo + (5.0 - lo) / 4, rel=1e-12)}
    assert arc_eps(second, None) == arc_eps(second, failed)


def test_resuming_a_store_whose_identity_line_was_torn_says_it_has_none(cs_min_backlash, tmp_path):
    """A store holding only a torn first line (a run stopped while writing its identity)
    is no store of any run: the resume is refused, saying so and how to start over."""
    from optdesign.storage import StoreError

    store = tmp_path / "epsilon.jsonl"
    store.write_text('{"__store__": 2, "identity": {"objec')
    with pytest.raises(StoreError) as caught:
        od.pareto(cs_min_backlash, ["backlash", "size"], 3, out=tmp_path, resume=True, starts=1)
    assert str(caught.value) == (
        f"resume=True: {store} cannot be resumed: it has no identity line; start over with "
        "overwrite=True or use another output folder"
    )
    assert store.read_text() == '{"__store__": 2, "identity": {"objec'


def test_an_arc_step_never_asks_below_the_first_anchors_limit():
    """A neighbour already past the point's arc position steps back, but never below
    the frame's lower end (anchor A's optimum plus the anchors' slack): no limit
    tighter than the best A can reach."""
    from optdesign.studies.pareto.tasks import ANCHOR_SLACK, arc_eps

    _, second = _arc_chain()
    lo = 1.0 * (1 + ANCHOR_SLACK) + 1e-12
    past = PointRecord(
        id="epsilon-0000",
        kind="eps",
        target="size",
        status="optimal",
        verified=True,
        objectives={"backlash": 1.0, "size": 2.0},
    )
    assert arc_eps(second, past) == {"backlash": lo}


# --- metrics ------------------------------------------------------------------------------
def test_the_spread_of_coincident_points_is_zero():
    """Points that all coincide have no uneven gap: their spread is 0, not NaN."""
    from optdesign.studies.pareto.metrics import spread

    F = np.array([[1.0, 2.0], [1.0, 2.0], [1.0, 2.0]])
    assert spread(F) == 0.0
    assert spread(np.array([[0.0, 2.0], [1.0, 1.0], [2.0, 0.0]])) == 0.0  # even gaps


# --- anchors ------------------------------------------------------------------------------
def test_an_anchor_whose_starts_succeed_solves_each_start_once(cs_min_backlash, tmp_path):
    """An anchor's multistart re-runs its starts with the fallback back-end only when no
    start reached a solution: starts that succeed cost one solve each (on the thinned
    grid), plus one for their optimum solved again on the whole grid."""
    od.pareto(cs_min_backlash, ["backlash", "size"], 3, out=tmp_path, starts=2)
    lines = (tmp_path / "epsilon.jsonl").read_text().splitlines()[1:]
    ms = [r for r in map(json.loads, lines) if r["kind"] == "anchor-multistart"]
    assert len(ms) == 2
    for r in ms:
        assert r["status"] == "optimal" and r["multistart"]["n_at_best"] >= 1
        assert r["multistart"]["n_starts"] == 2 and r["n_solves"] == 3


def test_an_anchor_multistart_whose_starts_succeed_is_not_solved_again_with_the_fallback():
    """The fallback re-run is for a search none of whose starts succeeded: one start
    that reaches the optimum is one solve, and the search stops on its odds (8 starts at
    one optimum leave fewer than half an optimum expected unseen; six free variables ask
    for 12 counted starts)."""
    from optdesign.studies.pareto.tasks import multistart_task

    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    order = ["backlash", "size"]
    # one start solves the problem itself; a search its thinned grid, then polishes
    for starts, agree, n_starts, solves in [(1, None, 1, 1), (20, 3, 12, 13)]:
        task = {"problem": problem, "order": order, "objectives": order, "starts": starts,
                "seed": 0, "agree": agree, "id": "anchor-backlash-ms"}  # fmt: skip
        record = multistart_task(task, {})
        assert record["status"] == "optimal" and record["n_solves"] == solves
        assert record["multistart"]["n_starts"] == n_starts
        assert record["objectives"]["backlash"] == pytest.approx(0.0362197, rel=1e-5)


def test_an_arc_step_back_starts_from_the_tighter_of_the_neighbours_value_and_limit():
    """Stepping back along the arc (the target lies before the neighbour), the new limit
    is a step below the lower of the neighbour's value and its own limit."""
    from dataclasses import replace

    from optdesign.studies.pareto.records import PointRecord
    from optdesign.studies.pareto.tasks import arc_eps

    frame = {"a0": 0.0, "b0": 1.0, "ra": 1.0, "rb": 2.0, "a_lo": 0.0, "a_hi": 1.0}
    task = {"frame": frame, "eps_name": "a", "target": "b", "arc": 0.0, "fallback_eps": 0.9}
    nb = PointRecord(id="p", kind="eps", status="optimal", verified=True, target="b",
                     objectives={"a": 0.5, "b": 1.2}, eps={"a": 0.45})  # fmt: skip
    # s1 = 0.5 + (1 - 1.2) / 2 = 0.4; ds/da = 1 + 2 / 2 = 2; step = (0 - 0.4) / 2 = -0.2
    assert arc_eps(task, nb) == {"a": pytest.approx(0.45 - 0.2)}
    assert arc_eps(task, replace(nb, eps={"a": 0.7})) == {"a": pytest.approx(0.5 - 0.2)}


def test_a_front_without_an_output_folder_keeps_its_store_in_a_named_temporary_folder():
    """No ``out``: the store goes to a new temporary folder whose name says what it is."""
    from optdesign.studies.pareto.run_setup import store_path

    path = store_path(None, "epsilon")
    assert path.name == "epsilon.jsonl" and path.parent.is_dir()
    assert path.parent.name.startswith("optdesign-pareto-")
    path.parent.rmdir()
