"""Seed 003 reproduction: the error-budget ranking is compared with the paper's, and the
output says where and why it differs."""

import numpy as np
import pytest

from optdesign.models import error_budget as eb
from optdesign.reproduce import li2016
from optdesign.reproduce.monte_carlo import run_monte_carlo


@pytest.fixture(scope="module")
def ranking():
    kw = dict(p=li2016.P_BUDGET, i_a=1.0, theta=2 * np.pi * li2016.TURNS_BUDGET)
    return run_monte_carlo(li2016.illustrative_sources(), 100_000, seed=2016, **kw).ranking()


def test_illustrative_budget_ranks_deformation_above_backlash_and_control(ranking):
    names = [name for name, _ in ranking]
    share = dict(ranking)
    assert names[:4] == ["lead error", "deformation", "backlash", "control"]
    # mean-square shares from the term sizes: lead error uniform +-1.5e-4 x 20 turns
    # (3e-3^2/3 = 3.0e-6 mm^2), deformation 1e-3 mm with sd 3e-4 (1.09e-6), backlash
    # 1e-3 (1.0e-6), control sd 5e-4 (2.5e-7): their ratios, independent of the MC
    assert share["deformation"] / share["backlash"] == pytest.approx(1.09, rel=0.03)
    assert share["backlash"] / share["control"] == pytest.approx(4.0, rel=0.03)
    assert share["lead error"] / share["backlash"] == pytest.approx(3.0, rel=0.03)
    swapped, note = li2016.ranking_vs_paper(ranking)
    assert swapped == [("deformation", "backlash"), ("deformation", "control")]
    assert "deformation (#2, 20." in note and "backlash (#3, 18." in note
    assert "illustrative" in note and "prints no values" in note


def test_note_when_the_ranking_agrees():
    swapped, note = li2016.ranking_vs_paper(
        [("lead error", 0.5), ("backlash", 0.3), ("control", 0.1), ("deformation", 0.1)]
    )
    assert swapped == [] and "agrees" in note
    assert eb.backlash_source(1e-3).mean == 1e-3
