"""One front-method template (studies/pareto/template.py): a new method is a small
subclass giving its step; the command line and od.pareto build methods by one function."""

import json
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import pytest

import optdesign as od
from optdesign.errors import InputError
from optdesign.formulations.nlp.solve import planned_starts
from optdesign.runtime.run_options import RunOptions
from optdesign.search.global_phase import default_max_starts
from optdesign.studies.pareto import (
    CatalogueEpsilon,
    EpsilonConstraint,
    FrontMethod,
    PointRecord,
    compute_front,
    make_method,
    template,
)
from optdesign.studies.pareto.chains import NoFeasibleAnchor, anchor_tasks
from optdesign.studies.pareto.tasks import front_task
from optdesign.studies.pareto.template import (
    FrontRun,
    Traced,
    has_catalogue,
    leaves_catalogue,
)

FORK = "problems/fork_min_backlash.toml"
CATALOGUE = "problems/cs_min_backlash_catalogue.toml"


@dataclass
class AnchorsOnly(FrontMethod):
    """The two ends of a front and nothing between: the smallest method the template
    runs (store, identity, resume, anchors' check and wrap-up come from the template)."""

    starts: int | None = 2
    seed: int | None = None
    name: str = "anchors"

    def identity(self, starts, seed, objectives):
        return "ipopt", {"method": "anchors", "starts": starts, "seed": seed}

    def trace(self, ctx: FrontRun) -> Traced:
        common = {"problem": ctx.problem, "objectives": sorted(ctx.objectives), "solver": "ipopt"}
        done = ctx.tasks(anchor_tasks(common, ctx.objectives, ctx.starts, ctx.seed, 3), front_task)
        anchors = {k: PointRecord.from_dict(done[f"anchor-{k}"]) for k in ctx.objectives}
        return Traced(list(anchors.values()), anchors, sum(r.n_solves for r in anchors.values()))


def test_a_new_front_method_is_a_small_subclass_of_the_template(tmp_path):
    problem = od.load(FORK)
    front = od.pareto(problem, ["backlash", "size"], method=AnchorsOnly(), out=tmp_path)
    assert front.store == str(tmp_path / "anchors.jsonl")
    assert sorted(p.id for p in front.points) == ["anchor-backlash", "anchor-size"]
    # each end is the optimum of its objective: the other end is worse in it
    ends = {p.id: p.objectives for p in front.points}
    assert ends["anchor-backlash"]["backlash"] < ends["anchor-size"]["backlash"]
    assert ends["anchor-size"]["size"] < ends["anchor-backlash"]["size"]
    assert front.anchors == {k: ends[f"anchor-{k}"] for k in ("backlash", "size")}
    # a resume reads the store the template wrote: no solve runs again
    seen = []
    again = od.pareto(
        problem,
        ["backlash", "size"],
        method=AnchorsOnly(),
        out=tmp_path,
        resume=True,
        on_record=seen.append,
    )
    assert seen == []
    assert [p.objectives for p in again.points] == [p.objectives for p in front.points]
    # the template's refusals hold for it too
    with pytest.raises(InputError, match="would leave the catalogue"):
        od.pareto(CATALOGUE, ["ripple", "backlash"], method=AnchorsOnly())
    with pytest.raises(InputError, match="time_limit: not applied by the anchors method"):
        od.pareto(problem, ["backlash", "size"], method=AnchorsOnly(), time_limit=5)


def test_the_command_line_builds_methods_as_od_pareto_does(tmp_path):
    """The same front, point for point, from ``optdesign pareto`` and from od.pareto with
    the same settings (both build the method by make_method)."""

    from optdesign.cli import main

    out = tmp_path / "cli"
    argv = ["pareto", FORK, "--objectives", "backlash,size", "--points", "4", "--method"]
    more = ["--starts", "2", "--workers", "1", "--deterministic", "--out", str(out)]
    quiet = ["--no-plot", "--no-report", "--no-progress"]
    assert main([*argv, "uniform,weighted_sum", *more, *quiet]) == 0
    stored = json.loads((out / "front.json").read_text())["fronts"]
    problem = od.load(FORK)
    for method, cli in zip(("uniform", "weighted_sum"), stored, strict=True):
        extra = {"deterministic": True} if method == "uniform" else {}
        front = od.pareto(problem, ["backlash", "size"], 4, method, starts=2, **extra)
        assert cli["method"] == front.method == method
        assert cli["settings"] == json.loads(json.dumps(front.settings))
        assert [p["objectives"] for p in cli["points"]] == [p.objectives for p in front.points]
    catalogue = od.load(CATALOGUE)
    assert make_method(catalogue, "epsilon", 7, starts=2, seed=5, deterministic=True) == (
        CatalogueEpsilon(points=7, starts=2, seed=5)
    )
    assert make_method(problem, "uniform", 7, starts=2) == EpsilonConstraint(
        points=7, spacing="uniform", name="uniform", starts=2
    )
    with pytest.raises(InputError, match="weighted_sum would leave the catalogue") as caught:
        make_method(catalogue, "weighted_sum", 7)
    assert caught.value.field == "method"  # the argument named, as od.pareto spells it


def test_a_front_takes_the_callers_seed_and_makes_its_nested_folder(tmp_path):
    """``seed`` reaches the method (its settings, the store's identity) in place of the
    file's; ``out`` may name a folder whose parents do not exist yet."""

    fork = od.load(FORK)
    assert fork.spec.solver.seed != 7
    out = tmp_path / "new" / "front"
    front = od.pareto(fork, ["size", "backlash"], 3, out=out, starts=1, seed=7)
    assert front.settings["seed"] == 7 and front.settings["starts"] == 1
    header = json.loads((out / "epsilon.jsonl").read_text().splitlines()[0])
    assert '"seed": 7' in json.dumps(header)


def test_a_method_whose_name_is_not_a_file_name_is_refused_naming_it(tmp_path):
    """A method's name becomes its store's file name: one with a path in it is refused
    before any work, naming the field, and nothing is written."""
    bad = AnchorsOnly(name="../escape")
    with pytest.raises(InputError) as caught:
        od.pareto(od.load(FORK), ["backlash", "size"], method=bad, out=tmp_path / "out")
    assert caught.value.field == "name"
    assert caught.value.reason.startswith("'../escape': a method's name names its store file")
    assert not (tmp_path / "escape.jsonl").exists()


# optdesign/studies/pareto/template.py as a whole, through a front method written as a
# user would (its step returns records it makes up, no solve): the refusals and their
# order, the starts and seed, the store and its identity, the anchors' check and the front
# the template wraps up.


PROBLEMS = Path(__file__).resolve().parents[3] / "problems"


@pytest.fixture(scope="module")
def continuous():
    return od.load(PROBLEMS / "cs_min_backlash.toml")


@pytest.fixture(scope="module")
def catalogue():
    return od.load(PROBLEMS / "cs_min_backlash_catalogue.toml")


def _rec(i, a, b, status="optimal", kind="eps"):
    return PointRecord(
        id=f"p{i}",
        kind=kind,
        target="ripple",
        status=status,
        verified=True,
        objectives={"ripple": a, "backlash": b},
        design={"R": float(i)},
    )


@dataclass
class Made:
    """A front method whose step makes up its records (and remembers its run)."""

    name: str = "made"
    starts: int | None = None
    seed: int | None = None
    anchor_status: str = "optimal"
    bad_setting: bool = False

    what: ClassVar[str] = "the made-up front"


class MadeMethod(Made, FrontMethod):
    seen: ClassVar[list] = []

    def check_settings(self):
        if self.bad_setting:
            raise InputError("bad_setting", "refused")

    def identity(self, starts, seed, objectives):
        return "ipopt", {"starts": starts, "seed": seed, "made": True, "of": list(objectives)}

    def settings(self, starts, seed, objectives):
        return {"starts": starts, "seed": seed}

    def trace(self, ctx: FrontRun) -> Traced:
        MadeMethod.seen.append(ctx)
        records = [
            _rec(0, 1.0, 5.0),
            _rec(1, 2.0, 3.0),
            _rec(2, 3.0, 4.0),
            _rec(3, 0.5, 9.0, "infeasible"),
        ]
        anchor = _rec(9, 1.0, 5.0, self.anchor_status, kind="anchor")
        return Traced(records, {"ripple": anchor}, n_solves=7, notes=["made up"])


class TwoOnly(MadeMethod):
    n_objectives: ClassVar[tuple[int, ...]] = (2,)


class CatalogueOnly(MadeMethod):
    designs: ClassVar[str] = "catalogue"


class AnyDesign(MadeMethod):
    designs: ClassVar[str] = "any"


class Unstored(MadeMethod):
    stored: ClassVar[bool] = False


class Capped(MadeMethod):
    max_default_starts: ClassVar[int | None] = 3


def test_a_method_refuses_an_objective_count_it_does_not_take(continuous):
    with pytest.raises(InputError) as err:
        TwoOnly().refuse(continuous, ["ripple", "backlash", "size"])
    assert err.value.field == "objectives"
    assert "the made-up front takes two objectives" in str(err.value)
    assert MadeMethod().refuse(continuous, ("ripple", "backlash", "size")) == [
        "ripple",
        "backlash",
        "size",
    ]


def test_a_continuous_method_refuses_catalogue_variables_naming_itself(catalogue):
    assert has_catalogue(catalogue)
    with pytest.raises(InputError) as err:
        MadeMethod().refuse(catalogue, ["ripple", "backlash"])
    assert err.value.field == "method"
    assert str(err.value).endswith(
        leaves_catalogue("MadeMethod 'made'") + " (the name 'epsilon' picks CatalogueEpsilon there)"
    )
    assert "use epsilon or nsga2 (the name 'epsilon' picks CatalogueEpsilon there)" in str(
        err.value
    )


def test_a_catalogue_method_refuses_a_continuous_problem_and_any_takes_both(continuous, catalogue):
    assert not has_catalogue(continuous)
    with pytest.raises(InputError) as err:
        CatalogueOnly(name="cat").refuse(continuous, ["ripple", "backlash"])
    assert err.value.field == "method"
    assert "cat: no variable takes catalogue values" in str(err.value)
    assert CatalogueOnly().refuse(catalogue, ["ripple", "backlash"]) == ["ripple", "backlash"]
    for problem in (continuous, catalogue):
        assert AnyDesign().refuse(problem, ["backlash", "ripple"]) == ["backlash", "ripple"]


def test_the_settings_are_checked_after_the_objectives_and_the_problem(continuous, catalogue):
    with pytest.raises(InputError) as err:
        MadeMethod(bad_setting=True).refuse(continuous, ["ripple"])
    assert err.value.field == "objectives"
    with pytest.raises(InputError) as err:
        MadeMethod(bad_setting=True).refuse(catalogue, ["ripple", "backlash"])
    assert err.value.field == "method"
    with pytest.raises(InputError) as err:
        MadeMethod(bad_setting=True).refuse(continuous, ["ripple", "backlash"])
    assert err.value.field == "bad_setting"


def test_the_leave_the_catalogue_refusal_reads_whole():
    assert leaves_catalogue("x") == (
        "x would leave the catalogue: with catalogue variables use epsilon or nsga2"
    )


def test_starts_and_seed_are_the_methods_else_the_problem_files(continuous):
    solver = continuous.spec.solver
    planned = planned_starts(continuous)  # the file sets none: chosen from the dimension
    assert solver.starts is None and planned == default_max_starts(len(continuous.free))
    assert MadeMethod().starts_and_seed(continuous) == (planned, solver.seed)
    assert MadeMethod(starts=2, seed=5).starts_and_seed(continuous) == (2, 5)
    # seed 0 is the method's own, not "unset"
    data = tomllib.loads((PROBLEMS / "cs_min_backlash.toml").read_text())
    data.setdefault("solver", {}).update(seed=4, starts=5)
    seeded = od.load(data)
    assert MadeMethod().starts_and_seed(seeded) == (5, 4)
    assert MadeMethod(starts=1, seed=0).starts_and_seed(seeded) == (1, 0)
    assert Capped().starts_and_seed(continuous) == (min(planned, 3), solver.seed)
    assert Capped(starts=12).starts_and_seed(continuous)[0] == 12


def test_a_method_without_starts_or_seed_fields_takes_the_problem_files(continuous):
    class Bare(FrontMethod):
        name = "bare"

    solver = continuous.spec.solver
    assert Bare().starts_and_seed(continuous) == (planned_starts(continuous), solver.seed)


def test_a_stored_run_sets_up_its_store_identity_and_check(continuous, tmp_path):
    MadeMethod.seen.clear()
    front = MadeMethod(starts=2, seed=3).run(
        continuous, ["ripple", "backlash"], RunOptions(out=tmp_path, workers=1)
    )
    ctx = MadeMethod.seen[-1]
    assert ctx.store == tmp_path / "made.jsonl"
    assert (ctx.starts, ctx.seed) == (2, 3)
    # a method's identity gets the checked objectives (a plug-in may key its store on them)
    assert ctx.key["method"] == {"starts": 2, "seed": 3, "made": True, "of": ["ripple", "backlash"]}
    assert ctx.key["solver"]["back_end"] == "ipopt"
    assert ctx.key["objectives"] == ["ripple", "backlash"]
    assert ctx.check is not None
    assert ctx.objectives == ["ripple", "backlash"]
    assert front.store == str(tmp_path / "made.jsonl")
    assert front.settings == {"starts": 2, "seed": 3}


def test_an_unstored_run_has_no_store_key_or_check(continuous, tmp_path):
    MadeMethod.seen.clear()
    front = Unstored().run(continuous, ["ripple", "backlash"], RunOptions(out=tmp_path))
    ctx = MadeMethod.seen[-1]
    assert (ctx.store, ctx.key, ctx.check) == (None, {}, None)
    assert front.store == ""
    assert not (tmp_path / "made.jsonl").exists()


def test_the_front_is_the_non_dominated_successes_sorted_with_the_rest_rejected(continuous):
    front = MadeMethod(starts=1, seed=0).run(
        continuous, ["ripple", "backlash"], RunOptions(out=None)
    )
    assert front.method == "made"
    assert [p.id for p in front.points] == ["p0", "p1"]
    assert all(p.method == "made" for p in front.points)
    assert {p.id: p.rejected for p in front.rejected} == {
        "p2": "dominated or duplicate",
        "p3": "failed",
    }
    assert front.n_solves == 7
    assert front.notes == ["made up"]
    assert front.anchors == {"ripple": {"ripple": 1.0, "backlash": 5.0}}
    assert front.wall_time_s >= 0.0
    assert front.metrics["n_failed"] == 1


def test_a_failed_anchor_is_refused_naming_it(continuous):
    with pytest.raises(NoFeasibleAnchor) as err:
        MadeMethod(anchor_status="infeasible").run(
            continuous, ["ripple", "backlash"], RunOptions(out=None)
        )
    assert "ripple" in str(err.value)


def test_the_runs_tasks_go_through_the_runner_with_the_runs_settings(monkeypatch, tmp_path):
    calls = []
    monkeypatch.setattr(
        template,
        "run_tasks",
        lambda tasks, fn, store, **kw: calls.append((tasks, fn, store, kw)) or {"t": 1},
    )
    run = RunOptions(out=tmp_path, workers=2, resume=True, progress=True, on_record=print)
    ctx = FrontRun(None, ["a", "b"], run, tmp_path / "s.jsonl", {"k": 1}, 2, 3, len)
    assert ctx.tasks([{"id": "t"}], abs) == {"t": 1}
    tasks, fn, store, kw = calls[-1]
    assert (tasks, fn, store) == ([{"id": "t"}], abs, tmp_path / "s.jsonl")
    assert kw == {
        "workers": 2,
        "scheduler": None,
        "resume": True,
        "progress": False,
        "key": {"k": 1},
        "on_record": print,
        "check": len,
    }
    ctx.tasks([], abs, workers=1, check=None)
    assert calls[-1][3]["workers"] == 1 and calls[-1][3]["check"] is None


ROOT = Path(__file__).resolve().parents[3]


# --- the front-method template ----------------------------------------------------------
@dataclass
class _NoSettings(FrontMethod):
    """A plug-in front method that declares neither ``starts`` nor ``seed``."""

    name: str = "plain"


def test_a_front_method_without_starts_or_seed_takes_the_problem_files():
    problem = od.load(ROOT / "problems" / "fork_min_backlash.toml")
    solver = problem.spec.solver
    # the file sets no starts: the global search's cap, chosen from the dimension
    assert solver.starts is None
    assert _NoSettings().starts_and_seed(problem) == (12 * len(problem.free), solver.seed)


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


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
