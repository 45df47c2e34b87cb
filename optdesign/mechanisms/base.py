"""The interface shared by the mechanisms, and their clearance chain."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models._checks import require_positive
from optdesign.models.clearance import pin_joint_clearance, root_sum_square, worst_case
from optdesign.models.fits import Fit
from optdesign.models.loads import force_from_rate, motor_torque
from optdesign.models.ratio import ratio_finite_step, ratio_from_nut_velocity, ratio_ripple

#: Joint kinds: how a clearance at the joint moves the output (see Mechanism.sensitivity).
JOINT_KINDS = ("rod_length", "axial", "lateral", "slot_normal", "angular")


@dataclass(frozen=True)
class PinJoint:
    """A pin in a bore: ISO 286 fit plus Hertz flattening under the joint's load.

    Parameters
    ----------
    d
        Pin diameter (mm); may be symbolic.
    L
        Loaded pin length (mm); may be symbolic.
    fit
        ISO 286 fit, e.g. ``"H7/g6"``.
    which
        ``"max"`` (largest clearance, worst case) or ``"min"``.
    E, nu
        Modulus (MPa) and Poisson ratio of the pin material.
    surfaces
        How many flattened surfaces to count (2: pin and bore).
    first_order
        Use the first-order flattening b^2/D (the GP form).
    """

    d: Any
    L: Any
    fit: str = "H7/g6"
    which: str = "max"
    E: float = 2.1e5
    nu: float = 0.3
    surfaces: int = 2
    first_order: bool = False

    def __post_init__(self):
        require_positive("pin.d", self.d)
        require_positive("pin.L", self.L)
        require_positive("pin.E", self.E)
        if not m.is_symbolic(self.nu) and not 0.0 < float(self.nu) < 0.5:
            raise InputError("pin.nu", f"Poisson ratio must lie in (0, 0.5), got {self.nu!r}")
        Fit.parse(self.fit, "pin.fit")

    def clearance(self, F):
        """Effective clearance (mm) under normal force F (N)."""
        return pin_joint_clearance(
            self.d,
            F,
            self.L,
            self.E,
            self.nu,
            self.fit,
            self.which,
            self.surfaces,
            self.first_order,
        )


@dataclass(frozen=True)
class Joint:
    """One link of a clearance chain.

    Parameters
    ----------
    name
        Label, e.g. ``"D"`` (the paper's letters) or ``"rod pin B"``.
    kind
        One of :data:`JOINT_KINDS`: what the clearance changes (``"rod_length"``: the
        effective rod length; ``"axial"``: nut position along the screw; ``"lateral"``:
        nut pin across the screw axis; ``"slot_normal"``: fork pin in its slot;
        ``"angular"``: the output shaft itself, clearance in rad).
    clearance
        A fixed clearance (mm, or rad for ``"angular"``), added to the pin's if any.
    pin
        A loaded pin, whose clearance depends on the joint force.
    load
        Which force loads the pin: ``"rod"``, ``"pin_normal"`` or ``"nut_axial"``.
    """

    name: str
    kind: str
    clearance: Any = 0.0
    pin: PinJoint | None = None
    load: str = "rod"

    def __post_init__(self):
        if self.kind not in JOINT_KINDS:
            raise InputError(f"joint {self.name}.kind", f"{self.kind!r} not in {JOINT_KINDS}")
        if not m.is_symbolic(self.clearance) and np.any(np.asarray(self.clearance) < 0):
            raise InputError(f"joint {self.name}.clearance", "must be >= 0")


@dataclass
class Backlash:
    """Output backlash (degrees) at each grid angle: per joint, worst case and RSS."""

    per_joint: dict[str, Any] = field(default_factory=dict)
    worst_case: Any = None
    rss: Any = None


class Mechanism(ABC):
    """What every mechanism offers: kinematics, loads, clearance sensitivities."""

    kind: str = ""
    p: Any
    i_a: Any
    phi0: Any

    # --- kinematics -------------------------------------------------------------
    @abstractmethod
    def nut_position(self, phi):
        """Nut position along the screw (mm)."""

    @abstractmethod
    def nut_velocity(self, phi):
        """dx/dphi of the nut (mm/rad)."""

    @abstractmethod
    def sensitivity(self, kind: str, phi):
        """Output rotation per unit clearance of a joint of ``kind`` (rad/mm)."""

    @abstractmethod
    def joint_force(self, load: str, phi, M_h):
        """Force (N) on a joint loaded by ``load`` under hinge moment M_h (N*mm)."""

    @abstractmethod
    def assembly_margin(self, phi):
        """Positive where the linkage assembles (mm^2)."""

    @abstractmethod
    def default_joints(self, pin: PinJoint | None = None) -> list[Joint]:
        """The paper's clearance chain of this mechanism (seed 000, Fig. 8 and 9)."""

    def ratio(self, phi):
        """Exact reduction ratio i(phi) = 2 pi i_a (dx/dphi) / p."""
        return ratio_from_nut_velocity(self.nut_velocity(phi), self.p, self.i_a)

    def ratio_finite_step(self, phi, step):
        """The papers' finite-step ratio (eq. 5 / eq. 9) with step ``step`` (rad)."""
        return ratio_finite_step(self.nut_position, phi, step, self.p, self.i_a)

    def ripple(self, phi):
        """Ratio ripple (i_max - i_min)/(i_max + i_min) over the grid ``phi``."""
        return ratio_ripple(self.ratio(phi))

    def nut_travel(self, phi_lo, phi_hi):
        """Nut travel |x(phi_hi) - x(phi_lo)| (mm)."""
        return m.fabs(self.nut_position(phi_hi) - self.nut_position(phi_lo))

    # --- loads ------------------------------------------------------------------
    def nut_force(self, phi, M_h):
        """Nut axial force (N) carrying the hinge moment M_h (N*mm), by virtual work."""
        return force_from_rate(M_h, self.nut_velocity(phi))

    def motor_torque(self, phi, M_h, eta_screw=1.0, eta_gear=1.0):
        """Motor torque (N*mm) to hold/drive the hinge moment M_h."""
        return motor_torque(self.nut_force(phi, M_h), self.p, self.i_a, eta_screw, eta_gear)

    # --- clearance ----------------------------------------------------------------
    def joint_clearance(self, joint: Joint, phi, M_h):
        """Clearance (mm) of ``joint`` at each angle under the hinge moment M_h."""
        c = joint.clearance
        if joint.pin is not None:
            F = m.fabs(self.joint_force(joint.load, phi, M_h))
            c = c + joint.pin.clearance(F)
        return c

    def backlash(self, phi, joints: list[Joint], M_h) -> Backlash:
        """Output backlash in degrees at every angle of ``phi``: per joint, worst case, RSS."""
        per_joint = {}
        for joint in joints:
            if joint.kind == "angular":
                theta = joint.clearance + 0.0 * phi
            else:
                theta = m.fabs(self.sensitivity(joint.kind, phi)) * self.joint_clearance(
                    joint, phi, M_h
                )
            per_joint[joint.name] = theta * (180.0 / np.pi)
        contributions = list(per_joint.values())
        return Backlash(per_joint, worst_case(contributions), root_sum_square(contributions))

    # --- checks -----------------------------------------------------------------
    def check_assembly(self, phi) -> None:
        """Raise AssemblyError at the first angle of ``phi`` where the linkage cannot
        assemble (numeric designs only)."""
        from optdesign.errors import AssemblyError

        phi = np.atleast_1d(np.asarray(phi, dtype=float))
        margin = np.asarray(self.assembly_margin(phi), dtype=float)
        margin = np.broadcast_to(margin, np.broadcast_shapes(margin.shape, phi.shape))
        bad = np.argwhere(~(margin > 0))
        if bad.size:
            idx = tuple(bad[0])
            raise AssemblyError(np.degrees(phi[idx[-1]]), margin[idx], self.describe())

    def describe(self) -> str:
        """Short text of the design, for messages."""
        return self.kind
