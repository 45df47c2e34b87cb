"""Crank-slider mechanism: arm R, rod l, offset n, neutral angle phi0 (seed 000 Fig. 2)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.mechanisms.base import Joint, Mechanism, PinJoint
from optdesign.models import crank_slider as cs
from optdesign.models._checks import require_finite, require_positive
from optdesign.models.loads import force_from_rate


@dataclass
class CrankSlider(Mechanism):
    """Crank-slider linkage driven by a ball screw.

    Parameters
    ----------
    R
        Arm (rocker) length OB (mm).
    l
        Rod length BC (mm).
    n
        Offset: distance between the output-shaft axis and the screw axis (mm).
    p
        Screw lead (mm).
    i_a
        Gear ratio motor -> screw.
    phi0
        Neutral angle of the arm (rad); the arm sits at phi0 + phi.
    floor
        Guard for sqrt(l^2 - u^2) used by solvers (None: no guard, NaN where it
        cannot assemble).
    """

    R: Any
    l: Any
    n: Any
    p: Any
    i_a: Any = 1.0
    phi0: Any = 0.0
    floor: float | None = None
    kind = "crank_slider"

    def __post_init__(self):
        for name in ("R", "l", "p", "i_a"):
            require_positive(name, getattr(self, name))
        require_finite("n", self.n)
        require_finite("phi0", self.phi0)

    def _args(self):
        return self.R, self.l, self.n

    def nut_position(self, phi):
        return cs.nut_position(*self._args(), phi, self.phi0, self.floor)

    def nut_velocity(self, phi):
        return cs.nut_velocity(*self._args(), phi, self.phi0, self.floor)

    def assembly_margin(self, phi):
        return cs.assembly_margin(*self._args(), phi, self.phi0)

    def rod_run(self, phi):
        """Rod extent along the screw axis, sqrt(l^2 - u^2) (mm)."""
        return cs.rod_run(*self._args(), phi, self.phi0, self.floor)

    def rod_length_rate(self, phi):
        """d|BC|/dphi with the nut held (mm/rad)."""
        return cs.rod_length_rate(*self._args(), phi, self.phi0, self.floor)

    def transmission_angle(self, phi):
        """Angle between arm and rod at B (rad)."""
        return cs.transmission_angle(*self._args(), phi, self.phi0, self.floor)

    def rod_inclination(self, phi):
        """Signed inclination of the rod to the screw axis (rad)."""
        return cs.rod_inclination(*self._args(), phi, self.phi0, self.floor)

    def pin_positions(self, phi):
        """(B, C) coordinates of the arm pin and nut pin, each a pair (x, y) in mm."""
        a = cs.arm_angle(phi, self.phi0)
        B = (self.R * m.sin(a), self.R * m.cos(a))
        C = (self.nut_position(phi), self.n + 0.0 * phi)
        return B, C

    def rod_force(self, phi, M_h):
        """Axial force of the rod (N), M_h / (d|BC|/dphi)."""
        return force_from_rate(M_h, self.rod_length_rate(phi))

    def joint_force(self, load, phi, M_h):
        if load == "rod":
            return self.rod_force(phi, M_h)
        if load == "nut_axial":
            return self.nut_force(phi, M_h)
        raise InputError("joint.load", f"{load!r} is not a load of a crank-slider (rod, nut_axial)")

    def sensitivity(self, kind, phi):
        args = (*self._args(), phi, self.phi0, self.floor)
        if kind == "rod_length":
            return cs.sensitivity_rod_length(*args)
        if kind == "axial":
            return cs.sensitivity_axial(*args)
        if kind == "lateral":
            return cs.sensitivity_lateral(*args)
        raise InputError("joint.kind", f"{kind!r} has no meaning for a crank-slider")

    def default_joints(self, pin: PinJoint | None = None) -> list[Joint]:
        """Seed 000 Fig. 8: A (screw bearings) and B (screw/nut) preloaded, C (nut slide)
        small, O (output shaft) ~0, D and E the two rod pins (the main source)."""
        return [
            Joint("A screw bearings", "axial"),
            Joint("B screw/nut", "axial"),
            Joint("C nut slide", "lateral"),
            Joint("O output shaft", "angular"),
            Joint("D rod pin (arm)", "rod_length", pin=pin, load="rod"),
            Joint("E rod pin (nut)", "rod_length", pin=pin, load="rod"),
        ]

    def describe(self) -> str:
        return f"crank-slider R={self.R}, l={self.l}, n={self.n}, phi0={self.phi0}"
