"""Shifting-fork (pin-in-slot) mechanism: lever R (seed 000 Fig. 5)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.mechanisms.base import Joint, Mechanism, PinJoint
from optdesign.models import fork
from optdesign.models._checks import require_finite, require_positive
from optdesign.models.loads import fork_pin_normal_force


@dataclass
class ShiftingFork(Mechanism):
    """Shifting fork: the nut pin runs on a line at distance R from the output axis and
    slides in a slot of the output arm.

    Parameters
    ----------
    R
        Perpendicular distance from the output axis to the pin's line (mm).
    p
        Screw lead (mm).
    i_a
        Gear ratio motor -> screw.
    phi0
        Neutral angle (rad), 0 in the paper (then the ratio is symmetric).
    """

    R: Any
    p: Any
    i_a: Any = 1.0
    phi0: Any = 0.0
    kind = "fork"

    def __post_init__(self):
        for name in ("R", "p", "i_a"):
            require_positive(name, getattr(self, name))
        require_finite("phi0", self.phi0)

    def nut_position(self, phi):
        return fork.nut_position(self.R, phi, self.phi0)

    def nut_velocity(self, phi):
        return fork.nut_velocity(self.R, phi, self.phi0)

    def assembly_margin(self, phi):
        # The slot holds the pin while the arm is short of perpendicular to the screw:
        # margin cos(a) R^2 > 0 (mm^2).
        return m.cos(self.phi0 + phi) * self.R**2

    def pin_normal_force(self, phi, M_h):
        """Normal force of the pin on the slot (N), M_h cos(phi)/R."""
        return fork_pin_normal_force(M_h, self.R, phi, self.phi0)

    def pin_positions(self, phi):
        """(O->pin direction end, pin) as ((x, y), (x, y)) in mm."""
        a = self.phi0 + phi
        pin = (self.nut_position(phi), self.R + 0.0 * phi)
        return (self.R * m.tan(a), self.R + 0.0 * phi), pin

    def joint_force(self, load, phi, M_h):
        if load in ("pin_normal", "rod"):
            return self.pin_normal_force(phi, M_h)
        if load == "nut_axial":
            return self.nut_force(phi, M_h)
        raise InputError("joint.load", f"{load!r} is not a load of a fork (pin_normal, nut_axial)")

    def sensitivity(self, kind, phi):
        if kind == "slot_normal":
            return fork.sensitivity_slot_normal(self.R, phi, self.phi0)
        if kind == "axial":
            return fork.sensitivity_axial(self.R, phi, self.phi0)
        raise InputError("joint.kind", f"{kind!r} has no meaning for a shifting fork")

    def default_joints(self, pin: PinJoint | None = None) -> list[Joint]:
        """Seed 000 Fig. 9: A, B, O as the crank-slider's, C the pin in the slot."""
        return [
            Joint("A screw bearings", "axial"),
            Joint("B screw/nut", "axial"),
            Joint("O output shaft", "angular"),
            Joint("C pin in slot", "slot_normal", pin=pin, load="pin_normal"),
        ]

    def check_assembly(self, phi) -> None:
        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        if np.any(np.abs(np.asarray(self.phi0) + phi) >= np.pi / 2):
            super().check_assembly(phi)

    def describe(self) -> str:
        return f"shifting fork R={self.R}"
