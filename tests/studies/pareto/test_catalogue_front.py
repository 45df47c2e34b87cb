"""The catalogue front (studies/pareto/catalogue_front.py): its end points are its
anchors' designs, not solved again, and they are the optima of their own limits."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import pytest

import optdesign as od
from optdesign.errors import InputError
from optdesign.formulations.catalogue.search import solve_catalogue
from optdesign.problem import problem_from_dict
from optdesign.runtime.run_options import RunOptions
from optdesign.solvers.registry import FRONT_SOLVERS
from optdesign.studies.pareto import (
    PointRecord,
    catalogue_front,
    compute_front,
)
from optdesign.studies.pareto.catalogue_front import CatalogueEpsilon, catalogue_task
from optdesign.studies.pareto.tasks import ANCHOR_SLACK
from optdesign.studies.pareto.template import FrontRun

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def small_front(tmp_path_factory):
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "6 mm", "8 mm"]}
    problem = problem_from_dict(data)
    out = tmp_path_factory.mktemp("front")
    front = od.pareto(problem, ["backlash", "motor_torque"], points=3, starts=2, out=out)
    lines = (out / "epsilon-catalogue.jsonl").read_text().splitlines()[1:]
    records = {r["id"]: r for r in map(json.loads, lines)}
    return problem, front, records


def test_the_ends_of_a_catalogue_front_are_its_anchors(small_front):
    _, front, records = small_front
    first, last = records["epsilon-catalogue-0000"], records["epsilon-catalogue-0002"]
    for end, anchor, limit in (
        (first, records["anchor-backlash"], "backlash_max"),
        (last, records["anchor-motor_torque"], "backlash_max"),
    ):
        assert end["design"] == anchor["design"] and end["objectives"] == anchor["objectives"]
        assert end["n_solves"] == 0 and end["target"] == "motor_torque"
        # the limit holds to the solver's feasibility tolerance
        assert anchor["objectives"]["backlash"] <= end["eps"]["backlash"] * (1 + 1e-6)
        assert limit in end["active"] and "motor_torque_max" not in end["active"]
    assert records["epsilon-catalogue-0001"]["n_solves"] > 0
    assert len(front.points) >= 2


def test_the_inner_point_is_solved_at_the_limit_midway_between_the_anchors(small_front):
    _, _, records = small_front
    middle = records["epsilon-catalogue-0001"]
    # the limits evenly spaced in backlash between the two anchors' values
    lo = records["anchor-backlash"]["objectives"]["backlash"] * (1 + 1e-7) + 1e-12
    hi = records["anchor-motor_torque"]["objectives"]["backlash"]
    assert middle["eps"]["backlash"] == pytest.approx(0.5 * (lo + hi), rel=1e-12)
    assert middle["objectives"]["backlash"] <= middle["eps"]["backlash"] * (1 + 1e-6)


def test_each_end_is_the_optimum_of_its_own_limit(small_front):
    """Solved again as a catalogue search of its own (min motor torque s.t. its backlash
    limit), each end point's torque is the search's, to the anchors' slack."""
    problem, _, records = small_front
    for pid in ("epsilon-catalogue-0000", "epsilon-catalogue-0002"):
        end = records[pid]
        again = solve_catalogue(problem, starts=2, objective="motor_torque", eps=end["eps"])
        assert again.success
        assert end["objectives"]["motor_torque"] == pytest.approx(again.objective, rel=1e-6)


@pytest.mark.slow  # two catalogue anchors searched twice: 8-24 s
def test_an_anchors_first_stage_leaves_the_ties_to_its_tie_break():
    """fin_actuator's motor torque does not depend on the pin: its catalogue optimum ties
    over the pins the requirements allow. The anchor's first stage only needs the value
    (its tie-break decides the design): searched with ``ties=False`` it gets the same
    value with fewer NLP solves, at one of the tied designs."""
    problem = od.load(ROOT / "problems" / "fin_actuator.toml")
    decided = solve_catalogue(problem, objective="motor_torque")
    value_only = solve_catalogue(problem, objective="motor_torque", ties=False)
    assert decided.success and value_only.success
    assert value_only.objective == pytest.approx(decided.objective, rel=1e-6)
    assert value_only.details.catalogue.nlp_solves < decided.details.catalogue.nlp_solves
    # the items decide the tie only in the first search: the smallest pin that works
    assert decided.design["d"] <= value_only.design["d"]
    assert decided.design["d0"] == value_only.design["d0"]


# optdesign/studies/pareto/catalogue_front.py as a whole without a catalogue search: the
# tasks a catalogue front plans (ids, kinds, limits, order, chain), what each task asks the
# search (caught before it runs), the ends of the front taken from their anchors, and the
# refusals and settings of the method.


PROBLEMS = Path(__file__).resolve().parents[3] / "problems"


@pytest.fixture(scope="module")
def problem():
    return od.load(PROBLEMS / "cs_min_backlash_catalogue.toml")


def _anchor(id_, ripple, backlash, status="optimal", active=("backlash_max", "stroke"), R=40.0):
    return PointRecord(
        id=id_,
        kind="anchor",
        target="x",
        status=status,
        verified=True,
        objectives={"ripple": ripple, "backlash": backlash},
        design={"R": R},
        eps={"backlash": 0.5},
        active=list(active),
        message="solved",
        n_solves=9,
    ).to_dict()


DEPS = {
    "anchor-ripple": _anchor("anchor-ripple", 0.01, 0.40),
    "anchor-backlash": _anchor("anchor-backlash", 0.05, 0.20, R=60.0),
}


class Asked(Exception):
    """What a task asked the catalogue search (raised instead of searching)."""


@pytest.fixture
def asked(monkeypatch):
    def search(problem, **kw):
        raise Asked(kw)

    monkeypatch.setattr(catalogue_front, "solve_catalogue", search)


def _point(problem, frac, **kw):
    return {
        "problem": problem,
        "starts": 2,
        "seed": 7,
        "id": "p",
        "kind": "eps",
        "target": "backlash",
        "eps_name": "ripple",
        "eps_frac": frac,
        **kw,
    }


def _trace(problem, run, points=3):
    planned = {}

    class Ctx(FrontRun):
        def tasks(self, tasks, fn, **kw):
            planned.update(tasks=tasks, fn=fn, kw=kw)
            done = {t["id"]: _anchor(t["id"], 0.01, 0.4) for t in tasks}
            return done

    ctx = Ctx(problem, ["ripple", "backlash"], run, None, {}, 2, 5, None)
    traced = CatalogueEpsilon(points=points).trace(ctx)
    return planned, traced


def test_a_point_limits_its_first_objective_between_the_anchors(problem, asked):
    with pytest.raises(Asked) as got:
        catalogue_task(_point(problem, 0.25), DEPS)
    kw = got.value.args[0]
    lo = 0.01 * (1 + ANCHOR_SLACK) + 1e-12
    assert kw["eps"] == {"ripple": pytest.approx(lo + 0.25 * (0.05 - lo), rel=1e-15)}
    assert (kw["objective"], kw["starts"], kw["seed"], kw["ties"]) == ("backlash", 2, 7, True)
    # the nearer anchor's design first (0.25: the ripple anchor), then the other
    assert kw["incumbents"] == [{"R": 40.0}, {"R": 60.0}]
    assert kw["memo"] is None
    assert kw["objectives"] == ()  # a task written before the front passed its objectives


def test_a_frame_whose_far_anchor_lies_below_the_near_one_is_held_at_the_near_limit(problem, asked):
    deps = {**DEPS, "anchor-backlash": _anchor("anchor-backlash", 0.005, 0.20)}
    with pytest.raises(Asked) as got:
        catalogue_task(_point(problem, 0.5), deps)
    lo = 0.01 * (1 + ANCHOR_SLACK) + 1e-12
    assert got.value.args[0]["eps"] == {"ripple": pytest.approx(lo, rel=1e-15)}


def test_an_anchors_first_stage_leaves_ties_and_its_tie_break_holds_the_first_objective(
    problem, asked
):
    common = {"problem": problem, "starts": 3, "seed": 1}
    with pytest.raises(Asked) as got:
        catalogue_task(
            {**common, "id": "anchor-ripple-ms", "kind": "anchor-multistart", "target": "ripple"},
            {},
        )
    kw = got.value.args[0]
    assert (kw["objective"], kw["ties"], kw["eps"]) == ("ripple", False, {})
    tie = {
        **common,
        "id": "anchor-ripple",
        "kind": "anchor",
        "target": "backlash",
        "tie_of": "anchor-ripple-ms",
        "fixed": "ripple",
    }
    with pytest.raises(Asked) as got:
        catalogue_task(tie, {"anchor-ripple-ms": DEPS["anchor-ripple"]})
    kw = got.value.args[0]
    assert kw["ties"] is True and kw["objective"] == "backlash"
    assert kw["eps"] == {"ripple": pytest.approx(0.01 * (1 + ANCHOR_SLACK) + 1e-12, rel=1e-15)}
    assert kw["incumbents"] == [{"R": 40.0}]


def test_a_tie_break_of_a_failed_first_stage_is_that_stage_relabelled(problem, asked):
    failed = _anchor("anchor-ripple-ms", 0.01, 0.4, status="infeasible")
    tie = {
        "problem": problem,
        "id": "anchor-ripple",
        "kind": "anchor",
        "tie_of": "ms",
        "fixed": "ripple",
    }
    out = PointRecord.from_dict(catalogue_task(tie, {"ms": failed}))
    assert (out.id, out.kind, out.status) == ("anchor-ripple", "anchor", "infeasible")


@pytest.mark.parametrize("failed", ["anchor-ripple", "anchor-backlash"])
def test_a_point_without_both_anchors_fails_naming_the_missing_one(problem, asked, failed):
    deps = {**DEPS, failed: _anchor(failed, 0.01, 0.4, status="infeasible")}
    out = PointRecord.from_dict(catalogue_task(_point(problem, 0.5, id="p3", kind="eps"), deps))
    assert (out.id, out.kind, out.status, out.target) == ("p3", "eps", "failed", "backlash")
    assert out.message == f"anchor {failed.removeprefix('anchor-')} has no design"


def test_the_first_point_is_the_limited_objectives_anchor_with_its_own_limit(problem, asked):
    out = PointRecord.from_dict(catalogue_task(_point(problem, 0.0, id="p0"), DEPS))
    assert (out.id, out.kind, out.target) == ("p0", "eps", "backlash")
    assert out.objectives == {"ripple": 0.01, "backlash": 0.40}
    assert out.eps == {"backlash": 0.5}
    assert out.active == ["ripple_max", "stroke"]
    assert out.message == "solved; the design of anchor-ripple"
    assert out.n_solves == 0 and out.wall_time_s >= 0.0


def test_the_last_point_is_the_other_anchor_at_the_far_limit(problem, asked):
    out = PointRecord.from_dict(catalogue_task(_point(problem, 1.0, id="p9"), DEPS))
    assert out.objectives == {"ripple": 0.05, "backlash": 0.20}
    assert out.eps == {"ripple": pytest.approx(0.05)}
    assert out.message == "solved; the design of anchor-backlash"
    no_message = {**DEPS, "anchor-backlash": {**DEPS["anchor-backlash"], "message": ""}}
    out = PointRecord.from_dict(catalogue_task(_point(problem, 1.0), no_message))
    assert out.message == "the design of anchor-backlash"


def test_the_methods_refusals_identity_and_settings(problem):
    with pytest.raises(InputError) as err:
        CatalogueEpsilon(points=1).refuse(problem, ["ripple", "backlash"])
    assert err.value.field == "points"
    assert "a front needs at least 2 points, got 1" in str(err.value)
    CatalogueEpsilon(points=2).refuse(problem, ["ripple", "backlash"])
    with pytest.raises(InputError, match="a catalogue front takes two objectives"):
        CatalogueEpsilon().refuse(problem, ["ripple", "backlash", "size"])
    method = CatalogueEpsilon(points=5)
    assert method.identity(2, 3, ["ripple", "backlash"]) == (
        FRONT_SOLVERS.fallback,
        {"method": "epsilon-catalogue", "points": 5, "starts": 2, "seed": 3},
    )
    assert method.settings(2, 3, ["backlash", "ripple"]) == {
        "points": 5,
        "starts": 2,
        "seed": 3,
        "spacing": "uniform in backlash",
    }
    solver = problem.spec.solver
    assert solver.starts is None  # the cap chosen from the dimension, at most 4 here
    assert method.starts_and_seed(problem) == (4, solver.seed)


def test_the_plan_two_anchors_in_two_stages_then_evenly_spaced_points(problem):
    planned, traced = _trace(problem, RunOptions(workers=2), points=3)
    tasks = planned["tasks"]
    assert planned["fn"] is catalogue_task
    assert planned["kw"] == {"progress": False}
    assert [(t["id"], t["kind"], t["target"]) for t in tasks] == [
        ("anchor-ripple-ms", "anchor-multistart", "ripple"),
        ("anchor-ripple", "anchor", "backlash"),
        ("anchor-backlash-ms", "anchor-multistart", "backlash"),
        ("anchor-backlash", "anchor", "ripple"),
        ("epsilon-catalogue-0000", "eps", "backlash"),
        ("epsilon-catalogue-0001", "eps", "backlash"),
        ("epsilon-catalogue-0002", "eps", "backlash"),
    ]
    assert tasks[1]["tie_of"] == "anchor-ripple-ms" and tasks[1]["fixed"] == "ripple"
    assert tasks[1]["after"] == ["anchor-ripple-ms"]
    assert tasks[3]["tie_of"] == "anchor-backlash-ms" and tasks[3]["fixed"] == "backlash"
    assert [t["eps_frac"] for t in tasks[4:]] == [0.0, 0.5, 1.0]
    assert [t["index"] for t in tasks[4:]] == [0, 1, 2]
    for t in tasks[4:]:
        assert t["after"] == ["anchor-ripple", "anchor-backlash"]
        assert t["eps_name"] == "ripple"
    assert all((t["problem"], t["starts"], t["seed"]) == (problem, 2, 5) for t in tasks)
    # every search holds both objectives: one node NLP (and its solvers) for the front
    assert all(t["objectives"] == ("ripple", "backlash") for t in tasks)
    # run side by side: no chain, no memo
    assert not any("memo" in t or "previous" in t for t in tasks)
    assert [r.id for r in traced.records] == [t["id"] for t in tasks[4:]]
    assert set(traced.anchors) == {"ripple", "backlash"}
    assert traced.anchors["backlash"].id == "anchor-backlash"
    assert traced.n_solves == 7 * 9


def test_one_local_worker_chains_the_points_and_shares_a_memo(problem):
    planned, _ = _trace(problem, RunOptions(workers=1, progress=True), points=3)
    tasks = planned["tasks"]
    assert all(t["memo"] for t in tasks)
    assert tasks[5]["previous"] == "epsilon-catalogue-0002"
    assert planned["kw"] == {"progress": "epsilon-catalogue: points"}
    planned, _ = _trace(problem, RunOptions(workers=1, scheduler="tcp://x:1"), points=3)
    assert not any("memo" in t for t in planned["tasks"])


def _small_catalogue():
    """cs_min_backlash_catalogue cut to 2 leads x 2 pins on an 11-point grid: a catalogue
    front of it takes about 20 NLP solves."""
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "8 mm"]}
    data["requirements"]["deflection"]["points"] = 11
    return problem_from_dict(data)


@pytest.fixture(scope="module")
def small_catalogue():
    return _small_catalogue()


def test_a_catalogue_front_of_three_objectives_is_refused_saying_it_takes_two():
    problem = od.load(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
    with pytest.raises(InputError) as caught:
        od.pareto(problem, ["backlash", "motor_torque", "size"], 3)
    assert caught.value.field == "objectives"
    assert str(caught.value) == "objectives: a catalogue front takes two objectives"


# --- catalogue fronts: the shared memo ----------------------------------------------------
def test_a_catalogue_front_task_without_a_shared_memo_finds_the_searchs_optimum(
    small_catalogue,
):
    """A parallel catalogue front's tasks carry no memo (each worker runs one alone): such
    a task is the plain catalogue search."""
    problem = small_catalogue
    task = {
        "problem": problem,
        "starts": 1,
        "seed": 3,
        "id": "anchor-backlash-ms",
        "kind": "anchor-multistart",
        "target": "backlash",
    }
    rec = PointRecord.from_dict(catalogue_task(task, {}))
    alone = solve_catalogue(problem, starts=1, seed=3, objective="backlash")
    assert rec.success and alone.success
    assert rec.objectives["backlash"] == pytest.approx(alone.objective, rel=1e-6)


def test_a_sequential_catalogue_fronts_inner_point_reuses_the_proofs_before_it(
    small_catalogue, tmp_path
):
    """Run one after another, a catalogue front's points share one memo of boxes proved
    infeasible: the inner point takes fewer NLP solves than the same search (same limit,
    same first incumbents) without it, for the same answer."""
    problem = small_catalogue
    od.pareto(problem, ["backlash", "motor_torque"], points=3, starts=1, out=tmp_path)
    lines = (tmp_path / "epsilon-catalogue.jsonl").read_text().splitlines()[1:]
    recs = {r["id"]: PointRecord.from_dict(r) for r in map(json.loads, lines)}
    inner = recs["epsilon-catalogue-0001"]
    # the first incumbents the point was given: the looser point before it, then the anchors
    before = ("epsilon-catalogue-0002", "anchor-backlash", "anchor-motor_torque")
    alone = solve_catalogue(
        problem,
        starts=1,
        seed=problem.spec.solver.seed,
        objective="motor_torque",
        eps=inner.eps,
        incumbents=[dict(recs[k].design) for k in before],
    )
    assert inner.success and alone.success
    assert inner.objectives["motor_torque"] == pytest.approx(alone.objective, rel=1e-6)
    assert inner.n_solves < alone.details.catalogue.nlp_solves


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


# --- catalogue fronts ---------------------------------------------------------------------
def test_a_catalogue_front_of_fewer_than_two_points_is_refused_naming_the_count():
    """A catalogue front needs two points at least: ``points=1`` is refused, naming the
    field and the count, before any search."""
    problem = od.load(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
    with pytest.raises(InputError) as caught:
        compute_front(problem, ["backlash", "motor_torque"], 1)
    assert caught.value.field == "points"
    assert str(caught.value) == "points: a front needs at least 2 points, got 1"


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


def test_every_search_of_a_catalogue_front_takes_the_fronts_seed(monkeypatch, tmp_path):
    from optdesign.studies.pareto import catalogue_front

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["6 mm", "8 mm"]}
    problem = problem_from_dict(data)
    assert problem.spec.solver.seed != 5
    seeds = []
    search = catalogue_front.solve_catalogue

    def spy(*args, **kwargs):
        seeds.append(kwargs.get("seed"))
        return search(*args, **kwargs)

    monkeypatch.setattr(catalogue_front, "solve_catalogue", spy)
    od.pareto(problem, ["backlash", "motor_torque"], 3, out=tmp_path, starts=1, seed=5)
    assert seeds and set(seeds) == {5}


def test_every_search_of_a_catalogue_front_solves_one_node_nlp(small_front, monkeypatch):
    """The anchors' first stages, their tie-breaks and the points pass both objectives to
    their node solvers: one NLP, so its solvers are built once for the front."""
    from optdesign.formulations.catalogue import node_solver

    problem, _, _ = small_front
    seen = []
    init = node_solver.NodeSolver.__init__

    def record(self, *args, **kwargs):
        init(self, *args, **kwargs)
        seen.append((self.objective, self.nlp.fingerprint))

    monkeypatch.setattr(node_solver.NodeSolver, "__init__", record)
    od.pareto(problem, ["backlash", "motor_torque"], points=3, starts=2, workers=1, files=False)
    assert {objective for objective, _ in seen} == {"backlash", "motor_torque"}
    assert len({fingerprint for _, fingerprint in seen}) == 1
