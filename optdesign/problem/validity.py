"""Where a design leaves the range of validity of the models that computed it.

The models declare their ranges (``VALIDITY`` of each module of :mod:`optdesign.models`;
:mod:`optdesign.models.validity`). A problem file's inputs are held to theirs when the
file is read (:mod:`optdesign.problem.spec`); what depends on the design - the backlash
against the small-angle limit, the contact strip against the pin's radius, the pin's
length against its diameter and the linkage - is evaluated here, on the NumPy path, for
one design: :func:`design_ranges` lists the quantities and :func:`outside_ranges` the ones
outside. The independent check of a result (:func:`optdesign.formulations.verify.
verify_design`) reports them, so that such a design is never a verified optimum.

Only the models a problem evaluates are checked: the pin's, the contact model the
problem chose and the clearance chain when the problem sizes a pin (``d``), the screw's
inclined plane when its efficiency comes from the lead (a ``[screw]`` section).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from optdesign.models import pin_contact
from optdesign.models.clearance import BACKLASH, JOINT_ROTATION
from optdesign.models.hertz_line import HALF_WIDTH_RATIO, contact_half_width
from optdesign.models.loads import PIN_LENGTH_OVER_SIZE, PIN_SLENDERNESS
from optdesign.models.lug_flexibility import THICKNESS_RATIO
from optdesign.models.screw import LEAD_ANGLE, lead_angle
from optdesign.models.validity import Validity

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem
    from optdesign.problem.quantities import Quantities


#: How the name of a row on a model's range of validity begins (:attr:`OutsideRange.name`).
VALIDITY_PREFIX = "validity: "


def is_validity(report: Any) -> bool:
    """True for a constraint row (a :class:`~optdesign.solvers.result.ConstraintReport`)
    on a model's range of validity (:attr:`OutsideRange.name`)."""
    return report.name.startswith(VALIDITY_PREFIX)


@dataclass(frozen=True)
class RangeQuantity:
    """A quantity of one design that a model's range bounds.

    ``values``: one value or one per deflection angle (internal units, the record's);
    ``what``: which part it belongs to (a joint's name, a lug), ``""`` for the design.
    """

    record: Validity
    values: Any
    what: str = ""


@dataclass(frozen=True)
class OutsideRange:
    """A quantity of a design outside its model's range: the worst value and where."""

    record: Validity
    value: float
    where: str = ""
    what: str = ""

    @property
    def name(self) -> str:
        """``"validity: small-angle clearance: worst-case backlash"`` (and the part)."""
        quantity = f"{self.record.quantity}, {self.what}" if self.what else self.record.quantity
        return f"{VALIDITY_PREFIX}{self.record.model}: {quantity}"

    def text(self) -> str:
        """``"small-angle clearance: worst-case backlash 1.29e+07 deg > 5 deg at
        phi=+30.0deg"``."""
        quantity = f"{self.record.quantity}, {self.what}" if self.what else self.record.quantity
        at = f" at {self.where}" if self.where else ""
        return f"{self.record.model}: {quantity} {self.record.outside_text(self.value)}{at}"


def design_ranges(q: Quantities) -> list[RangeQuantity]:
    """The quantities of the design ``q`` (NumPy path, one design) that the models'
    ranges bound, for the models the problem evaluates (module docstring)."""
    out: list[RangeQuantity] = []
    with np.errstate(all="ignore"):
        if q.pin is not None:
            out += _pin_ranges(q)
        out += _screw_ranges(q)
    return out


def _pin_ranges(q: Quantities) -> list[RangeQuantity]:
    pin = q.pin
    req = q.requirements
    d, L = pin.d, pin.L
    # a pin given by its length ratio has that L/d: (5 d)/d is 5.000000000000001 for some
    # d, which left the range [0.2, 5] that the file's ratio of 5 was accepted in
    ratio = q.design.get("pin_length_ratio")
    out = [RangeQuantity(PIN_SLENDERNESS, L / d if ratio is None else ratio)]
    size = _size(q)
    if size is not None:
        out.append(RangeQuantity(PIN_LENGTH_OVER_SIZE, L / size))
    contact = req.pin_contact
    # eq. 10's half-width: the flattening of duan2017, and the pressure of the models
    # that give none of their own (Palmgren, Huth) when a contact-pressure limit uses it
    hertz = contact == "duan2017" or (
        contact in ("palmgren", "huth") and req.pin_contact_pressure_max is not None
    )
    for joint in q.joints:
        if joint.pin is None:
            continue
        F = np.abs(np.asarray(joint.force, dtype=float))
        if hertz:
            b = contact_half_width(d, F, L, joint.pin.E, joint.pin.nu)
            out.append(RangeQuantity(HALF_WIDTH_RATIO, b / (0.5 * d), joint.name))
        if contact == "conforming":
            c = np.asarray(joint.pin.fit_clearance(), dtype=float)
            if np.all(c > 0):  # no gap is refused when the problem is read
                P = pin_contact.load_parameter(F, L, 0.5 * c, joint.pin.E, joint.pin.nu)
                out.append(RangeQuantity(pin_contact.LOAD_PARAMETER, P, joint.name))
    if contact == "huth" and pin.lug is not None:
        t1 = L if pin.lug.thickness is None else pin.lug.thickness
        out.append(RangeQuantity(THICKNESS_RATIO, t1 / d, "inner lug"))
        out.append(RangeQuantity(THICKNESS_RATIO, pin.lug.cheek_thickness / d, "cheeks"))
    backlash = q.backlash
    out.append(RangeQuantity(BACKLASH, backlash.worst_case))
    for name, theta in backlash.per_joint.items():
        out.append(RangeQuantity(JOINT_ROTATION, theta, name))
    return out


def _size(q: Quantities) -> float | None:
    """The mechanism's size (mm), None where it has none to compare with."""
    try:
        size = float(np.asarray(q.size, dtype=float).ravel()[0])
    except Exception:  # a mechanism's size is its own business: its objective reports it
        return None
    return size if np.isfinite(size) and size > 0 else None


def _screw_ranges(q: Quantities) -> list[RangeQuantity]:
    """The lead angle, where the efficiency comes from it (a ``[screw]`` section)."""
    if q.problem.spec.screw is None:
        return []
    data = q.screw
    if data is None or data.d_m is None:
        return []
    return [RangeQuantity(LEAD_ANGLE, lead_angle(data.p, data.d_m))]


def outside(quantity: RangeQuantity, labels: list[str]) -> OutsideRange | None:
    """The worst value of ``quantity`` outside its range (None when all lie inside);
    ``labels``: the deflection grid's labels, for a quantity with one value per angle."""
    values = np.atleast_1d(np.asarray(quantity.values, dtype=float)).ravel()
    excess = quantity.record.excess(values)
    k = int(np.argmax(excess))
    if not excess[k] > 0:
        return None
    where = labels[k] if values.size == len(labels) and values.size > 1 else ""
    return OutsideRange(quantity.record, float(values[k]), where, quantity.what)


def outside_ranges(problem: DesignProblem, x: np.ndarray) -> list[OutsideRange]:
    """The quantities of design ``x`` (the free-variable vector) outside their models'
    ranges, the worst value of each, in the order of :func:`design_ranges`."""
    x = np.asarray(x, dtype=float)
    q = problem.quantities(problem.design_dict(x))
    found = (outside(rq, problem.phi_labels) for rq in design_ranges(q))
    return [o for o in found if o is not None]
