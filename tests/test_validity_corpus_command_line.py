"""The validity corpus (tests/validity_corpus.py: impossible inputs within the schema's
types, written from the models' assumptions) through the command line, in both output
modes: each case refused with its field and range, or solved into a result that names
each model it leaves - as through the API (tests/test_validity.py)."""

from __future__ import annotations

import pytest
from validity_corpus import all_cases, run_case_cli

CASES = {c.name: c for c in all_cases()}


@pytest.mark.slow  # 106 cases x 2 modes, ~1 s each: the API run stays in the fast suite
@pytest.mark.parametrize("json_mode", [False, True], ids=["summary", "json"])
def test_every_impossible_input_ends_cleanly_on_the_command_line(json_mode, tmp_path):
    bad = []
    for k, case in enumerate(CASES.values()):
        verdict = run_case_cli(case, json_mode, tmp_path / str(k))
        if verdict.verdict != "clean":
            bad.append(f"{case.name}: {verdict.verdict}: {verdict.message[:200]}")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("json_mode", [False, True], ids=["summary", "json"])
@pytest.mark.parametrize(
    "name", ["pin length ratio 1e+09", "backlash_max 6 deg", "huth cheek 0.3 mm"]
)
def test_an_impossible_input_ends_cleanly_in_either_mode(name, json_mode, tmp_path):
    """One refused at load and one flagged after the solve, in both modes (fast)."""
    case = CASES[name]
    verdict = run_case_cli(case, json_mode, tmp_path)
    assert verdict.verdict == "clean", verdict
    if case.expect == "refused":
        assert "is outside" in verdict.message
