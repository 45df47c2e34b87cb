"""The drive's tables of a problem file (:mod:`optdesign.problem.spec`): pin and lug materials,
the screw and its sizing, the duty cycle and the motor's lock."""

from __future__ import annotations

from typing import Literal

from pydantic import (
    Field,
    model_validator,
)

from optdesign.models.lock import LOCK_FRICTION
from optdesign.models.lug_flexibility import LUG_THICKNESS
from optdesign.models.stiffness import MEMBER_STIFFNESS
from optdesign.models.validity import ELASTIC_MODULUS
from optdesign.problem.spec_types import (
    Angle,
    Dimensionless,
    Force,
    Length,
    Moment,
    Pressure,
    Stiffness,
    _Model,
    _shown,
    within,
)


class Material(_Model):
    """Elastic constants of a pin material (E within linear elasticity's range,
    :data:`~optdesign.models.validity.ELASTIC_MODULUS`)."""

    E: Pressure = 2.1e5
    nu: Dimensionless = 0.3

    @model_validator(mode="after")
    def _physical(self):
        if self.E <= 0:
            raise ValueError(f"E must be positive, got {self.E}")
        within(ELASTIC_MODULUS, self.E, "E")
        if not 0.0 < self.nu < 0.5:
            raise ValueError(f"nu must lie in (0, 0.5), got {self.nu}")
        return self


class Lug(_Model):
    """The lug (or clevis) around the sized pin, for ``pin_contact = "huth"`` (Huth's
    flexibility, :mod:`optdesign.models.lug_flexibility`). Single or double shear is the
    problem's ``pin_shear_planes`` (the mechanism's default unless the file sets it).
    Thicknesses and moduli within the model's ranges of validity
    (:data:`~optdesign.models.lug_flexibility.LUG_THICKNESS`,
    :data:`~optdesign.models.validity.ELASTIC_MODULUS`)."""

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
            record = LUG_THICKNESS if name.endswith("thickness") else ELASTIC_MODULUS
            within(record, value, name)
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
            if name.endswith("stiffness"):
                within(MEMBER_STIFFNESS, value, name)
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
    mu: Dimensionless = Field(0.3, gt=0.0)  # and at most 1 (LOCK_FRICTION, below)
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
        within(LOCK_FRICTION, self.mu, "mu")
        return self
