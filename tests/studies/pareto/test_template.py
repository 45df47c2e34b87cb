"""One front-method template (studies/pareto/template.py): a new method is a small
subclass giving its step; the command line and od.pareto build methods by one function."""

from dataclasses import dataclass

import pytest

import optdesign as od
from optdesign.errors import InputError
from optdesign.studies.pareto import (
    CatalogueEpsilon,
    EpsilonConstraint,
    FrontMethod,
    PointRecord,
    make_method,
)
from optdesign.studies.pareto.chains import anchor_tasks
from optdesign.studies.pareto.tasks import front_task
from optdesign.studies.pareto.template import FrontRun, Traced

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
    import json

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
    import json

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
