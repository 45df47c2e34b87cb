"""Evidence for the agreement rule of the catalogue search's node multistarts (issue 25).

A node's multistart stops once ``agree`` of its starts (the problem's ``[solver] agree``,
3 by default) agree on the best value so far, as the continuous multistart does. This
script runs the searches with that rule switched off (every start of every multistart
node is solved) and, for each node, finds the first prefix of its starts on which the
rule would have stopped; a node where a later start then beats that prefix's best by
more than the tie tolerance is one where the rule changes the node's value. Cases: the
catalogue instance family of ``bench_catalogue_solvers.py`` (both families, seeds 0-7,
branch and bound and enumeration), the two shipped catalogue problems (``od.solve``) and
the 6-point catalogue front of ``fin_actuator``. One JSON line per case (cumulative
counts) goes to ``--out`` as it is measured.

    .venv/bin/python benchmarks/catalogue_agreement.py [--agree 3]
        [--out benchmarks/results/catalogue_agreement.jsonl]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from optdesign.formulations.catalogue import search as cat
from optdesign.solvers.multistart import improves
from optdesign.tolerances import OBJECTIVE_TIE_TOL

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from catalogue_cases import run_cases, write_row  # noqa: E402


def stop_prefix(values: list[float], agree: int) -> int | None:
    """The length of the first prefix on which ``agree`` successful starts reach its best
    value within the tie tolerance (None: the rule never stops this node)."""
    for k in range(1, len(values) + 1):
        ok = [v for v in values[:k] if math.isfinite(v)]
        if not ok:
            continue
        best = min(ok)
        tol = OBJECTIVE_TIE_TOL * max(abs(best), 1e-300)
        if sum(v <= best + tol for v in ok) >= agree:
            return k
    return None


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--agree", type=int, default=3)
    ap.add_argument(
        "--out", type=Path, default=ROOT / "benchmarks" / "results" / "catalogue_agreement.jsonl"
    )
    args = ap.parse_args()
    lists: list[list[float]] = []
    solve = cat.NodeSolver.solve

    def recorded(self, *a, **k):
        self.agree = 0  # every start of the node
        r = solve(self, *a, **k)
        ms = r.multistart
        if ms is not None and ms.n_starts > args.agree:
            # a start counts with its value only when it converged to a checked design
            lists.append(
                [
                    v if o == "converged" and v is not None else math.nan
                    for v, o in zip(ms.objectives, ms.outcomes, strict=True)
                ]
            )
        return r

    cat.NodeSolver.solve = recorded

    def tally(case: str) -> None:
        stopped, changed, examples, saved = 0, 0, [], 0
        for values in lists:
            k = stop_prefix(values, args.agree)
            if k is None or k == len(values):
                continue
            stopped += 1
            saved += len(values) - k
            prefix = min(v for v in values[:k] if math.isfinite(v))
            rest = [v for v in values[k:] if math.isfinite(v)]
            if rest and improves(min(rest), prefix, OBJECTIVE_TIE_TOL):
                changed += 1
                examples.append(values)
        row = {
            "case": case,
            "agree": args.agree,
            "multistart_nodes": len(lists),
            "stopped_by_agreement": stopped,
            "starts_saved": saved,
            "later_start_better": changed,
            "examples": examples[:5],
        }
        write_row(args.out, row)

    args.out.parent.mkdir(parents=True, exist_ok=True)
    run_cases(tally)


if __name__ == "__main__":
    main()
