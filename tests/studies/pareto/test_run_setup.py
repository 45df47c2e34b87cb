"""What every front method does before its first task (studies/pareto/run_setup.py),
pinned function by function: the refusals of a problem and of objectives (field and
message), the store's path, the run's identity and the check of a stored record."""

from __future__ import annotations

import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import optdesign as od
from optdesign.errors import InputError
from optdesign.formulations.nlp.solve import formulation_for
from optdesign.storage import StoreError
from optdesign.studies.pareto import (
    PointRecord,
)
from optdesign.studies.pareto.records import RawSolution
from optdesign.studies.pareto.run_setup import (
    check_front_problem,
    check_objectives,
    record_check,
    run_key,
    store_path,
)

CS = "problems/cs_min_backlash.toml"
AVAILABLE = "ripple, backlash, backlash_rss, size, nut_travel, motor_torque, drive_loss"


@pytest.fixture(scope="module")
def cs():
    return od.load(CS)


# --- the problem and the objectives -------------------------------------------------------
def test_a_problem_without_a_free_variable_has_no_front():
    fixed = SimpleNamespace(free=[], name="fixed")
    with pytest.raises(InputError) as caught:
        check_front_problem(fixed)
    assert caught.value.field == "variables"
    assert str(caught.value) == (
        "variables: no free variable: a front trades objectives by moving the design, and "
        "this problem's design is fixed (od.solve, optdesign solve, checks it)"
    )
    # checked before the objectives: a wrong count is not what it is told
    with pytest.raises(InputError, match=r"^variables: no free variable"):
        check_objectives(fixed, ["a"])


def test_a_problem_with_a_free_variable_may_have_a_front(cs):
    assert check_front_problem(cs) is None


@pytest.mark.parametrize(
    "objectives, reason",
    [
        (["backlash"], "give two or three objectives, got ['backlash']"),
        ([], "give two or three objectives, got []"),
        (("a", "b", "c", "d"), "give two or three objectives, got ['a', 'b', 'c', 'd']"),
        (("size", "size"), "repeated objective in ['size', 'size']"),
        (["size", "ripple", "size"], "repeated objective in ['size', 'ripple', 'size']"),
        (["size", "nope"], f"'nope' is not an objective of cs_min_backlash (available: {AVAILABLE})"),
        (["nope", "size", "x"], f"'nope' is not an objective of cs_min_backlash (available: {AVAILABLE})"),
    ],
)  # fmt: skip
def test_objectives_a_front_cannot_trade_are_refused_naming_the_field(cs, objectives, reason):
    with pytest.raises(InputError) as caught:
        check_objectives(cs, objectives)
    assert caught.value.field == "objectives"
    assert str(caught.value) == f"objectives: {reason}"


def test_two_or_three_distinct_objectives_are_kept_in_their_order_as_a_list(cs):
    assert check_objectives(cs, ("size", "backlash")) == ["size", "backlash"]
    three = check_objectives(cs, iter(["ripple", "size", "backlash"]))
    assert three == ["ripple", "size", "backlash"] and isinstance(three, list)


# --- the store ---------------------------------------------------------------------------
def test_the_store_is_the_methods_name_in_the_output_folder_made_with_its_parents(tmp_path):
    out = tmp_path / "a" / "b"
    path = store_path(out, "epsilon")
    assert path == out / "epsilon.jsonl" and out.is_dir()
    assert store_path(str(out), "weighted_sum.v-2") == out / "weighted_sum.v-2.jsonl"
    assert not path.exists()  # the folder is made, the store is the runner's to write
    # no output folder: a new temporary one, named for what it holds
    temporary = store_path(None, "epsilon")
    assert temporary.name == "epsilon.jsonl" and temporary.parent.is_dir()
    assert temporary.parent.name.startswith("optdesign-pareto-")
    temporary.parent.rmdir()


@pytest.mark.parametrize("name, shown", [("../up", "'../up'"), ("a b", "'a b'"), (5, "5"),
                                         (".hidden", "'.hidden'"), ("", "''")])  # fmt: skip
def test_a_method_name_that_is_no_plain_file_name_is_refused_before_any_folder(
    tmp_path, name, shown
):
    with pytest.raises(InputError) as caught:
        store_path(tmp_path / "out", name)
    assert caught.value.field == "name"
    assert str(caught.value) == (
        f"name: {shown}: a method's name names its store file: use letters, digits, ._-"
    )
    assert not (tmp_path / "out").exists()


# --- the run's identity and the check of a stored record -----------------------------------
def test_a_runs_key_holds_its_objectives_settings_back_end_and_sorted_formulation(cs):
    key = run_key(cs, ["size", "backlash"], "ipopt", points=5, seed=None)
    assert key["objectives"] == ["size", "backlash"]
    assert key["method"] == {"points": 5, "seed": None}
    assert key["solver"]["back_end"] == "ipopt"
    assert key["formulation"] == formulation_for(cs, ("backlash", "size")).fingerprint
    assert run_key(cs, ["size", "backlash"], "slsqp")["solver"]["back_end"] == "slsqp"
    assert run_key(cs, ["size", "backlash"], "ipopt")["method"] == {}


def _design_record(cs, **design):
    x = cs.midpoint()
    full = {**cs.design_dict(x), **design}
    return PointRecord(
        id="epsilon-0001",
        kind="eps",
        target="size",
        status="optimal",
        verified=True,
        design=full,
        objectives={"backlash": 0.1, "size": 1.0},
        x=[full[v.name] for v in cs.free],
    ).to_dict()


def test_a_stored_record_is_checked_against_the_problem_and_the_fronts_formulation(cs):
    """The check is bound to the problem (a design outside its bounds) and to the
    formulation of the front's objectives, sorted (a warm start of its fingerprint must
    have its size, whatever order the objectives were given in)."""
    check = record_check(cs, ["size", "backlash"])
    assert check({"id": "x", "status": "failed"}) == "has no text field 'kind'"
    outside = check(_design_record(cs, R=500.0))
    assert outside == "has R = 500 mm, outside its bounds [30, 120]"
    nlp = formulation_for(cs, ("backlash", "size"))
    failed = PointRecord(id="e", kind="eps", target="size", status="failed")
    failed.raw = RawSolution(np.zeros(3), np.zeros(3), np.zeros(2), nlp.fingerprint)
    assert len(nlp.lbz) != 3
    assert check(failed.to_dict()) == "holds a warm start of the wrong size"
    assert record_check(cs, ["backlash", "size"])(failed.to_dict()) == (
        "holds a warm start of the wrong size"
    )
    # a warm start of another formulation is not this front's: not checked for size
    failed.raw.nlp = formulation_for(cs, ("size", "backlash")).fingerprint
    assert failed.raw.nlp != nlp.fingerprint and check(failed.to_dict()) is None


ROOT = Path(__file__).resolve().parents[3]


# --- resuming a stored front ------------------------------------------------------------
@pytest.fixture(scope="module")
def weighted_run(tmp_path_factory):
    """A finished 3-point weighted-sum front of cs_min_backlash (its output folder)."""
    out = tmp_path_factory.mktemp("weighted")
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    front = od.pareto(problem, ["backlash", "size"], 3, method="weighted_sum", starts=1, out=out)
    assert len(front.points) >= 2
    return problem, out, front


def _resume_weighted(problem, out, points=3, starts=1):
    return od.pareto(
        problem,
        ["backlash", "size"],
        points,
        method="weighted_sum",
        starts=starts,
        out=out,
        resume=True,
    )


def test_resuming_a_weighted_sum_front_with_other_settings_names_the_setting(
    weighted_run, tmp_path
):
    problem, finished, _ = weighted_run
    out = shutil.copytree(finished, tmp_path / "out")
    with pytest.raises(
        StoreError, match=r"method's settings changed \(method.n: stored 3, now 4\)"
    ):
        _resume_weighted(problem, out, points=4)
    with pytest.raises(StoreError, match=r"\(method.starts: stored 1, now 2\)"):
        _resume_weighted(problem, out, starts=2)


def test_a_front_without_an_output_folder_keeps_its_store_in_a_named_temporary_folder():
    """No ``out``: the store goes to a new temporary folder whose name says what it is."""
    from optdesign.studies.pareto.run_setup import store_path

    path = store_path(None, "epsilon")
    assert path.name == "epsilon.jsonl" and path.parent.is_dir()
    assert path.parent.name.startswith("optdesign-pareto-")
    path.parent.rmdir()
