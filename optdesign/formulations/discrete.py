"""Catalogue (discrete) variables: a variable restricted to a list of values.

The loader turns ``values = [...]`` or ``catalogue = "ISO 3408"`` into
:attr:`Variable.values` with the bounds set to the first and last item. Here: which
variables are discrete, how many combinations they make, how to branch on one. A node is
a sub-box of the catalogue variables (fixing a variable is the sub-box of one
value), passed to the NLP solver per solve (:meth:`NLP.bounds`): the NLP is built once.
"""

from __future__ import annotations

import math

from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.variables import Variable

#: A relaxed value within this relative distance of a catalogue item counts as that item.
ON_ITEM_TOL = 1e-6


def discrete_variables(problem: DesignProblem) -> list[Variable]:
    """The free variables that take catalogue values."""
    return [v for v in problem.free if v.discrete]


def has_discrete(problem: DesignProblem) -> bool:
    """True when some free variable takes catalogue values (``--formulation auto``)."""
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
