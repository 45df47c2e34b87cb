"""Catalogue (discrete) variables: a variable restricted to a list of values.

The loader turns ``values = [...]`` or ``catalogue = "ISO 3408"`` into
:attr:`Variable.values` with the bounds set to the first and last item. Here: which
variables are discrete, how many combinations they make, how to branch on one. A node is
a sub-box of the catalogue variables (fixing a variable is the sub-box of one
value), passed to the NLP solver per solve (:meth:`NLP.bounds`): the NLP is built once.
"""

from __future__ import annotations

import math

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.variables import Variable

#: A relaxed value within this relative distance of a catalogue item counts as that item.
ON_ITEM_TOL = 1e-6


def discrete_variables(problem: DesignProblem) -> list[Variable]:
    """The free variables that take catalogue values."""
    return [v for v in problem.free if v.discrete]


def has_discrete(problem: DesignProblem, objective: str | None = None) -> bool:
    """True when some free variable takes catalogue values (``--formulation auto``; the
    objective does not matter)."""
    return bool(discrete_variables(problem))


def n_combinations(problem: DesignProblem) -> int:
    """Product of the catalogue sizes."""
    return math.prod(len(v.values) for v in discrete_variables(problem))


def items_within(values: tuple[float, ...], lo: float, hi: float) -> list[float]:
    """Catalogue items in [lo, hi]."""
    tol = ON_ITEM_TOL * max(1.0, abs(hi))
    return [v for v in values if lo - tol <= v <= hi + tol]


def nearest_item(value: float, values: tuple[float, ...]) -> tuple[float, float]:
    """(nearest catalogue item, its relative distance to ``value``)."""
    item = min(values, key=lambda v: abs(v - value))
    return item, abs(item - value) / max(1.0, abs(item))


def branch(value: float, values: list[float]) -> tuple[list[float], list[float]]:
    """Split the items around a relaxed value: those below it and those above it."""
    below = [v for v in values if v < value]
    above = [v for v in values if v > value]
    return below, above


class CatalogueCoordinates:
    """Search coordinates of a problem with catalogue variables, for population methods
    (differential evolution, NSGA-II): a catalogue variable is searched as the index of
    its value (rounded to the nearest item), so that the search visits catalogue items
    only, as the catalogue formulation does; continuous variables keep their bounds.

    Attributes
    ----------
    discrete
        Positions of the catalogue variables among the free ones.
    bounds
        (lower, upper) of every coordinate: 0 and the last index for catalogue variables.
    integrality
        True where the coordinate is an index (scipy's ``integrality``).
    """

    def __init__(self, problem: DesignProblem):
        self.free = problem.free
        self.discrete = [k for k, v in enumerate(self.free) if v.discrete]
        self.values = {k: np.asarray(self.free[k].values, dtype=float) for k in self.discrete}
        lo, hi = problem.lower().astype(float), problem.upper().astype(float)
        for k in self.discrete:
            lo[k], hi[k] = 0.0, float(len(self.values[k]) - 1)
        self.bounds = list(zip(lo, hi, strict=True))
        self.integrality = np.array([k in self.values for k in range(len(self.free))])

    def to_design(self, Z: np.ndarray) -> np.ndarray:
        """Design vectors (rows, or one vector) from search coordinates."""
        X = np.array(Z, dtype=float, copy=True)
        for k, vals in self.values.items():
            idx = np.clip(np.rint(X[..., k]), 0, len(vals) - 1).astype(int)
            X[..., k] = vals[idx]
        return X
