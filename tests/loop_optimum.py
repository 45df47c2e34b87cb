"""fin_actuator_loop's optimum as a result that carries it, for the tests of its report
page: given (the design ``optdesign solve problems/fin_actuator_loop.toml`` finds,
docs/loop.md), so that they need no solve."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import Any

import optdesign as od
from optdesign.reports.html import solve_report
from optdesign.solvers.result import Result

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"

#: fin_actuator_loop's optimum (every variable, internal units).
OPTIMUM = {
    "i_a": 2.0,
    "pin_length_ratio": 1.5,
    "R": 105.57146581026235,
    "l": 59.794241478821306,
    "n": 102.08698946522527,
    "phi0": 0.22920398553588672,
    "d0": 25.0,
    "p": 5.0,
    "d": 16.0,
}


def optimum_report(problem: Any) -> str:
    """report.html of a solve of ``problem`` (fin_actuator_loop, or a problem with its
    variables) that found :data:`OPTIMUM`."""
    result = Result(
        status="optimal",
        verified=True,
        design=dict(OPTIMUM),
        objective=0.0,
        formulation="nlp",
        objective_name="backlash",
        problem_object=problem,
    )
    return solve_report(result)


@lru_cache(maxsize=1)
def loop_report() -> str:
    """fin_actuator_loop's :func:`optimum_report`, built once per test process (its loop
    figures and its time response take about a second)."""
    return optimum_report(od.load(PROBLEMS / "fin_actuator_loop.toml"))
