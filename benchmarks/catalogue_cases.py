"""The cases the catalogue search's evidence scripts run (``catalogue_verdicts.py``,
``catalogue_agreement.py``): the catalogue instance family of
``bench_catalogue_solvers.py`` (both families, seeds 0-7, branch and bound and
enumeration), the two shipped catalogue problems (``od.solve``, with the optimum's
neighbouring items) and the 6-point catalogue front of ``fin_actuator``. After each case
``tally(name)`` is called (the scripts count cumulatively)."""

from __future__ import annotations

import json
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

import optdesign as od
from optdesign.formulations.catalogue import search as cat

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_catalogue_solvers import instance  # noqa: E402


def run_cases(tally: Callable[[str], None]) -> None:
    for family in ("fin", "cs"):
        for seed in range(8):
            problem, _ = instance(family, seed)
            for method in ("bnb", "enumerate"):
                cat.solve_catalogue(problem, method=method)
            tally(f"{family}-{seed}")
    for name in ("fin_actuator", "cs_min_backlash_catalogue"):
        od.solve(od.load(ROOT / "problems" / f"{name}.toml"))
        tally(name)
    with tempfile.TemporaryDirectory() as out:
        fin = od.load(ROOT / "problems" / "fin_actuator.toml")
        od.pareto(fin, ["backlash", "motor_torque"], points=6, workers=1, out=out)
    tally("fin_actuator front, 6 points")


def write_row(path: Path, row: dict) -> None:
    """Append ``row`` to the JSON lines of ``path`` (the counts so far) and print it."""
    with path.open("a") as fh:
        fh.write(json.dumps(row) + "\n")
    print(json.dumps(row), flush=True)
