"""Conditions of the physics in a diagnosis (optdesign/problem/requirements.py,
optdesign/formulations/diagnosis.py, optdesign/formulations/nlp/relaxation.py): the
positive ratio (no dead point inside the stroke) is never proposed for relaxation; a
best point that violates it says so, in the record, result.json and the summary."""

import json
import tomllib
from pathlib import Path

import pytest

import optdesign as od
from optdesign.problem.requirements import physical_conditions
from optdesign.reports.result_json import result_json
from optdesign.reports.solve_text import physical_text

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"


def test_the_positive_ratio_is_the_shipped_linkages_one_condition_of_the_physics():
    for name in ("cs_min_ripple", "fork_min_backlash", "pivot_min_backlash"):
        assert physical_conditions(od.load(name)) == {"ratio_positive"}, name


@pytest.fixture(scope="module")
def beyond_the_stroke():
    """cs_min_ripple asked to turn +-120 deg: more than a crank turns between its dead
    points with the file's bounds and requirements. The crank-slider's closed form
    refuses it before any solve (tests/mechanisms/test_impossible.py); here the search
    and its diagnosis run as they do where no closed form is known, e.g. for a user's
    mechanism."""
    from optdesign.studies import solve as solve_study

    data = tomllib.loads((PROBLEMS / "cs_min_ripple.toml").read_text())
    data["requirements"]["deflection"] = {"min": "-120 deg", "max": "120 deg", "points": 61}
    problem = od.load(data)
    assert solve_study.impossibilities(problem)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(solve_study, "impossibilities", lambda problem: [])
        return od.solve(problem, ranges=False)


def test_a_dead_point_in_the_stroke_is_named_and_never_relaxed(beyond_the_stroke):
    result = beyond_the_stroke
    assert not result.success
    assert "ratio_positive" in {r.name.split("[")[0] for r in result.violated}
    diagnosis = result.diagnosis
    assert diagnosis.physical == ["ratio_positive"]
    proposed = {r.name for r in diagnosis.relaxations} | {r.name for r in diagnosis.together}
    assert "ratio_positive" not in proposed
    # what is proposed instead: the user's requirements, together (none suffices alone)
    assert {"mean_ratio", "transmission_angle"} <= proposed
    assert all(r.needed is None for r in diagnosis.relaxations)
    doc = json.loads(result_json(result))
    assert doc["diagnosis"]["physical"] == ["ratio_positive"]
    assert "ratio_positive" not in [r["name"] for r in doc["diagnosis"]["together"]]


def test_the_summary_says_the_stroke_or_the_bounds_must_change():
    text = physical_text(["ratio_positive"])
    assert text.startswith("the linkage itself fails at the best point found (ratio_positive:")
    assert "narrow the stroke (requirements.deflection) or widen the bounds" in text
