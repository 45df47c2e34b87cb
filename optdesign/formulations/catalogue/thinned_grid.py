"""The thinned grid of a catalogue node: the rows of every other grid angle (and of the
angles a search learnt), which a node of several item combinations keeps
(:mod:`optdesign.formulations.catalogue.node_solver`)."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.programs.nlp import NLP, Bounds
from optdesign.solvers.base import row_misses
from optdesign.tolerances import LEFT_OUT_ROW_TOL

#: A node of several item combinations keeps every this-many-th grid angle's rows ...
NODE_ANGLE_STEP = 2

#: ... when the grid has at least this many angles (fewer: the node's own rows).
NODE_THIN_FROM = 21


def thinned_angles(points: int) -> list[int]:
    """The grid angles (indices) whose rows a node of several item combinations keeps
    (its thinned grid): every :data:`NODE_ANGLE_STEP`-th and both ends; every angle below
    :data:`NODE_THIN_FROM`. Every other angle: with a sparser subset (13 of 61) the
    nodes of the motor's problems met rows between the kept angles that their leaves
    then missed, and the search solved more nodes than it saved (benchmarks/README.md,
    "Catalogue nodes on every other grid angle")."""
    if points < NODE_THIN_FROM:
        return list(range(points))
    return sorted({*range(0, points, NODE_ANGLE_STEP), points - 1})


def thinned_rows(problem: DesignProblem, nlp: NLP, extra: Iterable[str] = ()) -> list[int] | None:
    """The rows of ``nlp`` a node of several item combinations keeps: every row not
    labelled with a grid angle, and those of :func:`thinned_angles` and of the angles
    ``extra`` (labels; the NLP's rows are named ``NAME[phi=+12.0deg]``); None when every
    angle is kept, or when no row is left out (no row of the NLP names an angle the
    thinned grid leaves out)."""
    angles = thinned_angles(len(problem.phi))
    if len(angles) == len(problem.phi):
        return None
    labels = set(problem.phi_labels)
    kept = {problem.phi_labels[k] for k in angles} | set(extra)
    rows = [
        k
        for k, name in enumerate(nlp.g_names)
        if not (lab := _angle_label(name)) or lab not in labels or lab in kept
    ]
    return rows if len(rows) < len(nlp.g_names) else None


def missed_angles(nlp: NLP, z: np.ndarray, bounds: Bounds, rows: np.ndarray) -> list[str]:
    """The grid angles (labels) of the rows of ``nlp`` left out of ``rows`` that the
    point ``z`` misses beyond :data:`~optdesign.tolerances.LEFT_OUT_ROW_TOL` (or where a
    row is not a number) under ``bounds``."""
    miss = row_misses(nlp, z, bounds)
    left_out = np.ones(miss.size, dtype=bool)
    left_out[rows] = False
    bad = left_out & ~(miss <= LEFT_OUT_ROW_TOL)
    return sorted({lab for k in np.flatnonzero(bad) if (lab := _angle_label(nlp.g_names[k]))})


def _angle_label(name: str) -> str:
    """The grid angle's label in a row's name (``phi=+12.0deg``, also of a row's piece
    ``phi=+12.0deg (2)``), or ""."""
    inside = name[name.find("[") + 1 : name.rfind("]")] if "[" in name else ""
    words = inside.replace(",", " ").split()
    return next((word for word in words if word.startswith("phi=")), "")
