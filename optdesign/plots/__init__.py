"""Plots (matplotlib): every function returns a Figure and leaves the back-end alone.

Importing optdesign never selects a matplotlib back-end: in a notebook figures show as
usual; the command line selects the file-only Agg back-end for itself
(:func:`optdesign.cli.main`). :func:`save_figure` writes a figure as PNG.
"""

from __future__ import annotations

from pathlib import Path


def save_figure(fig, path: str | Path, dpi: int = 120, tight: bool = True) -> Path:
    """Lay out ``fig``, write it as PNG at ``path`` (folders made), close it; return the path."""
    import matplotlib.pyplot as plt

    if tight:
        fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
