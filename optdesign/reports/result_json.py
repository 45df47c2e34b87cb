"""``result.json``: the result of a solve as a user's program reads it.

Every number is ``{"value": ..., "unit": ...}`` in the unit a user reads (the file's
angle unit, moments in N*m, ripple in %); internal rows are left out; the document
carries its schema version (:data:`SCHEMA`), described in ``docs/reports.md``.
:meth:`Result.to_dict` stays the complete internal record (internal units, every row),
which the stores of fronts and benchmarks keep.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from typing import Any

from optdesign.display.limits import (
    bound_limits,
    limits_of,
    objective_where,
    relaxation_limits,
)
from optdesign.display.shown import (
    Shown,
    json_value,
    objective_shown,
    requirement_values,
    variable_shown,
)
from optdesign.reports.facts import objective_facts, shown_facts
from optdesign.reports.solve_text import objective_value
from optdesign.solvers.result import Result, clean_json
from optdesign.views.facts import design_facts

#: Name and version of the document's layout; bumped when a key changes meaning.
SCHEMA = "optdesign.result/2"


def result_document(result: Result) -> dict[str, Any]:
    """The ``result.json`` document of ``result`` (see ``docs/reports.md``)."""
    problem = result.problem_object
    doc: dict[str, Any] = {
        "schema": SCHEMA,
        "problem": result.problem,
        "mechanism": result.mechanism,
        "status": result.status,
        "success": result.success,
        "solver": result.solver,
        "formulation": result.formulation,
        "termination": result.termination.value,
        "message": result.message,
        "verified": result.verified,
        "validity": validity_document(result),
        "wall_time": {"value": result.wall_time_s, "unit": "s"},
    }
    name = result.objective_name
    doc["objective"] = {
        "name": name,
        **objective_shown(problem, name, objective_value(result)).to_json(),
        "attained_at": objective_where(result.active),
    }
    if problem is None:
        doc["design"] = {k: {"value": v, "unit": ""} for k, v in result.design.items()}
        doc["objectives"] = {k: {"value": v, "unit": ""} for k, v in result.objectives.items()}
        return clean_json(doc)
    doc["requirements"] = {k: json_value(v) for k, v in requirement_values(problem).items()}
    doc["design"] = _design(problem, result)
    doc["achieved"] = {
        f.name: f.to_json() for f in shown_facts(problem, design_facts(problem, result.design))
    }
    doc["objectives"] = {f.name: f.to_json() for f in objective_facts(problem, result.objectives)}
    limits = limits_of(problem, result.active)
    if result.design:
        limits += bound_limits(problem, result.design)
    doc["limits"] = [lim.to_json() for lim in limits]
    doc["violated"] = [lim.to_json() for lim in limits_of(problem, result.violated)]
    diagnosis = result.diagnosis
    if diagnosis is not None:
        relax = _relaxations_json(problem, diagnosis.relaxations)
        if relax:
            doc["relaxations"] = relax
        doc["diagnosis"] = {
            "basis": diagnosis.basis,
            "note": diagnosis.note,
            "relaxations": relax,
            "together": _relaxations_json(problem, diagnosis.together),
            "physical": list(diagnosis.physical),
            "impossible": [proof.to_json() for proof in diagnosis.impossible],
        }
    doc["sensitivities"] = [
        {
            "name": sen.name,
            "objective": sen.objective,
            "limit": {"value": sen.limit, "unit": sen.unit},
            "d_objective_d_limit": {
                "value": sen.d_objective_d_limit,
                "unit": f"{sen.objective_unit}/{sen.unit}" if sen.unit else sen.objective_unit,
            },
            "log_sensitivity": sen.log_sensitivity,
        }
        for sen in result.sensitivities
    ]
    if result.item_steps:
        doc["item_steps"] = [
            {
                "variable": step.variable,
                "item": {"value": step.item, "unit": step.unit},
                "chosen": {"value": step.chosen, "unit": step.unit},
                "status": step.status,
                "objective": step.objective_name,
                "value": None
                if step.objective is None
                else {"value": step.objective, "unit": step.objective_unit},
                "change_percent": step.change_percent,
            }
            for step in result.item_steps
        ]
    if result.bound is not None:
        doc["bound"] = objective_shown(problem, name, result.bound).to_json()
    if result.certificate is not None:
        cert = result.certificate
        doc["certificate"] = {
            "kind": cert.kind,
            "lower_bound": objective_shown(problem, name, cert.lower_bound).to_json(),
            "gap": Shown(100.0 * cert.gap_rel, "%").to_json(),
        }
    if result.globality is not None:
        doc["globality"] = {**asdict(result.globality), "text": result.globality.text()}
    if result.multistart is not None:
        doc["multistart"] = asdict(result.multistart)
    doc["notes"] = list(result.notes)
    return clean_json(doc)


def validity_document(result: Result) -> dict[str, Any]:
    """Whether the design lies where its models hold: ``{"within": true | false | null,
    "outside": [...]}``, one entry per quantity outside its model's range of validity
    (model, quantity, worst value, range, angle) - such a design is never verified
    (``within`` null: nothing was checked, no design)."""
    from optdesign.models.validity_registry import declared_ranges
    from optdesign.problem.validity import is_validity

    records = declared_ranges().values()
    outside = []
    for r in result.violated:
        if not is_validity(r):
            continue
        base, _, where = r.name.removeprefix("validity: ").partition("[")
        model, _, quantity = base.partition(": ")
        record = next(
            (v for v in records if v.model == model and quantity.startswith(v.quantity)), None
        )
        outside.append(
            {
                "name": r.name.split("[", 1)[0],
                "model": model,
                "quantity": quantity,
                "value": {"value": r.value, "unit": r.unit},
                "lower": None if r.lower is None else {"value": r.lower, "unit": r.unit},
                "upper": None if r.upper is None else {"value": r.upper, "unit": r.unit},
                "at": where.rstrip("]"),
                "why": "" if record is None else record.why,
            }
        )
    within = None if result.verified is None else not outside
    return {"within": within, "outside": outside}


def _design(problem: Any, result: Result) -> dict[str, Any]:
    out = {}
    for var in problem.variables:
        if var.name not in result.design:
            continue
        v = variable_shown(problem, var, result.design[var.name])
        entry: dict[str, Any] = {**v.to_json(), "description": var.description}
        if var.free:
            entry["lower"] = variable_shown(problem, var, var.lower).value
            entry["upper"] = variable_shown(problem, var, var.upper).value
        else:
            entry["fixed"] = True
        if var.name in result.ranges:
            lo, hi = result.ranges[var.name]
            entry["optimal_range"] = [
                variable_shown(problem, var, lo).value,
                variable_shown(problem, var, hi).value,
            ]
        out[var.name] = entry
    return out


def result_json(result: Result) -> str:
    """``result.json`` as text."""
    return json.dumps(result_document(result), indent=2)


def _relaxations_json(problem: Any, items: list[Any]) -> list[dict[str, Any]]:
    """Relaxation records as the JSON document writes them."""
    return [
        {
            "name": lim.name,
            "description": lim.description,
            "side": lim.side,
            "limit": lim.limit.to_json(),
            "needed": lim.value.to_json(),
            "at": lim.where[0] if lim.where else "",
        }
        for lim in relaxation_limits(problem, items)
    ]
