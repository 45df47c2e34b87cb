"""The checks of what a user adds to a problem (:meth:`DesignProblem.add_objective`,
:meth:`DesignProblem.add_constraint`), with the argument checks of
:mod:`optdesign.argument_checks`: refusals name ``add_objective.<argument>``.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator
from typing import Any

from optdesign.argument_checks import (
    ArgumentError,
    choice,
    flag,
    function,
    name,
    number,
    text,
    unit,
)
from optdesign.errors import InputError


def objective_declaration(
    problem: Any,
    name_: Any,
    fn: Any,
    unit_: Any,
    kind: Any,
    description: Any,
    formula: Any,
    display_unit: Any,
    display_scale: Any,
    replace: Any,
) -> None:
    """The arguments of :meth:`DesignProblem.add_objective`: a new name (an existing
    objective, a built-in one included, is replaced only with ``replace=True``), a
    function, units, a kind."""
    where = "add_objective."
    name(where + "name", name_)
    with _naming("objective", name_):
        _objective_arguments(
            problem,
            name_,
            fn,
            unit_,
            kind,
            description,
            formula,
            display_unit,
            display_scale,
            replace,
        )


def _objective_arguments(
    problem, name_, fn, unit_, kind, description, formula, display_unit, display_scale, replace
) -> None:
    from optdesign.problem.objectives import BUILTIN_OBJECTIVES, KINDS

    where = "add_objective."
    function(where + "fn", fn)
    unit(where + "unit", unit_)
    choice(where + "kind", kind, KINDS, "kind", optional=True)
    text(where + "description", description)
    text(where + "formula", formula)
    if display_unit is not None:
        unit(where + "display_unit", display_unit)
    # None: a default factor (the units' own, where the caller derives one)
    scale = number(where + "display_scale", display_scale, -math.inf, math.inf, optional=True)
    if scale == 0.0:
        raise ArgumentError(where + "display_scale", "0 would show every value as 0")
    if not flag(where + "replace", replace) and name_ in problem.objectives:
        what = "a built-in objective" if name_ in BUILTIN_OBJECTIVES else "an objective"
        raise ArgumentError(
            where + "name",
            f"{name_!r} is {what} of the problem already; pass replace=True to replace it on "
            "purpose, or choose another name",
        )


def constraint_declaration(
    problem: Any,
    name_: Any,
    fn: Any,
    lower: Any,
    upper: Any,
    unit_: Any,
    over: Any,
    description: Any,
) -> tuple[float | None, float | None]:
    """The arguments of :meth:`DesignProblem.add_constraint`: a new name, a function,
    bounds (numbers in ``unit`` or quantity strings), ``over``; returns the bounds in
    ``unit``."""
    where = "add_constraint."
    name(where + "name", name_)
    with _naming("constraint", name_):
        return _constraint_arguments(problem, name_, fn, lower, upper, unit_, over, description)


def _constraint_arguments(problem, name_, fn, lower, upper, unit_, over, description):
    from optdesign.units import convert

    where = "add_constraint."
    taken = {c.name for c in problem.user_constraints} | _row_names(problem)
    if name_ in taken:
        raise ArgumentError(
            where + "name",
            f"{name_!r} names a constraint of the problem already (a requirement or one "
            "added before): choose another name",
        )
    function(where + "fn", fn)
    unit(where + "unit", unit_)
    choice(where + "over", over, ("stroke", "design"), "over")
    text(where + "description", description)
    lo, hi = (
        None if v is None else _as_argument(convert, v, unit_, where + side)
        for side, v in (("lower", lower), ("upper", upper))
    )
    if lo is None and hi is None:
        raise ArgumentError(where + "upper", "give a lower or an upper bound (or both)")
    if lo is not None and hi is not None and lo > hi:
        raise ArgumentError(where + "lower", f"{lo:g} is above the upper bound {hi:g}")
    return lo, hi


def _as_argument(convert: Callable[..., Any], *args: Any) -> Any:
    """``convert(*args)``; its InputError as an :class:`ArgumentError`."""
    try:
        return convert(*args)
    except ArgumentError:
        raise
    except InputError as exc:
        raise ArgumentError(exc.field, exc.reason) from None


@contextlib.contextmanager
def _naming(what: str, name_: str) -> Iterator[None]:
    """A refusal of one of the declaration's other arguments also names the objective or
    constraint being declared (a script may declare many)."""
    try:
        yield
    except ArgumentError as exc:
        if exc.argument.endswith(".name"):  # the refusal names it already
            raise
        raise ArgumentError(
            exc.argument, f"{exc.template} ({what} {name_!r})", exc.mentions
        ) from None


def _row_names(problem: Any) -> set[str]:
    """Names of the problem's constraint blocks (its requirements' rows, the objective
    limits): a user's constraint of the same name would be confused with one in reports,
    stores and the relaxations."""
    expressions = problem.expressions(problem.design_dict(problem.midpoint()))
    return {b.name for b in expressions.constraints} | {
        f"{name}_max" for name in problem.objective_limits()
    }
