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


def test_the_sketches_of_a_front_share_one_legend_on_the_first_panel_that_draws():
    """The panels sketch one mechanism at the same stroke angles: one legend, on the
    first panel with a sketch (a panel whose mechanism draws none passes it on)."""
    import numpy as np

    from optdesign.mechanisms.base import Sketch
    from optdesign.plots.front import FrontFigure, FrontSeries, SketchPanel, draw_front

    def frame(label, x):
        arm = Sketch(links=[[(0.0, 0.0), (x, 50.0)]], pivots=[(0.0, 0.0)], slider=(x, 50.0))
        return (label, arm)

    drawn = tuple(
        SketchPanel(title, (frame("phi = -30 deg", 10.0), frame("phi = +30 deg", 40.0)))
        for title in ("B", "C")
    )
    blank = SketchPanel("A", (("phi = -30 deg", None),))
    F = np.array([[1.0, 3.0], [2.0, 2.0], [3.0, 1.0]])
    figure = FrontFigure(
        "toy",
        ("f1", "f2"),
        (FrontSeries("epsilon", F, 0.1),),
        ((1, 3), (3, 1), (2, 2)),
        panels=(blank, *drawn),
    )
    fig = draw_front(figure)
    main, *panels = fig.axes
    assert main.get_legend() is not None
    legends = [ax.get_legend() for ax in panels]
    assert [leg is not None for leg in legends] == [False, True, False]
    texts = [t.get_text() for t in legends[1].get_texts()]
    assert texts == ["phi = -30 deg", "nut", "ground pivot", "phi = +30 deg"]
