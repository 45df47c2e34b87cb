"""Curves over the deflection range: ratio, backlash."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from optdesign.plots import new_figure, plain, save_figure


def plot_curves(
    phi_deg: np.ndarray,
    curves: Mapping[str, np.ndarray],
    ylabel: str,
    title: str,
    path: Path,
    styles: Mapping[str, str] | None = None,
) -> Path:
    """Plot several curves against the deflection (degrees) into a PNG at ``path``."""
    fig = new_figure((6.4, 4.2))
    ax = fig.subplots()
    for label, y in curves.items():
        ax.plot(phi_deg, y, (styles or {}).get(label, "-"), label=plain(label))
    ax.set_ylabel(plain(ylabel))
    ax.set_title(plain(title))
    return save_deflection_figure(fig, [ax], path)


def save_deflection_figure(fig, axes, path: Path) -> Path:
    """Label the deflection axis, add grid and legend to ``axes``, save ``fig`` as PNG."""
    for ax in axes:
        ax.set_xlabel("deflection phi (deg)")
        ax.grid(True, alpha=0.3)
        ax.legend()
    return save_figure(fig, path)
