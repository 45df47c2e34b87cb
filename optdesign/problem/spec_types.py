"""The field types of a problem file (:mod:`optdesign.problem.spec`): quantities that
carry a unit, converted to the internal units (mm, N, MPa, N*mm, rad) on load by
:func:`optdesign.units.to_internal`; plain numbers (:data:`Dimensionless`, bare or in
percent); the base model that refuses unknown keys; the deflection range and the bands.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, get_args

import numpy as np
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationInfo,
    model_validator,
)

from optdesign.errors import InputError
from optdesign.models.validity import Validity
from optdesign.units import to_internal


def _quantity(dimension: str):
    def convert(value: Any, info: ValidationInfo) -> float:
        # A problem file (context bare="refuse") must give a dimensioned value its unit;
        # a dict from Python and a validated spec's own dump hold internal units.
        bare = (info.context or {}).get("bare", "internal")
        try:
            return to_internal(value, dimension, info.field_name or dimension, bare=bare)
        except InputError as exc:
            raise ValueError(exc.reason) from None

    return BeforeValidator(convert)


Length = Annotated[float, _quantity("length")]
Angle = Annotated[float, _quantity("angle")]
Moment = Annotated[float, _quantity("moment")]
Pressure = Annotated[float, _quantity("pressure")]
Force = Annotated[float, _quantity("force")]
Dimensionless = Annotated[float, _quantity("dimensionless")]
Stiffness = Annotated[float, _quantity("stiffness")]
RotationalStiffness = Annotated[float, _quantity("rotational_stiffness")]
AngularSpeed = Annotated[float, _quantity("angular_speed")]
Time = Annotated[float, _quantity("time")]
Inertia = Annotated[float, _quantity("inertia")]
Mass = Annotated[float, _quantity("mass")]
RotationalDamping = Annotated[float, _quantity("rotational_damping")]
Frequency = Annotated[float, _quantity("frequency")]
Speed = Annotated[float, _quantity("speed")]
AngularAcceleration = Annotated[float, _quantity("angular_acceleration")]
IntegralGain = Annotated[float, _quantity("integral_gain")]
Rate = Annotated[float, _quantity("rate")]

#: dimension name -> annotated type of a parsed quantity.
QUANTITY_TYPES: dict[str, Any] = {
    "length": Length,
    "angle": Angle,
    "moment": Moment,
    "pressure": Pressure,
    "force": Force,
    "dimensionless": Dimensionless,
}


class _Model(BaseModel):
    # NaN and inf are refused in every plain number (quantities check their own).
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    @model_validator(mode="before")
    @classmethod
    def _no_boolean_numbers(cls, data: Any) -> Any:
        # pydantic reads true as 1 in a number field (`pin_shear_planes = true`): refused;
        # and "yes" or 1 as true in a switch (`critical_speed = "yes"`): refused too.
        if isinstance(data, dict):
            for key, value in data.items():
                info = cls.model_fields.get(key)
                if info is None:
                    continue
                if isinstance(value, bool) and not _takes_bool(info.annotation):
                    shown = str(value).lower()  # as the file wrote it
                    raise ValueError(f"{key}: expected {expected(info.annotation)}, got {shown}")
                if info.annotation is bool and not isinstance(value, bool | np.bool_):
                    raise ValueError(f"{key}: expected true or false, got {value!r}")
        return data


def expected(annotation: Any) -> str:
    """What a field of type ``annotation`` takes, for a refusal: ``a table (kind,
    friction, catalogue, nut, ...)`` for a table such as ``screw``, ``one of 'ball',
    'roller'`` for a choice, ``a number or a string`` for a quantity."""
    model = _model_in(annotation)
    if model is not None:
        names = list(model.model_fields)
        more = ", ..." if len(names) > 4 else ""
        return f"a table ({', '.join(names[:4])}{more})"
    leaves = _flat_args(annotation)
    choices = [a for a in leaves if isinstance(a, str)]
    if choices:
        number = "a number or " if float in leaves or int in leaves else ""
        return number + "one of " + ", ".join(repr(c) for c in choices)
    return "a string" if annotation is str else "a number or a string"


def _model_in(annotation: Any) -> Any:
    """The pydantic model inside ``annotation`` (``X``, ``X | None``, ``Annotated[X, ...]``)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    return next((m for a in get_args(annotation) if (m := _model_in(a)) is not None), None)


def _flat_args(annotation: Any) -> list[Any]:
    # The leaves of an annotation: Literal["a", "b"] | None -> ["a", "b", NoneType].
    args = get_args(annotation)
    return [leaf for a in args for leaf in _flat_args(a)] if args else [annotation]


def _takes_bool(annotation: Any) -> bool:
    return (
        annotation is bool or annotation is Any or any(_takes_bool(a) for a in get_args(annotation))
    )


class Deflection(_Model):
    """The deflection range and its grid."""

    min: Angle
    max: Angle
    points: int = Field(61, ge=3, le=2001)

    @model_validator(mode="after")
    def _ordered(self):
        if not self.min < self.max:
            raise ValueError(f"min ({self.min} rad) must be below max ({self.max} rad)")
        return self


class _OrderedBand(_Model):
    """A band [min, max]; either side may be omitted, min may not exceed max."""

    @model_validator(mode="after")
    def _ordered(self):
        lo, hi = self.min, self.max  # type: ignore[attr-defined]
        if lo is not None and hi is not None and lo > hi:
            raise ValueError(f"min ({lo}) is above max ({hi})")
        return self


class Band(_OrderedBand):
    """A dimensionless band [min, max]."""

    min: Dimensionless | None = None
    max: Dimensionless | None = None


class AngleBand(_OrderedBand):
    """An angle band [min, max] (rad once parsed)."""

    min: Angle | None = None
    max: Angle | None = None


class LengthBand(_OrderedBand):
    """A length band [min, max] (mm once parsed)."""

    min: Length | None = None
    max: Length | None = None


#: dimension -> band model of a ``kind="band"`` requirement.
BAND_TYPES: dict[str, type[_OrderedBand]] = {
    "angle": AngleBand,
    "length": LengthBand,
    "dimensionless": Band,
}


#: Requirements that are magnitudes (checked > 0), with the unit a message shows them in
#: and its factor from the internal unit.
POSITIVE_REQUIREMENTS: dict[str, tuple[str, float]] = {
    "hinge_moment": ("N*m", 1e-3),
    "nut_travel_max": ("mm", 1.0),
    "pin_bearing_pressure_max": ("MPa", 1.0),
    "pin_shear_stress_max": ("MPa", 1.0),
    "motor_torque_max": ("N*m", 1e-3),
    "backlash_max": ("deg", 180.0 / math.pi),
    "pin_contact_pressure_max": ("MPa", 1.0),
    "deflection_rate": ("deg/s", 180.0 / math.pi),
    "life_min": ("h", 1.0),
    "duty_period": ("s", 3600.0),
    "stiffness_min": ("N*m/rad", 1e-3),
    "dn_max": ("mm/min", 1.0),
    "inertia_ratio_max": ("", 1.0),
    "natural_frequency_min": ("Hz", 1.0),
    "bandwidth_min": ("Hz", 1.0),
    "phase_margin_min": ("deg", 180.0 / math.pi),
    "resonance_margin_min": ("", 1.0),
    "limit_cycle_amplitude_max": ("deg", 180.0 / math.pi),
}


def within(record: Validity, value: Any, name: str = "") -> None:
    """Raise ValueError unless ``value`` (internal units) lies in the model's range of
    validity ``record``: ``"name: 1e-09 mm is outside [0.001 mm, 1000 mm] (Huth's lug
    flexibility: ...)"`` (``name`` empty: a field's own validator, which pydantic names)."""
    if value is not None and not record.contains(value):
        raise ValueError(f"{name}: {record.refusal(value)}" if name else record.refusal(value))


def in_range(record: Validity):
    """A field's validator (``Annotated[Length, AfterValidator(in_range(record))]``) that
    holds its value to the model's range of validity ``record`` (:func:`within`)."""

    def check(value: Any) -> Any:
        within(record, value)
        return value

    return check


def _shown(name: str, value: float) -> str:
    unit, factor = POSITIVE_REQUIREMENTS.get(name, ("", 1.0))
    return f"{value * factor:g} {unit}".rstrip()
