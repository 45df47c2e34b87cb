"""A problem's numeric parameters - its requirements' limits and its variables' bounds -
by path (``"requirements.hinge_moment"``, ``"variables.R.upper"``): their values, how the
user reads them, and copies of the problem with some of them moved.

What a sensitivity moves (:mod:`optdesign.formulations.nlp.sensitivities`), what a sweep varies
(:mod:`optdesign.studies.sweep`) and what their pages show of a limit
(:mod:`optdesign.reports.sweep_html`) are these paths; the rules live here, below the
studies, so that a page reads a point's problem and a limit's value without importing a
study.
"""

from __future__ import annotations

import dataclasses
import math
from collections import OrderedDict
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

from optdesign.errors import InputError
from optdesign.problem.design_problem import SETTING_SECTIONS, DesignProblem


def requirement_paths(problem: DesignProblem) -> Iterator[tuple[str, float]]:
    """Every numeric requirement of ``problem`` (path below ``requirements``, internal
    value): plain numbers and quantities, inside bands (``mean_ratio.min``) and tables
    (``lock.force_max``); counts, switches, texts and lists are not limits."""

    def walk(model: Any, prefix: str) -> Iterator[tuple[str, float]]:
        for name in type(model).model_fields:
            value = getattr(model, name)
            path = f"{prefix}{name}"
            if hasattr(type(value), "model_fields"):
                yield from walk(value, path + ".")
            elif isinstance(value, float) and math.isfinite(value):
                yield path, value

    yield from walk(problem.spec.requirements, "")


#: The copies of problems with one requirement moved, by (problem state, path, value): the
#: points of a front share their problem and its limits, so each copy is validated once per
#: front, not once per point.
_MOVED: OrderedDict[tuple[str, str, float], DesignProblem] = OrderedDict()
#: The most copies remembered (and the size of the studies' caches keyed the same way).
MOVED_SIZE = 64


def moved_copy(problem: DesignProblem, path: str, value: float) -> DesignProblem:
    """:meth:`DesignProblem.with_requirement`, remembered per problem state, so the
    caller must not change the copy it gets."""
    key = (problem.token, path, float(value))
    if key in _MOVED:
        _MOVED.move_to_end(key)
        return _MOVED[key]
    new = problem.with_requirement(path, value)
    _MOVED[key] = new
    while len(_MOVED) > MOVED_SIZE:
        _MOVED.popitem(last=False)
    return new


def limit_shown(problem: DesignProblem, path: str, p: float) -> Any:
    """The limit ``path`` of a :class:`~optdesign.solvers.result.Sensitivity` of ``problem`` (``"requirements.
    hinge_moment"``, ``"variables.R.upper"``) as the user reads it (a :class:`~optdesign.
    display.shown.Shown`); ``p``: its internal value (a requirement is shown as
    the problem holds it, in its written unit; ``p`` bare when that is unknown)."""
    from optdesign.display.shown import Shown, requirement_values, variable_shown

    if path.startswith("variables."):
        return variable_shown(problem, problem.by_name[path.split(".")[1]], p)
    node: Any = requirement_values(problem)
    for key in path.split(".")[1:]:
        node = node.get(key) if isinstance(node, dict) else None
    return node if isinstance(node, Shown) else Shown(p, "")


def with_bound(problem: DesignProblem, name: str, side: str, value: float) -> DesignProblem:
    """A copy of ``problem`` whose free variable ``name`` has its ``side`` ("lower" or
    "upper") bound at ``value`` (internal units)."""

    return _with_variable(problem, dataclasses.replace(problem.by_name[name], **{side: value}))


def _with_variable(problem: DesignProblem, variable: Any) -> DesignProblem:
    """A copy of ``problem`` whose variable of ``variable``'s name is ``variable``."""
    new = object.__new__(type(problem))
    new.__dict__.update(problem.__dict__)
    new.variables = [variable if v.name == variable.name else v for v in problem.variables]
    new.by_name = {v.name: v for v in new.variables}
    new._touch()
    return new


def at_values(problem: DesignProblem, values: Mapping[str, float]) -> DesignProblem:
    """A copy of ``problem`` with each parameter path at its value (internal units)."""
    for path, value in values.items():
        head, _, rest = path.partition(".")
        if head == "requirements":
            problem = moved_copy(problem, rest, value)
        elif head in SETTING_SECTIONS:
            problem = problem.with_setting(path, value)
        else:
            name, _, side = rest.partition(".")
            problem = with_bound(problem, name, side or "value", value)
            var = problem.by_name[name]
            if var.free and not var.lower < var.upper:
                raise InputError(
                    f"vary.{path}",
                    f"{name}'s lower bound {var.lower:g} is not below its upper "
                    f"bound {var.upper:g} {var.unit}",
                )
    return problem


def linked_values(values: Mapping[str, float], linked: Mapping[str, str]) -> dict[str, float]:
    """``values`` (path -> internal value) and each path of ``linked`` (path -> the path
    of ``values`` it follows) at the value of the path it follows: the parameters of a
    sweep's point whose swept parameter moves others with it."""
    return {**values, **{path: values[follows] for path, follows in linked.items()}}


def perturbed(problem: DesignProblem, name: str, value: float) -> DesignProblem:
    """``problem`` with the limit ``name`` of a :class:`~optdesign.solvers.result.Sensitivity` at ``value``
    (internal units)."""
    head, _, rest = name.partition(".")
    if head == "variables":
        var, _, side = rest.partition(".")
        return with_bound(problem, var, side, value)
    return moved_copy(problem, rest, value)


def limit_value(problem: DesignProblem, name: str) -> float:
    """The internal value of the limit ``name`` of a :class:`~optdesign.solvers.result.Sensitivity`."""
    head, _, rest = name.partition(".")
    if head == "variables":
        var, _, side = rest.partition(".")
        return float(getattr(problem.by_name[var], side))
    return dict(requirement_paths(problem))[rest]


#: The copies of problems without their impossible catalogue items, by problem state and
#: the requirements a search drops: a front's points share one, so their searches share
#: their proofs too.
_NARROWED: OrderedDict[tuple[str, frozenset[str]], tuple[DesignProblem, list[str]]] = OrderedDict()


def without_impossible_items(
    problem: DesignProblem, dropped: Iterable[str] = ()
) -> tuple[DesignProblem, list[str]]:
    """``problem`` without the catalogue items no design can use (proved from the bounds
    and closed forms before any NLP: the motors that cannot give the motion's torque,
    :func:`~optdesign.problem.motor_catalogue_variable.impossible_motors`), and why each
    went. The same problem and ``[]`` when none goes; a variable left with no item keeps
    none (``values == ()``): the caller reports the problem infeasible with the reasons.
    ``dropped``: requirements (row names) the caller's search leaves unbounded (a
    diagnosis's search without one); a proof that rests on one of them excludes nothing.
    """
    from optdesign.problem.motor_catalogue_variable import EXCLUSION_ROWS, impossible_motors

    dropped = frozenset(dropped)
    if EXCLUSION_ROWS & dropped:
        return problem, []
    key = (problem.token, dropped)
    if key in _NARROWED:
        _NARROWED.move_to_end(key)
        return _NARROWED[key]
    gone = impossible_motors(problem, dropped)
    if not gone:
        out: tuple[DesignProblem, list[str]] = (problem, [])
    else:
        var = problem.by_name["motor"]
        kept = tuple(v for v in var.values if v not in gone)
        narrowed = (
            dataclasses.replace(var, values=kept, lower=kept[0], upper=kept[-1])
            if kept
            else dataclasses.replace(var, values=())
        )
        reasons = [f"motor {k:g} ({reason})" for k, reason in sorted(gone.items())]
        out = (_with_variable(problem, narrowed), reasons)
    _NARROWED[key] = out
    while len(_NARROWED) > MOVED_SIZE:
        _NARROWED.popitem(last=False)
    return out
