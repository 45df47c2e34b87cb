"""Why a catalogue search found no feasible design: the NLP with the catalogue variables
held at the best items - of the catalogue combinations around the continuous
relaxation's best point, the one whose design violates the requirements least. A
relaxation found there is sufficient (the relaxed problem has a design with those
items); other items may need less."""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from optdesign.formulations.catalogue.bnb import first_feasible
from optdesign.formulations.catalogue.discrete import discrete_variables, nearest_item
from optdesign.formulations.catalogue.search import NodeSolver
from optdesign.formulations.diagnosis import Relaxing, best_point
from optdesign.formulations.nlp.relaxation import Site, relaxations
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.parameters import without_impossible_items
from optdesign.solvers.constraint_rows import constraint_rows
from optdesign.solvers.registry import solver_hints
from optdesign.solvers.result import Diagnosis, Result

#: Items of each catalogue variable tried around the continuous best point, and the most
#: combinations of them solved (nearest first).
NEAREST_ITEMS = 3
MAX_ITEM_COMBINATIONS = 4
#: Iteration cap of the solve at each combination (the relaxations' own cap is 80), for a
#: back-end that declares its iteration option.
NODE_MAX_ITER = 150
#: Combinations tried for each requirement beyond the nearest one.
MAX_ALTERNATIVES = 3


def catalogue_diagnosis(problem: DesignProblem, result: Result, how: Relaxing) -> Diagnosis:
    """The relaxations of the NLP at the catalogue items nearest the best point (the
    result's own best point when the search returned none)."""
    solver, options, relax = how.solver, how.options, how.relax
    dvars = discrete_variables(problem)
    objective = result.objective_name or problem.objective_names[0]
    info = result.details.get("catalogue")
    root = (info.relaxation_design if info else None) or {}
    x0 = problem.start()
    for k, v in enumerate(problem.free):
        value = root.get(v.name)
        if value is not None and math.isfinite(value):
            x0[k] = value
    # Each combination is solved once, capped like the relaxations' solves: a best point
    # to report, not an optimum (its infeasible solves are where Ipopt spends its time).
    cap = solver_hints(solver).iteration_option
    capped = {**(options or {}), cap: NODE_MAX_ITER} if cap is not None else options
    ns = NodeSolver(problem, objective, 1, problem.spec.solver.seed, solver, capped)
    tried: list[tuple[float, int, dict[str, float], Result]] = []
    for k, items in enumerate(item_combinations(problem, dvars, x0)):
        box = {name: (v, v) for name, v in items.items()}
        params = problem.parameter_values(box)
        bounds = ns.nlp.bounds(box=box, parameters=params)
        x = x0.copy()
        for j, v in enumerate(problem.free):
            if v.name in items:
                x[j] = items[v.name]
        r = ns.backend.solve(ns.nlp.start(x0=x, parameters=bounds.parameters), ns.target, bounds)
        if not r.design:
            continue
        for name, value in items.items():  # on the item exactly (the NLP holds it to 1e-9)
            r.design[name] = value
        xr = np.array([r.design[v.name] for v in problem.free])
        violation = float(problem.evaluate(xr).violation)
        tried.append((violation if math.isfinite(violation) else math.inf, k, items, r))
    if not tried:
        return Diagnosis(note="no catalogue combination near the best point could be solved")
    tried.sort(key=lambda t: (t[0], t[1]))  # least violation, then nearest
    _, _, items, node = tried[0]

    def label(items: dict[str, float]) -> str:
        return ", ".join(f"{v.name} = {items[v.name]:g} {v.unit}".rstrip() for v in dvars)

    shown = label(items)
    basis = "catalogue items chosen for each requirement"
    why = (
        "each relaxation holds with the catalogue items it names: of those nearest the "
        "design of the continuous relaxation's smallest change, the first that works, else "
        "those a catalogue search without the requirement finds; a requirement the "
        "continuous relaxation cannot relax alone conflicts with others whatever the items"
    )
    x = np.array([node.design[v.name] for v in problem.free])
    active, violated = constraint_rows(problem, x)
    if not result.design:
        from optdesign.formulations.verify import verify_design

        _, _, objectives = verify_design(problem, x)
        result.design = {**problem.fixed_values, **node.design}
        result.objectives = {k: float(v) for k, v in objectives.items()}
        result.objective = result.objectives.get(objective, math.nan)
        result.violated, result.active = violated, active
        result.verified = not violated
        result.notes.append(f"best point found: at the catalogue items {shown}")
    if not violated:
        return Diagnosis(
            basis=basis,
            note=(
                f"the catalogue items {shown} give a design that violates no requirement: "
                "the search missed it; more starts (starts=) may find it"
            ),
        )
    if not relax:
        return Diagnosis(basis=basis, note=why)
    point = best_point(objective, active, violated, node.raw.get("z"))
    full = problem.parameter_values({})  # favourable over every item: the relaxation's

    def site(items: dict[str, float], start: np.ndarray, z: Any = None) -> Site:
        box = {k: (v, v) for k, v in items.items()}
        return Site(box, problem.parameter_values(box), start, z, label(items))

    def sites_for(name: str, at):
        # from the best point and from the problem's own start, as the continuous
        # diagnosis starts: the best point may sit at a dead point, where the models are
        # not defined, and a relaxation that fails from there alone proves nothing
        t, relaxed = at(Site(None, full, x, also_from=(problem.start(),)))
        if t is None or not relaxed.design:
            return  # even the continuous relaxation needs more than this requirement
        # the items nearest the design of the continuous relaxation's smallest change
        xr = np.array([relaxed.design[v.name] for v in problem.free])
        for other in item_combinations(problem, dvars, xr)[: MAX_ALTERNATIVES + 1]:
            yield site(other, xr)
        # none of them: the catalogue search without the requirement (reached only then),
        # over the items the closed forms leave when their proof holds without it (the
        # motors too small for the motion: a search that misses everything visits every
        # box, theirs too), its starts capped as the combinations' are (a capped start
        # leaves its node to the retries)
        searched, _ = without_impossible_items(problem, dropped=(name,))
        if any(not v.values for v in discrete_variables(searched)):
            return  # no item the requirement's removal could use
        free = NodeSolver(searched, objective, 1, ns.seed, solver, capped)
        rows = [k for k, g in enumerate(free.nlp.g_names) if g.split("[", 1)[0] == name]
        free.free_rows = np.asarray(rows, dtype=int)
        found = first_feasible(free)
        if found is not None and found.design:
            items = {v.name: nearest_item(found.design[v.name], v.values)[0] for v in dvars}
            yield site(items, free.x_of(found), found.raw.get("z"))

    found = relaxations(problem, point, solver=solver, objective=objective, sites_for=sites_for)
    return Diagnosis(found, basis, why)


def item_combinations(problem: DesignProblem, dvars, x0: np.ndarray) -> list[dict[str, float]]:
    """Catalogue combinations near ``x0``, nearest first (relative distance): of each
    variable's :data:`NEAREST_ITEMS` nearest items, the combinations the catalogues hold
    (a screw's (d0, p) pair); if none, the held combinations nearest ``x0``. At most
    :data:`MAX_ITEM_COMBINATIONS`."""
    from optdesign.problem.drive import box_has_item

    index = {v.name: k for k, v in enumerate(problem.free)}

    def gap(name: str, item: float) -> float:
        value = x0[index[name]]
        if item > 0 and value > 0:
            return abs(math.log(item / value))
        return abs(item - value)

    def nearest(v) -> list[float]:
        return sorted(v.values, key=lambda c: (gap(v.name, c), c))[:NEAREST_ITEMS]

    def exists(items: dict[str, float]) -> bool:
        return box_has_item(problem, {k: (v, v) for k, v in items.items()})

    def distance(items: dict[str, float]) -> float:
        return sum(gap(k, v) for k, v in items.items())

    names = [v.name for v in dvars]
    near = [dict(zip(names, c, strict=True)) for c in itertools.product(*map(nearest, dvars))]
    found = [c for c in near if exists(c)]
    if not found:  # e.g. a screw catalogue whose pairs are far from the relaxed point
        every = itertools.islice(itertools.product(*(v.values for v in dvars)), 100_000)
        found = [c for c in (dict(zip(names, c, strict=True)) for c in every) if exists(c)]
    found.sort(key=lambda c: (distance(c), tuple(c.values())))
    return found[:MAX_ITEM_COMBINATIONS]
