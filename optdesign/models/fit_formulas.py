"""ISO 286-1 fits as smooth functions of the nominal diameter (docs/clearance_and_backlash.md).

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

Further letters (ISO 286-1 formulas, D in mm, um; the d..h forms above are unchanged):

    c   es = -52 D^0.2 (D <= 40), -(95 + 0.8 D) (D > 40)   (the two forms jump 18 um at 40)
    js  +-IT/2
    k   ei = +0.6 D^(1/3) for grades 4..7, 0 for the others
    m   ei = +(IT7 - IT6)
    n   ei = +5 D^0.34
    p   ei = +IT7 + 0.12 D^0.63   (ISO 286-1: "IT7 + 0 to 5"; the added term is our fit to
        the printed p - IT7, within 0.62 um of it at every step's geometric mean > 3 mm)
    u   ei = +IT7 + D
    IT12..IT18 = 160, 250, 400, 640, 1000, 1600, 2500 i

Holes C..H, JS by the general rule as above; K, M, N (grades <= 8) and P, U (grades <= 7)
by ES = -ei + Delta with the smooth Delta = IT_n - IT_(n-1) (so from grade 6: IT4 has no
formula in i); K above IT8 has no formula (the table gives it up to 3 mm only), N above
IT8 has ES = 0, M above IT8 and P, U above IT7 ES = -ei. Shafts r and s (and holes R, S)
have no formula of their own in ISO 286-1 (s: "IT8 + 1 to 4" up to 50 mm, r: geometric
mean of p and s): they exist only as table values (:mod:`optdesign.models.iso286`).

``values="table"`` (``Fit.clearance``, :func:`fit_clearance`) returns the standard's
printed, stepped values instead; see :mod:`optdesign.models.iso286`.

Validity
--------
D : 0 < D <= 500 mm
    The tolerance unit i = 0.45 D^(1/3) + 0.001 D is ISO 286-1's for sizes up to 500 mm
    (:data:`optdesign.models.iso286.NOMINAL_SIZE`, the same record).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import casadi as ca
import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models import iso286
from optdesign.models.iso286 import NOMINAL_SIZE

#: The ranges of validity of this model: the tables' (module docstring).
VALIDITY = (NOMINAL_SIZE,)

#: IT grade -> multiple of the tolerance unit i.
IT_FACTORS: dict[int, float] = {
    5: 7.0,
    6: 10.0,
    7: 16.0,
    8: 25.0,
    9: 40.0,
    10: 64.0,
    11: 100.0,
    12: 160.0,
    13: 250.0,
    14: 400.0,
    15: 640.0,
    16: 1000.0,
    17: 1600.0,
    18: 2500.0,
}

#: Shaft letter -> (coefficient, exponent) of the upper deviation es = coef * D^exp (um).
SHAFT_DEVIATIONS: dict[str, tuple[float, float]] = {
    "d": (-16.0, 0.44),
    "e": (-11.0, 0.41),
    "f": (-5.5, 0.41),
    "g": (-2.5, 0.34),
    "h": (0.0, 0.0),
}

#: Why a table letter has no smooth value.
_NO_FORMULA = {
    "r": "ISO 286-1 defines r only as the geometric mean of the p and s values",
    "s": "ISO 286-1 gives s only as IT8 + '1 to 4' um up to 50 mm",
}
#: Shaft letters with a smooth (formula) value: the table's, but r and s.
SMOOTH_SHAFT_LETTERS: tuple[str, ...] = tuple(
    x for x in iso286.SHAFT_LETTERS if x not in _NO_FORMULA
)
#: Hole letters with a smooth (formula) value.
SMOOTH_HOLE_LETTERS: tuple[str, ...] = tuple(x.upper() for x in SMOOTH_SHAFT_LETTERS)
#: IT grades with a smooth value (ISO 286-1 gives IT1..IT4 no multiple of i).
SMOOTH_GRADES: tuple[int, ...] = tuple(sorted(IT_FACTORS))
_DELTA_8 = ("K", "M", "N")  # ES = -ei + Delta up to IT8
_DELTA_7 = ("P", "U")  # ES = -ei + Delta up to IT7
_VALUES = ("smooth", "table")

_FIT_RE = re.compile(r"^\s*([A-Za-z]{1,2})(\d{1,2})\s*/\s*([A-Za-z]{1,2})(\d{1,2})\s*$")


def tolerance_unit(D):
    """Standard tolerance unit i (um) for nominal diameter D (mm)."""
    return 0.45 * D ** (1.0 / 3.0) + 0.001 * D


def it_tolerance(D, grade: int):
    """IT tolerance (um) of ``grade`` (5..11) at diameter D (mm)."""
    if grade not in IT_FACTORS:
        raise InputError("fit", f"IT grade {grade} not supported (use {sorted(IT_FACTORS)})")
    return IT_FACTORS[grade] * tolerance_unit(D)


def shaft_upper_deviation(D, letter: str):
    """Upper deviation es (um) of a shaft of fundamental deviation ``letter`` (c..h)."""
    if letter == "c":
        # Two forms with a jump at 40 mm, as ISO 286-1 gives them (not a posynomial).
        return m.where(D <= 40.0, -52.0 * D**0.2, -(95.0 + 0.8 * D))
    coef, exp = SHAFT_DEVIATIONS[letter]
    if coef == 0.0:
        return 0.0 * D
    return coef * D**exp


def shaft_lower_deviation(D, letter: str, grade: int):
    """Lower deviation ei (um) of a shaft k, m, n, p or u of IT ``grade`` (formulas above)."""
    if letter == "k":
        return 0.6 * D ** (1.0 / 3.0) if 4 <= grade <= 7 else 0.0 * D
    if letter == "m":
        return it_tolerance(D, 7) - it_tolerance(D, 6)
    if letter == "n":
        return 5.0 * D**0.34
    if letter == "p":
        return it_tolerance(D, 7) + 0.12 * D**0.63
    if letter == "u":
        return it_tolerance(D, 7) + D
    raise InputError("fit", f"shaft letter {letter!r} has no lower-deviation formula")


def _smooth_reason(letter: str, grade: int, hole: bool) -> str | None:
    """Why ``letter``+``grade`` has no smooth value (None if it has one)."""
    low = letter.lower()
    if low in _NO_FORMULA:
        return f"{letter}{grade} has no smooth formula: {_NO_FORMULA[low]} (use values='table')"
    if grade not in IT_FACTORS:
        return f"IT{grade} has no smooth formula (ISO 286-1 gives IT1..IT4 no multiple of i)"
    if hole and ((letter in _DELTA_8 and grade <= 8) or (letter in _DELTA_7 and grade <= 7)):
        if grade - 1 not in IT_FACTORS:
            return f"{letter}{grade} has no smooth formula: its Delta = IT{grade} - IT{grade - 1} needs IT{grade - 1}"
    if hole and letter == "K" and grade > 8:
        return f"K{grade} has no smooth formula (ISO 286-1 tabulates K above IT8 up to 3 mm only)"
    return None


def smooth_shaft_deviations(D, letter: str, grade: int):
    """(ei, es) in um of shaft ``letter``+``grade`` by the formulas at D."""
    reason = _smooth_reason(letter, grade, hole=False)
    if reason:
        raise InputError("fit", reason)
    if letter == "c" or letter in SHAFT_DEVIATIONS:
        es = shaft_upper_deviation(D, letter)
        return es - it_tolerance(D, grade), es
    it = it_tolerance(D, grade)
    if letter == "js":
        return -0.5 * it, 0.5 * it
    ei = shaft_lower_deviation(D, letter, grade)
    return ei, ei + it


def smooth_hole_deviations(D, letter: str, grade: int):
    """(EI, ES) in um of hole ``letter``+``grade`` by the formulas at D."""
    reason = _smooth_reason(letter, grade, hole=True)
    if reason:
        raise InputError("fit", reason)
    low = letter.lower()
    if low == "c" or low in SHAFT_DEVIATIONS:  # general rule EI = -es
        EI = -shaft_upper_deviation(D, low)
        return EI, EI + it_tolerance(D, grade)
    it = it_tolerance(D, grade)
    if letter == "JS":
        return -0.5 * it, 0.5 * it
    # The hole's Delta rule uses the shaft value of the letter (k: its grades-4..7 value).
    ei = shaft_lower_deviation(D, low, 6)
    if (letter in _DELTA_8 and grade <= 8) or (letter in _DELTA_7 and grade <= 7):
        ES = -ei + (IT_FACTORS[grade] - IT_FACTORS[grade - 1]) * tolerance_unit(D)
    elif letter == "N":
        ES = 0.0 * D
    else:  # M above IT8, P and U above IT7
        ES = -ei
    return ES - it, ES


def _check_values(values: str) -> None:
    if values not in _VALUES:
        raise InputError("fit_values", f"{values!r} must be 'table' or 'smooth'")


def _fixed_diameter(D):
    """D as floats for a table look-up; a symbol has no step to look up."""
    if isinstance(D, ca.DM):
        D = D.full().squeeze()
    if m.is_symbolic(D):
        raise InputError(
            "fit_values",
            "table values need a fixed diameter (the ISO 286 tables are stepped in D); "
            "use values='smooth' for a symbolic or optimised diameter",
        )
    try:
        return np.asarray(D, dtype=float) if np.ndim(D) else float(D)
    except (TypeError, ValueError) as exc:
        raise InputError(
            "fit_values", f"table values need a fixed numeric diameter, got {D!r}"
        ) from exc


def _supported(values: str) -> tuple[tuple[str, ...], tuple[str, ...], tuple[int, ...]]:
    if values == "table":
        return iso286.HOLE_LETTERS, iso286.SHAFT_LETTERS, iso286.GRADES
    return SMOOTH_HOLE_LETTERS, SMOOTH_SHAFT_LETTERS, SMOOTH_GRADES


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
    def parse(cls, text: str, field: str = "fit", values: str = "smooth") -> Fit:
        """Parse ``"H7/g6"``; raise :class:`InputError` naming ``field`` otherwise.

        ``values`` ("smooth" or "table") is the evaluation the fit must support; the error
        lists the letters and grades that evaluation supports.
        """
        _check_values(values)
        match = _FIT_RE.match(str(text))
        if not match:
            holes, shafts, grades = _supported(values)
            raise InputError(
                field,
                f"{text!r} is not a fit like 'H7/g6' (hole letters {', '.join(holes)}; "
                f"shaft letters {', '.join(shafts)}; grades {grades[0]}..{grades[-1]})",
            )
        hole, hg, shaft, sg = (
            match.group(1),
            int(match.group(2)),
            match.group(3),
            int(match.group(4)),
        )
        holes, shafts, grades = _supported(values)
        grade_list = f"IT{grades[0]}..IT{grades[-1]}"
        if hole not in holes:
            raise InputError(
                field,
                f"hole letter {hole!r} not supported with {values} values "
                f"(use {', '.join(holes)}; grades {grade_list})",
            )
        if shaft not in shafts:
            extra = f": {_NO_FORMULA[shaft]}" if values == "smooth" and shaft in _NO_FORMULA else ""
            raise InputError(
                field,
                f"shaft letter {shaft!r} not supported with {values} values{extra} "
                f"(use {', '.join(shafts)}; grades {grade_list})",
            )
        for grade, name in ((hg, "hole"), (sg, "shaft")):
            if grade not in grades:
                raise InputError(
                    field,
                    f"{name} grade IT{grade} not supported with {values} values (use {grade_list})",
                )
        if values == "smooth":
            for letter, grade, is_hole in ((hole, hg, True), (shaft, sg, False)):
                reason = _smooth_reason(letter, grade, is_hole)
                if reason:
                    raise InputError(field, reason)
        return cls(hole, hg, shaft, sg)

    def __str__(self) -> str:
        return f"{self.hole}{self.hole_grade}/{self.shaft}{self.shaft_grade}"

    @property
    def has_smooth(self) -> bool:
        """Whether ISO 286-1's formulas give this fit (r, s, R, S and IT1..IT4 exist only
        as table values)."""
        letters = (self.hole in SMOOTH_HOLE_LETTERS, self.shaft in SMOOTH_SHAFT_LETTERS)
        return all(letters) and not (
            _smooth_reason(self.hole, self.hole_grade, True)
            or _smooth_reason(self.shaft, self.shaft_grade, False)
        )

    def hole_deviations(self, D, values: str = "smooth"):
        """(EI, ES) of the hole in um (``values``: "smooth" formulas or "table")."""
        _check_values(values)
        if values == "table":
            return iso286.hole_deviations_um(_fixed_diameter(D), self.hole, self.hole_grade)
        if self.hole in ("F", "G", "H"):  # the original expressions, kept bit for bit
            EI = -shaft_upper_deviation(D, self.hole.lower())
            return EI, EI + it_tolerance(D, self.hole_grade)
        return smooth_hole_deviations(D, self.hole, self.hole_grade)

    def shaft_deviations(self, D, values: str = "smooth"):
        """(ei, es) of the shaft in um (``values``: "smooth" formulas or "table")."""
        _check_values(values)
        if values == "table":
            return iso286.shaft_deviations_um(_fixed_diameter(D), self.shaft, self.shaft_grade)
        if self.shaft in SHAFT_DEVIATIONS:  # the original expressions, kept bit for bit
            es = shaft_upper_deviation(D, self.shaft)
            return es - it_tolerance(D, self.shaft_grade), es
        return smooth_shaft_deviations(D, self.shaft, self.shaft_grade)

    def clearance_um(self, D, which: str = "max", values: str = "smooth"):
        """Smallest (``"min"``) or largest (``"max"``) clearance (um) at diameter D (mm).

        Negative values are interference (transition and interference fits).
        """
        EI, ES = self.hole_deviations(D, values)
        ei, es = self.shaft_deviations(D, values)
        if which == "max":
            return ES - ei
        if which == "min":
            return EI - es
        raise InputError("fit.clearance", f"{which!r} must be 'min' or 'max'")

    def clearance(self, D, which: str = "max", values: str = "smooth"):
        """Smallest or largest diametral clearance in mm (internal units)."""
        if values == "table":
            # Printed whole (or half) um: dividing keeps them exact in mm (-18 -> -0.018).
            return self.clearance_um(D, which, values) / 1000.0
        return 1e-3 * self.clearance_um(D, which, values)


def fit_clearance(D, fit: str | Fit, which: str = "max", values: str = "smooth"):
    """Diametral clearance (mm) of ``fit`` (e.g. ``"H7/g6"``) at nominal diameter D (mm).

    ``values="smooth"`` (default): the formulas at D; ``"table"``: ISO 286-2 as printed.
    """
    f = fit if isinstance(fit, Fit) else Fit.parse(fit, values=values)
    return f.clearance(D, which, values)
