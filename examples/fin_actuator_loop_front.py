"""The trade-off between the loop's bandwidth and the backlash of the shipped
``problems/fin_actuator_loop.toml``: the required bandwidth is swept with the loop's
gains placed for it (``[loop] bandwidth`` linked to ``requirements.bandwidth_min``), and
each point's loop is analysed exactly. Run it as a script:

    python examples/fin_actuator_loop_front.py [OUT]

It runs (or resumes) the sweep the command line runs with

    optdesign sweep problems/fin_actuator_loop.toml --vary requirements.bandwidth_min=6..11Hz:11 \\
        --with loop.bandwidth=requirements.bandwidth_min --out OUT

writes ``sweep.csv``, ``sweep.png``, ``sweep.html`` and ``front.png`` to ``OUT``, and
prints the table of docs/loop.md: at each bandwidth the optimal backlash, the items, the
binding set or what fails, and the resonance margin 1 / |L(j w_r)| (the requirement the
items answer to) of the optimum and of the low-bandwidth optimum's design (its 10 mm
pins) at that bandwidth. Default ``OUT``: ``fin_actuator_loop_front``.
"""

import math
import sys
from pathlib import Path

from matplotlib.figure import Figure

import optdesign as od
from optdesign.problem.loop_analysis import loop_figures

PROBLEM = Path(__file__).resolve().parents[1] / "problems" / "fin_actuator_loop.toml"
SWEPT = "requirements.bandwidth_min"
VARY = {SWEPT: ("6 Hz", "11 Hz", 11)}
LINKED = {"loop.bandwidth": SWEPT}


def point_problem(problem: od.DesignProblem, bandwidth: float) -> od.DesignProblem:
    """The problem at a point: the bandwidth required and the one the gains are placed
    for, both ``bandwidth`` (Hz)."""
    return problem.with_setting(SWEPT, bandwidth).with_setting("loop.bandwidth", bandwidth)


def resonance_margin(problem: od.DesignProblem, design: dict) -> tuple[float, float]:
    """The least resonance margin over the loop's angles and its angle (deg)."""
    figure = loop_figures(problem.quantities(design)).resonance_margin
    return figure.value, figure.angle


def main(out: Path) -> od.Sweep:
    resume = (out / "sweep.jsonl").exists()
    sweep = od.sweep(PROBLEM, VARY, linked=LINKED, out=out, resume=resume)
    problem = sweep.problem
    # the design of the lowest bandwidth: fin_actuator_motor's optimum (10 mm pins)
    low = sweep.points[0].design
    rows, margins = [], []
    for p in sweep.points:
        at = point_problem(problem, p.values[0])
        low_margin = resonance_margin(at, low)
        if p.success:
            figures = loop_figures(at.quantities(p.design))
            own = (figures.resonance_margin.value, figures.resonance_margin.angle)
            items = " / ".join(f"{p.design[n]:g}" for n in ("d0", "p", "d"))
            why = ", ".join(p.active)
            extra = (
                f"{figures.bandwidth.value:.2f} Hz, {figures.phase_margin.value:.1f} deg, "
                f"cycle {figures.limit_cycle.value:.4f} deg"
            )
            backlash = f"{p.objective:.7f}"
        else:
            own, items, backlash, extra = (math.nan, math.nan), "-", "-", "-"
            why = f"{p.status}: " + "; ".join(p.violated)
        margins.append((p.values[0], p.objective if p.success else math.nan, own[0], low_margin[0]))
        rows.append(
            f"| {p.values[0]:g} | {backlash} | {items} | {own[0]:.3f} ({own[1]:+.0f} deg) | "
            f"{low_margin[0]:.3f} ({low_margin[1]:+.0f} deg) | {extra} | {why} |"
            if p.success
            else f"| {p.values[0]:g} | - | - | - | {low_margin[0]:.3f} "
            f"({low_margin[1]:+.0f} deg) | - | {why} |"
        )
    print(
        "| bandwidth [Hz] | backlash [deg] | d0 / p / d [mm] | resonance margin | "
        "the same with 10 mm pins | least bandwidth, phase margin, largest cycle | "
        "binding, or what fails |"
    )
    print("|---|---|---|---|---|---|---|")
    print("\n".join(rows))
    front_figure(margins, problem.spec.requirements.resonance_margin_min, out / "front.png")
    return sweep


def front_figure(margins, required: float, path: Path) -> None:
    """The front (backlash against the bandwidth) above the resonance margins."""
    f = [m[0] for m in margins]
    fig = Figure(figsize=(6.4, 5.6))
    top, bottom = fig.subplots(2, 1, sharex=True)
    # the item changes somewhere between two points: the points, joined, not a step
    top.plot(f, [m[1] for m in margins], "o-", color="C0")
    bad = [x for x, m in zip(f, margins, strict=True) if math.isnan(m[1])]
    if bad:
        top.axvspan(min(bad) - 0.25, max(bad) + 0.25, color="0.85", zorder=0)
        top.text(min(bad), top.get_ylim()[0], " no design", va="bottom")
    top.set_ylabel("least backlash [deg]")
    top.set_title("fin_actuator_loop: backlash against the loop's bandwidth")
    bottom.plot(f, [m[2] for m in margins], "o-", label="the optimum")
    bottom.plot(f, [m[3] for m in margins], "s--", label="the 10 mm pins' design")
    bottom.axhline(required, color="k", lw=0.8, label=f"required {required:g}")
    bottom.set_ylabel("resonance margin 1/|L(j w_r)|")
    bottom.set_xlabel("bandwidth required = bandwidth placed [Hz]")
    bottom.legend()
    for ax in (top, bottom):
        ax.grid(alpha=0.4)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("fin_actuator_loop_front")
    print(main(folder).summary())
