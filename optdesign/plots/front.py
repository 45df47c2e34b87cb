"""Plot of Pareto fronts: objective space (methods overlaid) and sketches of picked designs
(the two ends of the front and its knee), drawn from their evaluated sketch frames.
Names (the problem's, the objectives', the methods') are drawn as plain text
(:func:`optdesign.plots.plain`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from optdesign.mechanisms.base import Sketch
from optdesign.plots import MAX_TITLE_NAME, new_figure, plain
from optdesign.views.sketches import sketch_frames

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


def axis_label(problem, name: str) -> tuple[str, float]:
    """(label with unit, scale to the displayed unit) of objective ``name``."""
    from optdesign.reports.solve_text import objective_unit

    unit, scale = objective_unit(problem, name)
    return (f"{name} ({unit})" if unit else name), scale


@dataclass(frozen=True)
class SketchPanel:
    """A design sketched at the stroke's ends and middle: each frame's label and the
    mechanism's :class:`~optdesign.mechanisms.Sketch` there (None: it draws none)."""

    title: str
    frames: tuple[tuple[str, Sketch | None], ...]


@dataclass(frozen=True)
class FrontSeries:
    """One front's points in the shown units, with its method and wall time."""

    method: str
    F: np.ndarray
    wall_time_s: float


@dataclass(frozen=True)
class FrontFigure:
    """What the figure of Pareto fronts shows, from the fronts and the picked designs'
    evaluated sketches (:mod:`optdesign.views`; :func:`front_figure`), so that drawing it
    (:func:`draw_front`) evaluates no model and can run in another process.

    Attributes
    ----------
    name
        The problem's name (the title's).
    axis_labels
        Each objective's label with its unit.
    series
        Every front, in the shown units (the first one carries the picks).
    picks
        The picked points of the first front (its ends and knee), in the shown units.
    reference
        A reference front drawn as a line (shown units, sorted), or None.
    panels
        The sketches of the picked designs (empty: the objective space alone).
    """

    name: str
    axis_labels: tuple[str, ...]
    series: tuple[FrontSeries, ...]
    picks: tuple[tuple[float, ...], ...]
    reference: np.ndarray | None = None
    panels: tuple[SketchPanel, ...] = ()


def linkage_panel(problem, design: dict, title: str = "") -> SketchPanel:
    """The sketch of a design at the stroke's ends and middle (mm): its evaluated
    :func:`~optdesign.views.sketches.sketch_frames`, labelled."""
    frames = tuple(
        (f"phi = {np.degrees(frame.phi):+.0f} deg", frame.sketch)
        for frame in sketch_frames(problem, design)
    )
    return SketchPanel(str(title), frames)


def draw_panel(ax, panel: SketchPanel, legend: bool = True) -> bool:
    """Draw a :class:`SketchPanel` on ``ax``, with its legend when ``legend``; whether
    it drew a sketch."""
    drawn = False
    for j, (label, sk) in enumerate(panel.frames):
        if sk is None:
            continue
        drawn = True
        alpha = 0.35 + 0.3 * j
        for k, link in enumerate(sk.links):
            xs, ys = zip(*link, strict=True)
            ax.plot(xs, ys, "-", color=f"C{k}", lw=2, alpha=alpha, label=label if k == 0 else None)
        if sk.slider is not None:
            ax.plot(*sk.slider, "s", color="C2", ms=6, alpha=alpha, label="nut" if j == 0 else None)
        if j == 0:
            for k, pv in enumerate(sk.pivots):
                ax.plot(*pv, "k^", ms=7, label="ground pivot" if k == 0 else None)
            if sk.axis is not None:
                (x0, y0), (x1, y1) = sk.axis
                ax.plot([x0, x1], [y0, y1], color="0.5", lw=0.8, ls="--", label="screw axis")
    if not drawn:
        ax.text(
            0.5,
            0.5,
            "no sketch for this mechanism",
            ha="center",
            va="center",
            transform=ax.transAxes,
            fontsize=8,
        )
        ax.set_axis_off()
    else:
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (mm)", fontsize=7)
        ax.set_ylabel("y (mm)", fontsize=7)
        if legend:
            ax.legend(fontsize=6, loc="best")
    ax.set_title(plain(panel.title), fontsize=8)
    ax.tick_params(labelsize=7)
    return drawn


def draw_linkage(ax, problem, design: dict, title: str = "") -> None:
    """Sketch of a design at the stroke's ends and middle (mm) on ``ax``."""
    draw_panel(ax, linkage_panel(problem, design, title))


def front_figure(
    problem, fronts: Sequence, reference: np.ndarray | None = None, sketches: bool = True
) -> FrontFigure:
    """The :class:`FrontFigure` of ``fronts`` (the first one's picked designs sketched
    when ``sketches``)."""
    main = fronts[0]
    objectives = main.objectives
    picks = pick_points(main.F)
    labels = [axis_label(problem, k) for k in objectives]
    scales = np.array([s for _, s in labels])
    series = tuple(
        FrontSeries(str(f.method), f.F * scales if len(f.F) else f.F, float(f.wall_time_s))
        for f in fronts
    )
    F0 = main.F * scales if len(main.F) else main.F
    ref = None
    if reference is not None and len(reference) and len(objectives) != 3:
        ref = reference[np.argsort(reference[:, 0])] * scales
    panels = []
    if sketches and problem is not None:
        for k, i in enumerate(picks):
            p = main.points[i]
            text = ", ".join(_value_text(problem, o, p.objectives[o]) for o in objectives)
            panels.append(linkage_panel(problem, p.design, f"{chr(65 + k)}: {text}"))
    return FrontFigure(
        str(problem.name) if problem is not None else "",
        tuple(label for label, _ in labels),
        series,
        tuple(tuple(float(v) for v in F0[i]) for i in picks),
        ref,
        tuple(panels),
    )


def draw_front(figure: FrontFigure, ax=None):
    """Draw a :class:`FrontFigure`: the objective space with every front overlaid, plus
    the sketches of the picked points (unless ``ax`` is given: then only the objective
    space, on ``ax``). Returns the Figure. Two objectives: a 2-D plot; three: a 3-D
    scatter."""
    three = len(figure.axis_labels) == 3
    if ax is None:
        n_sk = len(figure.picks)
        cols = max(1, (n_sk + 1) // 2)
        fig = new_figure((6 + 3.0 * max(n_sk, 1) / 1.5, 5), layout="constrained")
        gs = fig.add_gridspec(2, 1 + cols, width_ratios=[2.2] + [1] * cols)
        ax = fig.add_subplot(gs[:, 0], projection="3d" if three else None)
        panels = figure.panels
    else:
        fig, gs, panels = ax.figure, None, ()
    if figure.reference is not None:
        R = figure.reference
        ax.plot(
            R[:, 0], R[:, 1], color="0.3", label=f"reference ({len(R)} pts)", **_STYLE["reference"]
        )
    for f in figure.series:
        F = f.F
        if not len(F):
            continue
        style = _STYLE.get(f.method, dict(marker="o", ms=3, lw=0.0))
        label = f"{plain(f.method)} ({len(F)} pts, {f.wall_time_s:.1f} s)"
        if three:
            ax.scatter(
                F[:, 0], F[:, 1], F[:, 2], s=12, marker=style.get("marker") or "o", label=label
            )
        else:
            ax.plot(F[:, 0], F[:, 1], label=label, **style)
    for k, pt in enumerate(figure.picks):
        if three:
            ax.scatter(*pt, s=60, facecolors="none", edgecolors="r")
            ax.text(*pt, f" {chr(65 + k)}", color="r")
        else:
            ax.plot(*pt, "o", mfc="none", mec="r", ms=10)
            ax.annotate(chr(65 + k), pt, textcoords="offset points", xytext=(6, 6), color="r")
    ax.set_xlabel(plain(figure.axis_labels[0]))
    ax.set_ylabel(plain(figure.axis_labels[1]))
    if three:
        ax.set_zlabel(plain(figure.axis_labels[2]))
    else:
        ax.grid(True, alpha=0.3)
    ax.set_title(
        f"{plain(figure.name, MAX_TITLE_NAME)}: Pareto front (A, B...: designs sketched)",
        fontsize=10,
    )
    if ax.get_legend_handles_labels()[0]:  # a front with no point has nothing to list
        ax.legend(fontsize=7)
    # The panels sketch one mechanism at the same stroke angles: their legends would
    # repeat one another, so the first panel with a sketch carries it for all.
    legend = True
    for k, panel in enumerate(panels):
        drawn = draw_panel(fig.add_subplot(gs[k % 2, 1 + k // 2]), panel, legend)
        legend = legend and not drawn
    return fig


def plot_fronts(problem, fronts: Sequence, ax=None, reference: np.ndarray | None = None):
    """Objective space with every front overlaid, plus sketches of picked points of the
    first front (unless ``ax`` is given: then only the objective space, on ``ax``):
    :func:`front_figure` drawn by :func:`draw_front`. Returns the Figure."""
    return draw_front(front_figure(problem, fronts, reference, sketches=ax is None), ax)


def _value_text(problem, name: str, value: float) -> str:
    """``ripple=0.843 %``: an objective's value with its unit, for titles."""
    from optdesign.display.shown import objective_shown

    return f"{name}=" + objective_shown(problem, name, value).text(4)
