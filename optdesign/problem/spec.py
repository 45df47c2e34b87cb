"""Schema of a problem file, validated with pydantic; every quantity may carry a unit.

The generic part (:class:`ProblemSpec`) holds what every mechanism shares: the stroke, the
hinge moment, the drive and pin requirements, the objective, the solver settings. The
mechanism-specific part is *derived from the mechanism plug-in* by :func:`spec_model`:
its requirements (e.g. a crank-slider's transmission angle), the keys of its fixed
clearances, the variables a tolerance or a reference design may name. Quantities are
converted to the internal units (mm, N, MPa, N*mm, rad) on load by
:func:`optdesign.units.to_internal`, which counts the angle as a dimension of its own (a
moment carries none, a rotational stiffness is a moment per angle). Plain numbers
(efficiencies, ratios, factors) are :data:`Dimensionless`: bare, or in percent
(``"90 %"`` is 0.9); an angle there is refused.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Annotated, Any, Literal, get_args

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationInfo,
    create_model,
    field_validator,
    model_validator,
)

from optdesign.argument_checks import MAX_SEED, MAX_STARTS
from optdesign.errors import InputError
from optdesign.models.fit_formulas import Fit
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
                    raise ValueError(f"{key}: expected a number or a string, got {value}")
                if info.annotation is bool and not isinstance(value, bool | np.bool_):
                    raise ValueError(f"{key}: expected true or false, got {value!r}")
        return data


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


class Material(_Model):
    """Elastic constants of a pin material."""

    E: Pressure = 2.1e5
    nu: Dimensionless = 0.3

    @model_validator(mode="after")
    def _physical(self):
        if self.E <= 0:
            raise ValueError(f"E must be positive, got {self.E}")
        if not 0.0 < self.nu < 0.5:
            raise ValueError(f"nu must lie in (0, 0.5), got {self.nu}")
        return self


class Lug(_Model):
    """The lug (or clevis) around the sized pin, for ``pin_contact = "huth"`` (Huth's
    flexibility, :mod:`optdesign.models.lug_flexibility`). Single or double shear is the
    problem's ``pin_shear_planes`` (the mechanism's default unless the file sets it)."""

    cheek_thickness: Length
    thickness: Length | None = None
    E: Pressure | None = None
    cheek_E: Pressure | None = None
    fastener: Literal["bolted", "riveted"] = "bolted"

    @model_validator(mode="after")
    def _positive(self):
        for name in ("cheek_thickness", "thickness", "E", "cheek_E"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                unit = "mm" if name.endswith("thickness") else "MPa"
                raise ValueError(f"{name}: must be positive, got {value:g} {unit}")
        return self


class Materials(_Model):
    pin: Material = Material()
    lug: Lug | None = None


class ScrewSizing(_Model):
    """Catalogue sizing checks of the screw shaft under the nut force."""

    root_diameter: Length
    buckling_length: Length | None = None
    mounting: Literal["fixed-free", "supported-supported", "fixed-supported", "fixed-fixed"] = (
        "fixed-supported"
    )
    check_yield: bool = True

    @model_validator(mode="after")
    def _positive(self):
        if self.root_diameter <= 0:
            raise ValueError(f"root_diameter must be positive, got {self.root_diameter}")
        if self.buckling_length is not None and self.buckling_length <= 0:
            raise ValueError(f"buckling_length must be positive, got {self.buckling_length}")
        return self


class Screw(_Model):
    """The drive's screw: its type and friction (efficiency), where its size comes from,
    its mounting, and the stiffness of the parts a model cannot size.

    ``catalogue``: the screw is a catalogue item - declare ``d0`` and ``p`` with
    ``catalogue = "HIWIN"`` (their values are the catalogue's diameters and leads, and only
    the pairs it lists exist); the item gives root diameter, load ratings and nut
    stiffness. Without it, a declared ``d0`` is a continuous nominal (mean) diameter with a
    root diameter ``root_ratio * d0``.
    """

    kind: Literal["ball", "roller", "sliding", "trapezoidal", "acme"] = "ball"
    friction: Dimensionless | None = Field(None, ge=0.0, lt=1.0)
    catalogue: Literal["HIWIN"] | None = None
    nut: Literal["FSI", "FSC"] | None = None
    root_ratio: Dimensionless = Field(0.83, gt=0.0, lt=1.0)
    mounting: Literal["fixed-free", "supported-supported", "fixed-supported", "fixed-fixed"] = (
        "fixed-supported"
    )
    length: Length | None = None
    nut_offset: Length | None = None
    nut_stiffness: Stiffness | None = None
    bearing_stiffness: Stiffness | None = None
    gear_efficiency: Dimensionless = Field(1.0, gt=0.0, le=1.0)
    gear_back_efficiency: Dimensionless = Field(1.0, gt=0.0, le=1.0)
    check_buckling: bool = True
    check_yield: bool = True
    nut_stiffness_rule: Literal["load", "table", "preload"] | None = None
    nut_preload: Dimensionless | None = Field(None, gt=0.0, le=0.1)
    mounting_factors: Literal["conservative", "HIWIN", "common"] = "conservative"
    efficiency_design: Literal["friction", "HIWIN"] = "friction"

    @model_validator(mode="after")
    def _nut_rule(self):
        rule = self.nut_stiffness_rule
        if rule == "preload" and self.nut_preload is None:
            raise ValueError(
                'nut_stiffness_rule: "preload" needs nut_preload (the preload over Ca, e.g. 0.05)'
            )
        if self.nut_preload is not None and rule != "preload":
            raise ValueError('nut_preload: only with nut_stiffness_rule = "preload"')
        if self.efficiency_design == "HIWIN" and self.kind != "ball":
            raise ValueError(
                f'efficiency_design: "HIWIN" gives design values of ball screws, not of a '
                f'{self.kind} screw; use "friction"'
            )
        if rule is not None and self.catalogue is None:
            raise ValueError(
                "nut_stiffness_rule: the catalogue's rule needs the nut's table stiffness "
                'and rating: give catalogue (e.g. "HIWIN")'
            )
        return self

    @model_validator(mode="after")
    def _positive(self):
        for name in ("length", "nut_offset", "nut_stiffness", "bearing_stiffness"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise ValueError(f"{name} must be positive, got {value:g}")
        if self.nut is not None and self.catalogue is None:
            raise ValueError("nut selects a catalogue nut type: give catalogue too")
        return self


class DutyStep(_Model):
    """One step of a duty cycle: a deflection held under a hinge moment for a share of
    the time (the speed comes from ``deflection_rate``)."""

    deflection: Angle
    hinge_moment: Moment
    time: Dimensionless = Field(gt=0.0)

    @model_validator(mode="after")
    def _positive(self):
        if not self.hinge_moment > 0:
            shown = _shown("hinge_moment", self.hinge_moment)
            raise ValueError(f"hinge_moment: must be positive, got {shown}")
        return self


class MotorLock(_Model):
    """Power-off lock on the motor shaft (seed 002): what it must hold and its force."""

    kind: Literal["friction_plate", "pin", "pin_rolling"]
    radius: Length | None = None
    r1: Length | None = None
    r2: Length | None = None
    mu: Dimensionless = Field(0.3, gt=0.0)
    eta_screw_back: Dimensionless = Field(1.0, gt=0.0, le=1.0)
    eta_gear_back: Dimensionless = Field(1.0, gt=0.0, le=1.0)
    force_max: Force | None = None

    @model_validator(mode="after")
    def _geometry(self):
        if self.kind == "friction_plate":
            if self.r1 is None or self.r2 is None:
                raise ValueError("a friction_plate lock needs r1 and r2")
            if not 0 <= self.r1 < self.r2:
                raise ValueError(f"need 0 <= r1 < r2, got r1={self.r1}, r2={self.r2}")
        elif self.radius is None or self.radius <= 0:
            raise ValueError(f"a {self.kind} lock needs a positive radius")
        if self.force_max is not None and not self.force_max > 0:
            raise ValueError(f"force_max: must be positive, got {self.force_max:g} N")
        return self


class Requirements(_Model):
    """What a design must meet, whatever the mechanism. Omitted ones are not imposed.

    A mechanism adds its own requirements to this model (:func:`spec_model`).
    """

    deflection: Deflection
    hinge_moment: Moment
    mean_ratio: Band | None = None
    nut_travel_max: Length | None = None
    pin_bearing_pressure_max: Pressure | None = None
    pin_shear_stress_max: Pressure | None = None
    pin_shear_planes: int | None = Field(None, ge=1, le=2)
    motor_torque_max: Moment | None = None
    eta_screw: Dimensionless = Field(1.0, gt=0.0, le=1.0)
    eta_gear: Dimensionless = Field(1.0, gt=0.0, le=1.0)
    backlash_max: Angle | None = None
    ripple_max: Dimensionless | None = Field(None, gt=0.0)
    fit: str = "H7/g6"
    fit_clearance: Literal["min", "max"] = "max"
    screw: ScrewSizing | None = None
    lock: MotorLock | None = None
    fit_values: Literal["table", "smooth"] | None = None
    pin_contact: Literal["duan2017", "conforming", "palmgren", "huth"] = "duan2017"
    pin_contact_pressure_max: Pressure | None = None
    efficiency_min: Dimensionless | None = Field(None, gt=0.0, le=1.0)
    back_drive: Literal["required", "forbidden"] | None = None
    deflection_rate: AngularSpeed | None = None
    critical_speed: bool = False
    dn_max: float | Literal["rolled", "peeled", "ground", "high-speed"] | None = None
    dn_rule: Literal["ball-centre", "HIWIN"] = "ball-centre"
    static_safety_min: Dimensionless | None = Field(None, ge=1.0)
    life_min: Time | None = None
    duty_cycle: list[DutyStep] | None = Field(None, max_length=1000)
    f_w: Dimensionless = Field(1.0, ge=1.0, le=3.0)
    stiffness_min: RotationalStiffness | None = None
    stiffness_load: Literal["hinge", "duty-mean"] = "hinge"

    @model_validator(mode="after")
    def _physical(self):
        # Limits and loads are magnitudes: a negative or zero one is a sign error that a
        # solver would otherwise turn into a constraint that never binds.
        for name in POSITIVE_REQUIREMENTS:
            value = getattr(self, name)
            if isinstance(value, int | float) and not value > 0:
                raise ValueError(f"{name}: must be positive, got {_shown(name, value)}")
        span = self.deflection.max - self.deflection.min
        if span > 2 * math.pi + 1e-12:
            raise ValueError(
                f"deflection: the stroke spans {math.degrees(span):g} deg, more than a turn"
            )
        band = self.mean_ratio
        if band is not None and any(v is not None and not v > 0 for v in (band.min, band.max)):
            raise ValueError(
                f"mean_ratio: min and max must be positive, got {band.min}, {band.max}"
            )
        return self

    @model_validator(mode="after")
    def _drive_rules(self):
        if self.life_min is not None and not self.duty_cycle:
            raise ValueError("life_min needs a duty_cycle (deflection, hinge_moment, time)")
        if self.stiffness_load == "duty-mean" and not self.duty_cycle:
            raise ValueError('stiffness_load: "duty-mean" needs a duty_cycle')
        if (self.life_min is not None or self.critical_speed or self.dn_max is not None) and (
            self.deflection_rate is None
        ):
            raise ValueError(
                "life_min, critical_speed and dn_max need the screw's speed: give "
                'deflection_rate (e.g. "60 deg/s")'
            )
        return self

    @field_validator("dn_max", mode="before")
    @classmethod
    def _dn_max(cls, value: Any) -> Any:
        # One message for both forms (pydantic would list each branch of the union).
        grades = ("rolled", "peeled", "ground", "high-speed")
        if isinstance(value, str) and value not in grades:
            raise ValueError(
                f"a number (d x n in mm x 1/min, e.g. 70000) or a grade ({', '.join(grades)}),"
                f" got {value!r}"
            )
        return value

    @field_validator("fit")
    @classmethod
    def _fit(cls, value: str) -> str:
        # Any fit the ISO 286-2 tables give; whether the problem's values (smooth formulas
        # for a continuous d) can evaluate it is checked with the problem
        # (optdesign.problem.consistency).
        try:
            Fit.parse(value, values="table")
        except InputError as exc:
            raise ValueError(exc.reason) from None
        return value


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
    "stiffness_min": ("N*m/rad", 1e-3),
    "dn_max": ("mm/min", 1.0),
}


def _shown(name: str, value: float) -> str:
    unit, factor = POSITIVE_REQUIREMENTS.get(name, ("", 1.0))
    return f"{value * factor:g} {unit}".rstrip()


class Objective(_Model):
    """Objective(s) to minimise; several for Pareto fronts. Names are checked against the
    problem's objective catalogue (built-in and user-added) when the problem is built."""

    minimize: list[str] = Field(min_length=1, max_length=10)

    @model_validator(mode="before")
    @classmethod
    def _listify(cls, data):
        if isinstance(data, dict) and isinstance(data.get("minimize"), str):
            data = dict(data, minimize=[data["minimize"]])
        return data


class SolverOptions(_Model):
    """Defaults of ``optdesign solve`` for this problem (the CLI may override them)."""

    # the caps of the API's and the command line's arguments (optdesign.validation)
    starts: int = Field(8, ge=1, le=MAX_STARTS)
    seed: int = Field(0, ge=0, le=MAX_SEED)
    #: The multistart stops once this many starts agree on the best value (0: run all).
    agree: int = Field(3, ge=0, le=MAX_STARTS)
    ipopt: dict[str, Any] = Field(default_factory=dict)

    @field_validator("ipopt")
    @classmethod
    def _no_files(cls, value: dict[str, Any]) -> dict[str, Any]:
        # A problem file comes from anyone: an option that writes or reads a file
        # (output_file) or loads code (hsllib) is refused on load, before any solve.
        from optdesign.safe_io import file_option_problem

        found = file_option_problem(value, "ipopt")
        if found:
            where, reason = found
            raise ValueError(f"{where.removeprefix('ipopt.')}: refused: it {reason}")
        return value


def _band_table(data: Any) -> Any:
    # ``R = "0.05 mm"`` is short for ``R = { band = "0.05 mm" }``.
    return {"band": data} if isinstance(data, str | int | float) else data


class _Tolerance(_Model):
    distribution: Literal["normal", "uniform"] = "normal"

    @model_validator(mode="after")
    def _non_negative(self):
        if self.band < 0:  # type: ignore[attr-defined]
            raise ValueError(f"band must be >= 0, got {self.band}")  # type: ignore[attr-defined]
        return self


class LengthTolerance(_Tolerance):
    """Manufacturing tolerance +-band of a length: uniform on [-band, band] or normal with
    sigma = band/3 (a process capability Cp = 1)."""

    band: Length


class AngleTolerance(_Tolerance):
    """Manufacturing tolerance +-band of an angle (see :class:`LengthTolerance`)."""

    band: Angle


TOLERANCE_TYPES: dict[str, Any] = {
    "length": Annotated[LengthTolerance, BeforeValidator(_band_table)],
    "angle": Annotated[AngleTolerance, BeforeValidator(_band_table)],
}


class Tolerances(_Model):
    """Manufacturing scatter of a design, for robust design (formulations/robust.py).

    Any length or angle variable may get a tolerance (fields derived per mechanism).
    ``fit = "uniform"`` draws each pin joint's fit clearance uniformly between the fit's
    smallest and largest clearance (``"fixed"``: the requirement's ``fit_clearance``).
    ``samples`` and ``seed`` fix the sample-average approximation; ``risk`` is the
    minimised statistic of the objective over the samples: ``"cvar"`` (mean of the worst
    1 - alpha) or ``"mean_std"`` (mean + k std).
    """

    fit: Literal["fixed", "uniform"] = "fixed"
    samples: int = Field(32, ge=1, le=2000)
    seed: int = Field(0, ge=0, le=MAX_SEED)
    risk: Literal["cvar", "mean_std"] = "cvar"
    alpha: Dimensionless = Field(0.9, ge=0.0, lt=1.0)
    k: Dimensionless = Field(2.0, ge=0.0)

    def variables(self) -> dict[str, Any]:
        """Variable name -> tolerance, for the variables that have one."""
        own = set(Tolerances.model_fields)
        return {k: v for k, v in self if k not in own and v is not None}


class Reference(_Model):
    """A design to compare with (e.g. a paper's): a label and variable values (fields
    derived per mechanism)."""

    label: str = "reference"

    def values(self) -> dict[str, float]:
        """Variable name -> value (internal units) for the variables given."""
        return {k: v for k, v in self if k != "label" and v is not None}


class ProblemSpec(_Model):
    """A whole problem file (generic part; :func:`spec_model` derives the one of a
    mechanism)."""

    name: str
    description: str = ""
    mechanism: str
    variables: dict[str, Any]
    requirements: Requirements
    materials: Materials = Materials()
    clearances: _Model | None = None
    objective: Objective
    solver: SolverOptions = SolverOptions()
    tolerances: Tolerances | None = None
    reference: Reference | None = None
    screw: Screw | None = None


def _requirement_field(info) -> tuple[Any, Any]:
    """Pydantic field (type, default) of a mechanism-specific requirement."""
    if info.kind == "band":
        typ: Any = BAND_TYPES[info.dimension]
    elif info.kind == "value":
        typ = QUANTITY_TYPES[info.dimension]
    else:
        raise ValueError(f"requirement kind {info.kind!r}: use 'band' or 'value'")
    if getattr(info, "valid", None) is not None:
        typ = Annotated[typ, AfterValidator(_in_range(info.valid, info.dimension))]
    if info.default is None:
        return (typ | None, Field(None, description=info.description))
    return (typ, Field(info.default, description=info.description))


def _in_range(valid: tuple[float, float], dimension: str):
    """Validator: a value (or a band's min and max) within ``valid`` (inclusive)."""
    lo, hi = valid
    deg = dimension == "angle"

    def shown(v: float) -> str:
        return f"{math.degrees(v):g} deg" if deg else f"{v:g}"

    def check(value: Any) -> Any:
        values = [value] if isinstance(value, int | float) else [value.min, value.max]
        for v in values:
            if v is not None and not lo <= v <= hi:
                raise ValueError(f"{shown(v)} is outside [{shown(lo)}, {shown(hi)}]")
        return value

    return check


@cache
def spec_model(mechanism_cls: type) -> type[ProblemSpec]:
    """The problem-file model of one mechanism class (cached per class).

    Its ``requirements`` gain the mechanism's :attr:`~Mechanism.requirements`;
    ``clearances`` takes the keys of its fixed clearances; ``tolerances`` and
    ``reference`` accept its variables and the framework's (drive, pin).
    """
    from optdesign.problem.variables import variable_table

    name = mechanism_cls.__name__
    req_fields = {k: _requirement_field(v) for k, v in mechanism_cls.requirements.items()}
    Req = create_model(f"{name}Requirements", __base__=Requirements, **req_fields)
    cl_fields: dict[str, Any] = {
        key: (QUANTITY_TYPES[dim], Field(0.0, ge=0.0, description=desc))
        for key, (dim, desc) in mechanism_cls.fixed_clearances.items()
    }
    Cl = create_model(f"{name}Clearances", __base__=_Model, **cl_fields)
    table = variable_table(mechanism_cls)
    tol_fields = {
        k: (TOLERANCE_TYPES[v.dimension] | None, None)
        for k, v in table.items()
        if v.dimension in TOLERANCE_TYPES
    }
    Tol = create_model(f"{name}Tolerances", __base__=Tolerances, **tol_fields)
    ref_fields = {k: (QUANTITY_TYPES[v.dimension] | None, None) for k, v in table.items()}
    Ref = create_model(f"{name}Reference", __base__=Reference, **ref_fields)
    return create_model(
        f"{name}ProblemSpec",
        __base__=ProblemSpec,
        requirements=(Req, ...),
        clearances=(Cl, Cl()),
        tolerances=(Tol | None, None),
        reference=(Ref | None, None),
    )
