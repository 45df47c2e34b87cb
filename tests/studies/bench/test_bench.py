"""Solver benchmarks (issue 6): instances, scipy back-ends, profiles, failure handling,
and the quick suite end to end."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from optdesign.studies import bench
from optdesign.studies.bench.instances import instance_dict, make_instance, single_families, suite
from optdesign.studies.bench.rows import BenchRow, BenchRowError
from optdesign.studies.bench.scoring import (
    best_config,
    config_stats,
    paired_time_ratio,
    performance_profile,
)


def test_instances_are_reproducible_and_validated():
    a, b = instance_dict("cs_backlash", 7), instance_dict("cs_backlash", 7)
    assert a == b
    assert instance_dict("cs_backlash", 8) != a
    # same seed, other family: other requirements
    assert instance_dict("fork_backlash", 7)["requirements"] != a["requirements"]
    insts = suite("default", fronts=False)
    assert len(insts) >= 100
    assert len({i.id for i in insts}) == len(insts)
    n_catalogue = 0
    for inst in insts:
        p = inst.problem()  # same validation as a problem file
        if inst.family != "shipped":
            phi_max = np.degrees(p.phi[-1])
            assert 20.0 <= phi_max <= 40.0
            assert np.isclose(p.phi[0], -p.phi[-1])
        n_catalogue += any(v.discrete for v in p.free)
    assert 10 <= n_catalogue <= 60
    assert {i.family for i in insts} == {"shipped", *single_families()}


def test_performance_profile_hand_made_table():
    inf, nan = np.inf, np.nan
    T = np.array(
        [
            [1.0, 2.0, inf],
            [3.0, 3.0, 6.0],
            [nan, 1.0, 4.0],  # config 0 does not apply to instance 2
            [inf, inf, inf],  # nobody solved instance 3
        ]
    )
    taus = np.array([1.0, 2.0, 4.0, 100.0])
    rho = performance_profile(T, taus)
    np.testing.assert_allclose(rho[0], [2 / 3, 2 / 3, 2 / 3, 2 / 3])
    np.testing.assert_allclose(rho[1], [2 / 4, 3 / 4, 3 / 4, 3 / 4])
    np.testing.assert_allclose(rho[2], [0.0, 1 / 4, 2 / 4, 2 / 4])
    # gap profile: the best run has gap 0; gaps under the floor count as the floor
    G = np.array([[0.0, 1e-3], [2e-7, 0.0]])
    rho_g = performance_profile(G, np.array([1.0, 999.0, 1001.0]), floor=1e-6)
    np.testing.assert_allclose(rho_g[0], [1.0, 1.0, 1.0])
    np.testing.assert_allclose(rho_g[1], [0.5, 0.5, 1.0])


def test_scipy_back_ends_reach_the_fork_optimum():
    from optdesign.programs.nlp import build_nlp
    from optdesign.solvers.scipy_nlp import ScipyNLPSolver

    p = make_instance("shipped", 2).problem()  # fork_min_backlash, optimum 0.0194989 deg
    nlp = build_nlp(p)
    for der in ("exact", "fd"):
        r = ScipyNLPSolver(nlp, "SLSQP", der, time_limit=20).solve(p.start())
        assert r.status == "optimal", r.message
        assert r.objectives["backlash"] == pytest.approx(0.0194989, rel=1e-5)
        assert r.max_violation == 0.0
    r = bench.get_config("de").run(p, "backlash", 20.0)
    assert r.objective == pytest.approx(0.0194989, rel=1e-3)
    assert r.max_violation <= 0.0


def test_failures_are_recorded_and_the_run_goes_on(tmp_path):
    inst = make_instance("fork_backlash", 0)
    res = bench.run_bench(
        "quick",
        ["debug-crash", "debug-hang", "debug-abort", "ipopt-exact"],
        tmp_path,
        workers=2,
        progress=False,
        time_limit=2.0,
        hard_timeout=2.0,
        instances=[inst],
    )
    rows = {r.config: r for r in res.rows}
    assert set(rows) == {"debug-crash", "debug-hang", "debug-abort", "ipopt-exact"}
    assert rows["debug-crash"].status == "error"
    assert "deliberate crash" in rows["debug-crash"].reason
    assert rows["debug-hang"].status == "timeout"
    assert 2.0 <= rows["debug-hang"].time_s < 10.0
    assert rows["debug-abort"].status == "crash"
    assert not any(rows[c].success for c in ("debug-crash", "debug-hang", "debug-abort"))
    assert rows["ipopt-exact"].success and rows["ipopt-exact"].gap == 0.0
    # every run was streamed to the store as it finished
    lines = (tmp_path / "bench_runs.jsonl").read_text().splitlines()
    assert sum(1 for line in lines if '"config"' in line) == 4
    # resume: nothing runs again, the store does not grow
    again = bench.run_bench(
        "quick",
        ["debug-crash", "debug-hang", "debug-abort", "ipopt-exact"],
        tmp_path,
        workers=1,
        progress=False,
        time_limit=2.0,
        hard_timeout=2.0,
        instances=[inst],
        resume=True,
    )
    assert (tmp_path / "bench_runs.jsonl").read_text().splitlines() == lines
    assert [r.status for r in again.rows] == [r.status for r in res.rows]


@pytest.mark.slow  # every configuration on the quick suite: 20-24 s; test_bench's other cases run single configurations
def test_quick_suite_every_configuration_and_consistent_metrics(tmp_path):
    res = bench.run_bench(
        "quick", None, tmp_path, workers=2, progress=False, time_limit=2.0, hard_timeout=4.0
    )
    rows = res.rows
    configs = bench.default_configs()
    ran = {r.config for r in rows if r.applicable}
    assert ran == set(configs), f"not run: {set(configs) - ran}"
    for r in rows:
        if r.success:
            assert r.gap is not None and r.gap >= 0.0
            if not r.is_front:
                assert r.violation <= 1e-6
        else:
            assert r.gap is None
    by_inst: dict[str, list] = {}
    for r in rows:
        if r.success:
            by_inst.setdefault(r.instance, []).append(r.gap)
    assert by_inst, "no configuration succeeded anywhere"
    for gaps in by_inst.values():
        assert min(gaps) == 0.0  # the best configuration defines the best known value
    # the shipped crank-slider backlash problem: best known = the documented optimum
    best = {r.instance: r.best_known for r in rows if r.family == "shipped"}
    assert best["shipped-001"] == pytest.approx(0.0362197, rel=1e-5)
    # the catalogue fork instance: its design uses a catalogue lead
    fork = next(r for r in rows if r.family == "fork_backlash" and r.config == "ipopt-exact")
    assert fork.catalogue and fork.n_subproblems == 3
    with (tmp_path / "bench_runs.csv").open() as fh:
        assert len(list(csv.DictReader(fh))) == len(rows)
    summary = (tmp_path / "summary.md").read_text()
    for c in configs:
        assert c in summary
    assert (tmp_path / "bench_profiles.png").stat().st_size > 10_000
    stats = json.loads((tmp_path / "bench_stats.json").read_text())["all"]
    for c, s in stats.items():
        assert 0.0 <= s["solved_rate"] <= s["success_rate"] <= 1.0, c


def test_cli_lists_configurations(capsys):
    from optdesign.cli import main

    assert main(["bench", "--list"]) == 0
    out = capsys.readouterr().out
    assert "ipopt-exact" in out and "slsqp-fd" in out and "de " in out


def test_best_configuration_and_paired_time_ratio():
    def row(inst, cfg, t, ok=True):
        return BenchRow(inst, "f", 0, "m", "o", False, cfg, "nlp", time_s=t, success=ok, gap=0.0)

    rows = [
        row("a", "fast", 1.0),
        row("b", "fast", 2.0),
        row("c", "fast", 9.0, ok=False),
        row("a", "slow", 3.0),
        row("b", "slow", 10.0),
        row("c", "slow", 4.0),
        row("a", "subset", 0.1),  # applies to one instance only
    ]
    stats = config_stats(rows, ["fast", "slow", "subset"])
    assert stats["fast"].success_rate == pytest.approx(2 / 3)
    assert stats["slow"].median_time_s == 4.0
    # "slow" solves more instances; "subset" (1 run) is not crowned on its easy subset
    assert best_config(stats) == "slow"
    ratio, n = paired_time_ratio(rows, "fast", "slow")
    assert n == 2 and ratio == pytest.approx(np.median([1 / 3, 2 / 10]))


def test_front_configurations_keep_a_catalogue_lead_on_its_items():
    # fork_front-001 takes its lead from a 3-item catalogue. The epsilon configuration
    # once raised (a continuous sweep refuses catalogue problems) and NSGA-II evaluated
    # leads between the items. Both must return catalogue designs only.
    from optdesign.studies.bench.configs import get_config

    inst = make_instance("fork_front", 1)
    problem, objectives = inst.problem(), inst.objectives
    (lead,) = [v for v in problem.free if v.discrete]
    items = np.asarray(lead.values)
    fronts = {}
    for name in ("front-nsga2", "front-epsilon"):
        out = get_config(name).run(problem, objectives, 10.0)
        assert len(out["F"]) >= 5, name
        leads = np.array([d[lead.name] for d in out["designs"]])
        assert np.min(np.abs(leads[:, None] - items[None, :]), axis=1).max() == 0.0, name
        fronts[name] = np.array(out["F"])
    # the catalogue front is the exact one: NSGA-II never dominates any of its points
    eps, ga = fronts["front-epsilon"], fronts["front-nsga2"]
    dominated = [
        np.any(np.all(ga <= f * (1 - 1e-6), axis=1) & np.any(ga < f * (1 - 1e-6), axis=1))
        for f in eps
    ]
    assert not any(dominated)


def test_solver_libraries_are_imported_before_the_runs_fork():
    # Each run is forked from the worker: a library imported inside the run would be
    # imported again by every run and counted in its time (SLSQP's median once grew from
    # 0.045 to 0.24 s that way). preload_modules loads them once, in the parent.
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from optdesign.studies.bench.configs import preload_modules\n"
        "before = {m for m in ('scipy.optimize', 'cvxpy', 'pymoo.optimize') if m in sys.modules}\n"
        "preload_modules(['slsqp-exact', 'gp-clarabel', 'front-nsga2', 'ipopt-exact'])\n"
        "after = {m for m in ('scipy.optimize', 'cvxpy', 'pymoo.optimize') if m in sys.modules}\n"
        "print(sorted(before), sorted(after))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["[]", "['cvxpy',", "'pymoo.optimize',", "'scipy.optimize']"]


# --- the typed row and its store ----------------------------------------------------------
RESULTS = Path(__file__).resolve().parents[3] / "benchmarks" / "results"


def _committed_rows() -> list[str]:
    """The rows of the committed benchmark store (written before BenchRow existed)."""
    return (RESULTS / "bench_runs.jsonl").read_text().splitlines()[1:]


def test_every_committed_row_round_trips_byte_for_byte():
    lines = _committed_rows()
    assert len(lines) > 1000
    shapes = set()
    for line in lines:
        data = json.loads(line)
        row = BenchRow.from_dict(data)
        assert json.dumps(row.to_dict(), allow_nan=True) == line
        assert row.instance == data["instance"] and row.success is data["success"]
        shapes.add(tuple(data))
    assert len(shapes) == 3  # single-objective runs, failures, fronts: each kept as it is
    # a row built in code writes every stored field, and reads back equal
    made = BenchRow("x-1", "x", 1, "fork", "backlash", False, "c", "nlp", objective=0.5, id="i")
    assert BenchRow.from_dict(made.to_dict()) == made
    assert "gap" not in made.to_dict() and "stored_keys" not in made.to_dict()


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        ({"status": 3}, "has no status or success flag"),
        ({"success": "yes"}, "has no status or success flag"),
        ({"time_s": float("nan")}, "has a time that is not a finite number (nan)"),
        ({"time_s": -1.0}, "has a time that is not a finite number (-1.0)"),
        ({"objective": "low"}, "has an objective that is not a number"),
        ({"instance": None}, "has no text field 'instance'"),
        ({"seed": 1.5}, "has no integer field 'seed'"),
        ({"applicable": 1}, "has no flag field 'applicable'"),
        ({"colour": "red"}, "has an unknown field 'colour'"),
    ],
)
def test_a_stored_row_that_is_not_a_row_is_refused_naming_why(change, reason):
    data = json.loads(_committed_rows()[0])
    BenchRow.from_dict(data)
    with pytest.raises(BenchRowError) as info:
        BenchRow.from_dict({**data, **change})
    assert str(info.value) == reason


def test_the_committed_store_regenerates_the_readme_block(tmp_path):
    # What `optdesign bench --update-readme` pastes, rebuilt from the committed store's
    # rows through BenchRow, is the block the README holds, character for character.
    from optdesign.studies.bench.report import README_BEGIN, README_END, write_outputs
    from optdesign.studies.bench.scoring import add_gaps

    rows = add_gaps([BenchRow.from_dict(json.loads(line)) for line in _committed_rows()])
    names = [c for c in bench.default_configs(True) if c in {r.config for r in rows}]
    wall = json.loads((RESULTS / "bench_meta.json").read_text())["wall_time_s"]
    paths = write_outputs(rows, tmp_path, names, "default", wall, 1.0, 4.0, {})
    readme = (RESULTS.parent / "README.md").read_text()
    block = readme[readme.index(README_BEGIN) + len(README_BEGIN) + 1 : readme.index(README_END)]
    assert paths["summary_text"] == block
    with (tmp_path / "bench_runs.csv").open() as fh:
        assert len(list(csv.DictReader(fh))) == len(rows)


def test_a_store_of_the_old_format_resumes(tmp_path):
    # The store keeps the keys and their order of the rows written before BenchRow; a
    # row from the committed store (old code) takes the place of the run's own and is
    # trusted on resume, read back with its values.
    inst = make_instance("shipped", 2)
    kwargs = dict(workers=1, progress=False, time_limit=5.0, hard_timeout=10.0)
    res = bench.run_bench(
        "quick", ["slsqp-exact", "debug-crash"], tmp_path, instances=[inst], **kwargs
    )
    store = tmp_path / "bench_runs.jsonl"
    lines = store.read_text().splitlines()
    old = {json.loads(line)["id"]: line for line in _committed_rows()}
    old_failure = next(json.loads(v) for v in old.values() if json.loads(v)["status"] == "skipped")
    by_id = {json.loads(line)["id"]: k for k, line in enumerate(lines) if k}
    ours = json.loads(lines[by_id["shipped-002|slsqp-exact"]])
    assert list(ours) == list(json.loads(old["shipped-002|slsqp-exact"]))
    assert list(json.loads(lines[by_id["shipped-002|debug-crash"]])) == list(old_failure)
    lines[by_id["shipped-002|slsqp-exact"]] = old["shipped-002|slsqp-exact"]
    store.write_text("\n".join(lines) + "\n")
    again = bench.run_bench(
        "quick", ["slsqp-exact", "debug-crash"], tmp_path, instances=[inst], resume=True, **kwargs
    )
    assert store.read_text().splitlines() == lines  # nothing ran again
    rows = {r.config: r for r in again.rows}
    stored = json.loads(old["shipped-002|slsqp-exact"])
    assert (
        rows["slsqp-exact"].objective == stored["objective"] == pytest.approx(0.0194989, rel=1e-5)
    )
    assert rows["slsqp-exact"].to_dict() == {
        **stored,
        "gap": 0.0,
        "best_known": stored["objective"],
    }
    crash = rows["debug-crash"]
    assert crash.status == "error" and crash.reason == res.rows[1].reason
    assert "deliberate crash" in crash.reason and crash.best_known == stored["objective"]


def test_a_stored_row_without_its_identity_refuses_the_resume(tmp_path):
    # Once read unchecked: the summary then failed on the missing key with a traceback.
    from optdesign.storage import StoreError

    inst = make_instance("shipped", 2)
    kwargs = dict(workers=1, progress=False, time_limit=5.0, hard_timeout=10.0)
    bench.run_bench("quick", ["debug-crash"], tmp_path, instances=[inst], **kwargs)
    store = tmp_path / "bench_runs.jsonl"
    head, line = store.read_text().splitlines()
    row = json.loads(line)
    del row["family"]
    store.write_text(head + "\n" + json.dumps(row) + "\n")
    with pytest.raises(
        StoreError, match=r"line 2: record .*debug-crash' has no text field 'family'"
    ):
        bench.run_bench("quick", ["debug-crash"], tmp_path, instances=[inst], resume=True, **kwargs)


@pytest.mark.parametrize("hard", [2, 5])
def test_a_hard_timeout_not_above_the_time_limit_is_refused_naming_both(tmp_path, capsys, hard):
    """optdesign.validation.bench_timeouts: the hard timeout kills a run, set-up
    included, so one at or below the soft time limit would kill a run before the soft
    limit stops it; od.bench and optdesign bench refuse it before any work."""
    import optdesign as od
    from optdesign.cli import main
    from optdesign.errors import InputError

    out = tmp_path / "o"
    with pytest.raises(InputError) as err:
        od.bench(suite="quick", time_limit=5, hard_timeout=hard, out=out)
    assert err.value.field == "hard_timeout"
    assert str(err.value).startswith(f"hard_timeout: {hard} s is not above time_limit (5 s)")
    argv = ["bench", "--suite", "quick", "--time-limit", "5", "--hard-timeout", str(hard)]
    assert main([*argv, "--out", str(out)]) == 2
    assert capsys.readouterr().err.startswith(
        f"optdesign: error: --hard-timeout: {hard} s is not above --time-limit (5 s)"
    )
    assert not out.exists()
