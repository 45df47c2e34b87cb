"""Imports paid only by the command that needs them (issue 15): each case runs the CLI
in a fresh interpreter and lists the heavy modules it loaded."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
HEAVY = ("cvxpy", "pymoo", "dask", "matplotlib", "scipy.stats", "pint", "pandas")

RUN = """
import json, sys
from optdesign.cli import main
try:
    code = main(sys.argv[1:])
except SystemExit as exc:
    code = exc.code
heavy = [m for m in json.loads(HEAVY) if m in sys.modules]
print(json.dumps({"code": code, "heavy": heavy}))
"""


def loaded(*args: str, cwd: Path = ROOT, modules: tuple[str, ...] = HEAVY) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    code = RUN.replace("json.loads(HEAVY)", repr(list(modules)))
    proc = subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, env=env, cwd=cwd
    )
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_help_imports_no_heavy_module():
    out = loaded("--help")
    assert out["code"] == 0 and out["heavy"] == []


@pytest.mark.parametrize(
    "text", ["garbage = [", '[problem]\nmechanism = "crank_slider"\nfoo = 1\n']
)
def test_bad_file_error_imports_no_heavy_module(tmp_path, text):
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    out = loaded("solve", str(bad))
    assert out["code"] == 2 and out["heavy"] == []


def test_solve_without_plot_imports_no_heavy_module(tmp_path):
    out = loaded(
        "solve",
        str(ROOT / "problems" / "fork_min_backlash.toml"),
        "--formulation",
        "nlp",
        "--starts",
        "2",
        "--no-ranges",
        "--no-plot",
        "--out",
        str(tmp_path / "out"),
    )
    assert out["code"] == 0 and out["heavy"] == []


def test_solve_json_shows_written_units_without_pint():
    # cs_min_backlash writes its requirements in kN, deg, mm...: the JSON shows them in
    # those units from the table of common units, not from a pint registry.
    out = loaded(
        "solve",
        str(ROOT / "problems" / "cs_min_backlash.toml"),
        "--json",
        "--starts",
        "1",
        "--no-ranges",
    )
    assert out["code"] == 0 and out["heavy"] == []


#: A 4-point continuous front on one worker, with no figure or report.
_FRONT = (
    "pareto",
    str(ROOT / "problems" / "cs_min_backlash.toml"),
    "--objectives",
    "ripple,backlash",
    "--points",
    "4",
    "--workers",
    "1",
    "--no-plot",
    "--no-report",
)


def test_a_continuous_front_imports_no_catalogue_search(tmp_path):
    # the catalogue front's search (branch and bound, diagnosis) is for problems with
    # catalogue variables only
    catalogue = ("optdesign.formulations.catalogue.bnb", "optdesign.formulations.catalogue.search")
    out = loaded(*_FRONT, "--no-progress", "--out", str(tmp_path / "out"), modules=catalogue)
    assert out["code"] == 0 and out["heavy"] == []


def test_a_front_whose_stderr_is_no_terminal_imports_no_progress_bar(tmp_path):
    # tqdm draws nothing there (disable=None): its import, asyncio with it, is spared
    out = loaded(*_FRONT, "--out", str(tmp_path / "out"), modules=("tqdm", "asyncio"))
    assert out["code"] == 0 and out["heavy"] == []


def test_a_front_imports_no_scipy_optimize(tmp_path):
    # the sweep's primary is CasADi's sqpmethod: SLSQP's import (scipy.optimize, ~0.3 s in
    # each worker) was the largest fixed cost of a front after the interpreter's start-up
    out = loaded(*_FRONT, "--out", str(tmp_path / "out"), modules=("scipy.optimize",))
    assert out["code"] == 0 and out["heavy"] == []
