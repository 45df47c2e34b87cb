"""The fronts of backlash against ``bandwidth_period`` of fin_actuator_loop, one per
placement of the gains, against the sweep of docs/loop.md ("The trade-off between
bandwidth and backlash").

The shipped file places kp and kd for 9 Hz. Its loop's bandwidth then hardly depends on
the design (9.186 to 9.190 Hz over the whole front): the placement, not the linkage, sets
it. The staircase of docs/loop.md moves the placement with the required bandwidth. Here
each placement f (Hz) gets its own front, with ``[loop] bandwidth = f`` and
``bandwidth_min = f``: its least-backlash end is the sweep's point at f, and its
fastest end is the least bandwidth that placement reaches at any design.

    source /work/venv/bin/activate
    PYTHONPATH=. python benchmarks/loop/bandwidth_front.py [--placements 6,7,8,8.5,9,9.5]

Prints one row per placement and front point; the columns the sweep's table has (least
backlash, the items) beside the least bandwidth 1 / bandwidth_period and the exact
loop figures of the point (``loop_figures``), and the NLP solves the front counted.
"""

from __future__ import annotations

import argparse
import time
import tomllib
from pathlib import Path

import numpy as np

import optdesign as od
from optdesign.errors import InfeasibleRequirementsError
from optdesign.problem.loop_analysis import loop_figures

ROOT = Path(__file__).resolve().parents[2]

#: The sweep's least backlash (deg) and pins (mm) at each required bandwidth (docs/loop.md).
SWEEP = {6: (0.0377566, 10), 6.5: (0.0377566, 10), 7: (0.0377566, 10), 7.5: (0.0377566, 10),
         8: (0.0377566, 10), 8.5: (0.0377566, 10), 9: (0.0430784, 16)}  # fmt: skip


def problem_at(f: float) -> od.DesignProblem:
    data = tomllib.loads((ROOT / "problems" / "fin_actuator_loop.toml").read_text())
    data["loop"]["bandwidth"] = f"{f:g} Hz"
    data["requirements"]["bandwidth_min"] = f"{f:g} Hz"
    return od.load(data)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--placements", default="6,7,8,8.5,9,9.5")
    parser.add_argument("--points", type=int, default=4)
    args = parser.parse_args()
    print("placement Hz | point | backlash deg | d0/p/d mm | least bandwidth Hz (exact)"
          " | resonance margin | sweep's backlash, pins | NLP solves | wall s")  # fmt: skip
    for f in (float(v) for v in args.placements.split(",")):
        problem = problem_at(f)
        start = time.perf_counter()
        sweep = SWEEP.get(f)
        shown = "-" if sweep is None else f"{sweep[0]:.7f}, {sweep[1]} mm"
        try:
            front = od.pareto(
                problem, "backlash,bandwidth_period", points=args.points, workers=1, progress=False
            )
        except InfeasibleRequirementsError as exc:  # no design at this placement
            wall = time.perf_counter() - start
            print(f"{f:g} | none: {' '.join(str(exc).split())[:400]} | {shown} | | {wall:.0f}")
            continue
        wall = time.perf_counter() - start
        if not front.points:
            print(f"{f:g} | none | | | | | {shown} | {front.n_solves} | {wall:.0f}")
            continue
        for k, point in enumerate(sorted(front.points, key=lambda p: p.objectives["backlash"])):
            x = np.array([point.design[v.name] for v in problem.free])
            figures = loop_figures(problem.quantities(problem.design_dict(x)))
            items = "/".join(f"{point.design[n]:g}" for n in ("d0", "p", "d"))
            print(
                f"{f:g} | {k} | {point.objectives['backlash']:.7f} | {items} | "
                f"{1.0 / point.objectives['bandwidth_period']:.5f} "
                f"({figures.bandwidth.value:.5f}) | {figures.resonance_margin.value:.3f} | "
                + (f"{shown} | {front.n_solves} | {wall:.0f}" if k == 0 else "| |")
            )


if __name__ == "__main__":
    main()
