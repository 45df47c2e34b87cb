"""Why a problem is infeasible, as a change the engineer can make: for each requirement
in the conflict (violated, or binding, at the best infeasible point), the smallest
relaxation of that requirement alone (the others kept) that makes the problem feasible.

Each requirement's rows are relaxed by an amount ``t`` in its own unit (through the
solve's :class:`~optdesign.programs.nlp.Bounds`, so the formulation and the solver
are the ones of the solve). On Ipopt the smallest ``t`` is the minimum of a phase-1
problem (:class:`~optdesign.solvers.phase_one.PhaseOneSolver`: ``t`` minimised with the
requirement's rows widened by it and the others held), one solve per start, its point
checked against the widened rows; elsewhere, or where that solve does not converge,
``t`` is bracketed by removing the requirement altogether (the violation of the design
found then is enough) and bisected on feasibility. A requirement whose removal alone
leaves the problem infeasible is reported as such, and the requirements are then relaxed
together (:func:`relax_together`): the set to relax and by how much.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.formulations.nlp.solve import _objective_set, phase_one_for, solver_for
from optdesign.problem.requirements import physical_conditions
from optdesign.solvers.base import constraint_reports
from optdesign.solvers.registry import solver_hints
from optdesign.solvers.result import Relaxation

__all__ = ["Relaxation", "Site", "relax_together", "relaxations"]


def relaxations(
    problem: Any,
    result: Any,
    solver: str | None = None,
    iterations: int = 8,
    max_requirements: int = 6,
    max_iter: int = 80,
    *,
    objective: str | None = None,
    box: Mapping[str, tuple[float, float]] | None = None,
    parameters: Mapping[str, float] | None = None,
    x_start: np.ndarray | None = None,
    sites_for: Callable[[str, Callable[[Site], tuple[float | None, Any]]], Iterable[Site]]
    | None = None,
    direct: bool = True,
) -> list[Relaxation]:
    """The smallest relaxation of each requirement ``result`` violates.

    Parameters
    ----------
    problem, result
        The problem and its infeasible result: its violated and active rows name the
        candidates; its best point starts each solve (the NLP's own point ``raw["z"]``
        when ``result`` is a solve of this NLP, else ``x_start``).
    solver
        The back-end of the solve (None: the registry's default for an NLP).
    iterations
        Bisection steps on each relaxation (the answer is feasible and within
        ``2**-iterations`` of the bracket above the smallest one).
    max_requirements
        At most this many requirements are diagnosed (the largest violations first).
    max_iter
        Iteration cap of each solve (for a back-end that declares its iteration
        option).
    objective
        The objective of the NLP (default: the result's, if the problem has it).
    box, parameters
        Variables held in a sub-box (name -> (lower, upper); a catalogue item as (v, v))
        and the problem's parameter values there: the relaxation at those items.
    x_start
        A design (free-variable vector) to start from, for a result of another
        formulation (GP, robust).
    sites_for
        Instead of ``box``: the sites of each requirement, tried in order,
        ``sites_for(name, at)``, where ``at(site)`` is the smallest relaxation at a site
        and the design there ((None, None) if removing the requirement is not enough) -
        e.g. the catalogue items nearest the design of the continuous relaxation's
        smallest one. A relaxation found at a site says where (:attr:`Relaxation.at`).
    direct
        Minimise each relaxation by a phase-1 solve where the back-end is Ipopt (False:
        always bracket and bisect, as other back-ends do; ``iterations=0`` keeps the
        bracket alone).
    """
    # The conflict is between the violated requirements and the ones binding at the best
    # infeasible point: each is a candidate.
    names: dict[str, Any] = {}
    physical = physical_conditions(problem)  # never relaxed: beyond them nothing works
    for r in [*sorted(result.violated, key=lambda r: -r.amount), *result.active]:
        base = r.name.split("[", 1)[0]
        # not the objective's rows
        if "_envelope" not in base and base not in names and base not in physical:
            names[base] = r
    if objective is None:
        own = result.objective_name
        objective = own if own in problem.objectives else problem.objective_names[0]
    # Infeasible sub-problems are where an interior point spends its time (restoration phase): a
    # capped iteration count keeps the diagnosis cheap; a capped solve counts as
    # infeasible, so the reported relaxation stays a feasible one (at worst a little
    # larger than the smallest).
    cap = solver_hints(solver).iteration_option
    options = {cap: max_iter} if cap is not None else None
    backend = solver_for(problem, solver, options, _objective_set(problem, objective))
    nlp = backend.nlp
    phase_one = phase_one_for(problem, backend) if direct and iterations > 0 else None
    z_best = _own_z(result, nlp)  # not another formulation's point (the robust NLP's)
    sites = [_Prepared(problem, nlp, Site(box, parameters, x_start, z_best))]
    base_names = [g.split("[", 1)[0] for g in nlp.g_names]
    out = []
    for name, row in list(names.items())[:max_requirements]:
        idx = np.array([k for k, b in enumerate(base_names) if b == name], dtype=int)
        if idx.size == 0:
            continue
        scale = np.asarray(nlp.g_scale, dtype=float)[idx]
        count = 0

        def feasible(t: float, site: _Prepared, starts: list, idx=idx, scale=scale):
            nonlocal count
            b = _relaxed(site.bounds, idx, scale, t)
            for s in starts:
                count += 1
                r = backend.solve(s, None, b)
                if r.success and not r.violated:
                    return r
            return None

        hi_side = row.upper is not None and (
            row.lower is None or abs(row.value - row.upper) <= abs(row.value - row.lower)
        )

        def smallest(site: _Prepared, idx=idx, scale=scale, row=row, hi_side=hi_side):
            """(t, the design at it): the smallest relaxation found at ``site``, or
            (None, None) when removing the requirement leaves no feasible design."""
            nonlocal count
            if phase_one is not None:
                found, solves = _minimised(phase_one(), nlp, site, idx, scale)
                count += solves
                if found is not None:
                    return found
            ok = feasible(np.inf, site, site.starts, idx, scale)
            if ok is None:
                return None, None
            g = np.asarray(nlp.g_fun(ok.raw["z"], site.theta), dtype=float).ravel()[idx]
            t_hi, t_lo = float(_need(g * scale, row, hi_side)), 0.0
            starts = [nlp.start(z0=ok.raw["z"]), *site.starts]
            for _ in range(iterations):
                mid = 0.5 * (t_lo + t_hi)
                r = feasible(mid, site, starts, idx, scale)
                if r is not None:
                    t_hi, ok = mid, r
                else:
                    t_lo = mid
            return t_hi, ok

        here = sites
        if sites_for is not None:

            def at(site: Site, smallest=smallest) -> tuple[float | None, Any]:
                return smallest(_Prepared(problem, nlp, site))

            # lazily: a site may be costly to find, and is looked for only when needed
            here = (_Prepared(problem, nlp, s) for s in sites_for(name, at))
        # At the first site (catalogue items) where removing the requirement leaves a
        # feasible design (which brackets its relaxation).
        t_hi, used = None, None
        for used in here:
            t_hi, _ = smallest(used)
            if t_hi is not None:
                break
        record = _record(row, hi_side, t_hi, count)
        if t_hi is not None and used is not None:
            record.at = used.site.label
        out.append(record)
    return out


#: How far beyond the minimised relaxation (relative) the reported limit lies: at the
#: minimum itself the feasible set is a single design, which a search from random starts
#: rarely finds; a little beyond, it has room.
MARGIN = 1e-3


def _minimised(
    phase_one: Any, nlp: Any, site: _Prepared, idx: np.ndarray, scale: np.ndarray
) -> tuple[tuple[float | None, Any] | None, int]:
    """(the smallest relaxation of rows ``idx`` at ``site`` and its design, or (None,
    None) when Ipopt finds the other rows infeasible from every start; None: no answer,
    bisect), and the solves spent. The least ``t`` of the phase-1 solves from the site's
    starts (:data:`MARGIN` beyond it), accepted only when its point meets every row with
    the requirement's widened by it."""
    best = None
    refused = 0
    for start in site.starts:
        found = phase_one.solve(start.z0, site.bounds, rows=idx, per_row=1.0 / scale)
        refused += found.hard_rows_infeasible
        if found.converged and (best is None or found.value < best.value):
            best = found
    solves = len(site.starts)
    if best is None:
        return ((None, None) if refused == solves else None), solves
    t = max(0.0, best.value) * (1.0 + MARGIN)
    g = np.asarray(nlp.g_fun(best.z, site.theta), dtype=float).ravel()
    violated, _ = constraint_reports(nlp, g, _relaxed(site.bounds, idx, scale, t))
    if violated:
        return None, solves
    return (t, best.result), solves


def relax_together(
    problem: Any,
    result: Any,
    alone: list[Relaxation],
    solver: str | None = None,
    *,
    objective: str | None = None,
    x_start: np.ndarray | None = None,
) -> list[Relaxation]:
    """Where no requirement relaxed alone gives a feasible design (an entry of ``alone``
    without ``needed``): the requirements of ``alone`` relaxed together, as the phase-1
    problem with all their rows widened by one scaled amount (each row scaled by its
    limit, so by about one fraction of each) finds them; of them, those the design found
    needs changed, each to its worst value there. Empty when one relaxation alone is
    enough, on a back-end other than Ipopt, or when even that finds no design."""
    if not alone or any(r.needed is not None for r in alone):
        return []
    if objective is None:
        own = result.objective_name
        objective = own if own in problem.objectives else problem.objective_names[0]
    backend = solver_for(problem, solver, None, _objective_set(problem, objective))
    phase_one = phase_one_for(problem, backend)
    if phase_one is None:
        return []
    nlp = backend.nlp
    site = _Prepared(problem, nlp, Site(x_start=x_start, z_start=_own_z(result, nlp)))
    base_names = [g.split("[", 1)[0] for g in nlp.g_names]
    wanted = {r.name for r in alone}
    idx = np.array([k for k, b in enumerate(base_names) if b in wanted], dtype=int)
    found = [phase_one().solve(s.z0, site.bounds, rows=idx) for s in site.starts]
    found = [f for f in found if f.converged]
    if not found:
        return []
    best = min(found, key=lambda f: f.value)
    g = np.asarray(nlp.g_fun(best.z, site.theta), dtype=float).ravel()
    out = []
    for r in alone:
        rows = np.array([k for k in idx if base_names[k] == r.name], dtype=int)
        values = g[rows] * np.asarray(nlp.g_scale, dtype=float)[rows]
        row = _Row(r.lower_row, r.upper_row, r.name)
        t = _need(values, row, r.upper)
        if t > 0.0:
            out.append(_record(row, r.upper, t, len(found)))
    return out


@dataclass
class _Row:
    """The bounds (and name) of a requirement's rows, as a relaxation record reads them."""

    lower: float | None
    upper: float | None
    name: str = ""


def _own_z(result: Any, nlp: Any) -> np.ndarray | None:
    """The result's own NLP vector, when it is one of this NLP (else None)."""
    z = result.raw.get("z")
    return None if z is None or np.size(z) != nlp.z.numel() else z


@dataclass
class Site:
    """Where a relaxation is sought: variables held in a sub-box (catalogue items as
    (v, v)) with the problem's parameter values there, and where the solves start.

    ``label`` names it in a report (e.g. ``"d0 = 25 mm, p = 5 mm"``)."""

    box: Mapping[str, tuple[float, float]] | None = None
    parameters: Mapping[str, float] | None = None
    x_start: np.ndarray | None = None
    z_start: np.ndarray | None = None
    label: str = ""
    #: designs to start from after ``x_start`` (clipped to the box), e.g. the problem's
    #: own start beside a best point that may sit where the models are not defined
    also_from: tuple[np.ndarray, ...] = ()


class _Prepared:
    """A :class:`Site` on one NLP: its bounds, parameter values and starts."""

    def __init__(self, problem: Any, nlp: Any, site: Site):
        self.site = site
        self.bounds = nlp.bounds(box=site.box, parameters=site.parameters)
        self.theta = nlp.parameter_values(self.bounds.parameters)
        first = problem.start() if site.x_start is None else np.asarray(site.x_start, float)
        lo, hi = problem.lower().copy(), problem.upper().copy()
        if site.box:
            for k, v in enumerate(problem.free):
                if v.name in site.box:
                    lo[k], hi[k] = site.box[v.name]
        self.starts = [nlp.start(z0=site.z_start)] if site.z_start is not None else []
        designs: list[np.ndarray] = []
        for x in (first, *site.also_from):
            x = np.asarray(x, dtype=float)
            if site.box:
                x = np.clip(x, lo, hi)
            if not any(np.array_equal(x, seen) for seen in designs):  # a start solved once
                designs.append(x)
                self.starts.append(nlp.start(x0=x, parameters=self.bounds.parameters))


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
