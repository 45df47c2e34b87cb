"""CPU time of one period of the duty cycle of ``problems/fin_actuator_loop.toml``'s
optimum, the plant following the fin (``od.simulate(result, "duty", period=...)``),
against a 2 s, 1 deg step of the fixed plant at mid-stroke (``od.simulate(result,
horizon="2 s")``) and the same step with the path plant (``plant="path"``), in the same
run, interleaved.

The optimum is solved once. Each run is timed by ``time.process_time`` (the machine is
shared: CPU time, not wall time); the medians, their ratios to the fixed step's, and
each run's events and right-hand-side calls (machine-independent) are printed.

Usage: PYTHONPATH=. python benchmarks/loop/duty_cost.py [--repeats 7] [--period "5 s"]
[--periods N] (N > 1: a run of N periods is timed too)
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections import Counter
from pathlib import Path

import optdesign as od
from optdesign.models import loop_simulation as ls
from optdesign.models.loop_path import PathSystem

ROOT = Path(__file__).resolve().parents[2]
PROBLEM = ROOT / "problems" / "fin_actuator_loop.toml"


def counted(run):
    """``run()``'s result and how many times solve_ivp called a right-hand side."""
    calls = Counter()
    classes = (ls._System, PathSystem)
    originals = [cls.__dict__["rhs"] for cls in classes]

    def counting(original):
        def rhs(self, mode):
            fn = original(self, mode)

            def wrapped(t, x):
                calls["rhs"] += 1
                return fn(t, x)

            return wrapped

        return rhs

    for cls, original in zip(classes, originals, strict=True):
        cls.rhs = counting(original)
    try:
        out = run()
    finally:
        for cls, original in zip(classes, originals, strict=True):
            cls.rhs = original
    return out, calls["rhs"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--period", default="5 s")
    parser.add_argument("--periods", type=int, default=1, help="a run of this many periods too")
    args = parser.parse_args()
    result = od.solve(PROBLEM, ranges=False, sensitivities=False, diagnose=False)
    cases = {
        "2 s step, fixed plant": lambda: od.simulate(result, horizon="2 s"),
        "2 s step, path plant": lambda: od.simulate(result, horizon="2 s", plant="path"),
        f"one duty period ({args.period})": lambda: od.simulate(result, "duty", period=args.period),
    }
    if args.periods > 1:
        cases[f"{args.periods} duty periods"] = lambda: od.simulate(
            result, "duty", period=args.period, periods=args.periods
        )
    times = {name: [] for name in cases}
    for _ in range(args.repeats):
        for name, run in cases.items():
            start = time.process_time()
            run()
            times[name].append(time.process_time() - start)
    base = statistics.median(times["2 s step, fixed plant"])
    print(f"{'run':<28} {'median':>8} {'min':>8} {'max':>8} {'ratio':>6} {'events':>7} {'rhs':>7}")
    for name, run in cases.items():
        sim, calls = counted(run)
        t = times[name]
        print(
            f"{name:<28} {statistics.median(t):8.3f} {min(t):8.3f} {max(t):8.3f} "
            f"{statistics.median(t) / base:6.2f} {len(sim.response.event_times):7d} {calls:7d}"
        )


if __name__ == "__main__":
    main()
