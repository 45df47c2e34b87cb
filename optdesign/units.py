"""Units at the input boundary.

The package computes in one internal system: mm, N, MPa (N/mm^2), N*mm, rad.
Problem files and the CLI may give quantities with units ("90 mm", "500 N*m", "30 deg");
:func:`to_internal` parses them with pint and converts them to the internal unit of the
expected dimension. A bare number is taken as already in internal units.
"""

from __future__ import annotations

from functools import lru_cache

import pint

from optdesign.errors import InputError

#: Internal unit for each physical dimension name used in problem files.
INTERNAL_UNITS: dict[str, str] = {
    "length": "mm",
    "force": "N",
    "pressure": "MPa",
    "moment": "N*mm",
    "angle": "rad",
    "dimensionless": "dimensionless",
    "stiffness": "N/mm",
    "speed": "1/min",
    "time": "h",
}


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:
    """The shared pint registry (degrees and radians are dimensionless angles in pint)."""
    ureg = pint.UnitRegistry(autoconvert_offset_to_baseunit=True)
    return ureg


def to_internal(value: object, dimension: str, field: str) -> float:
    """Convert ``value`` to the internal unit of ``dimension``.

    Parameters
    ----------
    value
        A number (taken as internal units) or a string with a unit, e.g. ``"500 N*m"``.
    dimension
        Key of :data:`INTERNAL_UNITS`, e.g. ``"moment"``.
    field
        Name used in error messages.

    Returns
    -------
    float
        The magnitude in the internal unit.

    Raises
    ------
    InputError
        If the string cannot be parsed or has the wrong dimension.
    """
    if isinstance(value, bool):
        raise InputError(field, f"expected a {dimension} quantity, got a boolean")
    if isinstance(value, int | float):
        return float(value)
    if not isinstance(value, str):
        raise InputError(field, f"expected a number or a quantity string, got {value!r}")
    unit = INTERNAL_UNITS[dimension]
    ureg = registry()
    try:
        q = ureg.Quantity(value.strip())
    except Exception as exc:  # pint raises several unrelated types for bad strings
        raise InputError(field, f"cannot parse quantity {value!r} ({exc})") from None
    if not isinstance(q, pint.Quantity):  # plain number in a string
        return float(q)
    if q.dimensionless and dimension not in ("angle", "dimensionless"):
        # A unitless string like "90" is taken as internal units.
        if str(q.units) == "dimensionless":
            return float(q.magnitude)
    try:
        return float(q.to(unit).magnitude)
    except pint.DimensionalityError:
        raise InputError(
            field,
            f"{value!r} has dimension {q.dimensionality}, expected a {dimension} "
            f"(internal unit {unit})",
        ) from None


def convert(value: object, unit: str, field: str) -> float:
    """Convert a quantity string (or number, taken as already in ``unit``) to ``unit``.

    For bounds of user-declared constraints: ``convert("3 kN", "N", "nut_force.upper")``.
    """
    if isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    ureg = registry()
    try:
        target = ureg.Unit(unit or "dimensionless")
    except Exception as exc:
        raise InputError(field, f"unknown unit {unit!r} ({exc})") from None
    try:
        q = ureg.Quantity(str(value).strip())
        return float(q.to(target).magnitude) if isinstance(q, pint.Quantity) else float(q)
    except pint.DimensionalityError:
        raise InputError(field, f"{value!r} cannot be expressed in {unit!r}") from None
    except Exception as exc:
        raise InputError(field, f"cannot parse quantity {value!r} ({exc})") from None
