"""Evidence for the two-verdict rule of the catalogue search (issue 25).

A node of the catalogue branch and bound stops its multistart once two starts both end
with the back-end's own verdict of local infeasibility (Ipopt's
``Infeasible_Problem_Detected``) and calls the node infeasible. This script runs the
searches with that rule switched off (every start and every retry of a failed node is
solved) and counts the nodes whose first two starts were such verdicts, and among them
those where a later start or retry converged: one would be a node the rule calls
infeasible wrongly. Cases: the catalogue instance family of
``bench_catalogue_solvers.py`` (both families, seeds 0-7, branch and bound and
enumeration), the two shipped catalogue problems (``od.solve``, with the optimum's
neighbouring items) and the 6-point catalogue front of ``fin_actuator``. One JSON line
per case (cumulative counts) goes to ``--out`` as it is measured.

    .venv/bin/python benchmarks/catalogue_verdicts.py [--out benchmarks/results/catalogue_verdicts.jsonl]
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from optdesign.formulations.catalogue import search as cat

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from catalogue_cases import run_cases, write_row  # noqa: E402

VERDICT = "locally infeasible"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--out", type=Path, default=ROOT / "benchmarks" / "results" / "catalogue_verdicts.jsonl"
    )
    args = ap.parse_args()
    outcomes: list[list[str]] = []
    solve = cat.NodeSolver.solve

    def recorded(self, *a, **k):
        r = solve(self, *a, **k)
        if r.multistart is not None and r.multistart.outcomes:
            outcomes.append(list(r.multistart.outcomes))
        return r

    cat.NodeSolver.solve = recorded
    cat.NodeSolver.verdicts_decide = lambda self, results: False  # every start, every retry

    def tally(case: str) -> None:
        two = [o for o in outcomes if len(o) >= 3 and o[0] == o[1] == VERDICT]
        later = [o for o in two if "converged" in o[2:]]
        row = {
            "case": case,
            "nodes": len(outcomes),
            "first_two_verdicts": len(two),
            "later_converged": len(later),
            "examples": later[:5],
        }
        write_row(args.out, row)

    args.out.parent.mkdir(parents=True, exist_ok=True)
    run_cases(tally)


if __name__ == "__main__":
    main()
