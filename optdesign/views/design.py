"""One design as a page shows it, evaluated: its objectives, its binding and violated
constraint rows, its curves over the stroke, its sketch frames and its facts."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.solvers.constraint_rows import constraint_rows
from optdesign.solvers.result import ConstraintReport
from optdesign.views.curves import StrokeCurves, stroke_curves
from optdesign.views.facts import DesignFacts, design_facts
from optdesign.views.sketches import SketchFrame, sketch_frames


@dataclass(frozen=True)
class DesignRows:
    """A design's constraint rows that a page or a figure lists.

    Attributes
    ----------
    active
        The rows at their bound (what limits the design).
    violated
        The rows beyond their bound.
    """

    active: tuple[ConstraintReport, ...]
    violated: tuple[ConstraintReport, ...]


@dataclass(frozen=True)
class DesignView:
    """Everything a page shows of one design, evaluated.

    Attributes
    ----------
    design
        The design: variable name -> value.
    objectives
        Every objective's value at the design.
    rows
        Its binding and violated constraint rows.
    curves
        Its ratio and backlash over the stroke.
    frames
        Its sketch at the stroke's ends and middle.
    facts
        What it achieves (mean ratio, ratio range, drive efficiency, motor).
    """

    design: Mapping[str, float]
    objectives: Mapping[str, float]
    rows: DesignRows
    curves: StrokeCurves
    frames: tuple[SketchFrame, ...]
    facts: DesignFacts | None


def design_rows(problem: Any, design: dict[str, float], evaluation: Any = None) -> DesignRows:
    """The :class:`DesignRows` of ``design`` (``evaluation``: its ``problem.evaluate``
    when the caller has it already)."""
    active, violated = constraint_rows(problem, design, ev=evaluation)
    return DesignRows(tuple(active), tuple(violated))


def design_view(problem: Any, design: dict[str, float]) -> DesignView:
    """The :class:`DesignView` of ``design``: one evaluation of the problem for its
    objectives and rows, one of its quantities for its curves, sketch and facts.

    Raises
    ------
    OptDesignError
        A user's mechanism whose ``sketch`` fails.
    """
    with np.errstate(all="ignore"):
        ev = problem.evaluate(np.array([design[v.name] for v in problem.free], dtype=float))
        q = problem.quantities(design)
    return DesignView(
        dict(design),
        {k: float(v) for k, v in ev.objectives.items()},
        design_rows(problem, design, ev),
        stroke_curves(problem, design, q),
        sketch_frames(problem, design, q),
        design_facts(problem, design, q),
    )
