"""Trunnion-mounted (pivoting) screw actuator pushing a horn: the most common layout of fin
actuators. Written against the public mechanism contract only.

The output shaft's axis O is the origin. The horn (arm) of radius R carries the pin B at
``(R sin a, R cos a)``, ``a = phi0 + phi``. The actuator - motor, screw and nut in one
body - pivots on trunnions at T = (a_T, b_T) and pushes B; its length between the pivot
and the horn pin is the drive coordinate:

    L(phi)     = |B - T| = sqrt((R sin a - a_T)^2 + (R cos a - b_T)^2)
    dL/dphi    = R (b_T sin a - a_T cos a) / L

dL/dphi is also the lever arm of the actuator's force about O (virtual work), so the
ratio is ``2 pi i_a (dL/dphi) / p`` and the nut force ``M_h / (dL/dphi)``. Both pins -
the horn pin at B and the trunnion at T - carry that force along the actuator, and a
clearance in either lengthens the actuator by itself: its output rotation is
``delta / (dL/dphi)``. The transmission angle is the angle at B between the horn (B->O)
and the actuator (B->T).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from optdesign import math as m
from optdesign.mechanisms.base import Mechanism, RequirementInfo, Rows, Sketch, VariableInfo
from optdesign.mechanisms.joints import Joint, PinJoint
from optdesign.mechanisms.registry import register_mechanism
from optdesign.models.impossibility import ANGLE_TOL, Impossibility, NutVelocityBounds
from optdesign.models.impossibility import degrees_text as _deg


@register_mechanism
class PivotingScrew(Mechanism):
    """Trunnion-mounted screw actuator pushing a horn of radius R.

    Variables: R (horn radius), a_T and b_T (the trunnion pivot from the output axis:
    along the neutral horn's normal and along the neutral horn), phi0 (neutral horn angle)
    and the drive's p, i_a. The actuator extends as phi grows when the pivot lies behind
    the horn (a_T < 0).
    """

    name = "pivoting_screw"
    title = "pivoting screw"
    variables: ClassVar = {
        "R": VariableInfo("length", "horn radius"),
        "a_T": VariableInfo("length", "trunnion pivot abscissa", positive=False),
        "b_T": VariableInfo("length", "trunnion pivot ordinate", positive=False),
        "phi0": VariableInfo("angle", "neutral horn angle", positive=False, default=0.0),
    }
    requirements: ClassVar = {
        "transmission_angle": RequirementInfo(
            "band",
            "angle",
            "angle between horn and actuator at the horn pin",
            valid=(0.0, np.pi),
        ),
        "dead_length": RequirementInfo(
            "value",
            "length",
            "shortest actuator length minus its stroke (body, bearings, nut)",
            valid=(0.0, np.inf),
        ),
    }
    pin_shear_planes = 2
    size_description = "envelope radius R + |OT|"
    bench_families: ClassVar = {"pivot_backlash": ("backlash",)}

    def _horn(self, phi):
        a = self.phi0 + phi
        return self.R * m.sin(a), self.R * m.cos(a)

    def nut_position(self, phi):
        bx, by = self._horn(phi)
        return m.sqrt_domain((bx - self.a_T) ** 2 + (by - self.b_T) ** 2)

    def nut_velocity(self, phi):
        a = self.phi0 + phi
        return self.R * (self.b_T * m.sin(a) - self.a_T * m.cos(a)) / self.nut_position(phi)

    def joints(self, phi, M_h, pin: PinJoint | None = None) -> list[Joint]:
        """A, B axial (screw bearings, screw/nut), O the output shaft; the horn pin and the
        trunnion, both along the actuator's line of action."""
        s = self.sensitivity_axial(phi)
        F = self.nut_force(phi, M_h)
        return [
            Joint("A screw bearings", "A", sensitivity=s),
            Joint("B screw/nut", "B", sensitivity=s),
            Joint("O output shaft", "O", angular=True),
            Joint("horn pin", "", sensitivity=s, force=F, pin=pin),
            Joint("trunnion", "", sensitivity=s, force=F, pin=pin),
        ]

    def pin_force(self, phi, M_h):
        return self.nut_force(phi, M_h)

    def transmission_angle_cos(self, phi):
        """cos of the angle at B between B->O and B->T."""
        bx, by = self._horn(phi)
        dot = (-bx) * (self.a_T - bx) + (-by) * (self.b_T - by)
        return dot / (self.R * self.nut_position(phi))

    @classmethod
    def impossible(cls, stroke, requirements, bounds) -> list[Impossibility]:
        """The triangle's angle at the output axis. The horn pin B, the axis O and the
        trunnion T make a triangle whose angle at O changes by the stroke (the horn turns
        about O) and whose angle at B is the transmission angle. The ratio is positive
        only while that angle at O stays inside (0, 180) deg (at 0 or 180 deg O, B and T
        align: a dead point), and the three angles sum to 180 deg, so with the
        transmission angle at least gamma_min it stays below 180 deg - gamma_min: no
        stroke of that width or more can be turned."""
        lo, hi = stroke
        band = requirements.get("transmission_angle")
        gamma = band.min if band is not None and band.min is not None else 0.0
        if hi - lo >= np.pi - gamma - ANGLE_TOL:
            named = ("deflection",) + ("transmission_angle",) * (gamma > 0.0)
            reason = (
                "the angle at the output axis of the triangle (axis, horn pin, trunnion) "
                f"changes by the stroke, {_deg(hi - lo)} deg, and stays between 0 and 180 deg "
                f"less the least transmission angle ({_deg(gamma)} deg): at most "
                f"{_deg(np.pi - gamma)} deg"
            )
            remedies = [f"a stroke of less than {_deg(np.pi - gamma)} deg"]
            if gamma > 0.0 and hi - lo < np.pi - ANGLE_TOL:
                remedies.append(f"a least transmission angle below {_deg(np.pi - (hi - lo))} deg")
            return [Impossibility(named, reason, tuple(remedies))]
        return []

    @classmethod
    def nut_velocity_bounds(cls, stroke, requirements, bounds) -> NutVelocityBounds | None:
        """dL/dphi is the actuator's lever arm about the output axis, R sin(transmission
        angle): at most the horn radius's upper bound."""
        R_hi = bounds["R"][1]
        reason = (
            "a pivoting screw's dL/dphi is its lever arm about the output axis, R sin(the "
            f"transmission angle), at most R's upper bound, {R_hi:.4g} mm/rad"
        )
        return NutVelocityBounds(0.0, R_hi, reason, ("variables.R",))

    def requirement_rows(self, name: str, value: Any, phi) -> list[Rows]:
        if name == "transmission_angle":
            return [
                Rows(
                    "transmission_angle",
                    self.transmission_angle_cos(phi),
                    None if value.max is None else float(np.cos(value.max)),
                    None if value.min is None else float(np.cos(value.min)),
                    "",
                    "transmission angle (horn to actuator)",
                    display=lambda c: np.degrees(np.arccos(np.clip(c, -1.0, 1.0))),
                    display_unit="deg",
                )
            ]
        if name == "dead_length":
            L = self.nut_position(phi)
            stroke = self.nut_travel(phi[0], phi[-1])
            return [
                Rows(
                    "dead_length",
                    L - stroke,
                    float(value),
                    None,
                    "mm",
                    "actuator length minus stroke",
                )
            ]
        return super().requirement_rows(name, value, phi)

    def size(self):
        return self.R + m.sqrt(self.a_T**2 + self.b_T**2)

    def sketch(self, phi: float) -> Sketch:
        bx, by = (float(v) for v in self._horn(float(phi)))
        T = (float(self.a_T), float(self.b_T))
        return Sketch(
            links=[[(0.0, 0.0), (bx, by)], [T, (bx, by)]],
            pivots=[(0.0, 0.0), T],
            slider=(bx, by),
            axis=(T, (bx, by)),
        )

    @classmethod
    def bench_template(cls) -> tuple[dict[str, Any], dict[str, Any]]:
        variables = {
            "R": {"lower": "30 mm", "upper": "120 mm"},
            "a_T": {"lower": "-300 mm", "upper": "-40 mm"},
            "b_T": {"lower": "-100 mm", "upper": "150 mm"},
            "p": None,
            "phi0": {"lower": "-0.6 rad", "upper": "0.6 rad"},
        }
        requirements = {
            "transmission_angle": {"min": "40 deg", "max": "140 deg"},
            "dead_length": "60 mm",
        }
        return variables, requirements
