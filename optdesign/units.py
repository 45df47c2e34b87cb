"""Units at the input boundary.

The package computes in one internal system: mm, N, MPa (N/mm^2), N*mm, rad.
Problem files and the CLI may give quantities with units ("90 mm", "500 N*m", "30 deg");
:func:`to_internal` converts them to the internal unit of the expected dimension.

A quantity string is read by the restricted grammar of :mod:`optdesign.unit_grammar` (a
number and a unit expression, no arithmetic: every string is accepted or refused in
microseconds); unit names go to pint one at a time.

A bare number is taken as already in internal units (``bare="internal"``, the default),
or refused for a dimensioned field (``bare="refuse"``), with the unit to write.
pint is imported, and its registry built, on first use: importing this module is cheap.

Angles are a dimension of their own. pint, like SI, counts the radian as dimensionless,
so to pint ``"500 N*m/deg"`` is a moment (57.3 x 500 N*m) and ``"1 Hz"`` an angular
speed. The grammar therefore counts the *angle exponent* of every unit expression next
to pint's dimensionality (rad, deg, arcmin, arcsec, turn, rev, grad and their prefixed
forms count 1; rpm 1; sr 2; Hz and percent 0). A quantity fits a dimension when both
pint's dimensionality and the angle exponent match (:data:`ANGLE_EXPONENTS`): a moment
has no angle, a rotational stiffness is a moment per angle (exponent -1), an angular
speed an angle per time (+1); ``"30 mm*rad"``, ``"600 kN*m"`` for a stiffness and
``"1 Hz"`` for a rate are refused. Percent is a plain number (``"90 %"`` is 0.9), never
an angle.
"""

from __future__ import annotations

import math
import numbers
import re
from functools import cache
from typing import Any, Literal

from optdesign.errors import InputError
from optdesign.unit_grammar import (
    ALIASES,
    MAX_DEPTH,
    MAX_LENGTH,
    MAX_POWER,
    Parsed,
    Refused,
    angle_exponent,
    describe,
    parse,
    parse_unit_expression,
    registry,
)

__all__ = [
    "ALIASES",
    "ANGLE_EXPONENTS",
    "FAST_UNITS",
    "INTERNAL_UNITS",
    "MAX_DEPTH",
    "MAX_LENGTH",
    "MAX_MAGNITUDE",
    "MAX_POWER",
    "SUGGESTED_UNITS",
    "Parsed",
    "angle_exponent",
    "convert",
    "describe",
    "parse",
    "parse_quantity",
    "parse_unit",
    "registry",
    "to_internal",
    "unit_factor",
]

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
    "angular_speed": "rad/s",
    "rotational_stiffness": "N*mm/rad",
    # the drive's dynamics: with mm and N, a mass is in tonnes (N*s^2/mm) and
    # an inertia in t*mm^2 (N*mm*s^2), so that inertia x angular acceleration is N*mm
    "inertia": "t*mm**2",
    "mass": "t",
    "rotational_damping": "N*mm*s/rad",
    "frequency": "Hz",
    "angular_acceleration": "rad/s**2",
    # the position loop's integral gain: motor torque per fin angle per second
    "integral_gain": "N*mm/rad/s",
    # the cascade's position gain: the speed asked per angle of error, (rad/s)/rad
    "rate": "1/s",
}

#: The unit suggested to a user for each dimension (error messages, ``bare="refuse"``).
SUGGESTED_UNITS: dict[str, str] = {
    "length": "mm",
    "force": "N",
    "pressure": "MPa",
    "moment": "N*m",
    "angle": "deg",
    "dimensionless": "",
    "stiffness": "N/mm",
    "speed": "1/min",
    "time": "h",
    "angular_speed": "deg/s",
    "rotational_stiffness": "N*m/rad",
    "inertia": "kg*m^2",
    "mass": "kg",
    "rotational_damping": "N*m*s/rad",
    "frequency": "Hz",
    "angular_acceleration": "deg/s^2",
    "integral_gain": "N*m/(rad*s)",
    "rate": "1/s",
}

#: How a dimension is named in messages ("expected a moment").
_DIMENSION_NAMES: dict[str, str] = {
    "length": "a length",
    "force": "a force",
    "pressure": "a pressure",
    "moment": "a moment",
    "angle": "an angle",
    "dimensionless": "a plain number (no unit, or %)",
    "stiffness": "a linear stiffness, a force per length",
    "speed": "a rotational speed (turns per time)",
    "time": "a time",
    "angular_speed": "an angular speed, an angle per time",
    "rotational_stiffness": "a rotational stiffness, a moment per angle",
    "inertia": "a moment of inertia, a mass times a length squared",
    "mass": "a mass",
    "rotational_damping": "a rotational damping, a moment per angular speed",
    "frequency": "a frequency (cycles per time, or an angle per time)",
    "angular_acceleration": "an angular acceleration, an angle per time squared",
    "integral_gain": "an integral gain, a moment per angle per time",
    "rate": "a rate, per time (a speed per angle: (rad/s)/rad)",
}

#: The angle exponents a quantity of each dimension may have (see the module docstring).
#: ``speed`` is ISO's n in min^-1: turns per minute, with the turn written ("rpm",
#: "rad/s") or implied ("1/min", "Hz").
ANGLE_EXPONENTS: dict[str, tuple[int, ...]] = {
    "length": (0,),
    "force": (0,),
    "pressure": (0,),
    "moment": (0,),
    "angle": (1,),
    "dimensionless": (0,),
    "stiffness": (0,),
    "speed": (0, 1),
    "time": (0,),
    "angular_speed": (1,),
    "rotational_stiffness": (-1,),
    "inertia": (0,),
    "mass": (0,),
    "rotational_damping": (-1,),
    # cycles per time (Hz) or an angle per time (rad/s: one cycle is 2 pi rad)
    "frequency": (0, 1),
    "angular_acceleration": (1,),
    "integral_gain": (-1,),
    "rate": (0,),
}

#: Largest magnitude accepted in internal units: 1e15 mm is a billion kilometres; beyond
#: it a bound only breaks the solver's scaling (1e308 overflows to inf in the first sum).
MAX_MAGNITUDE = 1e15
#: Smallest nonzero magnitude accepted in internal units: 1e-12 mm is a hundredth of an
#: atom; below it the models' products and quotients (a buckling load over a squared
#: length, a compliance over a stiffness) overflow to inf and NaN.
MIN_MAGNITUDE = 1e-12

Bare = Literal["internal", "refuse"]


def parse_quantity(text: str) -> tuple[float, Any]:
    """``(number, unit)`` of a quantity string; ``unit`` is None when there is none.

    Raises
    ------
    InputError
        (field ``"quantity"``) when ``text`` is not a number optionally followed by a
        unit expression of the restricted grammar (:mod:`optdesign.unit_grammar`).
    """
    try:
        parsed = parse(text)
    except Refused as exc:
        raise InputError("quantity", str(exc)) from None
    return parsed.number, parsed.unit


def _number_text(value: float) -> str:
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)


def _suggest(number: str, dimension: str) -> str:
    unit = SUGGESTED_UNITS.get(dimension, "")
    return f'"{number} {unit}"' if unit else f'"{number}"'


def to_internal(value: object, dimension: str, field: str, bare: Bare = "internal") -> float:
    """Convert ``value`` to the internal unit of ``dimension``.

    Parameters
    ----------
    value
        A number, a string with a unit (e.g. ``"500 N*m"``, ``"30 deg"``, ``"12 um"``),
        or a pint ``Quantity``.
    dimension
        Key of :data:`INTERNAL_UNITS`, e.g. ``"moment"``.
    field
        Name used in error messages.
    bare
        A number without a unit: ``"internal"`` (default) takes it in the internal unit;
        ``"refuse"`` refuses it for a dimensioned field, suggesting the unit to write
        (zero, and dimensionless fields, stay bare).

    Returns
    -------
    float
        The magnitude in the internal unit.

    Raises
    ------
    InputError
        Naming ``field``: not a quantity, not finite, wrong dimension (an angle field
        takes only angle units: rad, deg, arcmin, arcsec, turn, grad), or a bare number
        refused.
    """
    if dimension not in INTERNAL_UNITS:
        raise ValueError(f"to_internal: unknown dimension {dimension!r}")
    if bare not in ("internal", "refuse"):
        raise ValueError(f"to_internal: bare must be 'internal' or 'refuse', got {bare!r}")
    if isinstance(value, bool) or type(value).__name__ == "bool_":
        raise InputError(field, f"expected {_DIMENSION_NAMES[dimension]}, got a boolean")
    if isinstance(value, numbers.Real):
        try:
            number = float(value)
        except OverflowError:  # an integer of hundreds of digits
            raise InputError(field, "an integer too large for a number is out of range") from None
        return _bare(number, _number_text(number), dimension, field, bare)
    if isinstance(value, str):
        text = value.strip()
        fast = _fast_internal(text, dimension)
        if fast is not None:
            return fast
        try:
            number, unit, angle = parse(text)
        except Refused as exc:
            raise InputError(field, str(exc)) from None
        if unit is None:
            return _bare(number, text, dimension, field, bare)
        return _convert(registry().Quantity(number, unit), angle, value, dimension, field)
    if _is_quantity(value):
        _check_scalar(value, field)
        return _convert(value, angle_exponent(value), str(value), dimension, field)
    raise InputError(
        field, f'expected a number or a quantity string such as "90 mm", got {value!r}'
    )


_DEG = math.pi / 180.0

#: The common units of each dimension, as written in problem files, and their factor to
#: the internal unit. Building pint's registry is most of a short command's time
#: (benchmarks/README.md, "Figures behind comments in the code"); these strings never need it (``tests/test_units.py`` checks
#: every factor against pint). Anything else, and every error, takes the pint path.
FAST_UNITS: dict[str, dict[str, float]] = {
    "length": {"mm": 1.0, "m": 1e3, "cm": 10.0, "um": 1e-3, "µm": 1e-3, "μm": 1e-3},
    "force": {"N": 1.0, "kN": 1e3},
    "pressure": {"MPa": 1.0, "GPa": 1e3, "kPa": 1e-3, "Pa": 1e-6, "N/mm^2": 1.0},
    "moment": {"N*mm": 1.0, "N*m": 1e3, "Nm": 1e3, "kN*m": 1e6, "Nmm": 1.0},
    "angle": {"rad": 1.0, "deg": _DEG, "degree": _DEG, "°": _DEG},
    "stiffness": {"N/mm": 1.0, "kN/mm": 1e3, "N/um": 1e3, "N/µm": 1e3},
    "speed": {"1/min": 1.0, "rpm": 1.0},
    "time": {"h": 1.0, "min": 1.0 / 60.0, "s": 1.0 / 3600.0, "ms": 1.0 / 3600e3},
    "angular_speed": {"rad/s": 1.0, "deg/s": _DEG},
    "rotational_stiffness": {"N*mm/rad": 1.0, "N*m/rad": 1e3, "kN*m/rad": 1e6},
    "inertia": {"kg*m^2": 1e3, "kg*cm^2": 0.1, "kg*mm^2": 1e-3, "t*mm^2": 1.0},
    "mass": {"kg": 1e-3, "g": 1e-6, "t": 1.0},
    "rotational_damping": {"N*m*s/rad": 1e3, "N*mm*s/rad": 1.0},
    "frequency": {"Hz": 1.0, "kHz": 1e3},
    "angular_acceleration": {"rad/s^2": 1.0, "deg/s^2": _DEG},
    "integral_gain": {"N*m/(rad*s)": 1e3, "N*mm/(rad*s)": 1.0},
    "rate": {"1/s": 1.0},
}

_FAST = re.compile(r"([+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)\s*(\S+)")


def _fast_internal(text: str, dimension: str) -> float | None:
    """``text`` in the internal unit when it is a number and a unit of
    :data:`FAST_UNITS` for ``dimension``; None otherwise (the caller takes pint's path)."""
    m = _FAST.fullmatch(text)
    if m is None:
        return None
    factor = FAST_UNITS.get(dimension, {}).get(m.group(2))
    if factor is None:
        return None
    number = float(m.group(1))
    result = number * factor
    if not (math.isfinite(number) and math.isfinite(result)) or not _in_range(result):
        return None  # pint's path gives the message
    return result


def _is_quantity(value: object) -> bool:
    # Without importing pint (a plain number or string never needs it).
    return type(value).__module__.startswith("pint") and hasattr(value, "units")


def _bare(number: float, text: str, dimension: str, field: str, bare: Bare) -> float:
    if not math.isfinite(number):
        raise InputError(field, f"{text!r} is not a finite number")
    _check_magnitude(number, text, field)
    if bare == "refuse" and number != 0.0 and dimension != "dimensionless":
        raise InputError(field, f"{text} has no unit; write {_suggest(text, dimension)}")
    return number


def _check_scalar(q: Any, field: str) -> None:
    magnitude = getattr(q, "magnitude", None)
    if not isinstance(magnitude, numbers.Real) or isinstance(magnitude, bool):
        raise InputError(field, f"expected a scalar quantity, got {q!r}")
    if not math.isfinite(float(magnitude)):
        raise InputError(field, f"{q!r} is not a finite number")


@cache
def _dimensionality(dimension: str) -> Any:
    """pint's dimensionality of ``dimension`` (angles left out, as pint does)."""
    return registry().Quantity(1.0, INTERNAL_UNITS[dimension]).dimensionality


def _convert(q: Any, angle: float, shown: object, dimension: str, field: str) -> float:
    """``q`` (angle exponent ``angle``) in the internal unit of ``dimension``."""
    if q.dimensionality != _dimensionality(dimension) or angle not in ANGLE_EXPONENTS[dimension]:
        expected = _DIMENSION_NAMES[dimension]
        if dimension == "dimensionless":
            raise InputError(field, f"{shown!r} is {describe(q, angle)}, expected {expected}")
        number = _number_text(float(q.magnitude))
        hint = "; angle units: rad, deg, arcmin, arcsec, turn, grad" if dimension == "angle" else ""
        raise InputError(
            field,
            f"{shown!r} is {describe(q, angle, _dimensionality(dimension))}, expected {expected} "
            f"(write e.g. {_suggest(number, dimension)}{hint})",
        )
    unit = INTERNAL_UNITS[dimension]
    if dimension == "speed" and angle == 1:
        unit = "turn/min"  # rpm and rad/s count turns: internal 1/min is turns per minute
    if dimension == "frequency" and angle == 1:
        unit = "turn/s"  # an angle per time counts cycles of 2 pi rad: internal Hz
    result = float(q.to(unit).magnitude)
    if not math.isfinite(result):
        raise InputError(field, f"{shown!r} is out of range")
    _check_magnitude(result, str(shown), field, INTERNAL_UNITS[dimension])
    return result


def _in_range(value: float) -> bool:
    return value == 0.0 or MIN_MAGNITUDE <= abs(value) <= MAX_MAGNITUDE


def _check_magnitude(value: float, shown: str, field: str, unit: str = "") -> None:
    internal = f" {unit}" if unit and unit != "dimensionless" else ""
    if abs(value) > MAX_MAGNITUDE:
        raise InputError(
            field, f"{shown} is out of range (magnitude above {MAX_MAGNITUDE:g}{internal})"
        )
    if not _in_range(value):
        raise InputError(
            field,
            f"{shown} is out of range (a nonzero magnitude below {MIN_MAGNITUDE:g}{internal})",
        )


def convert(value: object, unit: str, field: str) -> float:
    """A quantity (string, pint Quantity or number) in ``unit``; a bare number is taken as
    already in ``unit``. For bounds of user-declared constraints, e.g.
    ``convert("3 kN", "N", "nut_force.upper")``. The quantity must have ``unit``'s
    dimension, angles counted (``"5 N*m"`` is refused for ``"N*mm/rad"``)."""
    target, target_angle = parse_unit(unit, field)
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        number = float(value)
        if not math.isfinite(number):
            raise InputError(field, f"{value!r} is not a finite number")
        return number
    if isinstance(value, str):
        try:
            number, parsed, angle = parse(value.strip())
        except Refused as exc:
            raise InputError(field, str(exc)) from None
        if parsed is None:
            return number
        q = registry().Quantity(number, parsed)
    elif _is_quantity(value):
        _check_scalar(value, field)
        q, angle = value, angle_exponent(value)
    else:
        raise InputError(field, f"expected a number or a quantity string, got {value!r}")
    expected = registry().Quantity(1.0, target)
    if q.dimensionality != expected.dimensionality or angle != target_angle:
        shown = f" ({unit!r})" if unit.strip() else ""
        raise InputError(
            field,
            f"{value!r} is {describe(q, angle)}, expected {describe(expected, target_angle)}"
            + shown,
        )
    result = float(q.to(str(target)).magnitude)  # by name: q may be of a user's registry
    if not math.isfinite(result):
        raise InputError(field, f"{value!r} is out of range")
    return result


def unit_factor(unit: str, to: str, field: str) -> float:
    """The factor from ``unit`` to ``to`` (a value in ``unit`` times it is in ``to``), for
    units of one dimension, angles counted; InputError naming ``field`` otherwise, e.g.
    ``unit_factor("N*mm", "N*m/deg", ...)``."""
    source, source_angle = parse_unit(unit, field)
    target, target_angle = parse_unit(to, field)
    q = registry().Quantity(1.0, source)
    if q.dimensionality != target.dimensionality or source_angle != target_angle:
        shown = {u: f"{u!r}" if u.strip() else "no unit" for u in (unit, to)}
        expected = describe(registry().Quantity(1.0, target), target_angle)
        raise InputError(
            field,
            f"{shown[to]} is {expected} and {shown[unit]} {describe(q, source_angle)}: "
            "a unit of the same dimension is needed",
        )
    return float(q.to(target).magnitude)


def parse_unit(unit: str, field: str) -> tuple[Any, int]:
    """(pint unit, angle exponent) of a unit expression such as ``"N*mm/rad"`` (``""``:
    a plain number), read by the restricted grammar; InputError naming ``field``."""
    if not isinstance(unit, str):
        raise InputError(field, f'a unit is a string such as "N*mm", got {unit!r}')
    if not unit.strip():
        return registry().dimensionless, 0
    if len(unit) > MAX_LENGTH:
        raise InputError(field, f"too long for a unit ({len(unit)} characters)")
    try:
        return parse_unit_expression(unit, unit)
    except Refused as exc:
        reason = str(exc).replace("as a quantity", "as a unit").split(" (write a number")[0]
        raise InputError(field, f'{reason} (e.g. "N*mm", "rad/s"; "" for a plain number)') from None
