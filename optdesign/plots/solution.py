"""Plot of a solved design: ratio and backlash over the stroke, optimum vs initial."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from optdesign.plots.curves import save_deflection_figure
from optdesign.problem.design_problem import DesignProblem


def plot_solution(
    problem: DesignProblem, designs: Mapping[str, Mapping[str, float]], path: Path
) -> Path:
    """Ratio (and backlash, if the problem has pins) vs deflection for each named design."""
    phi = problem.phi
    phi_deg = np.degrees(phi)
    has_pin = problem.has("d")
    fig, axes = plt.subplots(1, 2 if has_pin else 1, figsize=(11 if has_pin else 6, 4.2), dpi=120)
    axes = np.atleast_1d(axes)
    for label, design in designs.items():
        with np.errstate(invalid="ignore", divide="ignore"):
            ex = problem.expressions(design)
            axes[0].plot(
                phi_deg, np.asarray(ex.objectives["ripple"].expr, dtype=float), label=label
            )
            if has_pin:
                axes[1].plot(
                    phi_deg, np.asarray(ex.objectives["backlash"].expr, dtype=float), label=label
                )
    axes[0].set_ylabel("reduction ratio i")
    axes[0].set_title(f"{problem.name}: ratio over the stroke")
    if has_pin:
        axes[1].set_ylabel("worst-case backlash (deg)")
        axes[1].set_title("output backlash over the stroke")
    return save_deflection_figure(fig, axes, path)
