"""Catalogue (discrete) variables: a variable restricted to a list of values.

The loader turns ``values = [...]`` or ``catalogue = "ISO 3408"`` into
:attr:`Variable.values` with the bounds set to the first and last item. Here: which
variables are discrete, how many combinations they make, how to branch on one, and how
to restrict an :class:`~optdesign.formulations.nlp.NLP` to a sub-box (fixing a variable
is the sub-box of one value). The NLP is built once; a node only changes its bounds.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from optdesign.formulations.nlp import NLP
from optdesign.problem.design_problem import DesignProblem, Variable

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


def restrict(nlp: NLP, bounds: Mapping[str, tuple[float, float]]) -> NLP:
    """A copy of ``nlp`` whose design variables ``name`` lie in ``bounds[name]`` (mm, ...).

    The scaling of z is kept (same x_lo, x_span), so starts and warm starts carry over.
    """
    lbz = np.array(nlp.lbz, dtype=float)
    ubz = np.array(nlp.ubz, dtype=float)
    for name, (lo, hi) in bounds.items():
        k = nlp.design_names.index(name)
        lbz[k] = (lo - nlp.x_lo[k]) / nlp.x_span[k]
        ubz[k] = (hi - nlp.x_lo[k]) / nlp.x_span[k]
    return replace(nlp, lbz=lbz, ubz=ubz)
