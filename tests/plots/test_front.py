"""Fronts drawn by optdesign/plots/front.py."""

from __future__ import annotations

from pathlib import Path

import pytest

import optdesign as od
from optdesign.studies.pareto.front import FrontPoint, make_front

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


def _front_of_midpoints(problem, objectives=("backlash", "size")):
    """A two-point front over the problem's mid-box design (no solve): enough to draw."""
    design = problem.design_dict(problem.midpoint())
    points = [
        FrontPoint(
            id=f"eps-{k}",
            kind="eps",
            target="backlash",
            objectives=dict(zip(objectives, values, strict=True)),
            design=dict(design),
            status="optimal",
            verified=True,
            method="epsilon",
        )
        for k, values in enumerate([(0.1, 30.0), (0.2, 20.0)])
    ]
    return make_front(points, list(objectives), "epsilon", problem=problem)


# --- the front's plot ---------------------------------------------------------------------
def test_a_fronts_plot_on_a_given_axes_draws_there_without_sketches(cs_min_backlash):
    """``front.plot(ax=...)`` draws the objective space on the caller's axes and returns
    the caller's figure, with no sketch axes added."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    front = _front_of_midpoints(cs_min_backlash)
    fig, ax = plt.subplots()
    try:
        assert front.plot(ax=ax) is fig
        assert fig.axes == [ax]
        x, y = ax.lines[0].get_data()
        assert list(y) == pytest.approx([30.0, 20.0])
        assert len(x) == 2
    finally:
        plt.close("all")
