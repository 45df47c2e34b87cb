"""Plot of a solved design: ratio and backlash over the stroke, optimum vs initial, with
the requirements a designer reads off it: the mean-ratio band, the backlash limit, and
where each limit binds (markers at those angles; the full list under the plot). Names
and labels are drawn as plain text (:func:`optdesign.plots.plain`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from optdesign.plots import MAX_TITLE_NAME, new_figure, plain
from optdesign.problem.design_problem import DesignProblem
from optdesign.reports.limits import binding_angles, bound_limits, limits_of
from optdesign.solvers.constraint_rows import constraint_rows


def plot_designs(
    problem: DesignProblem,
    designs: Mapping[str, Mapping[str, float]],
    ax=None,
    limits: Sequence | None = None,
    binding: Mapping[str, Sequence[float]] | None = None,
):
    """Ratio (and backlash, if the problem has pins) vs deflection for each named design.

    ``limits``: :class:`~optdesign.reports.limits.Limit` records listed under the plot;
    ``binding``: requirement name -> deflection angles (deg) where it binds, marked on the
    last design's ratio curve. Returns the Figure; with ``ax`` the ratio is drawn on that
    axes (and the backlash, if any, on a twin axis) instead of a new figure.
    """
    phi_deg = np.degrees(problem.phi)
    has_pin = problem.has("d")
    req = problem.spec.requirements
    if ax is None:
        # constrained: the footer (what limits the design) keeps its own room below the
        # axes' labels in a notebook too, where no save_figure lays the figure out
        fig = new_figure((11 if has_pin else 6, 4.6), layout="constrained")
        axes = list(fig.subplots(1, 2 if has_pin else 1, squeeze=False)[0])
    else:
        fig = ax.figure
        axes = [ax, ax.twinx()] if has_pin else [ax]
    if req.mean_ratio is not None:
        lo, hi = req.mean_ratio.min, req.mean_ratio.max
        lo_y = lo if lo is not None else 0.0
        hi_y = hi if hi is not None else lo_y
        axes[0].axhspan(lo_y, hi_y, color="C2", alpha=0.12, label="required mean ratio")
    ratio = None
    for k, (label, design) in enumerate(designs.items()):
        with np.errstate(invalid="ignore", divide="ignore"):
            q = problem.quantities(design)
            ratio = np.asarray(q.ratio, dtype=float).ravel()
            axes[0].plot(phi_deg, ratio, color=f"C{k}", label=plain(label))
            if req.mean_ratio is not None:
                axes[0].axhline(
                    float(np.mean(ratio)),
                    color=f"C{k}",
                    ls=":",
                    lw=0.9,
                    label=f"mean, {plain(label)}",
                )
            if has_pin:
                axes[1].plot(
                    phi_deg,
                    np.asarray(q.backlash.worst_case, dtype=float).ravel(),
                    "--",
                    color=f"C{k}",
                    label=plain(label),
                )
    if has_pin and req.backlash_max is not None:
        axes[1].axhline(
            float(np.degrees(req.backlash_max)), color="C3", lw=1.2, label="backlash_max"
        )
    if binding and ratio is not None:
        for j, (name, angles) in enumerate(binding.items()):
            idx = [int(np.argmin(np.abs(phi_deg - a))) for a in angles]
            axes[0].plot(
                phi_deg[idx],
                ratio[idx],
                ["x", "+", "D", "v", "^", "s"][j % 6],
                ms=8,
                mew=2,
                color=f"C{4 + j}",
                label=f"{plain(name)} binds",
            )
    axes[0].set_ylabel("reduction ratio i (motor rad / output rad)")
    axes[0].set_title(f"{plain(problem.name, MAX_TITLE_NAME)}: ratio over the stroke")
    if has_pin:
        axes[1].set_ylabel("worst-case backlash (deg)")
        axes[1].set_title("output backlash over the stroke")
    for a in axes:
        a.set_xlabel("deflection phi (deg)")
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7)
    if limits:
        text = "what limits the design: " + "; ".join(lim.text() for lim in limits[:6])
        fig.supxlabel(_wrap(plain(text, 6 * 170), 170), fontsize=7, x=0.01, ha="left")
    return fig


def _wrap(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width))


def plot_result(result, ax=None):
    """The optimum of ``result`` against the problem's initial design (a Figure); the
    initial design is labelled as violating the requirements when it does."""
    problem = result.problem_object
    if problem is None or not result.design:
        raise ValueError("plot: the result carries no problem or no design to draw")
    start = problem.design_dict(problem.start())
    _, violated = constraint_rows(problem, start)
    n_bad = len(limits_of(problem, violated))
    initial = "initial design" + (
        f" (violates {n_bad} requirement{'s' if n_bad > 1 else ''})" if n_bad else ""
    )
    best = "optimum" if result.success else "best point found (infeasible)"
    active, bad = constraint_rows(problem, result.design)
    # an infeasible point's violated requirements come first: they are the news
    limits = limits_of(problem, bad) + limits_of(problem, active)
    limits += bound_limits(problem, result.design)
    binding = binding_angles(active)
    return plot_designs(problem, {initial: start, best: result.design}, ax, limits, binding)
