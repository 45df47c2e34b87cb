"""Load-deflection of a pin in a lug or clevis: Huth's fastener flexibility [H86].

Huth fitted the joint's compliance (relative displacement of the joined members per
unit load carried by the fastener) to tests of single- and double-shear joints with
bolts and rivets (Huth, "Influence of fastener flexibility on the prediction of load
transfer and fatigue life for multiple-row joints", ASTM STP 927, 1986):

    C = ((t1 + t2) / (2 d))^a (b / n) (1/(t1 E1) + 1/(n t2 E2) + 1/(2 t1 E3) + 1/(2 n t2 E3))

with d the pin diameter, t1 the inner member (in double shear the single middle lug),
t2 the outer member (in double shear each of the two clevis cheeks; in single shear the
other lug), E1, E2 their moduli, E3 the pin's, n = 1 (single shear) or 2 (double
shear), and the constants a, b of the joint (:data:`HUTH_CONSTANTS`): bolted metallic
a = 2/3, b = 3.0; riveted metallic a = 2/5, b = 2.2. The approach under a load F is
delta = C F: linear in F, and it contains what the Hertz-type models of
:mod:`optdesign.models.pin_contact` leave out - the bending and shear of the pin and the
bearing (bulk) deformation of the lugs around the hole. It is empirical: it holds for
the proportions Huth tested (sheet joints, t/d about 0.2 ... 2) and says nothing of the
pressure in the contact.

The same form is what FE pre-processors use (Altair HyperMesh's ``*fastenercreation``
writes it as b1 = b/n on the t1 terms and b2 = b/n^2 on the t2 terms). Checked against
pyNastran's independent implementation (see docs/validation.md).

Validity
--------
t1 / d, t2 / d : 0.2 ... 2
    Huth's constants a, b were fitted to tests of sheet joints whose member thickness
    was about 0.2 to 2 pin diameters; the power law ((t1 + t2)/(2 d))^a is an
    extrapolation outside them (a lug far thinner than its pin tears out before it
    bends the pin; a lug far thicker turns the pin into a beam built in at both ends).
t1, t2 : 0.001 ... 1000 mm
    A member at least a micrometre thick (the roughness of a reamed bore is 0.4-1.6 um:
    a thinner one is a surface film, not a lug) and at most a metre (a bulkhead, no
    sheet joint).
E1, E2, E3 : :data:`~optdesign.models.validity.ELASTIC_MODULUS`
    Linear elasticity of a real solid.

Units: mm, N, MPa (C in mm/N).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from optdesign.errors import InputError
from optdesign.models._checks import require_positive
from optdesign.models.validity import ELASTIC_MODULUS, Validity

LUG_THICKNESS = Validity(
    "lug_flexibility.thickness",
    "Huth's lug flexibility",
    "lug thickness",
    1.0e-3,
    1.0e3,
    "mm",
    "a lug is at least a micrometre (the roughness of its bore) and at most a metre thick",
    checked=("file",),
)
THICKNESS_RATIO = Validity(
    "lug_flexibility.thickness_ratio",
    "Huth's lug flexibility",
    "thickness over pin diameter t/d",
    0.2,
    2.0,
    "",
    "Huth fitted his constants to joints with t/d of about 0.2 to 2",
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (LUG_THICKNESS, THICKNESS_RATIO, ELASTIC_MODULUS)

#: Huth's constants (a, b) per joint type, metallic members [H86].
HUTH_CONSTANTS: dict[str, tuple[float, float]] = {
    "bolted": (2.0 / 3.0, 3.0),
    "riveted": (2.0 / 5.0, 2.2),
}


def _joint(fastener: str, shear_planes: Any) -> tuple[float, float, int]:
    if fastener not in HUTH_CONSTANTS:
        raise InputError("lug.fastener", f"{fastener!r}: use one of {tuple(HUTH_CONSTANTS)}")
    if shear_planes not in (1, 2):
        raise InputError("lug.shear_planes", f"must be 1 or 2, got {shear_planes!r}")
    a, b = HUTH_CONSTANTS[fastener]
    return a, b, int(shear_planes)


def huth_compliance(d, t1, t2, E1, E2, E3, shear_planes: int = 1, fastener: str = "bolted"):
    """Huth's compliance C of a pin joint (mm/N); see the module docstring.

    Parameters
    ----------
    d
        Pin diameter (mm); may be symbolic.
    t1, t2
        Inner member (the middle lug in double shear) and outer member (each clevis cheek
        in double shear, the other lug in single shear) thicknesses (mm).
    E1, E2, E3
        Moduli of the inner member, the outer member and the pin (MPa).
    shear_planes
        1 (single shear) or 2 (double shear).
    fastener
        ``"bolted"`` or ``"riveted"`` (Huth's constants a, b).
    """
    a, b, n = _joint(fastener, shear_planes)
    for name, value in (("d", d), ("t1", t1), ("t2", t2), ("E1", E1), ("E2", E2), ("E3", E3)):
        require_positive(f"lug.{name}", value)
    bulk = 1.0 / (t1 * E1) + 1.0 / (n * t2 * E2) + 1.0 / (2.0 * t1 * E3)
    bulk = bulk + 1.0 / (2.0 * n * t2 * E3)
    # ((t1 + t2) / 2)^a d^-a: a monomial in d when the thicknesses are fixed (GP form)
    return (0.5 * (t1 + t2)) ** a * d ** (-a) * (b / n) * bulk


def huth_approach(F, d, t1, t2, E1, E2, E3, shear_planes: int = 1, fastener: str = "bolted"):
    """Approach delta = C F (mm) of the pin joint under the load F (N) it carries."""
    return huth_compliance(d, t1, t2, E1, E2, E3, shear_planes, fastener) * F


@dataclass(frozen=True)
class Lug:
    """The members around a sized pin (``[materials.lug]``), for Huth's model.

    Attributes
    ----------
    cheek_thickness
        Outer member t2 (mm): each clevis cheek (double shear), the other lug (single).
    thickness
        Inner member t1 (mm); None: the pin's loaded length L (the length that carries
        the whole joint force, as in the bearing pressure F / (d L)).
    E, cheek_E
        Moduli of the inner and outer members (MPa); None: the pin's modulus, and
        ``cheek_E`` None: ``E``.
    shear_planes
        1 (single shear) or 2 (double shear).
    fastener
        ``"bolted"`` (a pin in a clearance fit) or ``"riveted"``.
    """

    cheek_thickness: Any
    thickness: Any = None
    E: Any = None
    cheek_E: Any = None
    shear_planes: int = 2
    fastener: str = "bolted"

    def __post_init__(self):
        require_positive("materials.lug.cheek_thickness", self.cheek_thickness)
        for name in ("thickness", "E", "cheek_E"):
            value = getattr(self, name)
            if value is not None:
                require_positive(f"materials.lug.{name}", value)
        _joint(self.fastener, self.shear_planes)

    def compliance(self, d, L, E_pin):
        """Huth's compliance (mm/N) of this lug around a pin of diameter ``d``, loaded
        length ``L`` and modulus ``E_pin``."""
        t1 = L if self.thickness is None else self.thickness
        E1 = E_pin if self.E is None else self.E
        E2 = E1 if self.cheek_E is None else self.cheek_E
        return huth_compliance(
            d, t1, self.cheek_thickness, E1, E2, E_pin, self.shear_planes, self.fastener
        )


__all__ = ["HUTH_CONSTANTS", "Lug", "huth_approach", "huth_compliance"]
