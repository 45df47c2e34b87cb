"""The NumPy path's evaluation of a population: objective values, constraint rows and
each design's largest relative violation, from one design's (or a population's)
:class:`~optdesign.problem.design_problem.Expressions`.

Some values are costly per design: the checks of the NumPy path alone, never rows of an
NLP (the loop's pole damping and limit cycles: a root finding and a harmonic balance per
design and angle), and an objective that is a root (the loop's bandwidth). They are held
as :class:`RowsOnDemand`. In a population a constraint block's are computed only for the
designs that pass every other row, since a design that fails one is infeasible whatever
they say; an objective's only when it is read (:class:`PopulationObjectives`: a global
search's start sample reads the one objective it ranks by). A single design, and any
reader that takes such a value as an array, gets every row.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.tolerances import FEASIBILITY_TOL


@dataclass
class BlockValues:
    """Values of one constraint block on the NumPy path (rows of a population).

    ``unchecked``: the designs whose rows were not computed (NaN in ``values``) because
    another row already fails (:class:`RowsOnDemand`); None when every row was."""

    values: np.ndarray
    lower: float | None
    upper: float | None
    unchecked: np.ndarray | None = None


@dataclass
class Evaluation:
    """Objectives and constraints of designs on the NumPy path.

    ``objectives``: name -> value (array over the population, or a float for one
    design); ``constraints``: block name -> :class:`BlockValues`; ``violation``: the
    largest relative violation per design.
    """

    objectives: Mapping[str, Any]
    constraints: dict[str, BlockValues]
    violation: Any


@dataclass
class RowsOnDemand:
    """The rows of a check computed design by design, for the designs asked only.

    ``rows_of(designs)`` gives one row per design index in ``designs`` (shape
    ``(len(designs), width)``). As an array (``np.asarray``) it is every design's rows,
    computed once."""

    rows_of: Callable[[np.ndarray], np.ndarray]
    designs: int
    width: int
    _all: np.ndarray | None = field(default=None, repr=False)

    @property
    def shape(self) -> tuple[int, int]:
        return (self.designs, self.width)

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        if self._all is None:
            self._all = self.of(np.arange(self.designs))
        return self._all if dtype is None else self._all.astype(dtype)

    def of(self, designs: np.ndarray) -> np.ndarray:
        """Every design's rows, NaN for the designs not in ``designs``."""
        out = np.full((self.designs, self.width), np.nan)
        designs = np.asarray(designs, dtype=int)
        if len(designs):
            out[designs] = np.asarray(self.rows_of(designs), dtype=float).reshape(
                len(designs), self.width
            )
        return out


class PopulationObjectives(Mapping[str, np.ndarray]):
    """A population's objective values, each computed when it is first read: name ->
    one value per design (:func:`term_values` of the objective's term)."""

    def __init__(self, terms: Mapping[str, Any], pop: int, n_phi: int):
        self._terms, self._pop, self._n_phi = dict(terms), pop, n_phi
        self._values: dict[str, np.ndarray] = {}

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._values:
            term = self._terms[name]  # KeyError for a name the problem lacks
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                self._values[name] = term_values(term, self._pop, self._n_phi)
        return self._values[name]

    def __iter__(self):
        return iter(self._terms)

    def __len__(self) -> int:
        return len(self._terms)


def term_values(term: Any, pop: int, n_phi: int) -> np.ndarray:
    """Value of an objective term for each of ``pop`` designs on the NumPy path."""
    e = np.asarray(term.expr, dtype=float)
    if term.kind == "scalar" and e.shape == (pop,):
        # one value per design already reduced over the grid (od.math.grid_max of a
        # population): a column, not a row to spread over the angles
        e = e[:, None]
    e = np.broadcast_to(e, (pop, n_phi))
    if term.kind == "spread":
        return m.grid_spread(e)
    if term.kind == "max":
        return e.max(axis=-1)
    return e[:, 0]


def population_rows(e: np.ndarray, pop: int) -> np.ndarray:
    """A constraint block's values as one row per design of a population of ``pop``: a
    block that does not depend on the design (a grid row, one row, or one number) is
    the same row for every design."""
    if e.ndim == 0:
        return np.full((pop, 1), float(e))
    if e.ndim == 2 and e.shape[0] == 1 and pop > 1:
        return np.broadcast_to(e, (pop, e.shape[1]))
    if e.size % pop == 0:
        return e.reshape(pop, -1)
    return np.broadcast_to(e.reshape(1, -1), (pop, e.size))


def relative_violation(values, lower, upper):
    """Violation of lower <= values <= upper, relative to max(1, |bound|)."""
    values = np.asarray(values, dtype=float)
    viol = np.zeros_like(values)
    if lower is not None:
        viol = np.maximum(viol, (lower - values) / max(1.0, abs(lower)))
    if upper is not None:
        viol = np.maximum(viol, (values - upper) / max(1.0, abs(upper)))
    return np.where(np.isnan(values), np.inf, viol)


def evaluation_of(
    ex: Any, pop: int, n_phi: int, objective_limits: Mapping[str, float], single: bool
) -> Evaluation:
    """The :class:`Evaluation` of the expressions ``ex`` of ``pop`` designs (module
    docstring: the screened blocks last, for the designs that pass the others)."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        objectives = PopulationObjectives(ex.objectives, pop, n_phi)
        values: dict[str, BlockValues] = {}
        worst = np.zeros(pop)

        def add(name: str, e: np.ndarray, lower, upper, unchecked=None) -> None:
            nonlocal worst
            viol = np.nan_to_num(relative_violation(e, lower, upper).max(axis=-1), nan=np.inf)
            if unchecked is not None:
                viol = np.where(unchecked, 0.0, viol)
            worst = np.maximum(worst, viol)
            values[name] = BlockValues(e, lower, upper, unchecked)

        for block in ex.constraints:
            if not isinstance(block.expr, RowsOnDemand):
                e = population_rows(np.asarray(block.expr, dtype=float), pop)
                add(block.name, e, block.lower, block.upper)
        for name, limit in objective_limits.items():
            add(f"{name}_max", objectives[name][:, None], None, limit)
        passing = np.flatnonzero(worst <= FEASIBILITY_TOL) if pop > 1 else np.arange(pop)
        unchecked = np.ones(pop, dtype=bool)
        unchecked[passing] = False
        for block in ex.constraints:
            if isinstance(block.expr, RowsOnDemand):
                e = block.expr.of(passing)
                add(block.name, e, block.lower, block.upper, unchecked if unchecked.any() else None)
        # the blocks in the problem's order, then the objectives' limits
        order = [b.name for b in ex.constraints] + [f"{n}_max" for n in objective_limits]
        constraints = {name: values[name] for name in order}
    if single:
        objectives = {k: float(v[0]) for k, v in objectives.items()}
        constraints = {
            k: BlockValues(v.values[0], v.lower, v.upper) for k, v in constraints.items()
        }
        worst = float(worst[0])
    return Evaluation(objectives, constraints, worst)
