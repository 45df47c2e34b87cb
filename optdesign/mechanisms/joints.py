"""Joints of a clearance chain and how their clearance reaches the output (seed 000
section 2; the Jacobian mapping of docs/clearance_and_backlash.md).

A joint contributes an output rotation ``theta = |S(phi)| * delta`` where ``delta`` is its
clearance (mm; rad for an angular joint) and ``S`` the kinematic sensitivity of the
output angle to that clearance (rad/mm), which the mechanism computes. A sized pin adds
its ISO 286 fit clearance and its contact deformation under the joint's force.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cache
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models._checks import require_positive
from optdesign.models.clearance import pin_joint_clearance, root_sum_square, worst_case
from optdesign.models.fits import Fit


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
    extra
        Clearance added to the fit's (mm), e.g. a sampled share of the fit's band.
    """

    d: Any
    L: Any
    fit: str = "H7/g6"
    which: str = "max"
    E: float = 2.1e5
    nu: float = 0.3
    surfaces: int = 2
    first_order: bool = False
    extra: Any = 0.0

    def __post_init__(self):
        require_positive("pin.d", self.d)
        require_positive("pin.L", self.L)
        require_positive("pin.E", self.E)
        if not m.is_symbolic(self.nu) and not 0.0 < float(self.nu) < 0.5:
            raise InputError("pin.nu", f"Poisson ratio must lie in (0, 0.5), got {self.nu!r}")
        Fit.parse(self.fit, "pin.fit")

    @staticmethod
    @cache
    def placeholder() -> PinJoint:
        """A pin that marks which joints a mechanism sizes (its values are never used)."""
        return PinJoint(1.0, 1.0)

    def clearance(self, F):
        """Effective clearance (mm) under normal force F (N)."""
        return self.extra + pin_joint_clearance(
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

    def fit_band(self):
        """(smallest, largest) fit clearance (mm) of this pin's diameter."""
        f = Fit.parse(self.fit)
        return f.clearance(self.d, "min"), f.clearance(self.d, "max")


@dataclass(frozen=True)
class Joint:
    """One link of a clearance chain, with the expressions the mechanism computed.

    Attributes
    ----------
    name
        Label, e.g. ``"D rod pin (arm)"``.
    key
        Key of its fixed clearance in a problem's ``[clearances]`` (the paper's letter,
        e.g. ``"A"``), or ``""`` for a sized pin.
    sensitivity
        Output rotation per unit clearance (rad/mm) over the grid; unused if angular.
    force
        Force carried by the joint (N) over the grid; loads a sized pin.
    pin
        The sized pin of the joint, if any.
    clearance
        Fixed clearance (mm; rad for an angular joint), added to the pin's.
    angular
        The clearance is an angle at the output itself (e.g. the output shaft's fit).
    """

    name: str
    key: str = ""
    sensitivity: Any = None
    force: Any = None
    pin: PinJoint | None = None
    clearance: Any = 0.0
    angular: bool = False

    def __post_init__(self):
        if not m.is_symbolic(self.clearance) and np.any(np.asarray(self.clearance) < 0):
            raise InputError(f"joint {self.name}.clearance", "must be >= 0")
        if not self.angular and self.sensitivity is None:
            raise InputError(f"joint {self.name}", "needs a sensitivity (rad/mm)")
        if self.pin is not None and self.force is None:
            raise InputError(f"joint {self.name}", "a pin joint needs the force it carries")

    def total_clearance(self):
        """Fixed clearance plus the pin's (fit and contact) under the joint's force (mm)."""
        c = self.clearance
        if self.pin is not None:
            c = c + self.pin.clearance(m.fabs(self.force))
        return c

    def rotation(self, phi):
        """Output rotation (rad) from this joint's clearance at each angle of ``phi``."""
        if self.angular:
            return self.clearance + 0.0 * phi
        return m.fabs(self.sensitivity) * self.total_clearance()


@dataclass
class Backlash:
    """Output backlash (degrees) at each grid angle: per joint, worst case and RSS."""

    per_joint: dict[str, Any] = field(default_factory=dict)
    worst_case: Any = None
    rss: Any = None


def backlash_of(joints: Sequence[Joint], phi) -> Backlash:
    """Backlash of a clearance chain: each joint's output rotation in degrees, their sum
    (worst case) and root-sum-square (statistical estimate)."""
    per_joint = {j.name: j.rotation(phi) * (180.0 / np.pi) for j in joints}
    parts = list(per_joint.values())
    return Backlash(per_joint, worst_case(parts), root_sum_square(parts))


def with_fixed_clearances(joints: Sequence[Joint], fixed: dict[str, Any]) -> list[Joint]:
    """The chain a problem sees: sized pins kept, fixed clearances set from ``fixed``
    (key -> value); joints with neither a pin nor a clearance dropped."""
    out = []
    for joint in joints:
        value = fixed.get(joint.key, 0.0) if joint.key else 0.0
        if joint.pin is not None:
            out.append(replace(joint, clearance=joint.clearance + value) if value else joint)
        elif value:
            out.append(replace(joint, clearance=value))
    return out


def with_sampled_fits(joints: Sequence[Joint], fractions: Sequence[Any]) -> list[Joint]:
    """Each sized pin at ``c_min + u (c_max - c_min)`` of its fit, ``u`` from ``fractions``
    in the order of the pins (robust design draws one fraction per pin)."""
    out, k = [], 0
    for joint in joints:
        if joint.pin is not None:
            lo, hi = joint.pin.fit_band()
            pin = replace(joint.pin, which="min", extra=joint.pin.extra + fractions[k] * (hi - lo))
            joint = replace(joint, pin=pin)
            k += 1
        out.append(joint)
    if k != len(fractions):
        raise InputError("tolerances.fit", f"{len(fractions)} fit draws for {k} pin joints")
    return out
