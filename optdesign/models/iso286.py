"""ISO 286 limits and fits as the standard prints them (stepped tables, nominal sizes <= 500 mm).

:mod:`optdesign.models.fit_formulas` evaluates the ISO 286-1 *formulas* at the nominal size D
itself, which an optimiser needs (smooth in D) but which is not what a drawing means:
the standard evaluates the formulas once per size step (at the geometric mean of the
step), rounds them, and prints the result as the value of the whole step. This module
holds those printed values and the rules that combine them into limit deviations.

Size steps: "over a up to and including b"; a size equal to a step's upper limit belongs
to that step (D = 3 is in "up to 3", D = 3.0001 in "over 3 up to 6"). Units: um here,
:func:`clearance_um` too; :mod:`optdesign.fits` converts to mm.

Rules implemented (ISO 286-1:2010, its tables of fundamental deviations and their notes):

- Shafts a..h: upper deviation es from the table, ei = es - IT. Shafts k..zc: lower
  deviation ei from the table, es = ei + IT. Holes A..H: EI = -es of the same shaft letter
  (general rule), ES = EI + IT.
- js / JS: +-IT/2, as ISO 286-2:2010 prints it (js7 over 18 up to 30 mm, IT7 = 21:
  +-10.5). ISO 286-1:1988 allowed ("may") replacing an odd IT (um) of grades 7 to 11 by the
  even value immediately below (+-10); that older rounding is available with
  ``round_js=True``.
- k: ei from the table for grades 4 to 7; ei = 0 for grades <= 3 and >= 8.
- Holes K, M, N up to IT8 and P..ZC up to IT7 (Delta rule): ES = -ei + Delta, with ei the
  shaft value of the same letter and Delta = IT_n - IT_(n-1) (grade n of the hole, next
  finer grade); Delta = 0 up to 3 mm and for grades 1, 2. Above those grades: K: ES = 0
  (tabulated only up to 3 mm), M: ES = -ei, N: ES = 0 (over 3 mm; -4 um up to 3 mm, not to
  be used up to 1 mm), P..ZC: ES = -ei. Special case M6 over 250 up to 315 mm: ES = -9 um
  (not -11).
- IT14..IT18 are not used for sizes up to 1 mm.

Smooth (formulas at D, :mod:`optdesign.models.fit_formulas`) against table (printed steps),
measured on 20 000 log-spaced sizes 1..500 mm and at every step edge (pinned by
``tests/test_iso286.py::test_smooth_vs_table_bounds_are_the_measured_ones``): smooth minus
table, relative to |table| and in um ("n/a": the table value is zero or changes sign).
G7/h6, F8/h7 equal H7/g6, H8/f7.

========  ==============================  ==============================
fit       largest clearance               smallest clearance
========  ==============================  ==============================
H7/g6     -21.0..+14.4 % (-7.2..+6.5)     -11.7..+81.6 % (-1.3..+1.6)
H8/f7     -20.0..+17.9 % (-11.5..+11.8)   -13.7..+43.8 % (-3.8..+3.2)
H7/h6     -26.7..+9.2 % (-6.4..+5.7)      0 in both
H9/d9     -25.6..+12.4 % (-26.3..+32.1)   -20.0..+29.7 % (-13.5..+16.4)
H11/c11   -21.0..+8.7 % (-81.9..+53.2)    -15.7..+8.0 % (-25.0..+19.0)
H7/js6    -27.1..+9.1 % (-5.0..+4.6)      -9.9..+24.8 % (-1.1..+1.4)
H7/k6     -33.8..+10.5 % (-3.4..+3.6)     -23.1..+17.9 % (-2.6..+3.4)
H7/n6     -63.1..+16.0 % (-3.8..+1.7)     -37.8..+13.8 % (-4.4..+4.5)
H7/p6     n/a (-4.2..+0.8)                -43.3..+14.0 % (-5.9..+6.2)
H7/u6     -20.0..+87.5 % (-23.0..+27.0)   -11.7..+47.0 % (-25.9..+33.4)
K7/h6     -15.4..+59.4 % (-3.0..+3.6)     -12.9..+48.9 % (-2.6..+4.9)
N7/h6     -21.1..+58.4 % (-1.9..+1.7)     -10.1..+32.1 % (-4.4..+4.5)
P7/h6     n/a (-1.0..+0.8)                -9.9..+26.0 % (-5.9..+6.2)
========  ==============================  ==============================

Most extremes sit in the first step (1..3 mm, where the standard departs most from its
own formulas) or at a step's ends (the formula at D against the value of the step's
geometric mean); at the low end of a step the smooth model understates the clearance (the
unsafe side for backlash), so the table is the one to use for a design at a fixed size.

Validity
--------
D : 0 < D <= 500 mm
    The sizes ISO 286-2 tabulates here; larger sizes (to 3150 mm) follow another
    tolerance unit in the standard and are not stored. Refused by :func:`clearance_um`
    (field ``D``) and, in a problem, when the file is read (the pin diameter's range).
"""

# Sources of the tables below (values in um, as printed):
# - IT_UM: ISO 286-1:2010 Table 1 (standard tolerance grades IT1..IT18, sizes <= 500 mm),
#   as reproduced in GB/T 1800.3-1998 Table 1 (identical to ISO 286-1:1988 Table 1) and
#   in K. L. Narayana, P. Kannaiah, K. Venkata Reddy, "Machine Drawing", Table 15.1.
# - SHAFT_ES_UM, SHAFT_EI_UM: ISO 286-1:2010 tables of fundamental deviations of shafts, as reproduced in "Machine Drawing" Table 15.2 and in the DIN ISO 286 tables
#   of the open-source rf-tolerance project (data/DIN286/DIN286TypeData.js).
# - Holes: ISO 286-1:2010 tables of fundamental deviations of holes (Delta columns, the M6
#   footnote), as reproduced in "Machine Drawing" Table 15.3 and Machinery's
#   Handbook 31st ed. Table 6a (BS 4500, identical); the hole values are not stored but
#   derived from the shaft values by the rules above, and tests compare them with print.
# Every entry was cross-checked against a second reproduction: the ISO 286-2 limit
# deviation tables reproduced by the isofits package (1340 class/step entries, 3..400 mm)
# and the pressfit package (every H5..H11 with c..u5..11 fit, <= 500 mm). They agree
# except for three isofits entries whose width is not the IT value (K6 over 6 up to 10
# printed -6 for -7, f6 over 120 up to 180 -48 for -68, E7 over 315 up to 400 +185 for
# +182): misprints there, since ES - EI must equal IT. rf-tolerance differs only where it
# is evidently wrong (G over 3 up to 6 = +2, Delta missing for K 30-40 and N 24-30, no M6
# special case).

from __future__ import annotations

import numpy as np

from optdesign.errors import InputError
from optdesign.models.validity import Validity

#: Largest nominal size (mm) the tables cover.
MAX_SIZE = 500.0

NOMINAL_SIZE = Validity(
    "iso286.nominal_size",
    "ISO 286 fits",
    "nominal size D",
    0.0,
    MAX_SIZE,
    "mm",
    "the tables (and the formulas of ISO 286-1 as this project uses them) cover 0 < D <= 500 mm",
    open_lower=True,
    checked=("call",),
)

#: The ranges of validity of this model (module docstring).
VALIDITY: tuple[Validity, ...] = (NOMINAL_SIZE,)

#: Upper limits (mm) of the 25 size steps of the fundamental-deviation tables.
STEPS = (
    3,
    6,
    10,
    14,
    18,
    24,
    30,
    40,
    50,
    65,
    80,
    100,
    120,
    140,
    160,
    180,
    200,
    225,
    250,
    280,
    315,
    355,
    400,
    450,
    500,
)

#: Upper limits (mm) of the 13 main size steps of the IT table.
MAIN_STEPS = (3, 6, 10, 18, 30, 50, 80, 120, 180, 250, 315, 400, 500)

#: Lower limits (mm) of the main steps, for the geometric means (ISO 286-1 takes 1 mm as
#: the lower limit of the first step "up to 3 mm").
MAIN_STEP_LOWER = (1, 3, 6, 10, 18, 30, 50, 80, 120, 180, 250, 315, 400)

#: Standard tolerance grades (um), grade -> one value per main step.
IT_UM: dict[int, tuple[float, ...]] = {
    1: (0.8, 1, 1, 1.2, 1.5, 1.5, 2, 2.5, 3.5, 4.5, 6, 7, 8),
    2: (1.2, 1.5, 1.5, 2, 2.5, 2.5, 3, 4, 5, 7, 8, 9, 10),
    3: (2, 2.5, 2.5, 3, 4, 4, 5, 6, 8, 10, 12, 13, 15),
    4: (3, 4, 4, 5, 6, 7, 8, 10, 12, 14, 16, 18, 20),
    5: (4, 5, 6, 8, 9, 11, 13, 15, 18, 20, 23, 25, 27),
    6: (6, 8, 9, 11, 13, 16, 19, 22, 25, 29, 32, 36, 40),
    7: (10, 12, 15, 18, 21, 25, 30, 35, 40, 46, 52, 57, 63),
    8: (14, 18, 22, 27, 33, 39, 46, 54, 63, 72, 81, 89, 97),
    9: (25, 30, 36, 43, 52, 62, 74, 87, 100, 115, 130, 140, 155),
    10: (40, 48, 58, 70, 84, 100, 120, 140, 160, 185, 210, 230, 250),
    11: (60, 75, 90, 110, 130, 160, 190, 220, 250, 290, 320, 360, 400),
    12: (100, 120, 150, 180, 210, 250, 300, 350, 400, 460, 520, 570, 630),
    13: (140, 180, 220, 270, 330, 390, 460, 540, 630, 720, 810, 890, 970),
    14: (250, 300, 360, 430, 520, 620, 740, 870, 1000, 1150, 1300, 1400, 1550),
    15: (400, 480, 580, 700, 840, 1000, 1200, 1400, 1600, 1850, 2100, 2300, 2500),
    16: (600, 750, 900, 1100, 1300, 1600, 1900, 2200, 2500, 2900, 3200, 3600, 4000),
    17: (1000, 1200, 1500, 1800, 2100, 2500, 3000, 3500, 4000, 4600, 5200, 5700, 6300),
    18: (1400, 1800, 2200, 2700, 3300, 3900, 4600, 5400, 6300, 7200, 8100, 8900, 9700),
}

# fmt: off
#: Upper deviation es (um) of shafts c..h, one value per step of :data:`STEPS`.
SHAFT_ES_UM: dict[str, tuple[int, ...]] = {
    "c": (-60, -70, -80, -95, -95, -110, -110, -120, -130, -140, -150, -170, -180,
          -200, -210, -230, -240, -260, -280, -300, -330, -360, -400, -440, -480),
    "d": (-20, -30, -40, -50, -50, -65, -65, -80, -80, -100, -100, -120, -120,
          -145, -145, -145, -170, -170, -170, -190, -190, -210, -210, -230, -230),
    "e": (-14, -20, -25, -32, -32, -40, -40, -50, -50, -60, -60, -72, -72,
          -85, -85, -85, -100, -100, -100, -110, -110, -125, -125, -135, -135),
    "f": (-6, -10, -13, -16, -16, -20, -20, -25, -25, -30, -30, -36, -36,
          -43, -43, -43, -50, -50, -50, -56, -56, -62, -62, -68, -68),
    "g": (-2, -4, -5, -6, -6, -7, -7, -9, -9, -10, -10, -12, -12,
          -14, -14, -14, -15, -15, -15, -17, -17, -18, -18, -20, -20),
    "h": (0,) * 25,
}

#: Lower deviation ei (um) of shafts k..u (k: grades 4 to 7), one value per step.
SHAFT_EI_UM: dict[str, tuple[int, ...]] = {
    "k": (0, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 3, 3,
          3, 3, 3, 4, 4, 4, 4, 4, 4, 4, 5, 5),
    "m": (2, 4, 6, 7, 7, 8, 8, 9, 9, 11, 11, 13, 13,
          15, 15, 15, 17, 17, 17, 20, 20, 21, 21, 23, 23),
    "n": (4, 8, 10, 12, 12, 15, 15, 17, 17, 20, 20, 23, 23,
          27, 27, 27, 31, 31, 31, 34, 34, 37, 37, 40, 40),
    "p": (6, 12, 15, 18, 18, 22, 22, 26, 26, 32, 32, 37, 37,
          43, 43, 43, 50, 50, 50, 56, 56, 62, 62, 68, 68),
    "r": (10, 15, 19, 23, 23, 28, 28, 34, 34, 41, 43, 51, 54,
          63, 65, 68, 77, 80, 84, 94, 98, 108, 114, 126, 132),
    "s": (14, 19, 23, 28, 28, 35, 35, 43, 43, 53, 59, 71, 79,
          92, 100, 108, 122, 130, 140, 158, 170, 190, 208, 232, 252),
    "u": (18, 23, 28, 33, 33, 41, 48, 60, 70, 87, 102, 124, 144,
          170, 190, 210, 236, 258, 284, 315, 350, 390, 435, 490, 540),
}
# fmt: on

#: Shaft letters with table values.
SHAFT_LETTERS: tuple[str, ...] = (
    "c",
    "d",
    "e",
    "f",
    "g",
    "h",
    "js",
    "k",
    "m",
    "n",
    "p",
    "r",
    "s",
    "u",
)
#: Hole letters with table values.
HOLE_LETTERS: tuple[str, ...] = tuple(letter.upper() for letter in SHAFT_LETTERS)
#: IT grades with table values.
GRADES: tuple[int, ...] = tuple(sorted(IT_UM))

_STEPS = np.asarray(STEPS, dtype=float)
_MAIN = np.asarray(MAIN_STEPS, dtype=float)
_IT = {g: np.asarray(v, dtype=float) for g, v in IT_UM.items()}
_ES = {k: np.asarray(v, dtype=float) for k, v in SHAFT_ES_UM.items()}
_EI = {k: np.asarray(v, dtype=float) for k, v in SHAFT_EI_UM.items()}
_DELTA_LETTERS_8 = ("K", "M", "N")  # Delta rule up to IT8
_DELTA_LETTERS_7 = ("P", "R", "S", "U")  # Delta rule up to IT7


def _sizes(D) -> tuple[np.ndarray, bool]:
    """``D`` as a float array and whether it was a scalar; rejects sizes outside the tables."""
    try:
        arr = np.asarray(D, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError("D", f"nominal size {D!r} is not a number") from exc
    bad = ~np.isfinite(arr) | (arr <= 0.0) | (arr > MAX_SIZE)
    if np.any(bad):
        first = float(np.ravel(arr)[np.argmax(np.ravel(bad))])
        raise InputError(
            "D", f"nominal size {first:g} mm is outside the ISO 286 tables (0 < D <= 500 mm)"
        )
    return arr, arr.ndim == 0


def _out(x: np.ndarray, scalar: bool):
    return float(x) if scalar else x


def _check_grade(grade: int, field: str = "fit") -> None:
    if grade not in IT_UM:
        raise InputError(
            field, f"IT grade {grade} not in the tables (IT{GRADES[0]}..IT{GRADES[-1]})"
        )


def _it(arr: np.ndarray, grade: int) -> np.ndarray:
    # searchsorted(side="left") returns the first step whose upper limit is >= D, which is
    # the standard's "over a up to and including b".
    if grade >= 14 and np.any(arr <= 1.0):
        raise InputError("fit", f"IT{grade} is not used for nominal sizes up to 1 mm (ISO 286-1)")
    return _IT[grade][np.searchsorted(_MAIN, arr, side="left")]


def _step(arr: np.ndarray) -> np.ndarray:
    return np.searchsorted(_STEPS, arr, side="left")


def it_um(D, grade: int):
    """Standard tolerance IT``grade`` (um) at nominal size D (mm), as tabulated."""
    _check_grade(grade)
    arr, scalar = _sizes(D)
    return _out(_it(arr, grade), scalar)


def delta_um(D, grade: int):
    """Delta (um) of the hole rule ES = -ei + Delta: IT_n - IT_(n-1) for grades 3 to 8.

    ISO 286-1 tabulates Delta only for grades 3 to 8 and sets it to 0 up to 3 mm; the
    tabulated values equal the difference of consecutive IT values (tested against print).
    """
    arr, scalar = _sizes(D)
    if not 3 <= grade <= 8:
        return _out(np.zeros_like(arr), scalar)
    delta = _it(arr, grade) - _it(arr, grade - 1)
    return _out(np.where(arr <= 3.0, 0.0, delta), scalar)


def _js_half(it: np.ndarray, grade: int, round_js: bool) -> np.ndarray:
    # ISO 286-1:1988's optional rounding: grades 7..11 replace an odd IT by the even value
    # below (IT values of these grades are whole um, so floor(IT / 2) does it).
    if round_js and 7 <= grade <= 11:
        return np.floor(it / 2.0)
    return it / 2.0


def _shaft(
    arr: np.ndarray, letter: str, grade: int, round_js: bool
) -> tuple[np.ndarray, np.ndarray]:
    it = _it(arr, grade)
    if letter == "js":
        half = _js_half(it, grade, round_js)
        return -half, half
    if letter in _ES:
        es = _ES[letter][_step(arr)]
        return es - it, es
    if letter == "k" and not 4 <= grade <= 7:
        ei = np.zeros_like(arr)
    else:
        ei = _EI[letter][_step(arr)]
    return ei, ei + it


def _hole(
    arr: np.ndarray, letter: str, grade: int, round_js: bool
) -> tuple[np.ndarray, np.ndarray]:
    it = _it(arr, grade)
    low = letter.lower()
    if letter == "JS":
        half = _js_half(it, grade, round_js)
        return -half, half
    if low in _ES:  # general rule: EI = -es
        EI = -_ES[low][_step(arr)]
        return EI, EI + it
    ei = _EI[low][_step(arr)]
    if (letter in _DELTA_LETTERS_8 and grade <= 8) or (letter in _DELTA_LETTERS_7 and grade <= 7):
        ES = -ei + delta_um(arr, grade)
        if letter == "M" and grade == 6:
            ES = np.where((arr > 250.0) & (arr <= 315.0), -9.0, ES)  # footnote to Table 3
    elif letter == "K":
        if np.any(arr > 3.0):
            raise InputError("fit", f"K{grade}: ISO 286-1 gives K above IT8 only up to 3 mm")
        ES = np.zeros_like(arr)
    elif letter == "N":
        if np.any(arr <= 1.0):
            raise InputError("fit", f"N{grade}: N above IT8 is not used up to 1 mm (ISO 286-1)")
        ES = np.where(arr <= 3.0, -ei, 0.0)
    else:  # M above IT8, P..U above IT7
        ES = -ei
    return ES - it, ES


def _check_letter(letter: str, hole: bool) -> None:
    known = HOLE_LETTERS if hole else SHAFT_LETTERS
    if letter not in known:
        kind = "hole" if hole else "shaft"
        raise InputError(
            "fit", f"{kind} letter {letter!r} not in the tables (use {', '.join(known)})"
        )


def shaft_deviations_um(D, letter: str, grade: int, round_js: bool = False):
    """Limit deviations (ei, es) in um of shaft ``letter``+``grade`` at size D (mm).

    ``round_js``: apply ISO 286-1:1988's optional rounding of js7..js11 (module docstring).
    """
    _check_letter(letter, hole=False)
    _check_grade(grade)
    arr, scalar = _sizes(D)
    ei, es = _shaft(arr, letter, grade, round_js)
    return _out(ei, scalar), _out(es, scalar)


def hole_deviations_um(D, letter: str, grade: int, round_js: bool = False):
    """Limit deviations (EI, ES) in um of hole ``letter``+``grade`` at size D (mm)."""
    _check_letter(letter, hole=True)
    _check_grade(grade)
    arr, scalar = _sizes(D)
    EI, ES = _hole(arr, letter, grade, round_js)
    return _out(EI, scalar), _out(ES, scalar)


def clearance_um(
    D,
    hole: str,
    hole_grade: int,
    shaft: str,
    shaft_grade: int,
    which: str = "max",
    round_js: bool = False,
):
    """Largest (ES - ei) or smallest (EI - es) clearance in um; negative = interference."""
    if which not in ("max", "min"):
        raise InputError("fit.clearance", f"{which!r} must be 'min' or 'max'")
    EI, ES = hole_deviations_um(D, hole, hole_grade, round_js)
    ei, es = shaft_deviations_um(D, shaft, shaft_grade, round_js)
    return ES - ei if which == "max" else EI - es


def geometric_mean(step: int) -> float:
    """Geometric mean (mm) of main step ``step`` (index into :data:`MAIN_STEPS`)."""
    return float(np.sqrt(MAIN_STEP_LOWER[step] * MAIN_STEPS[step]))
