"""Units at the input boundary.

The package computes in one internal system: mm, N, MPa (N/mm^2), N*mm, rad.
Problem files and the CLI may give quantities with units ("90 mm", "500 N*m", "30 deg");
:func:`to_internal` converts them to the internal unit of the expected dimension.

A quantity string is read with a restricted grammar before pint sees any of it: a
decimal number literal, then an optional unit expression of unit names joined by ``*``,
``/``, ``.``, ``·`` or a space, with small integer powers (``^`` or ``**``) and
parentheses. pint's own parser evaluates arithmetic (``"10**10**10 mm"`` computes a
number with ten billion digits and hangs); here every string is accepted or refused in
microseconds. Unit names go to pint one at a time.

A bare number is taken as already in internal units (``bare="internal"``, the default),
or refused for a dimensioned field (``bare="refuse"``), with the unit to write.
pint is imported, and its registry built, on first use: importing this module is cheap.
"""

from __future__ import annotations

import math
import numbers
import re
from functools import lru_cache
from typing import TYPE_CHECKING, Any, Literal

from optdesign.errors import InputError

if TYPE_CHECKING:
    import pint

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
}

#: How a dimension is named in messages ("expected a moment").
_DIMENSION_NAMES: dict[str, str] = {
    "length": "a length",
    "force": "a force",
    "pressure": "a pressure",
    "moment": "a moment",
    "angle": "an angle",
    "dimensionless": "a plain number (no unit)",
    "stiffness": "a stiffness",
    "speed": "a speed",
    "time": "a time",
    "angular_speed": "an angular speed",
    "rotational_stiffness": "a rotational stiffness",
}

#: Spellings pint does not read as meant ("Nm" is pint's "number * metre" per gram!).
ALIASES: dict[str, str] = {
    "Nm": "N*m",
    "kNm": "kN*m",
    "MNm": "MN*m",
    "mNm": "mN*m",
    "Nmm": "N*mm",
    "Ncm": "N*cm",
    "°": "degree",
    "%": "percent",
    "rev": "revolution",
    "revs": "revolution",
    "grad": "gradian",
}

#: Longest quantity string read (a real one is a few characters).
MAX_LENGTH = 100
#: Largest power of a unit (mm^4 is the largest in use).
MAX_POWER = 9
#: Deepest nesting of parentheses.
MAX_DEPTH = 4
#: Largest magnitude accepted in internal units: 1e15 mm is a billion kilometres; beyond
#: it a bound only breaks the solver's scaling (1e308 overflows to inf in the first sum).
MAX_MAGNITUDE = 1e15
#: Smallest nonzero magnitude accepted in internal units: 1e-12 mm is a hundredth of an
#: atom; below it the models' products and quotients (a buckling load over a squared
#: length, a compliance over a stiffness) overflow to inf and NaN.
MIN_MAGNITUDE = 1e-12

Bare = Literal["internal", "refuse"]

_NUMBER = re.compile(r"\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)")
_TOKEN = re.compile(
    r"\s*(?:(?P<name>(?:[^\W\d_]|[°%])+)|(?P<pow>\^|\*\*)|(?P<mul>[*.·⋅×])|(?P<div>/)"
    r"|(?P<int>[+-]?\d+)|(?P<lp>\()|(?P<rp>\)))"
)


@lru_cache(maxsize=1)
def registry() -> pint.UnitRegistry:
    """The shared pint registry (degrees and radians are dimensionless angles in pint)."""
    import pint

    return pint.UnitRegistry(autoconvert_offset_to_baseunit=True)


class _Refused(Exception):
    """Why a string is not a quantity (becomes an InputError naming the field)."""


def parse_quantity(text: str) -> tuple[float, Any]:
    """``(number, unit)`` of a quantity string; ``unit`` is None when there is none.

    Raises
    ------
    InputError
        (field ``"quantity"``) when ``text`` is not a number optionally followed by a
        unit expression of the restricted grammar (see the module docstring).
    """
    try:
        return _parse(text)
    except _Refused as exc:
        raise InputError("quantity", str(exc)) from None


def _parse(text: str) -> tuple[float, Any]:
    if len(text) > MAX_LENGTH:
        raise _Refused(f"too long for a quantity ({len(text)} characters)")
    m = _NUMBER.match(text)
    if m is None:
        raise _Refused(
            f'cannot read {text!r} as a quantity: it must start with a number, e.g. "90 mm"'
        )
    number = float(m.group(1))
    if not math.isfinite(number):
        raise _Refused(f"{text!r} is not a finite number")
    rest = text[m.end() :]
    if not rest.strip():
        return number, None
    star = re.match(r"\s*[*·⋅×](?!\*)", rest)  # "2*mm", as pint allowed
    if star is not None:
        rest = rest[star.end() :]
    # "N-m", "lbf-ft": a hyphen between two unit names multiplies (engineering usage).
    rest = re.sub(r"(?<=[^\W\d_])-(?=[^\W\d_])", "*", rest)
    parser = _UnitParser(rest, text)
    unit = parser.expression(0)
    parser.expect_end()
    return number, unit


class _UnitParser:
    """Recursive descent over the unit part: expr := factor ((*|/|.|space) factor)*;
    factor := (name | 1 | '(' expr ')') [(^|**) int]."""

    def __init__(self, text: str, whole: str):
        text = text.replace("²", "^2").replace("³", "^3")  # N/mm²
        self.tokens: list[tuple[str, str]] = []
        pos = 0
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if m is None or m.end() == pos:
                if not text[pos:].strip():
                    break
                raise _Refused(
                    f"cannot read {whole!r} as a quantity: {text[pos:].strip()[:20]!r} is not "
                    'part of a unit (write a number and a unit, e.g. "500 N*m"; no arithmetic)'
                )
            kind = m.lastgroup or ""
            self.tokens.append((kind, m.group(kind)))
            pos = m.end()
        self.i = 0
        self.whole = whole

    def peek(self) -> tuple[str, str]:
        return self.tokens[self.i] if self.i < len(self.tokens) else ("end", "")

    def take(self) -> tuple[str, str]:
        tok = self.peek()
        self.i += 1
        return tok

    def fail(self, what: str) -> _Refused:
        return _Refused(
            f"cannot read {self.whole!r} as a quantity: {what} (write a number and a unit, "
            'e.g. "500 N*m"; no arithmetic)'
        )

    def expression(self, depth: int) -> Any:
        unit = self.factor(depth)
        while True:
            kind, _ = self.peek()
            if kind in ("mul", "div"):
                self.take()
                rhs = self.factor(depth)
                unit = unit * rhs if kind == "mul" else unit / rhs
            elif kind in ("name", "lp"):
                unit = unit * self.factor(depth)  # "N m": a space multiplies
            else:
                return unit

    def factor(self, depth: int) -> Any:
        kind, value = self.take()
        if kind == "name":
            unit = _unit(value, self)
        elif kind == "int" and value == "1":
            unit = registry().dimensionless  # "1/min"
        elif kind == "lp":
            if depth >= MAX_DEPTH:
                raise self.fail("too many parentheses")
            unit = self.expression(depth + 1)
            if self.take()[0] != "rp":
                raise self.fail("a parenthesis is not closed")
        else:
            raise self.fail(f"expected a unit name, found {value or 'the end'!r}")
        if self.peek()[0] == "pow":
            self.take()
            kind, value = self.take()
            if kind == "lp":  # mm^(-1)
                kind, value = self.take()
                if self.take()[0] != "rp":
                    raise self.fail("a parenthesis is not closed")
            if kind != "int" or abs(int(value)) > MAX_POWER:
                raise self.fail(f"a power must be a whole number from -{MAX_POWER} to {MAX_POWER}")
            unit = unit ** int(value)
        return unit

    def expect_end(self) -> None:
        kind, value = self.peek()
        if kind != "end":
            raise self.fail(f"unexpected {value!r}")


def _unit(name: str, parser: _UnitParser) -> Any:
    ureg = registry()
    spelled = ALIASES.get(name)
    if spelled is None and name[0] in "µμ" and len(name) > 1:
        spelled = "u" + name[1:]  # micro sign or Greek mu: pint's "u" prefix
    try:
        if spelled is not None:
            return ureg.parse_units(spelled)  # our own spellings only: safe
        return ureg.Unit(name)
    except Exception:  # pint raises several types for an unknown name
        raise parser.fail(f"unknown unit {name!r}") from None


def _number_text(value: float) -> str:
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)


def _suggest(number: str, dimension: str) -> str:
    unit = SUGGESTED_UNITS.get(dimension, "")
    return f'"{number} {unit}"' if unit else f'"{number}"'


def _angle_like(q: Any) -> bool:
    # pint treats rad, deg and also percent as dimensionless; only the angle units have
    # the radian as root unit.
    return q.to_root_units().units == q._REGISTRY.radian


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
            number, unit = _parse(text)
        except _Refused as exc:
            raise InputError(field, str(exc)) from None
        if unit is None:
            return _bare(number, text, dimension, field, bare)
        return _convert(registry().Quantity(number, unit), value, dimension, field)
    if _is_quantity(value):
        magnitude = getattr(value, "magnitude", None)
        if not isinstance(magnitude, numbers.Real) or isinstance(magnitude, bool):
            raise InputError(field, f"expected a scalar quantity, got {value!r}")
        if not math.isfinite(float(magnitude)):
            raise InputError(field, f"{value!r} is not a finite number")
        return _convert(value, str(value), dimension, field)
    raise InputError(
        field, f'expected a number or a quantity string such as "90 mm", got {value!r}'
    )


_DEG = math.pi / 180.0

#: The common units of each dimension, as written in problem files, and their factor to
#: the internal unit. Building pint's registry costs ~0.9 s of a ~3 s command; these
#: strings never need it (``tests/test_units_fast.py`` checks every factor against
#: pint). Anything else, and every error, takes the pint path.
FAST_UNITS: dict[str, dict[str, float]] = {
    "length": {"mm": 1.0, "m": 1e3, "cm": 10.0, "um": 1e-3, "µm": 1e-3, "μm": 1e-3},
    "force": {"N": 1.0, "kN": 1e3},
    "pressure": {"MPa": 1.0, "GPa": 1e3, "kPa": 1e-3, "Pa": 1e-6, "N/mm^2": 1.0},
    "moment": {"N*mm": 1.0, "N*m": 1e3, "Nm": 1e3, "kN*m": 1e6, "Nmm": 1.0},
    "angle": {"rad": 1.0, "deg": _DEG, "degree": _DEG, "°": _DEG},
    "stiffness": {"N/mm": 1.0, "kN/mm": 1e3, "N/um": 1e3, "N/µm": 1e3},
    "speed": {"1/min": 1.0, "rpm": 1.0},
    "time": {"h": 1.0, "min": 1.0 / 60.0, "s": 1.0 / 3600.0},
    "angular_speed": {"rad/s": 1.0, "deg/s": _DEG},
    "rotational_stiffness": {"N*mm/rad": 1.0, "N*m/rad": 1e3, "kN*m/rad": 1e6},
}

_FAST = re.compile(r"([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(\S+)")


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


def _convert(q: Any, shown: object, dimension: str, field: str) -> float:
    import pint

    if dimension in ("angle", "dimensionless") and q.dimensionless:
        angle = _angle_like(q)
        if dimension == "angle" and not angle:
            raise InputError(
                field,
                f"{shown!r} is not an angle (use rad, deg, arcmin, arcsec, turn or grad, "
                f'e.g. "{_number_text(float(q.magnitude))} deg")',
            )
        if dimension == "dimensionless" and angle:
            raise InputError(field, f"{shown!r} is an angle, expected a plain number")
    unit = INTERNAL_UNITS[dimension]
    if dimension == "speed" and "radian" in str(q.to_root_units().units):
        unit = "turn/min"  # rpm and rad/s count turns: internal 1/min is turns per minute
    try:
        result = float(q.to(unit).magnitude)
    except pint.DimensionalityError:
        number = _number_text(float(q.magnitude))
        raise InputError(
            field,
            f"{shown!r} has dimension {q.dimensionality}, expected "
            f"{_DIMENSION_NAMES[dimension]} (write e.g. {_suggest(number, dimension)})",
        ) from None
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
    ``convert("3 kN", "N", "nut_force.upper")``."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        number = float(value)
        if not math.isfinite(number):
            raise InputError(field, f"{value!r} is not a finite number")
        return number
    if isinstance(value, str):
        try:
            number, parsed = _parse(value.strip())
        except _Refused as exc:
            raise InputError(field, str(exc)) from None
        if parsed is None:
            return number
        q = registry().Quantity(number, parsed)
    elif _is_quantity(value):
        q = value
    else:
        raise InputError(field, f"expected a number or a quantity string, got {value!r}")
    import pint

    try:
        target = registry().Unit(unit or "dimensionless")
    except Exception as exc:
        raise InputError(field, f"unknown unit {unit!r} ({exc})") from None
    try:
        result = float(q.to(target).magnitude)
    except pint.DimensionalityError:
        raise InputError(field, f"{value!r} cannot be expressed in {unit!r}") from None
    if not math.isfinite(result):
        raise InputError(field, f"{value!r} is out of range")
    return result
