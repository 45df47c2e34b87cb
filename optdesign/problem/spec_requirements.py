"""The requirements of a problem file (:mod:`optdesign.problem.spec`): what a design must
meet, whatever the mechanism (the mechanism's own come from its plug-in,
:func:`optdesign.problem.spec.spec_model`)."""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import (
    Field,
    field_validator,
    model_validator,
)

from optdesign.errors import InputError
from optdesign.models.clearance import BACKLASH
from optdesign.models.fit_formulas import Fit
from optdesign.problem.spec_drive import (
    DutyStep,
    MotorLock,
    ScrewSizing,
)
from optdesign.problem.spec_types import (
    POSITIVE_REQUIREMENTS,
    Angle,
    AngularSpeed,
    Band,
    Deflection,
    Dimensionless,
    Frequency,
    Length,
    Moment,
    Pressure,
    RotationalStiffness,
    Time,
    _Model,
    _shown,
    within,
)


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
    # the duty cycle's length (its steps' times are shares of it): the motor's thermal
    # model compares it with the winding's time constant
    duty_period: Time | None = None
    f_w: Dimensionless = Field(1.0, ge=1.0, le=3.0)
    stiffness_min: RotationalStiffness | None = None
    stiffness_load: Literal["hinge", "duty-mean"] = "hinge"
    inertia_ratio_max: Dimensionless | None = None
    natural_frequency_min: Frequency | None = None
    # the position loop (optdesign.problem.loop): at every grid angle
    bandwidth_min: Frequency | None = None
    phase_margin_min: Angle | None = None
    modulus_margin_min: Dimensionless | None = Field(None, gt=0.0, lt=1.0)
    resonance_margin_min: Dimensionless | None = None
    limit_cycle_amplitude_max: Angle | None = None

    @model_validator(mode="after")
    def _physical(self):
        # Limits and loads are magnitudes: a negative or zero one is a sign error that a
        # solver would otherwise turn into a constraint that never binds.
        for name in POSITIVE_REQUIREMENTS:
            value = getattr(self, name)
            if isinstance(value, int | float) and not value > 0:
                raise ValueError(f"{name}: must be positive, got {_shown(name, value)}")
        if self.backlash_max is not None:  # the backlash model's range (small angles)
            within(BACKLASH, math.degrees(self.backlash_max), "backlash_max")
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
        if self.duty_period is not None and not self.duty_cycle:
            raise ValueError(
                "duty_period: the length of a duty cycle; give the duty_cycle (deflection, "
                "hinge_moment, time) too"
            )
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
