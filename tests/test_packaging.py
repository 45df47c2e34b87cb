"""Shipped problem files are package data (issue 13): ``optdesign solve cs_min_backlash``
and ``optdesign bench`` work after ``pip install .`` from any folder."""

from __future__ import annotations

import json
import os
import site
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

from optdesign.data import problems_dir
from optdesign.problem import load_problem

ROOT = Path(__file__).resolve().parents[1]


def test_shipped_problems_found_by_name_from_any_folder(tmp_path, monkeypatch):
    assert {p.stem for p in problems_dir().glob("*.toml")} == {
        p.stem for p in (ROOT / "problems").glob("*.toml")
    }
    monkeypatch.chdir(tmp_path)
    assert load_problem("cs_min_backlash").name == "cs_min_backlash"
    assert load_problem("cs_min_ripple.toml").name == "cs_min_ripple"
    (tmp_path / "cs_min_backlash.toml").write_text("not = = toml")
    with pytest.raises(Exception, match="not valid TOML"):
        load_problem("cs_min_backlash.toml")  # a file of that name in the folder comes first


@pytest.mark.slow
def test_pip_install_then_solve_and_bench_elsewhere(tmp_path):
    """A real ``pip install .`` into a fresh venv (the dependencies from this interpreter's
    site-packages), then the documented commands from an unrelated folder."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=120)
    py = venv / "bin" / "python"
    purelib = subprocess.run(
        [py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    deps = [*site.getsitepackages(), sysconfig.get_paths()["purelib"]]
    Path(purelib, "deps.pth").write_text("\n".join(dict.fromkeys(deps)) + "\n")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    pip = subprocess.run(
        [py, "-m", "pip", "install", "-q", "--no-deps", str(ROOT)],
        capture_output=True,
        text=True,
        timeout=600,
        env=env,
    )
    assert pip.returncode == 0, pip.stderr[-2000:]
    exe = venv / "bin" / "optdesign"
    work = tmp_path / "elsewhere"
    work.mkdir()
    run = subprocess.run(
        [exe, "solve", "cs_min_backlash", "--starts", "2", "--no-ranges", "--json"],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=work,
        env=env,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert json.loads(run.stdout)["objective"]["value"] == pytest.approx(0.0362197, rel=1e-5)
    bench = subprocess.run(
        [
            exe,
            "bench",
            "--suite",
            "quick",
            "--solvers",
            "ipopt-exact",
            "--workers",
            "1",
            "--no-progress",
            "--out",
            "b",
        ],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=work,
        env=env,
    )
    assert bench.returncode == 0, bench.stderr[-2000:]
    assert (work / "b" / "summary.md").is_file()
    assert sorted(p.name for p in work.iterdir()) == ["b"]  # nothing written elsewhere
