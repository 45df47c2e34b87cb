"""Dolan-More performance profiles of solver configurations (time and objective gap)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np


def plot_profiles(
    profiles: Mapping[str, tuple[np.ndarray, np.ndarray]],
    configs: Sequence[str],
    gap_floor: float = 1e-6,
):
    """The profiles side by side; returns the Figure.

    Parameters
    ----------
    profiles
        ``"time"`` and/or ``"gap"`` -> (taus, rho) with rho of shape (n_configs, n_taus)
        from :func:`optdesign.studies.bench.performance_profile`.
    configs
        Configuration names (rows of rho).
    gap_floor
        Floor used for the gap measure (the x axis of the gap panel is gap / floor).
    """
    import matplotlib

    from optdesign.display.figures import new_figure, plain

    keys = [k for k in ("time", "gap") if k in profiles]
    fig = new_figure((6.0 * len(keys), 5.4), dpi=110)
    axes = fig.subplots(1, len(keys), squeeze=False)
    cmap = matplotlib.colormaps["tab20"]
    styles = ["-", "--", "-.", ":"]
    for ax, key in zip(axes[0], keys, strict=True):
        taus, rho = profiles[key]
        for j, name in enumerate(configs):
            if np.all(np.isnan(rho[j])):
                continue
            ax.step(
                taus, rho[j], where="post", color=cmap(j % 20), ls=styles[j % 4], label=plain(name)
            )
        ax.set_xscale("log")
        ax.set_ylim(-0.02, 1.02)
        ax.grid(True, which="major", alpha=0.3)
        ax.set_ylabel("fraction of instances")
        if key == "time":
            ax.set_xlabel("tau: time within tau x the fastest successful configuration")
            ax.set_title("Performance profile: wall time")
        else:
            ax.set_xlabel(f"tau: objective gap <= tau x {gap_floor:g} (relative)")
            ax.set_title("Performance profile: objective gap")
    handles, labels = axes[0][0].get_legend_handles_labels()
    n_rows = -(-len(labels) // 6)
    fig.tight_layout(rect=(0.0, 0.04 * n_rows + 0.02, 1.0, 1.0))
    fig.legend(handles, labels, loc="lower center", ncol=6, fontsize=8, frameon=False)
    return fig
