"""The design chart of a sweep: the objective and every free variable against the swept
parameter, the points where the binding set changes marked, infeasible points shaded;
for two parameters, filled contours of the objective (infeasible points crossed)."""

from __future__ import annotations

from typing import Any

import numpy as np

from optdesign.display.frames import objective_column, variable_column
from optdesign.plots import MAX_TITLE_NAME, new_figure, plain
from optdesign.tolerances import OBJECTIVE_TIE_TOL


def plot_sweep(sweep: Any):
    """The chart of ``sweep`` (a :class:`optdesign.studies.sweep.Sweep`): a Figure."""
    if len(sweep.axes) == 2:
        return _contours(sweep)
    problem = sweep.problem
    axis = sweep.axes[0]
    x = np.array(axis.shown)
    pts = sweep.points
    ok = np.array([p.success for p in pts])
    cols = [objective_column(problem, sweep.objective)]
    cols += [variable_column(problem, v) for v in problem.free]
    n = len(cols)
    ncol = 2 if n > 3 else 1
    nrow = -(-n // ncol)
    fig = new_figure((5.5 * ncol, 2.2 * nrow + 0.8), layout="constrained")
    axs = fig.subplots(nrow, ncol, sharex=True, squeeze=False).ravel()
    dx = (x[1] - x[0]) / 2 if len(x) > 1 else 0.5
    for k, col in enumerate(cols):
        ax = axs[k]
        source = [p.objective if k == 0 else p.design.get(col.name, np.nan) for p in pts]
        y = np.array([col.value(v) if v is not None else np.nan for v in source], dtype=float)
        y[~ok] = np.nan
        ax.plot(x, y, "-o", ms=3, color="C0" if k == 0 else "C1", lw=1.2)
        for i in np.flatnonzero(~ok):
            ax.axvspan(x[i] - dx, x[i] + dx, color="0.85", lw=0, zorder=0)
        for i, p in enumerate(pts):
            if p.active_change:
                ax.axvline(x[i], color="C3", ls=":", lw=1)
            if p.jump:
                ax.plot(x[i], y[i], "x", color="C3", ms=8)
        ax.set_ylabel(plain(col.header))
        ax.grid(alpha=0.3)
        ax.ticklabel_format(axis="y", useOffset=False)
        finite = y[np.isfinite(y)]
        if finite.size and np.ptp(finite) <= OBJECTIVE_TIE_TOL * max(1.0, np.abs(finite).max()):
            mid = float(finite.mean())  # a constant: drawn flat, not its round-off
            pad = 0.05 * max(abs(mid), 1e-9)
            ax.set_ylim(mid - pad, mid + pad)
        if k + ncol >= n:  # nothing drawn below it: its x axis is labelled
            ax.set_xlabel(_axis_label(axis))
            ax.xaxis.set_tick_params(labelbottom=True)
    for ax in axs[n:]:
        ax.set_visible(False)
    changes = sum(p.active_change for p in pts)
    fig.suptitle(
        f"{plain(problem.name, MAX_TITLE_NAME)}: optimum against {plain(axis.label)} "
        f"(dotted: binding set or item changes ({changes}); grey: infeasible)",
        fontsize=9,
    )
    return fig


def _axis_label(axis: Any) -> str:
    """The swept parameter, and the parameters that move with it (set to its value at
    every point), so a chart of a linked sweep says what else changed along it."""
    linked = f" (with {', '.join(axis.linked)})" if axis.linked else ""
    return plain(axis.label + linked)


def _contours(sweep: Any):
    problem = sweep.problem
    a0, a1 = sweep.axes
    n0, n1 = len(a0.values), len(a1.values)
    col = objective_column(problem, sweep.objective)
    Z = np.full((n1, n0), np.nan)
    bad = []
    for k, p in enumerate(sweep.points):
        i, j = k % n0, k // n0
        if p.success:
            Z[j, i] = col.value(p.objective)
        else:
            bad.append((a0.shown[i], a1.shown[j]))
    fig = new_figure((6.5, 5), layout="constrained")
    ax = fig.subplots()
    X, Y = np.meshgrid(a0.shown, a1.shown)
    if np.isfinite(Z).sum() >= 4:
        cs = ax.contourf(X, Y, np.ma.masked_invalid(Z), levels=12, cmap="viridis")
        fig.colorbar(cs, ax=ax, label=plain(col.header))
    ax.plot(X.ravel(), Y.ravel(), ".", color="k", ms=2)
    if bad:
        bx, by = zip(*bad, strict=True)
        ax.plot(bx, by, "x", color="C3", ms=7, label="infeasible")
        ax.legend(loc="best", fontsize=8)
    for k, p in enumerate(sweep.points):
        if p.active_change:
            ax.plot(a0.shown[k % n0], a1.shown[k // n0], "o", mfc="none", color="C3", ms=7)
    ax.set_xlabel(_axis_label(a0))
    ax.set_ylabel(_axis_label(a1))
    name = plain(problem.name, MAX_TITLE_NAME)
    ax.set_title(f"{name}: {plain(col.header)} (circles: binding set changes)", fontsize=9)
    return fig
