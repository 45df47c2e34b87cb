"""Shifting-fork (pin-in-slot) mechanism: lever R ([D17] Fig. 5)."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from optdesign import math as m
from optdesign.mechanisms.base import Mechanism, Sketch, VariableInfo
from optdesign.mechanisms.joints import Joint, PinJoint
from optdesign.mechanisms.registry import register_mechanism
from optdesign.models import fork
from optdesign.models.impossibility import ANGLE_TOL, Impossibility, NutVelocityBounds
from optdesign.models.impossibility import degrees_text as _deg
from optdesign.models.loads import fork_pin_normal_force


@register_mechanism
class ShiftingFork(Mechanism):
    """Shifting fork: the nut pin runs on a line at distance R from the output axis and
    slides in a slot of the output arm.

    Variables: R (perpendicular distance from the output axis to the pin's line), phi0
    (neutral angle, 0 in the paper, where the ratio is symmetric) and the drive's p, i_a.
    """

    name = "fork"
    title = "shifting fork"
    variables: ClassVar = {
        "R": VariableInfo("length", "lever: distance from the output axis to the pin's line"),
        "phi0": VariableInfo("angle", "neutral angle", positive=False, default=0.0),
    }
    pin_shear_planes = 1
    size_description = "lever size R"
    bench_families: ClassVar = {
        "fork_backlash": ("backlash",),
        "fork_size": ("size",),
        "fork_torque": ("motor_torque",),
        "fork_front": ("backlash", "size"),
    }

    @classmethod
    def bench_template(cls) -> tuple[dict[str, Any], dict[str, Any]]:
        """Variables of the benchmark's fork instances (it has no requirement of its own)."""
        return {"R": {"lower": "30 mm", "upper": "120 mm"}, "p": None}, {}

    def nut_position(self, phi):
        return fork.nut_position(self.R, phi, self.phi0)

    def nut_velocity(self, phi):
        return fork.nut_velocity(self.R, phi, self.phi0)

    def assembly_margin(self, phi):
        # The slot holds the pin while the arm is short of perpendicular to the screw:
        # margin cos(a) R^2 > 0 (mm^2).
        return m.cos(self.phi0 + phi) * self.R**2

    def pin_normal_force(self, phi, M_h):
        """Normal force of the pin on the slot (N), M_h cos(phi0 + phi)/R."""
        return fork_pin_normal_force(M_h, self.R, phi, self.phi0)

    def sensitivity_slot_normal(self, phi):
        """Output rotation per unit slot-normal clearance at the pin (rad/mm)."""
        return fork.sensitivity_slot_normal(self.R, phi, self.phi0)

    def joints(self, phi, M_h, pin: PinJoint | None = None) -> list[Joint]:
        """Seed 000 Fig. 9: A, B, O as the crank-slider's, C the pin in the slot."""
        axial = fork.sensitivity_axial(self.R, phi, self.phi0)
        return [
            Joint("A screw bearings", "A", sensitivity=axial),
            Joint("B screw/nut", "B", sensitivity=axial),
            Joint("O output shaft", "O", angular=True),
            Joint(
                "C pin in slot",
                "",
                sensitivity=self.sensitivity_slot_normal(phi),
                force=self.pin_normal_force(phi, M_h),
                pin=pin,
            ),
        ]

    def pin_force(self, phi, M_h):
        return self.pin_normal_force(phi, M_h)

    def size(self):
        return self.R

    def pin_positions(self, phi):
        """(end of the arm's line at the pin, pin) as ((x, y), (x, y)) in mm."""
        a = self.phi0 + phi
        pin = (self.nut_position(phi), self.R + 0.0 * phi)
        return (self.R * m.tan(a), self.R + 0.0 * phi), pin

    @classmethod
    def impossible(cls, stroke, requirements, bounds) -> list[Impossibility]:
        """The arm's pole. The nut sits at R tan(a), a = phi0 + phi, which holds only for
        |a| < 90 deg: no stroke of 180 deg or more can be turned, and phi0 must keep both
        ends of the stroke inside (-90, 90) deg."""
        lo, hi = stroke
        if hi - lo >= np.pi - ANGLE_TOL:
            reason = (
                "the nut of a shifting fork sits at R tan(phi0 + phi), which has its poles "
                f"at -90 and 90 deg: a stroke of {_deg(hi - lo)} deg cannot lie between them"
            )
            return [Impossibility(("deflection",), reason, ("a stroke of less than 180 deg",))]
        window = (-np.pi / 2 - lo, np.pi / 2 - hi)
        p_lo, p_hi = bounds["phi0"]
        if p_hi <= window[0] + ANGLE_TOL or p_lo >= window[1] - ANGLE_TOL:
            reason = (
                "the arm phi0 + phi stays between the poles of R tan(phi0 + phi) at -90 and "
                f"90 deg over the stroke only with phi0 between {_deg(window[0])} and "
                f"{_deg(window[1])} deg (exclusive), and its bounds are {_deg(p_lo)} to "
                f"{_deg(p_hi)} deg"
            )
            remedy = f"bounds of phi0 that reach inside {_deg(window[0])} to {_deg(window[1])} deg"
            return [Impossibility(("variables.phi0", "deflection"), reason, (remedy,))]
        return []

    @classmethod
    def nut_velocity_bounds(cls, stroke, requirements, bounds) -> NutVelocityBounds | None:
        """dx/dphi = R / cos^2(a), a = phi0 + phi: at least the arm's lower bound (at a =
        0) and at most its upper bound over cos^2 of the widest arm angle phi0's bounds
        and the stroke allow (none when that reaches a pole)."""
        (R_lo, R_hi), (p_lo, p_hi) = bounds["R"], bounds["phi0"]
        widest = max(abs(p_lo + stroke[0]), abs(p_hi + stroke[1]))
        upper = R_hi / np.cos(widest) ** 2 if widest < np.pi / 2 - ANGLE_TOL else np.inf
        reason = (
            f"a shifting fork's nut velocity R / cos^2(phi0 + phi) lies between R's lower "
            f"bound, {R_lo:.4g} mm/rad, and R's upper bound over cos^2 of the widest arm "
            f"angle, {R_hi:.4g} / cos^2({_deg(widest)} deg) = {upper:.4g} mm/rad"
        )
        return NutVelocityBounds(R_lo, upper, reason, ("variables.R", "variables.phi0"))

    def sketch(self, phi: float) -> Sketch:
        with np.errstate(invalid="ignore"):
            x = float(self.nut_position(np.asarray(phi, dtype=float)))
        R = float(self.R)
        return Sketch(
            links=[[(0.0, 0.0), (x, R)]],
            pivots=[(0.0, 0.0)],
            slider=(x, R),
            axis=((min(x, 0.0) - 0.3 * R, R), (max(x, 0.0) + 0.3 * R, R)),
        )
