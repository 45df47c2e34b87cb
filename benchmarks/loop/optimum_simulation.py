"""CPU time of a 2 s, 1 deg step of the shipped optimum of ``problems/fin_actuator_loop.toml``
in its loop, against the simulation of another commit, in the same run.

The optimum is solved once (``od.solve``); its plant at the middle of the stroke (the
one ``od.simulate`` takes) is then simulated by this tree's
``optdesign.models.loop_simulation.simulate`` and by the same module read from the git
revision ``--against`` (the rest of the package is this tree's), interleaved, each run
timed by ``time.process_time`` (the machine is shared: CPU time, not wall time). The two
drives of ``simulation_time.py`` (a 10 deg step of the representative drive, and the one
that hunts) are timed the same way. It prints the medians and their ratio, the events,
and how far the two runs' fin angles and last 0.5 s lie apart (the results must agree to
the integration's tolerance).

Usage: PYTHONPATH=. python benchmarks/loop/optimum_simulation.py [--repeats 7] [--against REV]
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import optdesign as od
from optdesign.models import loop_simulation as ls
from optdesign.problem.loop import drive_plants_of

sys.path.insert(0, str(Path(__file__).resolve().parent))
import simulation_time as st  # the two drives timed there

ROOT = Path(__file__).resolve().parents[2]
PROBLEM = ROOT / "problems" / "fin_actuator_loop.toml"
MODULE = "optdesign/models/loop_simulation.py"


def module_at(rev: str):
    """``loop_simulation`` as it was at git revision ``rev`` (imported from a copy)."""
    text = subprocess.run(
        ["git", "-C", str(ROOT), "show", f"{rev}:{MODULE}"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    path = Path(tempfile.mkdtemp()) / f"loop_simulation_{rev}.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[path.stem] = module
    spec.loader.exec_module(module)
    return module


def optimum_plant():
    """The plant and loop of the optimum at the middle of the stroke, and the od.simulate
    arguments that give the same run."""
    result = od.solve(PROBLEM, ranges=False, diagnose=False)
    problem = od.load(PROBLEM)
    phi = np.asarray(problem.phi, dtype=float)
    k = int(np.argmin(np.abs(phi - np.mean(phi[[0, -1]]))))
    with np.errstate(all="ignore"):
        plants, loop = drive_plants_of(problem.quantities(result.design), [k])[0]
    return result, plants[0], loop


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--against", default="66d1e65", help="git revision to compare with")
    args = parser.parse_args()
    result, plant, loop = optimum_plant()
    before = module_at(args.against)
    cases = {
        "fin_actuator_loop optimum, 1 deg": (plant, loop, math.radians(1.0), 2001),
        "representative drive, 10 deg": (st.PLANT, st.LOOP, math.radians(10.0), 4001),
        "hunting drive, 10 deg": (st.CYCLING, st.CYCLING_LOOP, math.radians(10.0), 4001),
    }
    for case, (p, c, amplitude, samples) in cases.items():
        modules = {args.against: before, "this tree": ls}
        times: dict[str, list[float]] = {name: [] for name in modules}
        sims = {}
        for _ in range(args.repeats):
            for name, module in modules.items():
                reference = module.StepReference(amplitude)
                t0 = time.process_time()
                sims[name] = module.simulate(p, c, reference, 2.0, samples=samples)
                times[name].append(time.process_time() - t0)
        print(f"\n{case}, 2 s, {args.repeats} runs each:")
        old, new = (statistics.median(times[name]) for name in modules)
        for name, ts in times.items():
            print(
                f"  {name}: median {statistics.median(ts):.3f} s CPU "
                f"(min {min(ts):.3f}, max {max(ts):.3f}), {len(sims[name].event_times)} events"
            )
        print(f"  ratio this tree / {args.against}: {new / old:.3f}")
        a, b = (sims[name] for name in modules)
        gap = np.max(np.abs(a.fin_angle - b.fin_angle))
        print(
            f"  largest difference of the fin angle: {math.degrees(gap):.3g} deg "
            f"({gap / p.backlash:.3g} of the gap's half-width)"
        )
        for name, sim in sims.items():
            amp, w = ls.steady_oscillation(sim, 1.5)
            print(
                f"  {name}: last 0.5 s, {math.degrees(amp):.6f} deg at {w / (2 * math.pi):.3f} Hz"
            )
    api = []
    for _ in range(3):
        t0 = time.process_time()
        od.simulate(result, horizon="2 s")
        api.append(time.process_time() - t0)
    print(
        "\nod.simulate(result, horizon='2 s') of the optimum, this tree: median of 3 "
        f"{statistics.median(api):.3f} s CPU"
    )


if __name__ == "__main__":
    main()
