"""Why a solve found no feasible design, whatever the formulation: the best point found
(its violated requirements by name and amount) and the smallest relaxation of each
requirement in the conflict (:mod:`optdesign.studies.relaxation`), or why there is none.

:func:`diagnose` fills :attr:`Result.diagnosis <optdesign.solvers.result.Result>` of a
result that is not a success (``od.solve(..., diagnose=True)``, the default; the CLI's
``--no-diagnosis`` turns it off). What the relaxations rest on depends on the
formulation, and the diagnosis says it in its ``basis``:

- **NLP**: the problem's NLP, from the result's best point.
- **catalogue**: the NLP with the catalogue variables held at the best items - of the
  catalogue combinations around the continuous relaxation's best point, the one whose
  design violates the requirements least. A relaxation found there is sufficient (the
  relaxed problem has a design with those items); other items may need less.
- **GP**: a GP solver returns no point for an infeasible program; the exact NLP of the
  same problem (exact Hertz) gives the best point and the relaxations.
- **robust**: the robust formulation imposes the nominal requirements (its statistic is
  the objective only), so the nominal NLP's relaxations are the robust problem's.
- **fixed design** (no free variable): exact - a violated requirement that is the only
  one violated needs its limit moved to the design's worst value; with several violated,
  relaxing one alone is not enough.

A result whose best point violates no requirement (a solver that stopped early, a
catalogue search that missed every feasible item) gets no relaxation but a note saying
so: the problem may well be feasible. A best point whose models are used outside their
ranges of validity gets none either: relaxing a requirement cannot bring a model back
into its range; the note names the models and quantities, and the inputs to check.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from optdesign.formulations.discrete import discrete_variables, nearest_item
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.validity import is_validity
from optdesign.reports.limits import limits_of
from optdesign.solvers.constraint_rows import constraint_rows
from optdesign.solvers.registry import solver_for_kind, solver_hints
from optdesign.solvers.result import ConstraintReport, Diagnosis, Relaxation, Result
from optdesign.studies.catalogue import NodeSolver
from optdesign.studies.catalogue_bnb import first_feasible
from optdesign.studies.nlp_solve import solve_nlp
from optdesign.studies.relaxation import Site, relax_together, relaxations

#: Items of each catalogue variable tried around the continuous best point, and the most
#: combinations of them solved (nearest first).
NEAREST_ITEMS = 3
MAX_ITEM_COMBINATIONS = 4
#: Iteration cap of the solve at each combination (the relaxations' own cap is 80), for a
#: back-end that declares its iteration option.
NODE_MAX_ITER = 150
#: Combinations tried for each requirement beyond the nearest one.
MAX_ALTERNATIVES = 3


def diagnose(
    problem: DesignProblem,
    result: Result,
    solver: str | None = None,
    options: Mapping[str, Any] | None = None,
    relax: bool = True,
) -> Result:
    """Fill ``result.diagnosis`` (and, when the formulation returned no point, the best
    point found) of a result that is not a success; returns ``result``.

    ``solver``, ``options``: the NLP back-end of the relaxations and its options (a GP
    back-end, or None: the registry's default for an NLP). ``relax=False``: the best
    point only, no relaxation (e.g. for an error message)."""
    if result.success:
        return result
    outside = [r for r in result.violated if is_validity(r)]
    if outside:
        result.diagnosis = Diagnosis(basis="the best point found", note=validity_note(outside))
        return result
    nlp_solver = solver_for_kind(solver, "nlp")
    kind = result.formulation
    if kind == "fixed":
        result.diagnosis = _fixed(problem, result)
    elif kind.startswith("catalogue"):
        result.diagnosis = _catalogue(problem, result, nlp_solver, options, relax)
    elif kind == "gp":
        result.diagnosis = _gp(problem, result, relax)
    elif kind.startswith("robust"):
        result.diagnosis = _robust(problem, result, nlp_solver, relax)
    else:
        result.diagnosis = _nlp(problem, result, nlp_solver, relax)
    missed = [r for r in result.diagnosis.relaxations if r.needed == r.written]
    if missed:
        # a relaxation of nothing: the diagnosis met every requirement as written
        where = f" with {missed[0].at}" if missed[0].at else ""
        found = (
            f"a design meeting every requirement as written exists{where} (found while "
            f"relaxing {missed[0].name}): the solve missed it ({result.status}); more starts "
            "(starts=) may find it"
        )
        old = result.diagnosis.note
        result.diagnosis.note = f"{found}; {old}" if old else found
    return result


def validity_note(outside: list[ConstraintReport]) -> str:
    """Why a best point outside its models' ranges gets no relaxation, naming them."""
    what = sorted({r.name.removeprefix("validity: ").split("[", 1)[0] for r in outside})
    shown = "; ".join(what[:4]) + (f"; and {len(what) - 4} more" if len(what) > 4 else "")
    return (
        f"the best point found lies outside the range where its models hold ({shown}): "
        "no relaxation of a requirement brings a model back into its range; check the "
        "inputs those models read (the pin's material and lug, the fit, [clearances], "
        "pin_length_ratio) and the bounds of the variables (docs/validity.md)"
    )


def _nothing_violated(result: Result) -> str:
    return (
        f"no requirement is violated at the best point found: the solver stopped "
        f"({result.status}: {result.message or result.termination.value}) without proving "
        "the problem infeasible; more starts (starts=) may find a feasible design"
    )


def _nlp(problem: DesignProblem, result: Result, solver: str, relax: bool) -> Diagnosis:
    if not result.design:
        return Diagnosis(note="the solver returned no point to diagnose from")
    if not result.violated:
        return Diagnosis(basis="the NLP", note=_nothing_violated(result))
    if not relax:
        return Diagnosis(basis="the NLP")
    found = relaxations(problem, result, solver=solver)
    return Diagnosis(found, "the NLP", together=relax_together(problem, result, found, solver))


def _robust(problem: DesignProblem, result: Result, solver: str, relax: bool) -> Diagnosis:
    basis = "the nominal NLP"
    why = "the robust formulation imposes the nominal requirements (its statistic is the objective)"
    if not result.design:
        return Diagnosis(basis=basis, note="the solver returned no point to diagnose from")
    x = np.array([result.design[v.name] for v in problem.free])
    active, violated = constraint_rows(problem, x)
    if not violated:
        return Diagnosis(basis=basis, note=_nothing_violated(result))
    if not relax:
        return Diagnosis(basis=basis, note=why)
    point = _point(problem.objective_names[0], active, violated)
    found = relaxations(problem, point, solver=solver, x_start=x)
    together = relax_together(problem, point, found, solver, x_start=x)
    return Diagnosis(found, basis, why, together)


def _gp(problem: DesignProblem, result: Result, relax: bool) -> Diagnosis:
    objective = result.objective_name or problem.objective_names[0]
    nlp = solve_nlp(problem, objective=objective)
    basis = "the exact NLP"
    why = (
        "a GP solver gives no point for an infeasible program; the exact NLP has the same "
        "requirements (exact Hertz)"
    )
    if not result.design and nlp.design:
        _adopt(result, nlp)
        result.notes.append("best point found: the exact NLP's (the GP solver gives none)")
    if nlp.success:
        return Diagnosis(
            basis=basis,
            note=(
                f"the exact NLP found a feasible design ({objective} = {nlp.objective:.8g}) "
                "although the GP (first-order Hertz) has none: solve with formulation='nlp'"
            ),
        )
    if not nlp.violated:
        return Diagnosis(basis=basis, note=_nothing_violated(nlp))
    if not relax:
        return Diagnosis(basis=basis, note=why)
    found = relaxations(problem, nlp)
    return Diagnosis(found, basis, why, relax_together(problem, nlp, found))


def _catalogue(
    problem: DesignProblem,
    result: Result,
    solver: str,
    options: Mapping[str, Any] | None,
    relax: bool,
) -> Diagnosis:
    dvars = discrete_variables(problem)
    objective = result.objective_name or problem.objective_names[0]
    info = result.details.catalogue
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
    for k, items in enumerate(_item_combinations(problem, dvars, x0)):
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
        from optdesign.studies.verify import verify_design

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
    point = _point(objective, active, violated, node.raw.get("z"))
    full = problem.parameter_values({})  # favourable over every item: the relaxation's

    def site(items: dict[str, float], start: np.ndarray, z: Any = None) -> Site:
        box = {k: (v, v) for k, v in items.items()}
        return Site(box, problem.parameter_values(box), start, z, label(items))

    def sites_for(name: str, at):
        t, relaxed = at(Site(None, full, x))
        if t is None or not relaxed.design:
            return  # even the continuous relaxation needs more than this requirement
        # the items nearest the design of the continuous relaxation's smallest change
        xr = np.array([relaxed.design[v.name] for v in problem.free])
        for other in _item_combinations(problem, dvars, xr)[: MAX_ALTERNATIVES + 1]:
            yield site(other, xr)
        # none of them: the catalogue search without the requirement (reached only then)
        rows = tuple(k for k, g in enumerate(ns.nlp.g_names) if g.split("[", 1)[0] == name)
        free = NodeSolver(problem, objective, 1, ns.seed, solver, options, free_rows=rows)
        found = first_feasible(free)
        if found is not None and found.design:
            items = {v.name: nearest_item(found.design[v.name], v.values)[0] for v in dvars}
            yield site(items, free.x_of(found), found.raw.get("z"))

    found = relaxations(problem, point, solver=solver, objective=objective, sites_for=sites_for)
    return Diagnosis(found, basis, why)


def _item_combinations(problem: DesignProblem, dvars, x0: np.ndarray) -> list[dict[str, float]]:
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


def _point(
    objective: str,
    active: list[ConstraintReport],
    violated: list[ConstraintReport],
    z: Any = None,
) -> Result:
    """A result holding only what :func:`~optdesign.studies.relaxation.relaxations`
    reads: the rows of a best point (and its NLP vector)."""
    point = Result(
        status="infeasible", objective=math.nan, formulation="", objective_name=objective
    )
    point.active, point.violated = active, violated
    if z is not None:
        point.raw["z"] = z
    return point


def _adopt(result: Result, other: Result) -> None:
    """Give ``result`` the best point of ``other`` (a solve of the same problem)."""
    result.design = dict(other.design)
    result.objectives = dict(other.objectives)
    result.objective = other.objectives.get(result.objective_name, other.objective)
    result.violated, result.active = list(other.violated), list(other.active)
    result.verified = other.verified
    result.max_violation = other.max_violation


def _fixed(problem: DesignProblem, result: Result) -> Diagnosis:
    """Exact relaxations of a design with no free variable."""
    groups: dict[str, list[ConstraintReport]] = {}
    for r in result.violated:
        groups.setdefault(r.name.split("[", 1)[0], []).append(r)
    basis = "the fixed design"
    out = []
    for name, rows in groups.items():
        worst = max(rows, key=lambda r: r.amount)
        upper = worst.upper is not None and (
            worst.lower is None or worst.value - worst.upper > worst.lower - worst.value
        )
        written = worst.upper if upper else worst.lower
        needed: float | None = None  # with another requirement violated, not enough
        if len(groups) == 1:
            values = [r.value for r in rows]
            needed = max(values) if upper else min(values)
        out.append(Relaxation(name, upper, written, needed, worst.lower, worst.upper, 0))
    note = "" if len(groups) <= 1 else "several requirements are violated: relax them together"
    return Diagnosis(out, basis, note)


def violated_text(problem: DesignProblem, x: np.ndarray, limit: int = 8) -> str:
    """The requirements design ``x`` (free-variable vector) violates, by name and amount
    in the problem file's units, in one line ("" when it meets them all)."""
    _, violated = constraint_rows(problem, np.asarray(x, dtype=float))
    return "; ".join(lim.text() for lim in limits_of(problem, violated)[:limit])
