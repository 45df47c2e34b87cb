"""Plot of Pareto fronts: objective space (methods overlaid) and linkage sketches of a few
picked designs (the two ends of the front and its knee), drawn from
``mechanism.pin_positions``."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from optdesign.plots import save_figure
from optdesign.problem.design_problem import DesignProblem

_UNITS = {"backlash": "deg", "backlash_rss": "deg", "size": "mm", "nut_travel": "mm"}
_STYLE = {
    "epsilon": dict(marker="o", ms=4, lw=1.0),
    "uniform": dict(marker="s", ms=3, lw=0.8),
    "weighted_sum": dict(marker="D", ms=5, lw=0.0),
    "nsga2": dict(marker="x", ms=4, lw=0.0),
    "reference": dict(marker="", lw=2.5, alpha=0.35),
}


def pick_points(F: np.ndarray) -> list[int]:
    """Indices of the front's ends (best in each objective) and its knee (closest to the
    ideal point in objectives normalised by the front's range)."""
    F = np.asarray(F, dtype=float)
    if len(F) == 0:
        return []
    lo, hi = F.min(axis=0), F.max(axis=0)
    Z = (F - lo) / np.where(hi > lo, hi - lo, 1.0)
    picks = [int(np.argmin(F[:, k])) for k in range(F.shape[1])]
    picks.append(int(np.argmin(np.linalg.norm(Z, axis=1))))
    out: list[int] = []
    for i in picks:
        if i not in out:
            out.append(i)
    return out


def _label(name: str) -> str:
    unit = _UNITS.get(name, "")
    return f"{name} ({unit})" if unit else name


def draw_linkage(ax, problem: DesignProblem, design: dict, title: str = "") -> None:
    """Sketch of a design at the stroke's ends and middle (pin positions, mm)."""
    mech = problem.mechanism(design)
    phis = [problem.phi[0], 0.5 * (problem.phi[0] + problem.phi[-1]), problem.phi[-1]]
    for j, phi in enumerate(phis):
        alpha = 0.35 + 0.3 * j
        with np.errstate(invalid="ignore"):
            P, Q = mech.pin_positions(np.array(phi))
        P = (float(P[0]), float(P[1]))
        Q = (float(Q[0]), float(Q[1]))
        ax.plot([0, P[0]], [0, P[1]], "-", color="C0", lw=2, alpha=alpha)
        ax.plot([P[0], Q[0]], [P[1], Q[1]], "-", color="C1", lw=2, alpha=alpha)
        ax.plot(*Q, "s", color="C2", ms=6, alpha=alpha)
        ax.plot(*P, "o", color="k", ms=3, alpha=alpha)
    # The screw axis: the nut line (crank-slider) or the pin line (fork).
    y_axis = float(design.get("n", design.get("R", 0.0)))
    ax.axhline(y_axis, color="0.5", lw=0.8, ls="--")
    ax.plot(0, 0, "k^", ms=7)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(title, fontsize=8)
    ax.tick_params(labelsize=7)


def plot_fronts(
    problem: DesignProblem,
    fronts: Sequence,
    path: Path | str,
    reference: np.ndarray | None = None,
) -> Path:
    """Objective space with every front overlaid, plus sketches of picked points of the
    first front. Two objectives: a 2-D plot; three: a 3-D scatter."""
    main = fronts[0]
    objectives = main.objectives
    picks = pick_points(main.F)
    n_sk = len(picks)
    fig = plt.figure(figsize=(6 + 3.0 * max(n_sk, 1) / 1.5, 5), dpi=120)
    gs = fig.add_gridspec(
        2, 1 + max(1, (n_sk + 1) // 2), width_ratios=[2.2] + [1] * max(1, (n_sk + 1) // 2)
    )
    three = len(objectives) == 3
    ax = fig.add_subplot(gs[:, 0], projection="3d" if three else None)
    if reference is not None and len(reference) and not three:
        R = reference[np.argsort(reference[:, 0])]
        ax.plot(
            R[:, 0], R[:, 1], color="0.3", label=f"reference ({len(R)} pts)", **_STYLE["reference"]
        )
    for f in fronts:
        F = f.F
        if not len(F):
            continue
        style = _STYLE.get(f.method, dict(marker="o", ms=3, lw=0.0))
        label = f"{f.method} ({len(F)} pts, {f.wall_time_s:.1f} s)"
        if three:
            ax.scatter(
                F[:, 0], F[:, 1], F[:, 2], s=12, marker=style.get("marker") or "o", label=label
            )
        else:
            ax.plot(F[:, 0], F[:, 1], label=label, **style)
    F0 = main.F
    for k, i in enumerate(picks):
        pt = F0[i]
        if three:
            ax.scatter(*pt, s=60, facecolors="none", edgecolors="r")
            ax.text(*pt, f" {chr(65 + k)}", color="r")
        else:
            ax.plot(*pt, "o", mfc="none", mec="r", ms=10)
            ax.annotate(chr(65 + k), pt, textcoords="offset points", xytext=(6, 6), color="r")
    ax.set_xlabel(_label(objectives[0]))
    ax.set_ylabel(_label(objectives[1]))
    if three:
        ax.set_zlabel(_label(objectives[2]))
    else:
        ax.grid(True, alpha=0.3)
    ax.set_title(f"{problem.name}: Pareto front", fontsize=10)
    ax.legend(fontsize=7)
    for k, i in enumerate(picks):
        sub = fig.add_subplot(gs[k % 2, 1 + k // 2])
        p = main.points[i]
        text = ", ".join(f"{o}={p.objectives[o]:.4g}" for o in objectives)
        draw_linkage(sub, problem, p.design, f"{chr(65 + k)}: {text}")
    return save_figure(fig, path)
