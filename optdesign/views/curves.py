"""A design's curves over the stroke: its reduction ratio and, with pins, its worst-case
backlash, on the problem's deflection grid."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class StrokeCurves:
    """A design's curves on the problem's deflection grid (``problem.phi``).

    Attributes
    ----------
    ratio
        The reduction ratio at each angle of the grid (motor rad / output rad).
    backlash
        The worst-case output backlash at each angle (deg), or None without pins.
    """

    ratio: np.ndarray
    backlash: np.ndarray | None = None


def stroke_curves(problem: Any, design: dict[str, float], quantities: Any = None) -> StrokeCurves:
    """The :class:`StrokeCurves` of ``design`` (NumPy path of the models).

    Parameters
    ----------
    problem
        The design problem.
    design
        The design: variable name -> value.
    quantities
        ``problem.quantities(design)`` when the caller has it already.
    """
    # a design off its valid range is drawn as it is: NaN where the model has no value
    with np.errstate(all="ignore"):
        q = problem.quantities(design) if quantities is None else quantities
        ratio = np.asarray(q.ratio, dtype=float).ravel()
        backlash = (
            np.asarray(q.backlash.worst_case, dtype=float).ravel() if problem.has("d") else None
        )
    return StrokeCurves(ratio, backlash)
