"""Which linkage wins where: Pareto fronts of the three built-in layouts on one job.

The requirements of ``problems/cs_min_backlash.toml`` (+-30 deg, 500 N*m, mean ratio 200-260,
nut travel <= 110 mm, H7/g6 pins of L = 1.5 d, bearing pressure <= 100 MPa, shear <= 200
MPa) imposed on the crank-slider, the shifting fork and the pivoting screw (each with its
own geometry variables and, where it has them, a transmission angle of 40-140 deg), and
two trade-offs traced by the epsilon-constraint method: backlash against ratio ripple, and
backlash against peak motor torque. Run::

    python benchmarks/compare_layouts.py [--points 20] [--out benchmarks/data/layouts.json]

Writes the fronts (JSON) and ``layouts.png`` next to it, and prints which layout is best
along each front.
"""

from __future__ import annotations

import argparse
import copy
import json
import tomllib
from pathlib import Path

import numpy as np

import optdesign as od

ROOT = Path(__file__).resolve().parents[1]
BASE = tomllib.loads((ROOT / "problems" / "cs_min_backlash.toml").read_text())

LAYOUTS = {
    "crank_slider": (
        {k: BASE["variables"][k] for k in ("R", "l", "n", "phi0")},
        {k: BASE["requirements"][k] for k in ("transmission_angle", "rod_inclination_max")},
    ),
    "fork": ({"R": BASE["variables"]["R"]}, {}),
    "pivoting_screw": (
        {
            "R": BASE["variables"]["R"],
            "a_T": {"lower": "-300 mm", "upper": "-40 mm"},
            "b_T": {"lower": "-100 mm", "upper": "150 mm"},
            "phi0": BASE["variables"]["phi0"],
        },
        {"transmission_angle": BASE["requirements"]["transmission_angle"], "dead_length": "60 mm"},
    ),
}
COMMON_REQUIREMENTS = {
    k: v
    for k, v in BASE["requirements"].items()
    if k not in ("transmission_angle", "rod_inclination_max", "pin_shear_planes")
}
TRADE_OFFS = (["ripple", "backlash"], ["motor_torque", "backlash"])


def problem_of(mechanism: str) -> od.DesignProblem:
    own_vars, own_reqs = LAYOUTS[mechanism]
    data = copy.deepcopy(BASE)
    data.update(name=f"{mechanism}_layout", mechanism=mechanism)
    data["variables"] = {
        **copy.deepcopy(own_vars),
        **{k: BASE["variables"][k] for k in ("p", "d", "i_a", "pin_length_ratio")},
    }
    data["requirements"] = {**copy.deepcopy(COMMON_REQUIREMENTS), **copy.deepcopy(own_reqs)}
    return od.load(data)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=20)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "data" / "layouts.json")
    args = ap.parse_args()
    results: dict = {"points": args.points, "fronts": {}}
    fronts = {}
    for objectives in TRADE_OFFS:
        key = "+".join(objectives)
        for mechanism in LAYOUTS:
            front = od.pareto(problem_of(mechanism), objectives, args.points, workers=args.workers)
            fronts[(key, mechanism)] = front
            results["fronts"].setdefault(key, {})[mechanism] = {
                "F": front.F.tolist(),
                "anchors": front.anchors,
                "designs": [p.design for p in front.points],
                "time_s": front.wall_time_s,
            }
            print(f"{key:22s} {mechanism:15s} {len(front.points):3d} points "
                  f"{front.wall_time_s:6.2f} s  ends {front.F[0]} .. {front.F[-1]}")  # fmt: skip
        grid = winners({m: fronts[(key, m)].F for m in LAYOUTS}, n=200)
        results.setdefault("winner", {})[key] = segments(grid)
        for a0, a1, name in results["winner"][key]:
            print(f"  {objectives[0]} {a0:.6g} .. {a1:.6g}: least {objectives[1]} with {name}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(results, indent=1, default=float))
    plot(fronts, args.out.with_suffix(".png"))
    print(f"wrote {args.out} and {args.out.with_suffix('.png')}")


def winners(fronts: dict[str, np.ndarray], n: int = 12) -> list[tuple[float, str, float]]:
    """Along the first objective (a grid over the union of the fronts' ranges): the layout
    with the least second objective there (fronts interpolated; a front counts only
    inside its own range), as (first objective, layout, second objective)."""
    lo = min(F[:, 0].min() for F in fronts.values())
    hi = max(F[:, 0].max() for F in fronts.values())
    out = []
    for a in np.linspace(lo, hi, n):
        best = None
        for name, F in fronts.items():
            # a front is a staircase: at A = a, the best B any of its points with A <= a has
            ok = F[:, 0] <= a * (1 + 1e-9)
            if ok.any():
                b = float(F[ok, 1].min())
                if best is None or b < best[1]:
                    best = (name, b)
        if best is not None:
            out.append((float(a), best[0], best[1]))
    return out


def segments(grid: list[tuple[float, str, float]]) -> list[tuple[float, float, str]]:
    """Runs of the same winner along the grid: (first value, last value, layout)."""
    out: list[tuple[float, float, str]] = []
    for a, name, _ in grid:
        if out and out[-1][2] == name:
            out[-1] = (out[-1][0], a, name)
        else:
            out.append((a, a, name))
    return out


def plot(fronts, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from optdesign.plots.front import axis_label

    fig, axes = plt.subplots(1, len(TRADE_OFFS), figsize=(11, 4.2))
    for ax, objectives in zip(axes, TRADE_OFFS, strict=True):
        key = "+".join(objectives)
        for mechanism in LAYOUTS:
            front = fronts[(key, mechanism)]
            (xl, xs), (yl, ys) = (axis_label(front.problem_object, k) for k in objectives)
            ax.plot(front.F[:, 0] * xs, front.F[:, 1] * ys, "o-", ms=3, label=mechanism)
            ax.set_xlabel(xl)
            ax.set_ylabel(yl)
        ax.grid(True, alpha=0.3)
        ax.legend()
        ax.set_title(f"{objectives[1]} against {objectives[0]}, same requirements")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
