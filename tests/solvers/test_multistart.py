"""Every multistart shows its starts: how many failed and why, in the summary, the
result (result.json) and the report; a time limit per solve (``time_limit=``,
``--time-limit``) that stops the multistart and says so."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import optdesign as od
from optdesign.cli import main
from optdesign.errors import InputError
from optdesign.reports.html import solve_report
from optdesign.reports.result_json import result_json
from optdesign.solvers.multistart import NOT_STARTED, outcome_counts, start_outcome
from optdesign.solvers.result import Result, SolutionStatus, TerminationCondition

PROBLEM = Path(__file__).resolve().parents[2] / "problems" / "cs_min_backlash.toml"
#: A deadline that has always passed by Ipopt's first iteration: the time limit's tests
#: depend on no timing.
INSTANT = 1e-6


def _result(term: TerminationCondition, message: str = "", status: str = "failed") -> Result:
    sol = SolutionStatus.OPTIMAL if status == "optimal" else SolutionStatus.NO_SOLUTION
    return Result(
        status=status,
        objective=float("nan"),
        design={},
        solver="ipopt",
        formulation="nlp-epigraph",
        wall_time_s=0.0,
        termination=term,
        solution_status=sol,
        message=message,
    )


@pytest.mark.parametrize(
    ("term", "message", "status", "word"),
    [
        (TerminationCondition.CONVERGED, "Solve_Succeeded", "optimal", "converged"),
        (
            TerminationCondition.NUMERICAL_ERROR,
            "Restoration_Failed",
            "failed",
            "restoration failed",
        ),
        (
            TerminationCondition.MAX_ITERATIONS,
            "Maximum_Iterations_Exceeded",
            "max_iterations",
            "iteration limit",
        ),
        (TerminationCondition.MAX_TIME, "Maximum_WallTime_Exceeded", "time_limit", "time limit"),
        (
            TerminationCondition.NUMERICAL_ERROR,
            "Invalid_Number_Detected",
            "failed",
            "not assembling",
        ),
        (
            TerminationCondition.INFEASIBLE,
            "Infeasible_Problem_Detected",
            "infeasible",
            "locally infeasible",
        ),
        (TerminationCondition.ERROR, "Error in Function::call", "failed", "evaluation error"),
    ],
)
def test_each_start_is_named_by_how_it_ended(term, message, status, word):
    assert start_outcome(_result(term, message, status)) == word


def test_failures_counted_most_frequent_first_ties_in_order():
    outcomes = ["iteration limit", "converged", "restoration failed", "restoration failed"]
    outcomes += ["not assembling", "iteration limit", "converged", "restoration failed"]
    counts = outcome_counts(outcomes)
    assert list(counts.items()) == [
        ("restoration failed", 3),
        ("iteration limit", 2),
        ("not assembling", 1),
    ]


def test_failed_starts_in_the_summary_the_json_and_the_report():
    # 8 iterations are too few for any start of this problem: every start fails so
    result = od.solve(PROBLEM, starts=4, agree=0, ranges=False, options={"max_iter": 8})
    ms = result.multistart
    assert ms.outcomes == ["iteration limit"] * 4 and ms.failed == {"iteration limit": 4}
    assert ms.n_converged == 0 and not result.success
    summary = result.summary()
    assert "\n          4 failed: 4 iteration limit\n" in summary
    doc = json.loads(result_json(result))
    assert doc["multistart"]["failed"] == {"iteration limit": 4}
    assert doc["multistart"]["outcomes"] == ["iteration limit"] * 4
    page = solve_report(result)
    assert "max_iterations (0 of 4 starts converged; 4 failed: 4 iteration limit)" in page


def test_a_multistart_with_no_failure_says_nothing_more():
    result = od.solve(PROBLEM, starts=3, agree=0, ranges=False)
    assert result.multistart.outcomes == ["converged"] * 3 and result.multistart.failed == {}
    assert "failed:" not in result.summary()
    assert "(3 of 3 starts converged)" in solve_report(result)


def test_time_limit_stops_the_multistart_and_says_so():
    result = od.solve(PROBLEM, starts=8, agree=0, time_limit=INSTANT)
    ms = result.multistart
    # the first start always runs: stopped at its first iteration; no other begins
    assert ms.outcomes == ["time limit"] and ms.n_planned == 8
    assert ms.failed == {"time limit": 1, NOT_STARTED: 7}
    assert result.status == "time_limit" and not result.success
    assert "time limit of 1e-06 s reached: 1 of 8 starts run (1 stopped at the limit), 7 not " in (
        "\n".join(result.notes)
    )
    assert "the diagnosis not computed: the time limit of 1e-06 s was reached" in result.notes
    assert result.diagnosis is None
    assert "8 failed: 7 not started (time limit), 1 time limit" in result.summary()


def test_time_limit_on_the_command_line(tmp_path, capsys):
    args = ["solve", str(PROBLEM), "--starts", "8", "--time-limit", str(INSTANT)]
    code = main([*args, "--no-plot", "--no-report", "--out", str(tmp_path / "out")])
    out = capsys.readouterr().out
    assert code == 1  # no design that meets the requirements: the result, exit 1
    assert "status    time_limit" in out and "time limit of 1e-06 s reached" in out
    assert "8 failed: 7 not started (time limit), 1 time limit" in out
    doc = json.loads((tmp_path / "out" / "result.json").read_text())
    assert doc["multistart"]["failed"] == {"not started (time limit)": 7, "time limit": 1}
    code = main([*args, "--json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 1 and doc["status"] == "time_limit"


def test_a_generous_time_limit_changes_nothing():
    plain = od.solve(PROBLEM, starts=3, agree=0, ranges=False)
    limited = od.solve(PROBLEM, starts=3, agree=0, ranges=False, time_limit=3600)
    assert limited.status == "optimal" and limited.multistart.failed == {}
    assert limited.objective == pytest.approx(plain.objective, rel=1e-12)
    assert limited.design == plain.design and not limited.notes


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (0, "time_limit: 0 is outside (0, 86400]"),
        (-1, "time_limit: -1 is outside (0, 86400]"),
        (True, "time_limit: True is not a number"),
        ("5 s", "time_limit: '5 s' is not a number"),
        (1e9, "time_limit: 1e+09 is outside (0, 86400]"),
    ],
)
def test_time_limit_refused_naming_the_argument(value, message):
    with pytest.raises(InputError) as caught:
        od.solve(PROBLEM, time_limit=value)
    assert str(caught.value) == message


def test_time_limit_refused_on_the_command_line(capsys):
    with pytest.raises(SystemExit) as caught:
        main(["solve", str(PROBLEM), "--time-limit", "0"])
    assert caught.value.code == 2
    assert "argument --time-limit: 0 is outside (0, 86400]" in capsys.readouterr().err
