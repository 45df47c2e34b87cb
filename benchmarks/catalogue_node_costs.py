"""Where a catalogue front's NLP solves go: each node start of the 6-point catalogue front
of a problem (default ``fin_actuator``, backlash against motor torque, one worker), by
how it ended and how it was solved (on the thinned grid, checked, whole), with its Ipopt
iterations and CPU time; with ``--phase-one``, each start that ended with Ipopt's verdict
of local infeasibility solved again as a phase-1 problem (least violation,
``optdesign.solvers.phase_one``) from the same start, on the same rows and bounds (the
point's epsilon limit included), to compare the cost of the two certificates.

    PYTHONPATH=. python benchmarks/catalogue_node_costs.py [--problem fin_actuator] [--phase-one]

One JSON line per category, then a summary line, go to ``--out`` (default
``benchmarks/results/catalogue_node_costs.jsonl``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections import defaultdict
from dataclasses import replace
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

import optdesign as od
from optdesign.formulations.catalogue import node_solver as nsm
from optdesign.formulations.nlp.solve import rows_solver_for
from optdesign.solvers.phase_one import PhaseOneSolver

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_catalogue import _clear_caches  # noqa: E402

VERDICT = "Infeasible_Problem_Detected"


def _logged_front(problem, points: int) -> tuple[list[tuple], float, int]:
    """The front's node starts (node solver, start, result, CPU s) and its CPU time."""
    starts: list[tuple] = []
    solve_start = nsm.NodeSolver._solve_start

    def logged(self, item):
        t0 = time.process_time()
        result = solve_start(self, item)
        starts.append((self, item, result, time.process_time() - t0))
        return result

    nsm.NodeSolver._solve_start = logged
    try:
        t0 = time.process_time()
        front = od.pareto(
            problem, ["backlash", "motor_torque"], points=points, workers=1, files=False
        )
        cpu = time.process_time() - t0
    finally:
        nsm.NodeSolver._solve_start = solve_start
    return starts, cpu, front.n_solves


def _phase_one(ns, item) -> tuple[float, int, float]:
    """(least violation, iterations, CPU s) of the phase-1 problem from a start's point."""
    box, x0, mode, rows = item
    backend = (
        ns.backend if mode == "whole" else rows_solver_for(ns.backend, rows, ns._options, ns.solver)
    )
    nlp = backend.nlp
    if mode == "checked":  # the thinned solve's rows and bounds
        box = replace(box, lbg=np.asarray(box.lbg)[list(rows)], ubg=np.asarray(box.ubg)[list(rows)])
    z0 = nlp.start(x0=x0, parameters=box.parameters).z0
    t0 = time.process_time()
    found = _solver(nlp).solve(z0, box)
    return found.value, found.result.iterations or 0, time.process_time() - t0


_SOLVERS: dict[int, PhaseOneSolver] = {}


def _solver(nlp) -> PhaseOneSolver:
    if id(nlp) not in _SOLVERS:
        _SOLVERS[id(nlp)] = PhaseOneSolver(nlp)
    return _SOLVERS[id(nlp)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problem", default="fin_actuator")
    ap.add_argument("--points", type=int, default=6)
    ap.add_argument("--phase-one", action="store_true")
    ap.add_argument(
        "--out", type=Path, default=ROOT / "benchmarks" / "results" / "catalogue_node_costs.jsonl"
    )
    args = ap.parse_args()
    problem = od.load(ROOT / "problems" / f"{args.problem}.toml")
    od.pareto(problem, ["backlash", "motor_torque"], points=3, workers=1, files=False)  # imports
    _clear_caches()
    starts, cpu, n_solves = _logged_front(problem, args.points)
    rows = defaultdict(lambda: {"starts": 0, "iterations": 0, "cpu_s": 0.0})
    phase = {"starts": 0, "certified": 0, "iterations": 0, "cpu_s": 0.0, "verdicts_cpu_s": 0.0}
    for ns, item, result, dt in starts:
        key = (item[2], result.message, result.raw.get(nsm.THINNED_START) or "")
        row = rows[key]
        row["starts"] += 1
        row["iterations"] += result.iterations or 0
        row["cpu_s"] += dt
        if args.phase_one and result.message == VERDICT:
            value, iterations, phase_cpu = _phase_one(ns, item)
            phase["starts"] += 1
            phase["certified"] += bool(value > 1e-6)
            phase["iterations"] += iterations
            phase["cpu_s"] += phase_cpu
            phase["verdicts_cpu_s"] += dt
    with args.out.open("a") as fh:
        for (mode, message, checked), row in sorted(rows.items(), key=lambda kv: -kv[1]["cpu_s"]):
            line = {"problem": args.problem, "mode": mode, "end": message, "checked": checked}
            line.update({k: round(v, 3) if isinstance(v, float) else v for k, v in row.items()})
            fh.write(json.dumps(line) + "\n")
            print(json.dumps(line))
        summary = {
            "problem": args.problem,
            "front_cpu_s": round(cpu, 3),
            "nlp_solves": n_solves,
            "starts": len(starts),
            "starts_cpu_s": round(sum(s[3] for s in starts), 3),
        }
        if args.phase_one:
            summary["phase_one"] = {
                k: round(v, 3) if isinstance(v, float) else v for k, v in phase.items()
            }
        fh.write(json.dumps(summary) + "\n")
        print(json.dumps(summary))


if __name__ == "__main__":
    main()
