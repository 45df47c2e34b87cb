"""The benchmark for your own problems and mechanisms: ``optdesign bench --problem FILE``
runs the user's files; every registered mechanism either gets instances from its
families or is listed as skipped with the reason (never left out silently)."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

import optdesign as od
from optdesign import math as m
from optdesign.cli import main
from optdesign.studies.bench.instances import coverage, families, suite

ROOT = Path(__file__).resolve().parents[3]
PIVOT = ROOT / "problems" / "pivot_min_backlash.toml"
FORK = ROOT / "problems" / "fork_min_backlash.toml"


class _Lever(od.Mechanism):
    variables = {"R": od.VariableInfo("length", "lever")}  # noqa: RUF012
    pin_joints = ("pin",)

    def nut_position(self, phi):
        return self.R * m.sin(phi)


def test_bench_problem_runs_the_users_files(tmp_path, capsys):
    out = tmp_path / "bench"
    argv = ["bench", "--problem", str(PIVOT), str(FORK), "--solvers", "slsqp-exact"]
    code = main([*argv, "--workers", "1", "--no-progress", "--out", str(out)])
    text = capsys.readouterr().out
    assert code == 0
    assert "Suite `user`: 2 instances, 2 runs" in text
    with (out / "bench_runs.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["instance"] for r in rows] == [
        "user-000-pivot_min_backlash",
        "user-001-fork_min_backlash",
    ]
    assert all(r["success"] == "True" for r in rows)
    # a user run lists no skipped mechanisms: it has no suite to cover them
    assert "without instances" not in text


def test_bench_problem_refusals_name_the_option(tmp_path, capsys):
    out = tmp_path / "bench"
    assert main(["bench", "--problem", str(PIVOT), "--suite", "quick", "--out", str(out)]) == 2
    assert "--suite: excludes --problem" in capsys.readouterr().err
    missing = tmp_path / "missing.toml"
    assert main(["bench", "--problem", str(missing), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{missing}: cannot read problem file" in err and "Traceback" not in err


def test_every_registered_mechanism_is_covered_or_skipped_with_its_reason():
    class NoFamilies(_Lever):
        name = "t23_no_families"

    class BrokenTemplate(_Lever):
        name = "t23_broken_template"
        bench_families = {"t23_broken": ("size",)}  # noqa: RUF012

        @classmethod
        def bench_template(cls):
            return {"R": {"lower": "30 mm", "upper": "20 mm"}, "p": None}, {}

    class Covered(_Lever):
        name = "t23_covered"
        bench_families = {"t23_lever_size": ("size",)}  # noqa: RUF012

        @classmethod
        def bench_template(cls):
            return {"R": {"lower": "30 mm", "upper": "120 mm"}, "p": None}, {}

    for cls in (NoFamilies, BrokenTemplate, Covered):
        od.register_mechanism(cls, replace=True)
    cover = coverage()
    registered = set(od.registered_mechanisms())
    assert set(cover.families) | set(cover.skipped) == registered
    assert not set(cover.families) & set(cover.skipped)
    assert "declares no bench_families" in cover.skipped["t23_no_families"]
    broken = cover.skipped["t23_broken_template"]
    assert "its family 't23_broken' builds no valid problem" in broken and "R" in broken
    assert cover.families["t23_covered"] == ("t23_lever_size",)
    assert {"crank_slider", "fork", "pivoting_screw"} <= set(cover.families)
    # the suite draws the covered mechanism's instances, never the broken one's
    assert families()["t23_lever_size"] == ("t23_covered", ("size",))
    assert "t23_broken" not in families()
    ids = {i.family for i in suite("default", fronts=False)}
    assert "t23_lever_size" in ids and "t23_broken" not in ids


def test_a_suite_run_lists_the_skipped_mechanisms(tmp_path):
    from optdesign.studies.bench.run import run_bench

    class Quiet(_Lever):
        name = "t23_quiet"

    od.register_mechanism(Quiet, replace=True)
    report = run_bench(
        "quick", ["slsqp-exact"], tmp_path / "b", workers=1, progress=False, time_limit=1.0
    )
    assert "t23_quiet" in report.skipped
    text = report.summary()
    assert "### Registered mechanisms without instances" in text
    assert "- t23_quiet: declares no bench_families" in text
    assert (tmp_path / "b" / "summary.md").read_text() == text


@pytest.mark.parametrize("name", ["bell_crank"])
def test_the_bell_crank_templates_build_valid_instances(name):
    import runpy

    runpy.run_path(str(ROOT / "examples" / "bell_crank.py"), run_name="bell_crank_example")
    assert coverage().families[name] == ("bell_crank_backlash",)
