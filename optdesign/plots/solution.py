"""Plot of a solved design: ratio and backlash over the stroke, optimum vs initial."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from optdesign.problem.design_problem import DesignProblem


def plot_designs(problem: DesignProblem, designs: Mapping[str, Mapping[str, float]], ax=None):
    """Ratio (and backlash, if the problem has pins) vs deflection for each named design.

    Returns the Figure; with ``ax`` the ratio is drawn on that axes (and the backlash,
    if any, on a twin axis) instead of a new figure.
    """
    import matplotlib.pyplot as plt

    phi_deg = np.degrees(problem.phi)
    has_pin = problem.has("d")
    if ax is None:
        fig, axes = plt.subplots(
            1, 2 if has_pin else 1, figsize=(11 if has_pin else 6, 4.2), dpi=120, squeeze=False
        )
        axes = list(axes[0])
    else:
        fig = ax.figure
        axes = [ax, ax.twinx()] if has_pin else [ax]
    for label, design in designs.items():
        with np.errstate(invalid="ignore", divide="ignore"):
            q = problem.quantities(design)
            axes[0].plot(phi_deg, np.asarray(q.ratio, dtype=float), label=label)
            if has_pin:
                axes[1].plot(
                    phi_deg, np.asarray(q.backlash.worst_case, dtype=float), "--", label=label
                )
    axes[0].set_ylabel("reduction ratio i (motor rad / output rad)")
    axes[0].set_title(f"{problem.name}: ratio over the stroke")
    if has_pin:
        axes[1].set_ylabel("worst-case backlash (deg)")
        axes[1].set_title("output backlash over the stroke")
    for a in axes:
        a.set_xlabel("deflection phi (deg)")
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8)
    return fig


def plot_result(result, ax=None):
    """The optimum of ``result`` against the problem's initial design (a Figure)."""
    problem = result.problem_object
    if problem is None or not result.design:
        raise ValueError("plot: the result carries no problem or no design to draw")
    start = problem.design_dict(problem.start())
    return plot_designs(problem, {"initial design": start, "optimum": result.design}, ax)
