"""Why a problem is infeasible, as a change the engineer can make: for each requirement
in the conflict (violated, or binding, at the best infeasible point), the smallest
relaxation of that requirement alone (the others kept) that makes the problem feasible.

Each requirement's rows are relaxed by an amount ``t`` in its own unit (through the
solve's :class:`~optdesign.formulations.nlp.Bounds`, so the formulation and the solver
are the ones of the solve); ``t`` is bracketed by removing the requirement altogether
(the violation of the design found then is enough) and bisected on feasibility. A
requirement whose removal alone leaves the problem infeasible is reported as such: it
conflicts only together with another one.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass
class Relaxation:
    """The smallest change of one requirement that makes the problem feasible, in the
    requirement rows' own (internal) quantity; reports show it as the user wrote it
    (:func:`optdesign.reports.limits.relaxation_limits`).

    Attributes
    ----------
    name
        The requirement (constraint block) name.
    upper
        True when its upper limit must rise, False when its lower limit must fall.
    written, needed
        The row limit as written and the one that makes the problem feasible (None:
        relaxing this requirement alone gave no feasible design).
    lower_row, upper_row
        Both row bounds as written (for showing a band ``|x| <= a`` as its magnitude).
    solves
        Solves spent on it.
    """

    name: str
    upper: bool
    written: float
    needed: float | None
    lower_row: float | None = None
    upper_row: float | None = None
    solves: int = 0


def relaxations(
    problem: Any,
    result: Any,
    solver: str = "ipopt",
    iterations: int = 8,
    max_requirements: int = 6,
    max_iter: int = 80,
) -> list[Relaxation]:
    """The smallest relaxation of each requirement ``result`` violates.

    Parameters
    ----------
    problem, result
        The problem and its infeasible NLP result (its best point starts each solve).
    solver
        The back-end of the solve.
    iterations
        Bisection steps on each relaxation (the answer is feasible and within
        ``2**-iterations`` of the bracket above the smallest one).
    max_requirements
        At most this many requirements are diagnosed (the largest violations first).
    max_iter
        Iteration cap of each Ipopt solve.
    """
    from optdesign.studies.solve import _objective_set, solver_for

    # The conflict is between the violated requirements and the ones binding at the best
    # infeasible point: each is a candidate.
    names: dict[str, Any] = {}
    for r in [*sorted(result.violated, key=lambda r: -r.amount), *result.active]:
        base = r.name.split("[", 1)[0]
        if "_envelope" not in base and base not in names:  # not the objective's rows
            names[base] = r
    objective = result.objective_name or problem.objective_names[0]
    # Infeasible sub-problems are where Ipopt spends its time (restoration phase): a
    # capped iteration count keeps the diagnosis cheap; a capped solve counts as
    # infeasible, so the reported relaxation stays a feasible one (at worst a little
    # larger than the smallest).
    options = {"max_iter": max_iter} if solver == "ipopt" else None
    backend = solver_for(problem, solver, options, _objective_set(problem, objective))
    nlp = backend.nlp
    base = nlp.bounds()
    theta = nlp.parameter_values(base.parameters)
    z_best = result.raw.get("z")
    x_start = nlp.start(x0=problem.start(), parameters=base.parameters)
    starts = [nlp.start(z0=z_best)] if z_best is not None else []
    starts.append(x_start)
    base_names = [g.split("[", 1)[0] for g in nlp.g_names]
    out = []
    for name, row in list(names.items())[:max_requirements]:
        idx = np.array([k for k, b in enumerate(base_names) if b == name], dtype=int)
        if idx.size == 0:
            continue
        scale = np.asarray(nlp.g_scale, dtype=float)[idx]
        count = 0

        def feasible(t: float, starts=starts, idx=idx, scale=scale):
            nonlocal count
            b = _relaxed(base, idx, scale, t)
            for s in starts:
                count += 1
                r = backend.solve(s, None, b)
                if r.success and not r.violated:
                    return r
            return None

        hi_side = row.upper is not None and (
            row.lower is None or abs(row.value - row.upper) <= abs(row.value - row.lower)
        )
        ok = feasible(np.inf)
        if ok is None:
            out.append(_record(row, hi_side, None, count))
            continue
        g = np.asarray(nlp.g_fun(ok.raw["z"], theta), dtype=float).ravel()[idx] * scale
        t_hi = float(_need(g, row, hi_side))
        t_lo = 0.0
        starts = [nlp.start(z0=ok.raw["z"]), *starts]
        for _ in range(iterations):
            mid = 0.5 * (t_lo + t_hi)
            if feasible(mid, starts=starts) is not None:
                t_hi = mid
            else:
                t_lo = mid
        out.append(_record(row, hi_side, t_hi, count))
    return out


def _need(g: np.ndarray, row: Any, hi_side: bool) -> float:
    """Relaxation the design with rows ``g`` needs (0 if it already meets the row)."""
    if hi_side:
        return max(0.0, float(np.max(g)) - row.upper)
    return max(0.0, row.lower - float(np.min(g)))


def _relaxed(base: Any, idx: np.ndarray, scale: np.ndarray, t: float) -> Any:
    from dataclasses import replace

    lbg = np.array(base.lbg, dtype=float)
    ubg = np.array(base.ubg, dtype=float)
    lbg[idx] -= t / scale
    ubg[idx] += t / scale
    return replace(base, lbg=lbg, ubg=ubg)


def _record(row: Any, hi_side: bool, t: float | None, count: int) -> Relaxation:
    written = row.upper if hi_side else row.lower
    needed = None if t is None else (written + t if hi_side else written - t)
    return Relaxation(
        row.name.split("[", 1)[0], hi_side, written, needed, row.lower, row.upper, count
    )
