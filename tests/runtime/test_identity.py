"""Resume never mixes runs (issue 21, class 8): the store's identity covers the problem's
content, the objectives, the method's settings, the solver and every solver option and
the version; the store format is checked; every stored record is checked (finite, inside
the bounds, confirmed by the independent check) before it is trusted. Each refusal names
what changed, or the store's line and the reason - through the CLI and the Python API.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest

import optdesign as od
from optdesign.cli import main
from optdesign.runtime.runner import run_tasks
from optdesign.storage import STORE_VERSION, StoreError, open_store

ROOT = Path(__file__).resolve().parents[2]
FORK = (ROOT / "problems" / "fork_min_backlash.toml").read_text()
OBJECTIVES = ["size", "backlash"]


def _write_problem(folder: Path, extra: str = "") -> Path:
    path = folder / "fork.toml"
    path.write_text(FORK + extra)
    return path


def _front(problem_file: Path, out: Path, resume: bool = False):
    return od.pareto(
        od.load(problem_file), OBJECTIVES, points=3, out=out, workers=1, starts=1, resume=resume
    )


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished 3-point front of the fork (its problem file and output folder)."""
    base = tmp_path_factory.mktemp("finished")
    problem = _write_problem(base, "\n[solver]\nipopt = { tol = 1e-10 }\n")
    front = _front(problem, base / "out")
    assert len(front.points) >= 2
    return base


@pytest.fixture
def run(finished, tmp_path):
    """A private copy of the finished run: (problem file, output folder, store)."""
    shutil.copytree(finished, tmp_path / "run")
    base = tmp_path / "run"
    return base / "fork.toml", base / "out", base / "out" / "epsilon.jsonl"


def _cli_resume(problem: Path, out: Path, capsys) -> tuple[int, str]:
    code = main(
        [
            "pareto",
            str(problem),
            "--objectives",
            ",".join(OBJECTIVES),
            "--points",
            "3",
            "--starts",
            "1",
            "--workers",
            "1",
            "--out",
            str(out),
            "--resume",
            "--no-progress",
            "--no-plot",
            "--no-report",
        ]
    )
    return code, capsys.readouterr().err


def _records(store: Path) -> list[dict]:
    return [json.loads(x) for x in store.read_text().splitlines()]


def _rewrite(store: Path, lines: list[dict]) -> None:
    store.write_text("".join(json.dumps(x, allow_nan=True) + "\n" for x in lines))


def test_an_unchanged_resume_is_accepted_and_recomputes_nothing(run, capsys):
    problem, out, store = run
    before = store.read_bytes()
    front = _front(problem, out, resume=True)
    assert len(front.points) >= 2
    assert store.read_bytes() == before  # every record was trusted, none recomputed
    code, err = _cli_resume(problem, out, capsys)
    assert code == 0, err
    assert store.read_bytes() == before


def test_the_identity_line_holds_its_components(run):
    _, _, store = run
    head = _records(store)[0]
    assert head["__store__"] == STORE_VERSION
    ident = head["identity"]
    assert set(ident) == {"problem", "formulation", "objectives", "method", "solver", "optdesign"}
    assert ident["solver"]["file"]["ipopt"] == {"tol": 1e-10}
    assert ident["objectives"] == OBJECTIVES
    assert ident["optdesign"] == od.__version__


@pytest.mark.parametrize(
    ("edit", "named"),
    [
        # the [solver] table's Ipopt options: the anchors' and tie-breaks' solver
        (("ipopt = { tol = 1e-10 }", "ipopt = { tol = 1e-8 }"), "solver.file.ipopt.tol"),
        (
            ("ipopt = { tol = 1e-10 }", 'ipopt = { tol = 1e-10, mu_strategy = "monotone" }'),
            "solver.file.ipopt.mu_strategy",
        ),
        (("[solver]", "[solver]\nagree = 2"), "solver.file.agree"),
        # the problem's content, not only its name
        (('hinge_moment = "500 N*m"', 'hinge_moment = "480 N*m"'), "problem's content"),
        (
            (
                'R = { lower = "30 mm", upper = "120 mm" }',
                'R = { lower = "31 mm", upper = "120 mm" }',
            ),
            "problem's content",
        ),
    ],
)
def test_resume_with_a_changed_input_is_refused_naming_it(run, capsys, edit, named):
    problem, out, store = run
    old, new = edit
    text = problem.read_text()
    assert old in text
    problem.write_text(text.replace(old, new, 1))
    before = store.read_bytes()
    code, err = _cli_resume(problem, out, capsys)
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "belongs to another run" in err and named in err
    assert "--overwrite" in err
    with pytest.raises(StoreError, match="belongs to another run") as info:
        _front(problem, out, resume=True)
    assert named in str(info.value)
    assert store.read_bytes() == before  # refused before anything was written


def test_a_renamed_problem_resumes(run):
    # The name changes no record: renaming a problem file's study keeps its store.
    problem, out, store = run
    problem.write_text(problem.read_text().replace('name = "fork_min_backlash"', 'name = "fork-b"'))
    before = store.read_bytes()
    _front(problem, out, resume=True)
    assert store.read_bytes() == before


def test_resume_with_other_method_settings_or_version_is_refused(run, monkeypatch):
    problem, out, _ = run
    p = od.load(problem)
    with pytest.raises(
        StoreError, match=r"method's settings changed \(method.points: stored 3, now 4"
    ):
        od.pareto(p, OBJECTIVES, points=4, out=out, workers=1, starts=1, resume=True)
    with pytest.raises(StoreError, match=r'solver\.back_end: stored "sqpmethod", now "ipopt"'):
        od.pareto(
            p, OBJECTIVES, points=3, out=out, workers=1, starts=1, resume=True, solver="ipopt"
        )
    monkeypatch.setattr(od, "__version__", "99.0.0")
    with pytest.raises(StoreError, match=r"optdesign version changed .*now \"99.0.0\""):
        _front(problem, out, resume=True)


def test_resume_with_a_constraint_added_in_python_is_refused(run):
    problem, out, _ = run
    p = od.load(problem)
    p.add_constraint("nut_force", lambda q: q.nut_force, upper="30 kN", unit="N")
    with pytest.raises(StoreError, match=r"belongs to another run: .*formulation"):
        od.pareto(p, OBJECTIVES, points=3, out=out, workers=1, starts=1, resume=True)


@pytest.mark.parametrize(
    ("version", "word"),
    [(99, "newer"), (1, "older"), ("2", "something other"), (True, "something other")],
)
def test_a_store_of_another_format_is_refused_naming_its_version(run, capsys, version, word):
    problem, out, store = run
    lines = _records(store)
    lines[0]["__store__"] = version
    _rewrite(store, lines)
    code, err = _cli_resume(problem, out, capsys)
    assert code == 2
    assert f"store format {json.dumps(version)}" in err and word in err
    assert f"reads format {STORE_VERSION} only" in err
    with pytest.raises(StoreError, match=f"store format {json.dumps(version)}"):
        _front(problem, out, resume=True)


def _trusted_index(lines: list[dict]) -> int:
    return next(
        k for k, r in enumerate(lines) if k and r.get("status") == "optimal" and r["verified"]
    )


def _tamper(rec: dict, how: str) -> None:
    if how == "nan objective":
        rec["objectives"]["backlash"] = math.nan
    elif how == "null objective":
        rec["objectives"]["size"] = None
    elif how == "design outside the bounds":
        rec["design"]["R"] = 500.0
        rec["x"][0] = 500.0
    elif how == "design not finite":
        rec["design"]["d"] = math.inf
    elif how == "objective edited":
        rec["objectives"]["backlash"] *= 0.99
    elif how == "verified without a check":
        rec["verified"] = None
    elif how == "objectives not numbers":
        rec["objectives"]["size"] = "small"
    elif how == "no status":
        del rec["status"]
    elif how == "x and design disagree":
        rec["x"][1] += 0.5
    elif how == "fixed variable changed":
        rec["design"]["i_a"] = 3.0
    elif how == "fixed variable nudged":  # 1e-10 relative: more than a float's rounding
        rec["design"]["i_a"] *= 1 + 1e-10
    elif how == "warm start of no formulation":
        rec["raw"]["nlp"] = 3
    elif how == "warm start of the wrong size":
        rec["raw"]["z"] = rec["raw"]["z"][:1] if isinstance(rec["raw"]["z"], list) else [0.0]
    else:  # pragma: no cover
        raise AssertionError(how)


@pytest.mark.parametrize(
    ("how", "reason"),
    [
        ("nan objective", "objective backlash = nan"),
        ("null objective", "objective size = nan"),
        ("design outside the bounds", "R = 500 mm, outside its bounds [30, 120]"),
        ("design not finite", "d = inf mm, outside its bounds"),
        ("objective edited", "but its design gives"),
        ("verified without a check", "without the independent check"),
        ("objectives not numbers", "'objectives' is not a table of numbers"),
        ("no status", "no text field 'status'"),
        ("x and design disagree", "'x' that is not its design"),
        ("fixed variable changed", "fixed variable i_a = 3"),
        ("fixed variable nudged", "fixed variable i_a = 2.0000000002, the problem 2.0"),
        ("warm start of the wrong size", " holds a warm start of the wrong size"),
        ("warm start of no formulation", "field 'raw' is not a solution with its multipliers"),
    ],
)
def test_a_record_that_cannot_be_trusted_refuses_the_resume(run, capsys, how, reason):
    problem, out, store = run
    lines = _records(store)
    k = _trusted_index(lines)
    _tamper(lines[k], how)
    _rewrite(store, lines)
    before = store.read_bytes()
    code, err = _cli_resume(problem, out, capsys)
    assert code == 2, err
    assert f"{store} line {k + 1}: record {lines[k]['id']!r}" in err
    assert reason in err and "cannot be trusted" in err and "--overwrite" in err
    with pytest.raises(StoreError, match=f"line {k + 1}: record") as info:
        _front(problem, out, resume=True)
    assert reason in str(info.value)
    assert store.read_bytes() == before


def test_a_failed_record_with_nan_objectives_is_not_refused(run):
    # A failed point is shown as failed; its NaN objectives are what a failure holds.
    problem, out, store = run
    lines = _records(store)
    k = _trusted_index(lines)
    lines[k]["status"] = "failed"
    lines[k]["objectives"] = {"size": math.nan, "backlash": math.nan}
    _rewrite(store, lines)
    front = _front(problem, out, resume=True)
    assert lines[k]["id"] not in {p.id for p in front.points}


def test_overwrite_after_a_refusal_starts_afresh(run, capsys):
    problem, out, store = run
    lines = _records(store)
    _tamper(lines[_trusted_index(lines)], "nan objective")
    _rewrite(store, lines)
    code = main(
        [
            "pareto", str(problem), "--objectives", "size,backlash", "--points", "3",
            "--starts", "1", "--workers", "1", "--out", str(out), "--overwrite",
            "--no-progress", "--no-plot", "--no-report",
        ]
    )  # fmt: skip
    assert code == 0, capsys.readouterr().err
    assert all(
        math.isfinite(v) for r in _records(store)[1:] for v in r["objectives"].values()
        if r["status"] == "optimal"
    )  # fmt: skip


# --- the runner and the store, generically ---------------------------------------------
def _double(task, deps):
    return {"value": 2 * task["n"]}


def test_run_tasks_check_names_the_line_and_keeps_the_store(tmp_path):
    store = tmp_path / "s.jsonl"
    tasks = [{"id": f"t{i}", "n": i} for i in range(4)]
    run_tasks(tasks, _double, store, key={"a": 1, "b": [1, 2]})
    lines = _records(store)
    lines[3]["value"] = -1
    _rewrite(store, lines)
    before = store.read_bytes()

    def check(rec):
        return None if rec["value"] >= 0 else f"has value {rec['value']}"

    with pytest.raises(StoreError, match=r"s.jsonl line 4: record 't2' has value -1; it cannot"):
        run_tasks(tasks, _double, store, key={"a": 1, "b": [1, 2]}, resume=True, check=check)
    assert store.read_bytes() == before
    with pytest.raises(StoreError, match=r"b\[?.*stored \[1,2\], now \[1,3\]|b: stored"):
        run_tasks(tasks, _double, store, key={"a": 1, "b": [1, 3]}, resume=True)


def test_identity_components_are_compared_one_by_one(tmp_path):
    store = tmp_path / "s.jsonl"
    open_store(store, {"solver": {"ipopt": {"tol": 1e-8}}, "objectives": ["a", "b"]}, False)
    with pytest.raises(StoreError) as info:
        open_store(store, {"solver": {"ipopt": {"tol": 1e-6}}, "objectives": ["a", "b"]}, True)
    msg = str(info.value)
    assert "the solver or its options changed (solver.ipopt.tol: stored 1e-08, now 1e-06)" in msg
    assert "objectives" not in msg.split("changed")[1]
    # a string key (older callers) is still compared as a whole
    open_store(store, "k1", False, overwrite=True)
    with pytest.raises(StoreError, match="its identity is 'k1', this run's 'k2'"):
        open_store(store, "k2", True)


# --- the benchmark's store ----------------------------------------------------------------
def test_bench_resume_checks_its_problems_options_and_its_rows(tmp_path):
    problem_file = _write_problem(tmp_path, "\n[solver]\nipopt = { tol = 1e-10 }\n")
    out = tmp_path / "bench"
    first = od.bench(problems=[od.load(problem_file)], solvers=["slsqp"], out=out)
    assert [r.status for r in first.rows] == ["optimal"]
    store = out / "bench_runs.jsonl"
    # the same run resumes, recomputing nothing
    before = store.read_bytes()
    again = od.bench(problems=[od.load(problem_file)], solvers=["slsqp"], out=out, resume=True)
    assert again.rows[0].objective == first.rows[0].objective
    assert store.read_bytes() == before
    # the problem's [solver] options changed: refused, naming them
    problem_file.write_text(problem_file.read_text().replace("1e-10", "1e-8"))
    with pytest.raises(StoreError, match=r"problems' content or their \[solver\] options changed"):
        od.bench(problems=[od.load(problem_file)], solvers=["slsqp"], out=out, resume=True)
    problem_file.write_text(problem_file.read_text().replace("1e-8", "1e-10"))
    # a row edited by hand: refused, naming its line
    lines = _records(store)
    lines[1]["objective"] *= 0.5
    _rewrite(store, lines)
    with pytest.raises(
        StoreError, match=r"bench_runs.jsonl line 2: record .* but its design gives"
    ):
        od.bench(problems=[od.load(problem_file)], solvers=["slsqp"], out=out, resume=True)
    lines[1]["objective"] /= 0.5
    lines[1]["design"]["R"] = 1e4
    _rewrite(store, lines)
    with pytest.raises(StoreError, match=r"line 2: record .* outside the bounds: R = 10000 mm"):
        od.bench(problems=[od.load(problem_file)], solvers=["slsqp"], out=out, resume=True)
