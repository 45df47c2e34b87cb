"""Dual warm starts of catalogue child nodes, measured (issue 25).

The catalogue branch and bound starts a child node from its parent's optimum (primal
only). This script solves the shipped catalogue problems as users do and, at every warm
child node, solves the child's first start twice more: (a) primal, as the search does,
and (b) primal and dual from the parent's solution (its multipliers, clipped point) with
Ipopt's warm-start options (``IPOPT_WARM``). It prints, per node, the status, iterations,
seconds and value of both, then the totals and how often they disagree.

    .venv/bin/python benchmarks/catalogue_dual_warm.py
"""

from __future__ import annotations

import os
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

import optdesign as od
from optdesign.formulations.catalogue import search as cat
from optdesign.formulations.catalogue.discrete import discrete_variables
from optdesign.formulations.nlp.solve import _objective_set, solver_for, solver_options
from optdesign.solvers.ipopt_options import IPOPT_NODE, IPOPT_WARM

ROOT = Path(__file__).resolve().parents[1]


class _WithRaw(np.ndarray):
    """A node's design vector that also carries the node's solution (for the dual start)."""

    raw: dict | None = None


def main() -> None:
    rows: list[tuple] = []
    warm_backends: dict[int, object] = {}
    x_of, solve = cat.NodeSolver.x_of, cat.NodeSolver.solve

    def x_with_raw(self, result):
        x = x_of(self, result)
        if x is None:
            return None
        x = x.view(_WithRaw)
        x.raw = result.raw
        return x

    def measured(self, bounds, x_hint=None, warm=False, prunes=None, fallback=True, floor=None):
        r = solve(self, bounds, x_hint, warm, prunes, fallback, floor)
        raw = getattr(x_hint, "raw", None)
        if not (warm and raw is not None and r.multistart):
            return r
        if id(self) not in warm_backends:
            opts = {**IPOPT_NODE, **solver_options(self.problem, self.solver), **IPOPT_WARM}
            names = tuple(_objective_set(self.problem, self.objective))
            warm_backends[id(self)] = solver_for(self.problem, self.solver, opts, names)
        wb = warm_backends[id(self)]
        node = {
            v.name: bounds.get(v.name, (v.lower, v.upper)) for v in discrete_variables(self.problem)
        }
        box = wb.nlp.bounds(
            eps=self.eps, box=bounds, parameters=self.problem.parameter_values(node)
        )
        z0 = np.clip(raw["z"], box.lbz, box.ubz)
        t0 = time.perf_counter()
        start = wb.nlp.start(
            z0=z0, lam_x0=raw["lam_x"], lam_g0=raw["lam_g"], parameters=box.parameters
        )
        dual = wb.solve(start, self.target, box)
        t_dual = time.perf_counter() - t0
        t0 = time.perf_counter()
        start = self.nlp.start(x0=np.asarray(x_hint), parameters=box.parameters)
        primal = self.backend.solve(start, self.target, box)
        t_primal = time.perf_counter() - t0
        rows.append((primal, t_primal, dual, t_dual))
        return r

    cat.NodeSolver.x_of, cat.NodeSolver.solve = x_with_raw, measured
    for name in ("fin_actuator", "cs_min_backlash_catalogue"):
        od.solve(od.load(ROOT / "problems" / f"{name}.toml"))
    print("primal: status iterations s value | primal and dual: status iterations s value")
    for p, tp, d, td in rows:
        pv = f"{p.objective:.6g}" if p.success else "-"
        dv = f"{d.objective:.6g}" if d.success else "-"
        print(f"{p.status} {p.iterations} {tp:.3f} {pv} | {d.status} {d.iterations} {td:.3f} {dv}")
    print(f"nodes {len(rows)}")
    print(
        f"primal: {sum(p.iterations or 0 for p, *_ in rows)} iterations, {sum(r[1] for r in rows):.2f} s"
    )
    print(
        f"dual: {sum(d.iterations or 0 for _, _, d, _ in rows)} iterations, {sum(r[3] for r in rows):.2f} s"
    )
    lost = sum(p.success and not d.success for p, _, d, _ in rows)
    print(f"solved from the primal start but not from the dual one: {lost}")


if __name__ == "__main__":
    main()
