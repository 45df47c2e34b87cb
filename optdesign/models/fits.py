"""ISO 286-1 fits as smooth functions of the nominal diameter (physics.md 2.4).

The standard's tables are these formulas evaluated at the geometric mean of each
diameter step and rounded. An optimiser needs them continuous in D, so optdesign
evaluates the formulas at D itself (results differ from the tables by the step
rounding: H7/g6 largest clearance at D = 10 mm is 30.9 um here, 29 um in the table).

Tolerance unit (D in mm, result in um), valid for D <= 500 mm:

    i = 0.45 D^(1/3) + 0.001 D
    IT5..IT11 = 7, 10, 16, 25, 40, 64, 100 i

Fundamental deviations of shafts (upper deviation es, um): d -16 D^0.44, e -11 D^0.41,
f -5.5 D^0.41, g -2.5 D^0.34, h 0; lower deviation ei = es - IT. Holes F, G, H mirror the
shafts (general rule EI = -es of the same letter); ES = EI + IT.
Clearance of a fit: smallest = EI - es, largest = ES - ei. All are posynomials in D for
H holes with d..h shafts, which the geometric-programming formulation relies on.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from optdesign.errors import InputError

#: IT grade -> multiple of the tolerance unit i.
IT_FACTORS: dict[int, float] = {5: 7.0, 6: 10.0, 7: 16.0, 8: 25.0, 9: 40.0, 10: 64.0, 11: 100.0}

#: Shaft letter -> (coefficient, exponent) of the upper deviation es = coef * D^exp (um).
SHAFT_DEVIATIONS: dict[str, tuple[float, float]] = {
    "d": (-16.0, 0.44),
    "e": (-11.0, 0.41),
    "f": (-5.5, 0.41),
    "g": (-2.5, 0.34),
    "h": (0.0, 0.0),
}

_FIT_RE = re.compile(r"^\s*([A-Za-z])(\d{1,2})\s*/\s*([A-Za-z])(\d{1,2})\s*$")


def tolerance_unit(D):
    """Standard tolerance unit i (um) for nominal diameter D (mm)."""
    return 0.45 * D ** (1.0 / 3.0) + 0.001 * D


def it_tolerance(D, grade: int):
    """IT tolerance (um) of ``grade`` (5..11) at diameter D (mm)."""
    if grade not in IT_FACTORS:
        raise InputError("fit", f"IT grade {grade} not supported (use {sorted(IT_FACTORS)})")
    return IT_FACTORS[grade] * tolerance_unit(D)


def shaft_upper_deviation(D, letter: str):
    """Upper deviation es (um) of a shaft of fundamental deviation ``letter``."""
    coef, exp = SHAFT_DEVIATIONS[letter]
    if coef == 0.0:
        return 0.0 * D
    return coef * D**exp


@dataclass(frozen=True)
class Fit:
    """A hole/shaft fit such as H7/g6.

    Parameters
    ----------
    hole, hole_grade, shaft, shaft_grade
        Letters and IT grades, e.g. ``Fit("H", 7, "g", 6)``.
    """

    hole: str
    hole_grade: int
    shaft: str
    shaft_grade: int

    @classmethod
    def parse(cls, text: str, field: str = "fit") -> Fit:
        """Parse ``"H7/g6"``; raise :class:`InputError` naming ``field`` otherwise."""
        match = _FIT_RE.match(str(text))
        if not match:
            raise InputError(field, f"{text!r} is not a fit like 'H7/g6'")
        hole, hg, shaft, sg = (
            match.group(1),
            int(match.group(2)),
            match.group(3),
            int(match.group(4)),
        )
        if not hole.isupper() or hole.lower() not in SHAFT_DEVIATIONS:
            raise InputError(field, f"hole letter {hole!r} not supported (use F, G or H)")
        if hole not in ("F", "G", "H"):
            raise InputError(field, f"hole letter {hole!r} not supported (use F, G or H)")
        if not shaft.islower() or shaft not in SHAFT_DEVIATIONS:
            raise InputError(
                field, f"shaft letter {shaft!r} not supported (use {', '.join(SHAFT_DEVIATIONS)})"
            )
        for grade, name in ((hg, "hole"), (sg, "shaft")):
            if grade not in IT_FACTORS:
                raise InputError(field, f"{name} grade IT{grade} not supported")
        return cls(hole, hg, shaft, sg)

    def __str__(self) -> str:
        return f"{self.hole}{self.hole_grade}/{self.shaft}{self.shaft_grade}"

    def hole_deviations(self, D):
        """(EI, ES) of the hole in um."""
        EI = -shaft_upper_deviation(D, self.hole.lower())
        return EI, EI + it_tolerance(D, self.hole_grade)

    def shaft_deviations(self, D):
        """(ei, es) of the shaft in um."""
        es = shaft_upper_deviation(D, self.shaft)
        return es - it_tolerance(D, self.shaft_grade), es

    def clearance_um(self, D, which: str = "max"):
        """Smallest (``"min"``) or largest (``"max"``) clearance (um) at diameter D (mm)."""
        EI, ES = self.hole_deviations(D)
        ei, es = self.shaft_deviations(D)
        if which == "max":
            return ES - ei
        if which == "min":
            return EI - es
        raise InputError("fit.clearance", f"{which!r} must be 'min' or 'max'")

    def clearance(self, D, which: str = "max"):
        """Smallest or largest diametral clearance in mm (internal units)."""
        return 1e-3 * self.clearance_um(D, which)


def fit_clearance(D, fit: str | Fit, which: str = "max"):
    """Diametral clearance (mm) of ``fit`` (e.g. ``"H7/g6"``) at nominal diameter D (mm)."""
    f = fit if isinstance(fit, Fit) else Fit.parse(fit)
    return f.clearance(D, which)
