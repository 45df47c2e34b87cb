"""optdesign/studies/pareto/template.py as a whole, through a front method written as a
user would (its step returns records it makes up, no solve): the refusals and their
order, the starts and seed, the store and its identity, the anchors' check and the front
the template wraps up."""

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import pytest

import optdesign as od
from optdesign.errors import InputError
from optdesign.search.global_phase import default_max_starts
from optdesign.studies.nlp_solve import planned_starts
from optdesign.studies.pareto import template
from optdesign.studies.pareto.chains import NoFeasibleAnchor
from optdesign.studies.pareto.records import PointRecord
from optdesign.studies.pareto.template import (
    FrontMethod,
    FrontRun,
    Traced,
    has_catalogue,
    leaves_catalogue,
)
from optdesign.studies.run_options import RunOptions

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"


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


# --- refusals -------------------------------------------------------------------------------


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


# --- starts and seed ----------------------------------------------------------------------------


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


# --- the run --------------------------------------------------------------------------------------


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
