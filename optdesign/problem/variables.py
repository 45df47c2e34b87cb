"""Design variables: the table a problem may declare, and one declared variable.

The table of a problem is the mechanism's own variables, the drive's (screw lead ``p``,
gear ratio ``i_a``) and the framework's pin variables (``d``, ``pin_length`` or
``pin_length_ratio``). Each entry of a problem file's ``[variables]`` is fixed (a value),
free (bounds, optionally a start) or a catalogue (``values = [...]`` or
``catalogue = "ISO 2338"``); :func:`parse_variable` validates one with errors that name
the field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from optdesign.errors import InputError, ProblemError
from optdesign.mechanisms.base import VariableInfo
from optdesign.models.loads import PIN_DIAMETER, PIN_LENGTH, PIN_SLENDERNESS
from optdesign.units import Bare, to_internal

#: Variables of the sized pin joints and of the screw's size, the same for every mechanism;
#: the pin's carry the pin model's ranges of validity (:mod:`optdesign.models.loads`).
PIN_VARIABLES: dict[str, VariableInfo] = {
    "d": VariableInfo("length", "pin diameter", valid=PIN_DIAMETER),
    "pin_length": VariableInfo("length", "pin length L", valid=PIN_LENGTH),
    "pin_length_ratio": VariableInfo(
        "dimensionless", "pin length ratio L/d", valid=PIN_SLENDERNESS
    ),
    "d0": VariableInfo("length", "screw nominal (mean) diameter"),
    "motor": VariableInfo(
        "dimensionless", "motor: its number in the catalogue, smallest rated torque first"
    ),
}

#: Internal unit of each variable dimension (for tables).
UNITS = {"length": "mm", "angle": "rad", "dimensionless": ""}

#: Most values a discrete variable may list (branch and bound grows with them).
MAX_CATALOGUE = 1000

#: Catalogues a discrete variable may name (ISO 3408 preferred leads, ISO 2338 pins).
CATALOGUES: dict[str, tuple[float, ...]] = {
    "ISO 3408": (1, 2, 2.5, 3, 4, 5, 6, 8, 10, 12, 16, 20, 25, 32, 40),
    "ISO 2338": (3, 4, 5, 6, 8, 10, 12, 16, 20, 25),
}


def variable_table(mechanism_cls: type) -> dict[str, VariableInfo]:
    """Every variable a problem of ``mechanism_cls`` may declare, in table order."""
    table = dict(mechanism_cls.variable_table())
    for k, v in PIN_VARIABLES.items():
        table.setdefault(k, v)
    return table


@dataclass(frozen=True)
class Variable:
    """A declared design variable, in internal units.

    Attributes
    ----------
    name, description, unit
        Identification (``unit`` is the internal unit, for tables).
    dimension
        ``"length"``, ``"angle"`` or ``"dimensionless"``.
    lower, upper
        Bounds of a free variable (None for a fixed one).
    value
        Value of a fixed variable.
    values
        Catalogue values of a discrete variable (None when continuous).
    start
        A declared start of a free variable (one multistart start among the others).
    """

    name: str
    description: str
    unit: str
    lower: float | None = None
    upper: float | None = None
    value: float | None = None
    values: tuple[float, ...] | None = None
    start: float | None = None
    dimension: str = "dimensionless"

    @property
    def free(self) -> bool:
        return self.value is None

    @property
    def discrete(self) -> bool:
        return self.values is not None


def catalogue_items(catalogue: str, variable: str, field: str, screw=None) -> list[float]:
    """The values catalogue ``catalogue`` gives ``variable``."""
    if catalogue in CATALOGUES:
        return list(CATALOGUES[catalogue])
    if catalogue == "HIWIN":
        from optdesign.problem.drive import catalogue_values

        if screw is None or screw.catalogue != "HIWIN":
            raise ProblemError(
                f'{field}: a catalogue screw needs [screw] catalogue = "HIWIN" (its d0 and p '
                "are pairs of one catalogue item)"
            )
        return list(catalogue_values(catalogue, variable, screw.nut))
    from optdesign.problem.motor_catalogue_variable import MOTOR_CATALOGUES, motor_numbers

    if catalogue in MOTOR_CATALOGUES:
        if variable != "motor":
            raise ProblemError(f"{field}: a motor catalogue gives the variable motor only")
        return motor_numbers(catalogue)
    known = ", ".join([*CATALOGUES, "HIWIN", *MOTOR_CATALOGUES])
    raise ProblemError(f"{field}: unknown catalogue {catalogue!r} (known: {known})")


def parse_variable(
    name: str,
    raw: Any,
    info: VariableInfo,
    mechanism: str,
    screw=None,
    bare: Bare = "internal",
) -> Variable:
    """Validate the ``[variables]`` entry ``name`` of a problem of ``mechanism``.

    ``bare``: a number without a unit is taken in internal units (``"internal"``, dicts
    from Python) or refused with the unit to write (``"refuse"``, problem files).
    """
    field = f"variables.{name}"
    unit = UNITS[info.dimension]
    make = dict(name=name, description=info.description, unit=unit, dimension=info.dimension)

    def q(value: Any, sub: str) -> float:
        where = f"{field}.{sub}" if sub else field
        try:
            v = to_internal(value, info.dimension, where, bare=bare)
        except InputError as exc:
            raise ProblemError(str(exc)) from None
        if not math.isfinite(v):
            raise ProblemError(f"{where}: must be finite, got {value!r}")
        return v

    def positive(value: float, where: str) -> None:
        if info.positive and not value > 0:
            raise ProblemError(f"{where}: must be positive, got {value:g} {unit}".rstrip())
        valid = getattr(info, "valid", None)
        if valid is not None and not valid.contains(value):
            raise ProblemError(f"{where}: {valid.refusal(value)}")

    if not isinstance(raw, dict):
        value = q(raw, "")
        positive(value, field)
        return Variable(**make, value=value)
    allowed = {"value", "lower", "upper", "start", "values", "catalogue"}
    extra = set(raw) - allowed
    if extra:
        raise ProblemError(
            f"{field}.{sorted(extra)[0]}: unknown field (allowed: {', '.join(sorted(allowed))})"
        )
    if "value" in raw:
        if set(raw) - {"value"}:
            raise ProblemError(f"{field}: a fixed value excludes bounds and catalogues")
        value = q(raw["value"], "value")
        positive(value, field)
        return Variable(**make, value=value)
    if "values" in raw and "catalogue" in raw:
        raise ProblemError(
            f"{field}: values and catalogue both given: a variable takes its items from one "
            "(values = [...] lists them; catalogue = NAME takes a named catalogue's)"
        )
    lower = q(raw["lower"], "lower") if "lower" in raw else None
    upper = q(raw["upper"], "upper") if "upper" in raw else None
    if lower is not None:  # also when a catalogue narrows the bounds to its items below
        positive(lower, f"{field}.lower")
    values = None
    if "values" in raw or "catalogue" in raw:
        if "values" in raw:
            if not isinstance(raw["values"], list) or not raw["values"]:
                raise ProblemError(f"{field}.values: must be a non-empty list")
            if len(raw["values"]) > MAX_CATALOGUE:
                raise ProblemError(
                    f"{field}.values: {len(raw['values'])} values, at most {MAX_CATALOGUE}"
                )
            values = [q(v, f"values[{k}]") for k, v in enumerate(raw["values"])]
        else:
            if not isinstance(raw["catalogue"], str):
                raise ProblemError(f"{field}.catalogue: give a catalogue's name (a string)")
            values = catalogue_items(raw["catalogue"], name, f"{field}.catalogue", screw)
        if lower is not None:
            values = [v for v in values if v >= lower - 1e-12]
        if upper is not None:
            values = [v for v in values if v <= upper + 1e-12]
        if not values:
            raise ProblemError(f"{field}: no catalogue value lies within the bounds")
        values = sorted(set(values))
        lower, upper = values[0], values[-1]
    if lower is None or upper is None:
        missing = "lower" if lower is None else "upper"
        raise ProblemError(f"{field}.{missing}: a free variable needs both bounds")
    if lower > upper:
        raise ProblemError(
            f"{field}: lower bound {lower:g} {unit} is above upper bound {upper:g} {unit}"
        )
    positive(lower, f"{field}.lower")
    positive(upper, f"{field}.upper")  # its range (positive: it is above the lower bound)
    start = q(raw["start"], "start") if "start" in raw else None
    if start is not None and not lower <= start <= upper:
        raise ProblemError(f"{field}.start: {start:g} lies outside [{lower:g}, {upper:g}]")
    if lower == upper:
        return Variable(**make, value=lower)
    return Variable(
        **make,
        lower=lower,
        upper=upper,
        values=tuple(values) if values else None,
        start=start,
    )
