"""ISO 286 fit clearances: one public entry point.

>>> from optdesign.fits import clearance
>>> clearance("H7/g6", 6.0)                       # ISO 286-2 as printed, mm
0.024
>>> round(clearance("H7/g6", 6.0, values="smooth"), 5)  # formulas at D (optimisers)
0.02601

``values="table"`` (default) is what a drawing means: the standard's stepped values,
constant within a size step ("over a up to and including b", D <= 500 mm); it needs a
numeric D (float or NumPy array). ``values="smooth"`` evaluates the ISO 286-1 formulas at
D itself and accepts CasADi symbols; it differs from the table by up to +82 % on the
smallest clearance of H7/g6 (table in :mod:`optdesign.models.iso286`).
"""

from __future__ import annotations

from optdesign.models import iso286
from optdesign.models.fit_formulas import (
    SMOOTH_GRADES,
    SMOOTH_HOLE_LETTERS,
    SMOOTH_SHAFT_LETTERS,
    Fit,
)

__all__ = [
    "GRADES",
    "HOLE_LETTERS",
    "SHAFT_LETTERS",
    "Fit",
    "clearance",
    "supported_fits",
]

#: Hole letters, shaft letters and IT grades with table values (all that is supported).
HOLE_LETTERS: tuple[str, ...] = iso286.HOLE_LETTERS
SHAFT_LETTERS: tuple[str, ...] = iso286.SHAFT_LETTERS
GRADES: tuple[int, ...] = iso286.GRADES


def clearance(fit: str | Fit, D, which: str = "max", values: str = "table"):
    """Diametral clearance (mm) of ``fit`` at nominal diameter D (mm).

    Parameters
    ----------
    fit
        A fit such as ``"H7/g6"``, ``"H11/c11"``, ``"H7/p6"`` or a :class:`Fit`.
    D
        Nominal diameter in mm: float or NumPy array; with ``values="smooth"`` also a
        CasADi expression.
    which
        ``"max"`` (largest clearance, ES - ei) or ``"min"`` (smallest, EI - es).
    values
        ``"table"``: ISO 286-2 as printed (stepped in D); ``"smooth"``: ISO 286-1
        formulas evaluated at D (continuous, for optimisers).

    Returns
    -------
    float, numpy.ndarray or CasADi expression
        Clearance in mm; negative values are interference (transition and interference
        fits).

    Raises
    ------
    optdesign.errors.InputError
        ``"fit"`` for an unsupported letter or grade, ``"fit_values"`` for a symbolic D
        with ``values="table"`` or an unknown ``values``, ``"D"`` for a size outside
        0 < D <= 500 mm (table), ``"fit.clearance"`` for an unknown ``which``.
    """
    f = fit if isinstance(fit, Fit) else Fit.parse(fit, values=values)
    return f.clearance(D, which, values)


def supported_fits() -> dict[str, dict[str, tuple]]:
    """Hole letters, shaft letters and IT grades supported by each kind of values.

    Any hole may be combined with any shaft. A few combinations have no value even so:
    K above IT8 exists only up to 3 mm (table) and has no formula; smooth Delta-rule holes
    (K, M, N, P, U) need grade 6 or more.
    """
    return {
        "table": {"holes": HOLE_LETTERS, "shafts": SHAFT_LETTERS, "grades": GRADES},
        "smooth": {
            "holes": SMOOTH_HOLE_LETTERS,
            "shafts": SMOOTH_SHAFT_LETTERS,
            "grades": SMOOTH_GRADES,
        },
    }
