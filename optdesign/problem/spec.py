"""Schema of a problem file, validated with pydantic; every quantity may carry a unit.

Quantities are converted to the internal units (mm, N, MPa, N*mm, rad) on load by
:func:`optdesign.units.to_internal`; a bare number is taken as already internal.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationInfo,
    field_validator,
    model_validator,
)

from optdesign.errors import InputError
from optdesign.models.fits import Fit
from optdesign.units import to_internal


def _quantity(dimension: str):
    def convert(value: Any, info: ValidationInfo) -> float:
        try:
            return to_internal(value, dimension, info.field_name or dimension)
        except InputError as exc:
            raise ValueError(exc.reason) from None

    return BeforeValidator(convert)


Length = Annotated[float, _quantity("length")]
Angle = Annotated[float, _quantity("angle")]
Moment = Annotated[float, _quantity("moment")]
Pressure = Annotated[float, _quantity("pressure")]
Force = Annotated[float, _quantity("force")]
Dimensionless = Annotated[float, _quantity("dimensionless")]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


#: Design variables of the crank-slider, and their dimension.
_CRANK_SLIDER_VARIABLES: dict[str, str] = {
    "R": "length",
    "l": "length",
    "n": "length",
    "p": "length",
    "phi0": "angle",
    "i_a": "dimensionless",
    "d": "length",
    "pin_length": "length",
    "pin_length_ratio": "dimensionless",
}

#: Design variables each mechanism knows. The fork has no rod and no offset: its lever
#: R is the distance from the output axis to the pin's line.
VARIABLE_DIMENSIONS: dict[str, dict[str, str]] = {
    "crank_slider": _CRANK_SLIDER_VARIABLES,
    "fork": {k: v for k, v in _CRANK_SLIDER_VARIABLES.items() if k not in ("l", "n")},
}

#: What each variable is, for tables and errors.
VARIABLE_DESCRIPTIONS: dict[str, str] = {
    "R": "arm length",
    "l": "rod length",
    "n": "offset of the screw axis",
    "p": "screw lead",
    "phi0": "neutral angle",
    "i_a": "gear ratio",
    "d": "pin diameter",
    "pin_length": "pin length L",
    "pin_length_ratio": "pin length ratio L/d",
}

#: Objective names a problem may minimise.
OBJECTIVES = (
    "ripple",
    "backlash",
    "backlash_rss",
    "size",
    "nut_travel",
    "motor_torque",
    "lock_force",
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

    min: float | None = None
    max: float | None = None


class AngleBand(_OrderedBand):
    """An angle band [min, max] (rad once parsed)."""

    min: Angle | None = None
    max: Angle | None = None


class Material(_Model):
    """Elastic constants of a pin material."""

    E: Pressure = 2.1e5
    nu: float = 0.3

    @model_validator(mode="after")
    def _physical(self):
        if self.E <= 0:
            raise ValueError(f"E must be positive, got {self.E}")
        if not 0.0 < self.nu < 0.5:
            raise ValueError(f"nu must lie in (0, 0.5), got {self.nu}")
        return self


class Materials(_Model):
    pin: Material = Material()


class Clearances(_Model):
    """Fixed clearances of the joints that are not sized by the problem (seed 000 Fig. 8-9).

    A, B: axial (screw bearings, screw/nut), C: nut slide across the screw axis
    (crank-slider), O: output shaft (angle).
    """

    A: Length = 0.0
    B: Length = 0.0
    C: Length = 0.0
    O: Angle = 0.0


class ScrewSizing(_Model):
    """Catalogue sizing checks of the screw shaft under the nut force (physics.md 8)."""

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


class MotorLock(_Model):
    """Power-off lock on the motor shaft (seed 002): what it must hold and its force."""

    kind: Literal["friction_plate", "pin", "pin_rolling"]
    radius: Length | None = None
    r1: Length | None = None
    r2: Length | None = None
    mu: float = Field(0.3, gt=0.0)
    eta_screw_back: float = Field(1.0, le=1.0)
    eta_gear_back: float = Field(1.0, gt=0.0, le=1.0)
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
        return self


class Requirements(_Model):
    """What a design must meet. Omitted requirements are not imposed."""

    deflection: Deflection
    hinge_moment: Moment
    mean_ratio: Band | None = None
    nut_travel_max: Length | None = None
    transmission_angle: AngleBand | None = None
    rod_inclination_max: Angle | None = None
    assembly_margin_min: float = Field(
        0.01, ge=0.0, lt=1.0, description="smallest (l^2 - u^2)/l^2 over the grid"
    )
    pin_bearing_pressure_max: Pressure | None = None
    pin_shear_stress_max: Pressure | None = None
    pin_shear_planes: int | None = Field(None, ge=1, le=2)
    motor_torque_max: Moment | None = None
    eta_screw: float = Field(1.0, gt=0.0, le=1.0)
    eta_gear: float = Field(1.0, gt=0.0, le=1.0)
    backlash_max: Angle | None = None
    ripple_max: float | None = Field(None, gt=0.0)
    fit: str = "H7/g6"
    fit_clearance: Literal["min", "max"] = "max"
    screw: ScrewSizing | None = None
    lock: MotorLock | None = None

    @field_validator("fit")
    @classmethod
    def _fit(cls, value: str) -> str:
        try:
            Fit.parse(value)
        except InputError as exc:
            raise ValueError(exc.reason) from None
        return value


class Objective(_Model):
    """Objective(s) to minimise; several for Pareto fronts."""

    minimize: list[Literal[OBJECTIVES]]  # type: ignore[valid-type]

    @model_validator(mode="before")
    @classmethod
    def _listify(cls, data):
        if isinstance(data, dict) and isinstance(data.get("minimize"), str):
            data = dict(data, minimize=[data["minimize"]])
        return data


class SolverOptions(_Model):
    """Defaults of ``optdesign solve`` for this problem (the CLI may override them)."""

    starts: int = Field(8, ge=1, le=10_000)
    seed: int = 0
    ipopt: dict[str, Any] = Field(default_factory=dict)


def _band_table(data: Any) -> Any:
    # ``R = "0.05 mm"`` is short for ``R = { band = "0.05 mm" }``.
    return {"band": data} if isinstance(data, str | int | float) else data


class _Tolerance(_Model):
    @model_validator(mode="after")
    def _non_negative(self):
        if self.band < 0:  # type: ignore[attr-defined]
            raise ValueError(f"band must be >= 0, got {self.band}")  # type: ignore[attr-defined]
        return self


class LengthTolerance(_Tolerance):
    """Manufacturing tolerance +-band of a length: uniform on [-band, band] or normal with
    sigma = band/3 (a process capability Cp = 1)."""

    band: Length
    distribution: Literal["normal", "uniform"] = "normal"


class AngleTolerance(_Tolerance):
    """Manufacturing tolerance +-band of an angle (see :class:`LengthTolerance`)."""

    band: Angle
    distribution: Literal["normal", "uniform"] = "normal"


_LengthTol = Annotated[LengthTolerance, BeforeValidator(_band_table)]
_AngleTol = Annotated[AngleTolerance, BeforeValidator(_band_table)]


class Tolerances(_Model):
    """Manufacturing scatter of a design, for robust design (formulations/robust.py).

    R, l, n, p, d: length tolerances; phi0: angle tolerance. ``fit = "uniform"`` draws
    each pin joint's fit clearance uniformly between the fit's smallest and largest
    clearance (``"fixed"``: the requirement's ``fit_clearance``). ``samples`` and ``seed``
    fix the sample-average approximation; ``risk`` is the minimised statistic of the
    objective over the samples: ``"cvar"`` (mean of the worst 1 - alpha) or
    ``"mean_std"`` (mean + k std).
    """

    R: _LengthTol | None = None
    l: _LengthTol | None = None
    n: _LengthTol | None = None
    p: _LengthTol | None = None
    d: _LengthTol | None = None
    phi0: _AngleTol | None = None
    fit: Literal["fixed", "uniform"] = "fixed"
    samples: int = Field(32, ge=1, le=2000)
    seed: int = 0
    risk: Literal["cvar", "mean_std"] = "cvar"
    alpha: float = Field(0.9, ge=0.0, lt=1.0)
    k: float = Field(2.0, ge=0.0)


class ProblemSpec(_Model):
    """A whole problem file."""

    name: str
    description: str = ""
    mechanism: Literal["crank_slider", "fork"]
    variables: dict[str, Any]
    requirements: Requirements
    materials: Materials = Materials()
    clearances: Clearances = Clearances()
    objective: Objective
    solver: SolverOptions = SolverOptions()
    tolerances: Tolerances | None = None
    #: A design to compare with (e.g. a paper's); checked by optdesign.studies.reference.
    reference: dict[str, Any] | None = None
