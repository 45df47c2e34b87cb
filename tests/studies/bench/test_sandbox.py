"""What a benchmark row may record as its objective (issue "Bench that cannot record the
impossible"): a value of the NumPy model at a design the independent check confirmed,
within the objective's physical range - never the solver's own value (an epigraph
variable, a scaled value) at an unfinished iterate, never NaN, never a negative ripple;
and SLSQP with exact derivatives at Ipopt's optimum on the shipped problems."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.formulations.verify import verify_design
from optdesign.problem.objectives import BUILTIN_OBJECTIVES, ObjectiveInfo
from optdesign.solvers.result import Result, TerminationCondition
from optdesign.studies import bench
from optdesign.studies.bench.configs import Config
from optdesign.studies.bench.sandbox import row_problem, run_task
from optdesign.studies.bench.scoring import config_stats

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"

#: A design of cs_min_ripple (shipped-000) where the ratio changes sign over the stroke:
#: its NumPy ripple is -1.62 (an iterate an unfinished solve may stop at).
NEGATIVE_RIPPLE = {"R": 44.5, "l": 97.8, "n": 127.4, "p": 4.8, "phi0": -0.3}

#: The optimum of cs_min_ripple (the committed benchmark's Ipopt run): ripple 1.2111 %.
RIPPLE_OPTIMUM = {
    "R": 71.91183282941671,
    "l": 103.94194573336492,
    "n": 89.9216430490189,
    "p": 3.514539798468872,
    "phi0": 0.4912611931196259,
}


def _fake_run(monkeypatch, status: str, objective: float, design: dict, problem=None):
    """One run, in this process, of a configuration that returns ``status`` with the
    solver's value ``objective`` at ``design``, on ``problem`` (default: cs_min_ripple)."""

    def run(problem, name, time_limit):
        return Result(
            status=status,
            objective=objective,
            design=dict(design),
            formulation="nlp-epigraph",
            solver="fake",
            message=f"fake {status}",
            termination=TerminationCondition.MAX_TIME,
        )

    monkeypatch.setitem(bench.CONFIGS, "fake", Config("fake", "nlp", run, hidden=True))
    task = {"id": "x|fake", "family": "user", "seed": 0, "config": "fake", "time_limit": 5.0}
    task["problem"] = problem if problem is not None else od.load(PROBLEMS / "cs_min_ripple.toml")
    task["hard_timeout"] = 10.0
    return task, run_task(task)


def test_a_time_limited_run_never_records_a_negative_ripple_or_the_solvers_value(monkeypatch):
    problem = od.load(PROBLEMS / "cs_min_ripple.toml")
    x = np.array([NEGATIVE_RIPPLE[v.name] for v in problem.free])
    assert problem.evaluate(x).objectives["ripple"] < 0  # what the old row recorded
    _, row = _fake_run(monkeypatch, "time_limit", -0.21, NEGATIVE_RIPPLE)
    assert row["status"] == "time_limit" and row["success"] is False
    assert row["objective"] is None and row["solver_objective"] is None
    assert row["design"] is None and row["verified"] is False
    assert "no verified point: independent check failed: ratio_positive" in row["reason"]
    # stopped at a design the check confirms: its NumPy ripple, not the solver's -0.21
    task, row = _fake_run(monkeypatch, "time_limit", -0.21, RIPPLE_OPTIMUM)
    assert row["status"] == "time_limit" and row["success"] is False
    assert row["verified"] is True and row["design"] == RIPPLE_OPTIMUM
    assert row["objective"] == pytest.approx(0.0121114, rel=1e-5)
    assert row["solver_objective"] is None
    assert "not solved: its best verified point" in row["reason"]
    assert row_problem(task, {**row, "id": task["id"]}, {}) is None


def test_time_limited_real_runs_record_verified_numpy_values_only(tmp_path):
    # Stopped after 20 ms: SLSQP, trust-constr and Ipopt at unfinished iterates.
    problem = od.load(PROBLEMS / "cs_min_ripple.toml")
    report = od.bench(
        problems=[problem],
        solvers=["slsqp-exact", "trust-constr-exact", "ipopt-exact", "ipopt-naive"],
        time_limit=0.02,
        out=tmp_path,
    )
    assert len(report.rows) == 4
    for row in report.rows:
        if row.objective is None:
            assert not row.success and row.design is None and "no verified point" in row.reason
            continue
        x = np.array([row.design[v.name] for v in problem.free])
        ok, _, objs = verify_design(problem, x)
        assert ok and row.verified is True
        assert row.objective == objs["ripple"] and 0.0 <= row.objective <= 1.0
        if not row.success:
            assert row.solver_objective is None
    lines = (tmp_path / "bench_runs.jsonl").read_text()
    assert "NaN" not in lines and "Infinity" not in lines


def test_a_nan_objective_is_a_failure_naming_why(monkeypatch):
    # The solver claims an optimum where the mechanism does not assemble: NaN on the
    # NumPy path.
    problem = od.load(PROBLEMS / "cs_min_ripple.toml")
    broken = {"R": 95.6, "l": 70.1, "n": 8.3, "p": 4.2, "phi0": 0.2}  # the rod is too short
    x = np.array([broken[v.name] for v in problem.free])
    assert math.isnan(problem.evaluate(x).objectives["ripple"])
    _, row = _fake_run(monkeypatch, "optimal", 0.01, broken)
    assert row["status"] == "optimal" and row["success"] is False
    assert row["objective"] is None and row["verified"] is False
    assert "independent check failed" in row["reason"]
    row = bench.BenchRow.from_dict(row)
    assert config_stats([row], ["fake"])["fake"].failures == {"check failed": 1}


def test_a_users_objective_that_is_nan_or_infinite_at_the_optimum_fails_the_run(
    tmp_path, monkeypatch
):
    # fork_min_backlash's optimum has R = 95.3 mm: sqrt(90 - R) is NaN there. A user's
    # objective declares no range, but it must be a finite number.
    problem = od.load(PROBLEMS / "fork_min_backlash.toml")
    problem.add_objective("nan_beyond_90", lambda q: od.math.sqrt(90.0 - q.R), unit="mm")
    report = od.bench(problems=[problem], solvers=["slsqp-exact"], out=tmp_path)
    (row,) = report.rows
    assert row.status == "optimal" and not row.success and row.objective is None
    assert "no verified point: independent check failed: objective nan_beyond_90" in row.reason
    # infinite at the optimum of cs_min_ripple: the check of the requirements passes
    problem = od.load(PROBLEMS / "cs_min_ripple.toml")
    pole = RIPPLE_OPTIMUM["R"]
    problem.add_objective("pole", lambda q: 1.0 / (q.R - pole), unit="1/mm")
    _, row = _fake_run(monkeypatch, "optimal", 0.0121, RIPPLE_OPTIMUM, problem)
    assert row["success"] is False and row["objective"] is None
    assert row["reason"].endswith("independent check failed: pole is inf, not a finite number")


def test_built_in_objectives_declare_their_physical_range():
    for name in ("ripple", "drive_loss"):
        assert BUILTIN_OBJECTIVES[name].valid == (0.0, 1.0)
    for name in ("backlash", "backlash_rss", "size", "motor_torque", "nut_travel"):
        assert BUILTIN_OBJECTIVES[name].valid == (0.0, None)
    ripple = BUILTIN_OBJECTIVES["ripple"]
    assert ripple.range_problem(0.012) == ""
    assert ripple.range_problem(-0.21) == "ripple -21 % is below its physical range [0, 100] %"
    assert BUILTIN_OBJECTIVES["backlash"].range_problem(-1e-3) == (
        "backlash -0.001 deg is below its physical range [0, inf] deg"
    )
    assert BUILTIN_OBJECTIVES["size"].range_problem(math.nan) == "size is nan, not a finite number"
    with pytest.raises(od.InputError, match="valid"):
        ObjectiveInfo("x", lambda q: q.R, "scalar", valid=(1.0, 0.0))


def test_a_stored_success_outside_the_physical_range_is_not_trusted():
    # A row of the old code that counted a negative ripple (and a NaN) as a success is
    # refused on resume, naming why.
    task = {"id": "shipped-000|slsqp-exact", "family": "shipped", "seed": 0}
    task["config"] = "slsqp-exact"
    base = {
        "instance": "shipped-000",
        "family": "shipped",
        "seed": 0,
        "mechanism": "crank_slider",
        "objective_name": "ripple",
        "catalogue": False,
        "config": "slsqp-exact",
        "kind": "nlp",
        "applicable": True,
        "time_s": 0.1,
        "status": "optimal",
        "success": True,
        "design": RIPPLE_OPTIMUM,
        "verified": True,
        "violation": 0.0,
        "id": task["id"],
    }
    assert row_problem(task, {**base, "objective": 0.01211142428105366}, {}) is None
    why = row_problem(task, {**base, "objective": -0.21}, {})
    assert why == "counts as a success where ripple -21 % is below its physical range [0, 100] %"
    assert row_problem(task, {**base, "objective": math.nan}, {}).startswith(
        "counts as a success with objective nan"
    )


SHIPPED_CONTINUOUS = [
    "cs_min_ripple",
    "cs_min_backlash",
    "cs_min_backlash_robust",
    "fork_min_backlash",
    "pivot_min_backlash",
    "duan2017_redesign",
]


def _slsqp_at_ipopts_optimum(name: str, out: Path) -> None:
    problem = od.load(PROBLEMS / f"{name}.toml")
    report = od.bench(
        problems=[problem], solvers=["ipopt-exact", "slsqp-exact"], time_limit=60.0, out=out
    )
    rows = {r.config: r for r in report.rows}
    assert rows["ipopt-exact"].success, rows["ipopt-exact"].reason
    assert rows["slsqp-exact"].status == "optimal", rows["slsqp-exact"].reason
    assert rows["slsqp-exact"].success
    assert rows["slsqp-exact"].objective == pytest.approx(rows["ipopt-exact"].objective, rel=1e-6)


@pytest.mark.parametrize("name", SHIPPED_CONTINUOUS)
def test_slsqp_exact_reaches_ipopts_optimum_on_the_shipped_problems(name, tmp_path):
    _slsqp_at_ipopts_optimum(name, tmp_path)


@pytest.mark.slow
def test_slsqp_exact_reaches_ipopts_optimum_on_the_shipped_catalogue_problem(tmp_path):
    # every catalogue combination solved by each (about a minute): the same best item
    _slsqp_at_ipopts_optimum("cs_min_backlash_catalogue", tmp_path)
