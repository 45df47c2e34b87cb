"""What a catalogue optimum depends on: the sensitivities of its continuous part at the
chosen items, and the step of each catalogue variable to its neighbouring items.

The catalogue optimum is the NLP solved with every catalogue variable fixed at its item
(:mod:`optdesign.formulations.catalogue.search`); its multipliers give d(objective)/d(limit) exactly as
for an NLP optimum (:func:`optdesign.formulations.nlp.sensitivities.nlp_sensitivities`), with the
items held (a catalogue variable's fixed value is not a bound the file states). A
catalogue variable has no derivative: its answer is the step to the next item up and
down, the other items kept and the continuous part re-solved from the optimum (one warm
start, more starts only if it fails, as every node of the search), or "infeasible".
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from optdesign.formulations.catalogue.bnb import InfeasibleBoxes
from optdesign.formulations.catalogue.discrete import discrete_variables
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.request import SolveRequest
from optdesign.solvers.result import ItemStep, Result, Sensitivity


def neighbour_items(values: tuple[float, ...] | list[float], item: float) -> list[float]:
    """The items next to ``item`` in a catalogue's sorted ``values`` (below, then above)."""
    ordered = sorted(values)
    k = min(range(len(ordered)), key=lambda i: abs(ordered[i] - item))
    return [ordered[i] for i in (k - 1, k + 1) if 0 <= i < len(ordered)]


def catalogue_sensitivities(
    problem: DesignProblem,
    result: Result,
    solver: str | None = None,
    options: Mapping[str, Any] | None = None,
) -> tuple[list[Sensitivity], list[ItemStep]]:
    """The sensitivities of a catalogue optimum's continuous part (from the multipliers
    of the NLP with the items fixed) and the steps to the neighbouring items.

    Parameters
    ----------
    problem, result
        A problem with catalogue variables and its catalogue optimum (``result.raw``
        holding the final NLP's multipliers).
    solver, options
        The NLP back-end and options the optimum was solved with (the re-solves of the
        neighbouring items use the same, warm-started from the optimum).
    """
    from optdesign.display.shown import objective_shown, variable_shown
    from optdesign.formulations.catalogue.search import NodeSolver, _fixed
    from optdesign.formulations.nlp.sensitivities import nlp_sensitivities
    from optdesign.formulations.nlp.solve import finish

    if not result.success or not result.design:
        return [], []
    objective = result.objective_name or problem.objective_names[0]
    sensitivities = nlp_sensitivities(problem, result)
    dvars = discrete_variables(problem)
    items = {v.name: float(result.design[v.name]) for v in dvars}
    ns = NodeSolver(problem, objective, 1, problem.spec.solver.seed, solver, options)
    searched = result.details.catalogue
    if searched is not None and searched.infeasible_boxes:
        # an item inside a box the search proved infeasible is infeasible, with no NLP
        full = {v.name: (v.lower, v.upper) for v in dvars}
        ns.memo = InfeasibleBoxes.from_proofs(full, searched.infeasible_boxes)
    x0 = np.array([result.design[v.name] for v in problem.free])
    v0 = float(result.objective)
    shown0 = objective_shown(problem, objective, v0)
    steps: list[ItemStep] = []
    for var in dvars:
        for item in neighbour_items(var.values, items[var.name]):
            r = ns.solve(_fixed({**items, var.name: item}), x0)
            if r.design:
                r = finish(problem, r, objective)
            ok = r.success and r.verified is not False
            value = objective_shown(problem, objective, r.objective) if ok else None
            steps.append(
                ItemStep(
                    variable=var.name,
                    item=variable_shown(problem, var, item).value,
                    chosen=variable_shown(problem, var, items[var.name]).value,
                    unit=variable_shown(problem, var, item).unit,
                    status=r.status if not r.success else ("optimal" if ok else "infeasible"),
                    objective_name=objective,
                    objective=None if value is None else float(value.value),
                    objective_unit=shown0.unit,
                    change_percent=(100 * (r.objective - v0) / abs(v0) if ok and v0 != 0 else None),
                )
            )
    return sensitivities, steps


def fixed_item_difference(
    problem: DesignProblem, result: Result, name: str, rel: float = 1e-3
) -> tuple[float, float]:
    """d(optimal objective)/d(limit) of a catalogue optimum by re-solves with its items
    fixed: the limit ``name`` moved by ``rel`` to both sides, each side's continuous
    part re-solved from the optimum; (derivative in internal units, the limit's internal
    value). The check of :func:`catalogue_sensitivities` (tests)."""
    from optdesign.formulations.catalogue.search import NodeSolver, _fixed
    from optdesign.problem.parameters import limit_value, perturbed

    items = {v.name: float(result.design[v.name]) for v in discrete_variables(problem)}
    p = limit_value(problem, name)
    h = rel * max(abs(p), 1e-9)
    x0 = np.array([result.design[v.name] for v in problem.free])
    values = []
    for q in (p + h, p - h):
        ns = NodeSolver(perturbed(problem, name, q), result.objective_name or None, 1)
        r = ns.solve(_fixed(items), x0)
        if not r.success:
            raise RuntimeError(f"{name} = {q:g}: the re-solve ended {r.status}")
        values.append(r.objective)
    return (values[0] - values[1]) / (2 * h), p


def catalogue_evidence(problem: DesignProblem, result: Result, request: SolveRequest) -> None:
    """What a catalogue optimum's neighbourhood says, when ``request`` asks for the
    sensitivities: the costs of the continuous part at the chosen items and the
    neighbouring items (a failure is a note, never the loss of the optimum)."""
    from optdesign.formulations.nlp.solution import has_multipliers
    from optdesign.solvers.registry import solver_hints

    solver, options = request.solver, request.options
    catalogue = result.formulation.startswith("catalogue")
    if not (request.sensitivities and result.success and catalogue):
        return
    if not has_multipliers(result, solver):
        return
    try:
        # a MINLP back-end only picked the items: the default NLP back-end solved them
        # (optdesign.formulations.catalogue.minlp), and re-solves their neighbours
        minlp = solver_hints(solver).minlp is not None
        result.sensitivities, result.item_steps = catalogue_sensitivities(
            problem, result, None if minlp else solver, None if minlp else options
        )
    except Exception as exc:  # a report, not the result: never lose the optimum
        result.notes.append(f"sensitivities not computed: {exc}")
