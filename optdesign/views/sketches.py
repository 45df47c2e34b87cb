"""A design's sketch at the stroke's ends and middle, from the mechanism's public
:meth:`~optdesign.mechanisms.Mechanism.sketch` (no mechanism is named here)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.mechanisms.base import Sketch
from optdesign.user_code import call_method


@dataclass(frozen=True)
class SketchFrame:
    """The mechanism's sketch at one deflection.

    Attributes
    ----------
    phi
        The deflection (rad).
    sketch
        The mechanism's :class:`~optdesign.mechanisms.Sketch` there, or None: the
        mechanism draws none.
    """

    phi: float
    sketch: Sketch | None


def stroke_angles(problem: Any) -> tuple[float, float, float]:
    """The deflections a design is sketched at: the stroke's ends and its middle (rad)."""
    first, last = problem.phi[0], problem.phi[-1]
    return float(first), float(0.5 * (first + last)), float(last)


def sketch_frames(
    problem: Any, design: dict[str, float], quantities: Any = None
) -> tuple[SketchFrame, ...]:
    """The :class:`SketchFrame` of ``design`` (variable name -> value) at each of
    :func:`stroke_angles`, drawn by the mechanism of its ``quantities`` (computed here
    unless the caller has them).

    Raises
    ------
    OptDesignError
        A user's mechanism whose ``sketch`` fails (:func:`~optdesign.user_code.
        call_method` names it).
    """
    mech = (problem.quantities(design) if quantities is None else quantities).mechanism
    frames = []
    for phi in stroke_angles(problem):
        with np.errstate(all="ignore"):
            sk = call_method(mech, "sketch", phi, doing="while drawing its sketch")
        frames.append(SketchFrame(phi, sk))
    return tuple(frames)
