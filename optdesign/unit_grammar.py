"""The grammar of quantity strings and the angle exponent of a unit expression.

A quantity string is read with a restricted grammar before pint sees any of it: a
decimal number literal, then an optional unit expression of unit names joined by ``*``,
``/``, ``.``, ``·`` or a space, with small integer powers (``^`` or ``**``) and
parentheses. pint's own parser evaluates arithmetic (``"10**10**10 mm"`` computes a
number with ten billion digits and hangs); here every string is accepted or refused in
microseconds. Unit names go to pint one at a time.

Next to pint's dimensionality the parser counts the *angle exponent* of the expression
(pint, like SI, counts the radian as dimensionless): each unit name contributes the
exponent of the radian in its root units (rad, deg, arcmin, arcsec, turn, rev, grad and
their prefixed forms 1; rpm 1; sr 2; Hz, percent 0), added over products, subtracted
over quotients and multiplied by powers, in whole numbers. :mod:`optdesign.units`
checks both against the dimension a field expects. pint is imported, and its registry
built, on first use.
"""

from __future__ import annotations

import math
import re
import unicodedata
from functools import lru_cache
from typing import TYPE_CHECKING, Any, NamedTuple

if TYPE_CHECKING:
    import pint

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
    "grad": "grade",  # pint's name since 0.23 at least ("gradian" only from 0.25)
}

#: Longest quantity string read (a real one is a few characters).
MAX_LENGTH = 100
#: Largest power of a unit (mm^4 is the largest in use).
MAX_POWER = 9
#: Deepest nesting of parentheses.
MAX_DEPTH = 4

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


class Refused(Exception):
    """Why a string is not a quantity (the caller makes it an InputError naming the field)."""


class Parsed(NamedTuple):
    """A quantity string read: its number, its pint unit (None when it has none) and the
    angle exponent of that unit (0 without a unit)."""

    number: float
    unit: Any
    angle: int


def check_ascii_digits(text: str, whole: str) -> None:
    """Refused naming the first decimal digit of ``text`` that is not one of 0-9: Python's
    ``float`` and ``re``'s ``\\d`` read every script's digits ("11\\u0660" as 110), so a
    digit that looks like a letter or a space would change the number unseen."""
    for ch in text:
        if ch.isdecimal() and not ch.isascii():
            name = unicodedata.name(ch, "a digit")
            raise Refused(
                f"{whole!r} has the digit {ch!r} (U+{ord(ch):04X} {name}): write numbers with "
                "the digits 0-9"
            )


def parse(text: str) -> Parsed:
    """The number, unit and angle exponent of a quantity string; Refused saying why not."""
    if len(text) > MAX_LENGTH:
        raise Refused(f"too long for a quantity ({len(text)} characters)")
    check_ascii_digits(text, text)
    m = _NUMBER.match(text)
    if m is None:
        raise Refused(
            f'cannot read {text!r} as a quantity: it must start with a number, e.g. "90 mm"'
        )
    number = float(m.group(1))
    if not math.isfinite(number):
        raise Refused(f"{text!r} is not a finite number")
    rest = text[m.end() :]
    if not rest.strip():
        return Parsed(number, None, 0)
    star = re.match(r"\s*[*·⋅×](?!\*)", rest)  # "2*mm", as pint allowed
    if star is not None:
        rest = rest[star.end() :]
    unit, angle = parse_unit_expression(rest, text)
    return Parsed(number, unit, angle)


def parse_unit_expression(text: str, whole: str) -> tuple[Any, int]:
    """(pint unit, angle exponent) of a unit expression (``whole``: the string shown in
    an error)."""
    check_ascii_digits(text, whole)
    # "N-m", "lbf-ft": a hyphen between two unit names multiplies (engineering usage).
    text = re.sub(r"(?<=[^\W\d_])-(?=[^\W\d_])", "*", text)
    parser = _UnitParser(text, whole)
    unit = parser.expression(0)
    parser.expect_end()
    return unit


class _UnitParser:
    """Recursive descent over the unit part: expr := factor ((*|/|.|space) factor)*;
    factor := (name | 1 | '(' expr ')') [(^|**) int]. Each rule returns (pint unit,
    angle exponent): exponents add over products, subtract over quotients and multiply
    by powers, in whole numbers."""

    def __init__(self, text: str, whole: str):
        text = text.replace("²", "^2").replace("³", "^3")  # N/mm²
        self.tokens: list[tuple[str, str]] = []
        pos = 0
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if m is None or m.end() == pos:
                if not text[pos:].strip():
                    break
                raise Refused(
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

    def fail(self, what: str) -> Refused:
        return Refused(
            f"cannot read {self.whole!r} as a quantity: {what} (write a number and a unit, "
            'e.g. "500 N*m"; no arithmetic)'
        )

    def expression(self, depth: int) -> tuple[Any, int]:
        unit, angle = self.factor(depth)
        while True:
            kind, _ = self.peek()
            if kind in ("mul", "div"):
                self.take()
                rhs, rhs_angle = self.factor(depth)
                if kind == "mul":
                    unit, angle = unit * rhs, angle + rhs_angle
                else:
                    unit, angle = unit / rhs, angle - rhs_angle
            elif kind in ("name", "lp"):
                rhs, rhs_angle = self.factor(depth)  # "N m": a space multiplies
                unit, angle = unit * rhs, angle + rhs_angle
            else:
                return unit, angle

    def factor(self, depth: int) -> tuple[Any, int]:
        kind, value = self.take()
        if kind == "name":
            unit, angle = _unit(value, self)
        elif kind == "int" and value == "1":
            unit, angle = registry().dimensionless, 0  # "1/min"
        elif kind == "lp":
            if depth >= MAX_DEPTH:
                raise self.fail("too many parentheses")
            unit, angle = self.expression(depth + 1)
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
            power = int(value)
            unit, angle = unit**power, angle * power
        return unit, angle

    def expect_end(self) -> None:
        kind, value = self.peek()
        if kind != "end":
            raise self.fail(f"unexpected {value!r}")


def _unit(name: str, parser: _UnitParser) -> tuple[Any, int]:
    try:
        return _named_unit(name)
    except Refused:
        raise parser.fail(f"unknown unit {name!r}") from None


@lru_cache(maxsize=512)
def _named_unit(name: str) -> tuple[Any, int]:
    """(pint unit, angle exponent) of one unit name; Refused when pint does not know it."""
    ureg = registry()
    spelled = ALIASES.get(name)
    if spelled is None and name[0] in "µμ" and len(name) > 1:
        spelled = "u" + name[1:]  # micro sign or Greek mu: pint's "u" prefix
    try:
        # our own spellings only go through pint's expression parser: they are safe
        unit = ureg.parse_units(spelled) if spelled is not None else ureg.Unit(name)
    except Exception:  # pint raises several types for an unknown name
        raise Refused(name) from None
    return unit, angle_exponent(ureg.Quantity(1.0, unit))


def angle_exponent(q: Any) -> int:
    """The exponent of the angle in pint quantity ``q``: that of the radian in its root
    units (pint keeps the radian as a base unit of its own, with no dimension). Whole
    for every unit pint defines; a fractional exponent (only from a user's own pint
    arithmetic) is refused by the callers' checks, as no dimension has one."""
    # (the units container: Quantity.unit_items() exists only from pint 0.24 on)
    for name, exponent in q.to_root_units()._units.items():
        if name == "radian":
            return int(exponent) if float(exponent).is_integer() else exponent
    return 0


#: Names of the dimensionalities a message may meet, from a unit of each.
_NAMED_DIMENSIONS: dict[str, str] = {
    "": "a plain number",
    "mm": "a length",
    "N": "a force",
    "MPa": "a pressure",
    "N*mm": "a moment",
    "N/mm": "a linear stiffness",
    "h": "a time",
    "Hz": "a frequency",
    "mm/s": "a velocity",
    "mm^2": "an area",
    "mm^3": "a volume",
    "kg": "a mass",
    "W": "a power",
    "K": "a temperature",
}


@lru_cache(maxsize=1)
def _dimension_names() -> dict[Any, str]:
    ureg = registry()
    return {
        ureg.Quantity(1.0, unit or "dimensionless").dimensionality: name
        for unit, name in _NAMED_DIMENSIONS.items()
    }


def describe(q: Any, angle: float, expected: Any = None) -> str:
    """What the pint quantity ``q`` of angle exponent ``angle`` measures, for messages:
    "a moment per angle", "an angle per time", "a frequency with no angle" (the latter
    when the dimensionality ``expected`` is ``q``'s: only the angle is missing)."""
    dims = q.dimensionality
    base = _dimension_names().get(dims)
    plain = base == "a plain number"
    per_time = base == "a frequency"
    if base is None:
        base = f"of dimension {dims}"
    if angle == 0:
        if not plain and expected is not None and dims == expected:
            return f"{base} with no angle"
        return base
    if per_time and angle > 0:
        return "an angle per time" if angle == 1 else f"angle^{angle} per time"
    if plain:
        return "an angle" if angle == 1 else "one per angle" if angle == -1 else f"angle^{angle}"
    if angle == 1:
        return f"{base} times an angle"
    if angle > 0:
        return f"{base} times angle^{angle}"
    return f"{base} per angle" if angle == -1 else f"{base} per angle^{-angle}"
