"""What the objective ``limit_cycle_amplitude`` costs an evaluation on the NumPy path
(docs/loop.md, "The margins and the limit cycle as objectives").

The problem is tests/loop_problems.py's small fin_actuator_loop (items and linkage fixed
but the offset n, no ``limit_cycle_amplitude_max``) with its loop rows at 7 angles. Each
measurement is CPU time, best of ``--repeat``, in one run:

* a single design's evaluation, which reads every objective, on designs met for the
  first time (one harmonic balance per loop angle) and again on the same designs with
  only the cycles in the per-plant cache (the bandwidth's roots and the poles emptied);
* a population of 256 designs evaluated, reading ``backlash`` only (no harmonic
  balance: the cycles are computed when read) and then ``limit_cycle_amplitude`` too.

    source /work/venv/bin/activate
    PYTHONPATH=. python benchmarks/loop_objectives/evaluation_cost.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import sys
import time
from functools import partial
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))

from loop_problems import small_loop_problem  # noqa: E402

from optdesign.problem import loop_margins  # noqa: E402
from optdesign.problem.loop_bandwidth import _bandwidth  # noqa: E402
from optdesign.problem.loop_requirements import _least_damping  # noqa: E402


def _each(problem, xs) -> None:
    for x in xs:
        problem.evaluate(np.array([x]))


def _cpu(fn) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    problem = small_loop_problem("backlash", angles=7)
    problem.evaluate(np.array([120.0]))  # imports and the first build out of the timing
    rng = np.random.default_rng(0)
    fresh, cached, reads, both = [], [], [], []
    for _ in range(args.repeat):
        xs = rng.uniform(100.0, 150.0, 20)
        for out in (fresh, cached):
            # the other per-plant caches (bandwidth, poles) emptied each pass, the cycles'
            # only for the first: the difference is the harmonic balances alone
            _bandwidth.cache_clear()
            _least_damping.cache_clear()
            if out is fresh:
                loop_margins._largest_cycle.cache_clear()
            out.append(_cpu(partial(_each, problem, xs)) / len(xs))
        X = rng.uniform(100.0, 150.0, (256, 1))
        loop_margins._largest_cycle.cache_clear()
        ev = problem.evaluate(X)
        reads.append(_cpu(partial(ev.objectives.__getitem__, "backlash")))
        both.append(_cpu(partial(ev.objectives.__getitem__, "limit_cycle_amplitude")))
    f, c = min(fresh), min(cached)
    print(f"single design, new designs:       {1e3 * f:8.2f} ms CPU per evaluation")
    print(f"single design, cycles cached:     {1e3 * c:8.2f} ms CPU per evaluation")
    print(f"ratio new / cached:               {f / c:8.2f}")
    print(f"per harmonic balance (7 angles):  {1e3 * (f - c) / 7:8.2f} ms CPU")
    print(f"256 designs, read backlash:       {1e3 * min(reads):8.2f} ms CPU")
    print(f"256 designs, read the amplitude:  {1e3 * min(both):8.2f} ms CPU")


if __name__ == "__main__":
    main()
