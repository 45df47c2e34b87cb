"""Units a user reads: every number of a report with its unit, in the unit system of the
problem file where that is unambiguous.

The package computes in mm, N, N*mm, rad (:mod:`optdesign.units`); reports convert at
the last moment: moments in N*m, ratios of a whole in %, and angles in the unit the file
wrote them in (degrees in, degrees out). Which unit a file wrote where is read once, when
the file is loaded (:func:`written_units`), and kept on the problem as
``problem.written_units`` (path -> unit text, e.g. ``"variables.phi0.lower": "deg"``; see
:func:`optdesign.problem.load.written_units`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from optdesign.text import printable
from optdesign.units import INTERNAL_UNITS

#: Unit texts that mean degrees or radians in a problem file.
DEGREES = ("deg", "degree", "degrees", "°")
RADIANS = ("rad", "radian", "radians")

#: Internal unit -> (unit shown, scale): value * scale is what the user reads.
SHOWN: dict[str, tuple[str, float]] = {
    "N*mm": ("N*m", 1e-3),
    "rad": ("deg", 180.0 / math.pi),
}


def _angle_kind(unit: str) -> str | None:
    unit = unit.strip().lower()
    if unit in DEGREES:
        return "deg"
    if unit in RADIANS:
        return "rad"
    return None


def angle_unit(problem: Any, field: str | None = None) -> str:
    """The angle unit to show for ``field`` (a path prefix such as ``variables.phi0``).

    The unit the file wrote that field in; else the one unit the file wrote every angle
    in; else degrees (the engineer's unit; radians only when the file used them alone).
    """
    units = getattr(problem, "written_units", None) or {}
    if field is not None:
        kinds = {
            _angle_kind(u) for p, u in units.items() if p == field or p.startswith(field + ".")
        }
        kinds.discard(None)
        if len(kinds) == 1:
            return kinds.pop()  # type: ignore[return-value]
    kinds = {_angle_kind(u) for u in units.values()} - {None}
    return "rad" if kinds == {"rad"} else "deg"


@dataclass(frozen=True)
class Shown:
    """A number as the user reads it: value in ``unit`` (``unit`` "" when dimensionless)."""

    value: float
    unit: str = ""

    def text(self, digits: int = 6) -> str:
        """``"12.5 deg"``; ``"-"`` for a missing value."""
        if self.value is None or (isinstance(self.value, float) and math.isnan(self.value)):
            return "-"
        number = f"{self.value:.{digits}g}"
        if self.unit == "%":
            return number + " %"
        return f"{number} {printable(self.unit)}".rstrip()

    def to_json(self) -> dict[str, Any]:
        """``{"value": ..., "unit": ...}`` (NaN as None)."""
        v = float(self.value) if self.value is not None else None
        return {"value": v if v is not None and math.isfinite(v) else None, "unit": self.unit}


def shown(value: float, unit: str, angle: str = "deg") -> Shown:
    """``value`` in internal ``unit`` as the user reads it (``angle``: "deg" or "rad")."""
    if unit == "rad":
        return Shown(value, "rad") if angle == "rad" else Shown(math.degrees(value), "deg")
    if unit in SHOWN:
        to, scale = SHOWN[unit]
        return Shown(value * scale, to)
    return Shown(value, unit)


def variable_shown(problem: Any, var: Any, value: float) -> Shown:
    """Value of design variable ``var`` in the unit the file wrote it in."""
    angle = angle_unit(problem, f"variables.{var.name}")
    return shown(value, var.unit, angle)


def objective_shown(problem: Any, name: str, value: float) -> Shown:
    """Objective ``name`` (or a statistic of it, ``CVaR_0.9(backlash)``) as read."""
    if problem is None:
        return Shown(value, "")
    infos = problem.objectives
    info = infos.get(name) or next((i for k, i in infos.items() if f"({k})" in name), None)
    if info is None:
        return Shown(value, "")
    return Shown(value * info.display_scale, info.shown_unit)


def requirement_values(problem: Any) -> dict[str, Any]:
    """The parsed requirements as the package will use them, in the file's units.

    Each set field maps to a :class:`Shown` (a quantity), a dict of them (a band such
    as ``{min, max}``) or a plain value (a fit, a count); a bare number of a dimensioned
    field shows what it was taken as.
    """
    req = problem.spec.requirements
    out: dict[str, Any] = {}
    for name, field in type(req).model_fields.items():
        value = getattr(req, name)
        if value is None or (value == field.default and name != "hinge_moment"):
            continue
        out[name] = _value(problem, f"requirements.{name}", value, _dimension(field))
    return out


def requirement_echo(problem: Any) -> list[tuple[str, str]]:
    """The parsed requirements as (field, text with unit) pairs, for echoing them back."""
    return [(k, _text(v)) for k, v in requirement_values(problem).items()]


def _text(value: Any) -> str:
    if isinstance(value, Shown):
        return value.text()
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_text(v)}" for k, v in value.items()) + "}"
    if isinstance(value, float):
        return f"{value:.6g}"
    return printable(value)


def json_value(value: Any) -> Any:
    """A requirement value (:func:`requirement_values`) as JSON."""
    if isinstance(value, Shown):
        return value.to_json()
    if isinstance(value, dict):
        return {k: json_value(v) for k, v in value.items()}
    if isinstance(value, float | int) and not isinstance(value, bool):
        return {"value": value, "unit": ""}
    return value


#: Dimension -> internal unit (the package's one table).
_DIMENSION_UNITS = {k: v for k, v in INTERNAL_UNITS.items() if k != "dimensionless"}


#: Each spec field's dimension, by the field's id (the field kept beside it, so an id
#: is never reused): a front's page shows every point's costs, each reading the whole
#: table of requirements.
_FIELD_DIMENSIONS: dict[int, tuple[Any, str | None]] = {}


def _dimension(field: Any) -> str | None:
    """The dimension of a spec field (its quantity validator's), looking inside
    ``Length | None`` and the like."""
    known = _FIELD_DIMENSIONS.get(id(field))
    if known is not None and known[0] is field:
        return known[1]
    dim = _field_dimension(field)
    _FIELD_DIMENSIONS[id(field)] = (field, dim)
    return dim


def _field_dimension(field: Any) -> str | None:
    import typing

    metas = list(field.metadata)
    stack = [field.annotation]
    while stack:
        t = stack.pop()
        metas += list(getattr(t, "__metadata__", ()))
        stack += list(typing.get_args(t))
    for meta in metas:
        fn = getattr(meta, "func", None)
        for c in getattr(fn, "__closure__", None) or ():
            if isinstance(c.cell_contents, str) and c.cell_contents in _DIMENSION_UNITS:
                return c.cell_contents
    return None


def _value(problem: Any, path: str, value: Any, dim: str | None) -> Any:
    if hasattr(type(value), "model_fields"):
        return {
            k: _value(problem, f"{path}.{k}", getattr(value, k), _dimension(f))
            for k, f in type(value).model_fields.items()
            if getattr(value, k) is not None
        }
    if isinstance(value, list):
        return f"[{len(value)} items]"
    if isinstance(value, float) and dim is None:
        # a plain number the file wrote in percent ("90 %") is shown so
        written = (getattr(problem, "written_units", None) or {}).get(path, "").strip()
        return Shown(_tidy(value * 100.0), "%") if written in ("%", "percent") else value
    if isinstance(value, float):
        written = _in_written_unit(problem, path, value, dim)
        if written is not None:
            return written
        if dim == "angular_speed":
            return Shown(math.degrees(value), "deg/s")
        angle = angle_unit(problem, path) if dim == "angle" else "deg"
        return shown(value, _DIMENSION_UNITS[dim], angle)
    return value


def _in_written_unit(problem: Any, path: str, value: float, dim: str) -> Shown | None:
    """``value`` (internal unit of ``dim``) in the unit the file wrote at ``path``; None
    when the file gave a bare number there (or a unit pint cannot convert to)."""
    unit = (getattr(problem, "written_units", None) or {}).get(path)
    if not unit:
        return None
    factor = _shown_factor(dim, unit)
    if factor is not None:
        return Shown(_tidy(value * factor), unit)
    from optdesign.units import registry

    try:
        q = registry().Quantity(value, _DIMENSION_UNITS[dim]).to(unit)
    except Exception:  # a display nicety: fall back to the package's own unit
        return None
    return Shown(_tidy(float(q.magnitude)), unit)


def _tidy(x: float) -> float:
    """A value converted back to the unit the file wrote, without the last bit of the
    round trip ("30 deg" shown as 30, not 29.999999999999996): 15 significant digits."""
    return float(f"{x:.15g}")


#: Units of the input table that pint converts otherwise (it reads "rpm" as revolutions,
#: and neither "Nm" nor "Nmm" as a moment), or whose inverse factor is not pint's to the
#: last bit (ms in hours): pint decides, as before.
_NOT_FAST_SHOWN = {("speed", "rpm"), ("moment", "Nm"), ("moment", "Nmm"), ("time", "ms")}


def _shown_factor(dim: str, unit: str) -> float | None:
    """Internal -> ``unit`` factor for the common units of problem files, without pint
    (importing it and building its registry costs ~0.3 s, more than a solve). ``value *
    (1 / factor)`` is what pint computes, bit for bit (``tests/test_units_fast.py``);
    None when pint must decide."""
    from optdesign.units import FAST_UNITS

    if (dim, unit) in _NOT_FAST_SHOWN:
        return None
    factor = FAST_UNITS.get(dim, {}).get(unit)
    return None if factor is None else 1.0 / factor
