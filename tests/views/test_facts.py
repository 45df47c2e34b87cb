"""optdesign.views.facts: what a design achieves, evaluated; the summary words it."""

from __future__ import annotations

from pathlib import Path

import optdesign as od
from optdesign.reports.facts import shown_facts
from optdesign.views.facts import DesignFacts, design_facts

PROBLEM = Path(__file__).resolve().parents[2] / "problems" / "cs_min_ripple.toml"


def test_no_design_or_no_problem_has_no_facts():
    problem = od.load(PROBLEM)
    assert design_facts(problem, {}) is None
    assert design_facts(None, {"a": 1.0}) is None
    assert shown_facts(problem, None) == []


def test_the_summary_words_the_evaluated_facts_without_evaluating():
    problem = od.load(PROBLEM)
    facts = DesignFacts(mean_ratio=2.5, ratio_min=2.0, ratio_max=3.0, drive_efficiency=0.9)
    shown = {f.name: f for f in shown_facts(problem, facts)}
    assert list(shown) == ["mean_ratio", "ratio_min", "ratio_max", "drive_efficiency"]
    assert shown["mean_ratio"].value.value == 2.5
    assert shown["drive_efficiency"].value.value == 90.0
    assert shown["drive_efficiency"].value.unit == "%"
