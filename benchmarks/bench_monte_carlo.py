"""Monte Carlo throughput of the output error of a crank-slider design (issue 7).

Run:  /work/venv/bin/python benchmarks/bench_monte_carlo.py [--n 4000000] [--seed 7]

Samples the transmission-error sources of seed 003 (lead, backlash, coaxiality,
deformation of the stiffness chain under a 500 N*m hinge moment, encoder, mounting, rod
pins, environment), maps them to the output angle of the seed-000 crank-slider (R=90, l=80, n=50 mm, p=5 mm,
i_a=2) through its kinematics, and prints samples per second, best of ``--repeat`` runs.
Two cases: a fixed deflection, and a deflection drawn per sample over the +-30 deg stroke
(kinematics evaluated per sample). The result is reproducible from the seed; the timing
is not a unit test. Goal: >= 1e6 samples/s.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from optdesign.mechanisms import CrankSlider
from optdesign.models import error_budget as eb
from optdesign.models import screw_sizing
from optdesign.reproduce.monte_carlo import run_monte_carlo


def design_sources(mech: CrankSlider):
    """Error sources of a crank-slider drive; the deformation is the stiffness chain's
    compliance under the nut force of the hinge moment at each sampled angle."""
    K = screw_sizing.axial_stiffness_chain(
        screw_sizing.shaft_stiffness(16.0, 300.0, "fixed-free"), 4e5, 6e5, 1e6
    )
    return [
        eb.lead_error_source(0.003),
        eb.backlash_source(0.005),
        eb.coaxiality_source(0.01, mech.p, 20.0),
        eb.compliance_source(K, cv=0.2),
        eb.encoder_source(np.radians(0.02)),
        eb.random_source("mounting", 0.002),
        eb.random_source("rod pins", 0.004, "rod_length", "uniform"),
        eb.random_source("environment", 0.001),
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=4_000_000)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    mech = CrankSlider(R=90.0, l=80.0, n=50.0, p=5.0, i_a=2.0)
    sources = design_sources(mech)
    cases = {
        "fixed deflection 10 deg": dict(phi=np.radians(10.0)),
        "deflection sampled over +-30 deg": dict(phi_range=(np.radians(-30), np.radians(30))),
    }
    print(f"{len(sources)} sources, n = {args.n}, seed = {args.seed}, best of {args.repeat}")
    for name, kw in cases.items():
        best = np.inf
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            res = run_monte_carlo(sources, args.n, args.seed, mech, M_h=5e5, **kw)
            best = min(best, time.perf_counter() - t0)
        top = ", ".join(f"{k} {100 * v:.1f} %" for k, v in res.ranking()[:3])
        print(
            f"{name}: {args.n / best:.3e} samples/s; output error mean "
            f"{np.degrees(res.mean):.5f} deg, sd {np.degrees(res.std):.5f} deg; top: {top}"
        )


if __name__ == "__main__":
    main()
