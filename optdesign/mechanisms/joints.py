"""Joints of a clearance chain and how their clearance reaches the output ([D17]
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
from optdesign.models import pin_contact
from optdesign.models._checks import require_positive
from optdesign.models.clearance import root_sum_square, worst_case
from optdesign.models.fit_formulas import Fit
from optdesign.models.hertz_line import (
    contact_half_width,
    pin_flattening,
    pin_flattening_first_order,
)
from optdesign.models.lug_flexibility import Lug

#: Contact models of a loaded pin (``requirements.pin_contact``).
CONTACT_MODELS = ("duan2017", "conforming", "palmgren", "huth")


def _numeric(value) -> bool:
    """A plain number or NumPy array (not a CasADi symbol nor a GP tracer)."""
    return not m.is_symbolic(value) and np.asarray(value).dtype.kind in "fiu"


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
    contact
        ``"duan2017"``: [D17] eq. 10-11, a cylinder on a flat (``surfaces`` x Delta);
        ``"conforming"``: the pin in its bore with the fit's clearance
        (:mod:`optdesign.models.pin_contact`), the elastic approach of the pair;
        ``"palmgren"``: Palmgren's empirical approach of a steel line contact,
        3.84e-5 F^0.9 / L^0.8 ([P59]; the bulk compression included, steel only);
        ``"huth"``: Huth's flexibility of the pin in its lug or clevis, C F
        (:mod:`optdesign.models.lug_flexibility`; pin bending and shear and the lugs'
        bearing deformation included), which needs ``lug``.
    values
        ISO 286 values: ``"smooth"`` (the formulas at D) or ``"table"`` (as ISO 286-2
        prints them; a symbolic D takes the smooth value times ``ratio_max`` /
        ``ratio_min``, the table's ratio that the catalogue search sets per solve).
    lug
        The members around the pin (thicknesses, moduli, shear planes), for
        ``contact = "huth"``.
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
    contact: str = "duan2017"
    values: str = "smooth"
    ratio_max: Any = 1.0
    ratio_min: Any = 1.0
    lug: Lug | None = None

    def __post_init__(self):
        require_positive("pin.d", self.d)
        require_positive("pin.L", self.L)
        require_positive("pin.E", self.E)
        if not m.is_symbolic(self.nu) and not 0.0 < float(self.nu) < 0.5:
            raise InputError("pin.nu", f"Poisson ratio must lie in (0, 0.5), got {self.nu!r}")
        Fit.parse(self.fit, "pin.fit", values=self.values)
        if self.contact not in CONTACT_MODELS:
            raise InputError("pin.contact", f"{self.contact!r}: use one of {CONTACT_MODELS}")
        if self.contact == "palmgren" and not m.is_symbolic(self.E):
            if not pin_contact.PALMGREN_MODULUS.contains(float(self.E)):
                raise InputError(
                    "materials.pin.E",
                    f"Palmgren's approach is an empirical law of steel (E about 2.1e5 MPa), "
                    f"got {float(self.E):g} MPa; use pin_contact duan2017 or conforming",
                )
        if self.contact == "huth" and self.lug is None:
            raise InputError(
                "materials.lug",
                'pin_contact "huth" needs the lug around the pin: give [materials.lug] '
                "cheek_thickness (and thickness, E where they differ from the pin's L, E)",
            )

    @staticmethod
    @cache
    def placeholder() -> PinJoint:
        """A pin that marks which joints a mechanism sizes (its values are never used)."""
        return PinJoint(1.0, 1.0)

    def fit_clearance(self, which: str | None = None):
        """Diametral clearance of the fit (mm), ``which`` = "max" or "min"."""
        which = which or self.which
        if self.values == "table" and _numeric(self.d):
            from optdesign.fits import clearance

            return clearance(self.fit, self.d, which, values="table")
        ratio = self.ratio_max if which == "max" else self.ratio_min
        fit = Fit.parse(self.fit, values=self.values)
        if not fit.has_smooth:
            # A table-only fit (r, s, R, S letters) has no formula in d: the parameter is
            # the table's clearance itself (mm), set per solve from the node's items.
            return ratio + 0.0 * self.d
        return fit.clearance(self.d, which) * ratio

    def clearance(self, F):
        """Effective clearance (mm) under normal force F (N): the fit's, plus the contact
        deformation of the chosen model."""
        c = self.fit_clearance()
        if self.contact == "conforming":
            approach = pin_contact.approach(F, self.L, 0.5 * self.d, 0.5 * c, self.E, self.nu)
            return self.extra + c + approach
        if self.contact == "palmgren":
            return self.extra + c + pin_contact.palmgren_approach(F, self.L)
        if self.contact == "huth":
            return self.extra + c + self.lug_compliance() * F
        flat = pin_flattening_first_order if self.first_order else pin_flattening
        return self.extra + c + self.surfaces * flat(self.d, F, self.L, self.E, self.nu)

    def contact_stiffness(self, F):
        """dF/d(clearance) of the loaded pin (N/mm): how the joint yields under its load."""
        if self.contact == "conforming":
            c = self.fit_clearance()
            return pin_contact.contact_stiffness(F, self.L, 0.5 * self.d, 0.5 * c, self.E, self.nu)
        if self.contact == "palmgren":
            return pin_contact.palmgren_stiffness(F, self.L)
        if self.contact == "huth":
            return 1.0 / self.lug_compliance() + 0.0 * F
        # Delta = D/2 - sqrt(D^2/4 - k F) (eq. 11): dDelta/dF = k / (2 sqrt(D^2/4 - k F))
        k = 4.0 * self.d * (1.0 - self.nu**2) / (np.pi * self.E * self.L)
        root = m.sqrt_domain(0.25 * self.d**2 - k * F)
        return 2.0 * root / (self.surfaces * k)

    def contact_pressure(self, F):
        """Largest contact pressure (MPa) under F: Hertz line contact (eq. 10; also for
        Palmgren's and Huth's approaches, which give no pressure) or the conforming
        solution."""
        if self.contact == "conforming":
            c = self.fit_clearance()
            return pin_contact.max_pressure(F, self.L, 0.5 * self.d, 0.5 * c, self.E, self.nu)
        b = contact_half_width(self.d, F, self.L, self.E, self.nu)
        return 2.0 * F / (np.pi * b * self.L)

    def lug_compliance(self):
        """Huth's compliance of the pin in its lug (mm/N; needs ``lug``)."""
        if self.lug is None:
            raise InputError("materials.lug", "Huth's model needs the lug around the pin")
        return self.lug.compliance(self.d, self.L, self.E)

    def fit_band(self):
        """(smallest, largest) fit clearance (mm) of this pin's diameter."""
        return self.fit_clearance("min"), self.fit_clearance("max")


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
    (worst case) and root-sum-square (statistical estimate). Each joint counts under its
    own name: two joints of one name (the two eyes turning on a pin that joins three
    links, both called after the pin) are refused, naming the name, since one of them
    would otherwise be lost from the sums."""
    names = [j.name for j in joints]
    repeated = next((n for n in names if names.count(n) > 1), None)
    if repeated is not None:
        raise InputError(
            "joints",
            f"two joints of the clearance chain are named {repeated!r}: the backlash counts "
            "each joint by its name, so one would be lost; give each running clearance a "
            "name of its own (a pin joining three links: one joint per eye that turns on "
            "it, e.g. 'knee pin (coupler eye)', 'knee pin (pushrod eye)')",
        )
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
    pins = sum(joint.pin is not None for joint in joints)
    if pins != len(fractions):
        raise InputError("tolerances.fit", f"{len(fractions)} fit draws for {pins} pin joints")
    out, k = [], 0
    for joint in joints:
        if joint.pin is not None:
            lo, hi = joint.pin.fit_band()
            pin = replace(joint.pin, which="min", extra=joint.pin.extra + fractions[k] * (hi - lo))
            joint = replace(joint, pin=pin)
            k += 1
        out.append(joint)
    return out
