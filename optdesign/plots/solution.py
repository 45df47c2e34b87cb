"""Plot of a solved design: ratio and backlash over the stroke, optimum vs initial, with
the requirements a designer reads off it: the mean-ratio band, the backlash limit, and
where each limit binds (markers at those angles; the full list under the plot). Names
and labels are drawn as plain text (:func:`optdesign.plots.plain`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from optdesign.display.limits import binding_angles, bound_limits, limits_of
from optdesign.plots import MAX_TITLE_NAME, new_figure, plain
from optdesign.problem.design_problem import DesignProblem
from optdesign.views.curves import stroke_curves
from optdesign.views.design import design_rows


@dataclass(frozen=True)
class DesignCurves:
    """One design's curves over the stroke: its ratio and, with pins, its worst-case
    backlash (deg)."""

    label: str
    ratio: np.ndarray
    backlash: np.ndarray | None = None


@dataclass(frozen=True)
class SolutionFigure:
    """What the figure of a solved design shows, from the designs' evaluated curves and
    rows (:mod:`optdesign.views`; :func:`solution_figure`), so that drawing it
    (:func:`draw_solution`) evaluates no model and can run in another process.

    Attributes
    ----------
    name
        The problem's name (the titles').
    phi_deg
        The deflection grid (deg).
    designs
        The curves of each design drawn, in order (the last one carries the markers).
    mean_band
        The required mean ratio's (low, high) drawn as a band, or None.
    backlash_limit
        The backlash limit (deg) drawn as a line, or None.
    binding
        Requirement name -> the grid indices where it binds, marked on the last design.
    footer
        What limits the design, listed under the plot ("" for none).
    """

    name: str
    phi_deg: np.ndarray
    designs: tuple[DesignCurves, ...]
    mean_band: tuple[float, float] | None = None
    backlash_limit: float | None = None
    binding: tuple[tuple[str, tuple[int, ...]], ...] = ()
    footer: str = ""

    @property
    def has_backlash(self) -> bool:
        """Whether the figure has the backlash panel (the problem has pins)."""
        return any(d.backlash is not None for d in self.designs) or (
            not self.designs and self.backlash_limit is not None
        )


def solution_figure(
    problem: DesignProblem,
    designs: Mapping[str, Mapping[str, float]],
    limits: Sequence | None = None,
    binding: Mapping[str, Sequence[float]] | None = None,
) -> SolutionFigure:
    """The :class:`SolutionFigure` of the named ``designs`` of ``problem``.

    ``limits``: :class:`~optdesign.display.limits.Limit` records listed under the plot;
    ``binding``: requirement name -> deflection angles (deg) where it binds, marked on the
    last design's ratio curve.
    """
    phi_deg = np.degrees(np.asarray(problem.phi, dtype=float))
    has_pin = problem.has("d")
    req = problem.spec.requirements
    curves = []
    for label, design in designs.items():
        drawn = stroke_curves(problem, dict(design))
        curves.append(DesignCurves(str(label), drawn.ratio, drawn.backlash))
    band = None
    if req.mean_ratio is not None:
        lo, hi = req.mean_ratio.min, req.mean_ratio.max
        lo_y = lo if lo is not None else 0.0
        band = (float(lo_y), float(hi if hi is not None else lo_y))
    limit = None
    if has_pin and req.backlash_max is not None:
        limit = float(np.degrees(req.backlash_max))
    marks = tuple(
        (str(name), tuple(int(np.argmin(np.abs(phi_deg - a))) for a in angles))
        for name, angles in (binding or {}).items()
    )
    footer = ""
    if limits:
        footer = "what limits the design: " + "; ".join(lim.text() for lim in limits[:6])
    return SolutionFigure(str(problem.name), phi_deg, tuple(curves), band, limit, marks, footer)


def draw_solution(figure: SolutionFigure, ax=None):
    """Draw a :class:`SolutionFigure`: the ratio (and the backlash, with pins) against the
    deflection for each design. Returns the Figure; with ``ax`` the ratio is drawn on
    that axes (and the backlash, if any, on a twin axis) instead of a new figure."""
    has_pin = figure.has_backlash
    phi_deg = figure.phi_deg
    if ax is None:
        # constrained: the footer (what limits the design) keeps its own room below the
        # axes' labels in a notebook too, where no save_figure lays the figure out
        fig = new_figure((11 if has_pin else 6, 4.6), layout="constrained")
        axes = list(fig.subplots(1, 2 if has_pin else 1, squeeze=False)[0])
    else:
        fig = ax.figure
        axes = [ax, ax.twinx()] if has_pin else [ax]
    if figure.mean_band is not None:
        lo_y, hi_y = figure.mean_band
        axes[0].axhspan(lo_y, hi_y, color="C2", alpha=0.12, label="required mean ratio")
    ratio = None
    for k, curves in enumerate(figure.designs):
        ratio = curves.ratio
        axes[0].plot(phi_deg, ratio, color=f"C{k}", label=plain(curves.label))
        if figure.mean_band is not None:
            with np.errstate(invalid="ignore"):
                mean = float(np.mean(ratio))
            axes[0].axhline(
                mean, color=f"C{k}", ls=":", lw=0.9, label=f"mean, {plain(curves.label)}"
            )
        if has_pin and curves.backlash is not None:
            axes[1].plot(phi_deg, curves.backlash, "--", color=f"C{k}", label=plain(curves.label))
    if has_pin and figure.backlash_limit is not None:
        axes[1].axhline(figure.backlash_limit, color="C3", lw=1.2, label="backlash_max")
    if ratio is not None:
        for j, (name, idx) in enumerate(figure.binding):
            axes[0].plot(
                phi_deg[list(idx)],
                ratio[list(idx)],
                ["x", "+", "D", "v", "^", "s"][j % 6],
                ms=8,
                mew=2,
                color=f"C{4 + j}",
                label=f"{plain(name)} binds",
            )
    axes[0].set_ylabel("reduction ratio i (motor rad / output rad)")
    axes[0].set_title(f"{plain(figure.name, MAX_TITLE_NAME)}: ratio over the stroke")
    if has_pin:
        axes[1].set_ylabel("worst-case backlash (deg)")
        axes[1].set_title("output backlash over the stroke")
    for a in axes:
        a.set_xlabel("deflection phi (deg)")
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7)
    if figure.footer:
        fig.supxlabel(_wrap(plain(figure.footer, 6 * 170), 170), fontsize=7, x=0.01, ha="left")
    return fig


def plot_designs(
    problem: DesignProblem,
    designs: Mapping[str, Mapping[str, float]],
    ax=None,
    limits: Sequence | None = None,
    binding: Mapping[str, Sequence[float]] | None = None,
):
    """Ratio (and backlash, if the problem has pins) vs deflection for each named design
    (:func:`solution_figure` drawn by :func:`draw_solution`); returns the Figure."""
    return draw_solution(solution_figure(problem, designs, limits, binding), ax)


def _wrap(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width))


def result_figure(result) -> SolutionFigure:
    """The :class:`SolutionFigure` of ``result``: its optimum against the problem's
    initial design, the initial design labelled as violating the requirements when it
    does."""
    problem = result.problem_object
    if problem is None or not result.design:
        raise ValueError("plot: the result carries no problem or no design to draw")
    start = problem.design_dict(problem.start())
    n_bad = len(limits_of(problem, list(design_rows(problem, start).violated)))
    initial = "initial design" + (
        f" (violates {n_bad} requirement{'s' if n_bad > 1 else ''})" if n_bad else ""
    )
    best = "optimum" if result.success else "best point found (infeasible)"
    rows = design_rows(problem, result.design)
    active = list(rows.active)
    # an infeasible point's violated requirements come first: they are the news
    limits = limits_of(problem, list(rows.violated)) + limits_of(problem, active)
    limits += bound_limits(problem, result.design)
    binding = binding_angles(active)
    return solution_figure(problem, {initial: start, best: result.design}, limits, binding)


def plot_result(result, ax=None):
    """The optimum of ``result`` against the problem's initial design (a Figure)."""
    return draw_solution(result_figure(result), ax)
