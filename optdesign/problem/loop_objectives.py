"""The loop's objectives beside ``resonance_gain`` and ``bandwidth_period`` (docs/loop.md,
"The margins and the limit cycle as objectives").

* ``sensitivity_peak``: Ms = 1 / min |1 + L(jw)|, the peak of the sensitivity function,
  at each loop angle 1 / the smooth minimum the ``phase_margin`` and ``modulus_margin``
  rows hold (:func:`~optdesign.problem.loop_margins.soft_least_return_difference`,
  over the margins' 14 frequencies). The soft minimum is never above the exact least
  |1 + L| on those frequencies, so the value is an upper bound of the exact Ms over them
  (by at most the factor 3^(1/128), 0.9 %, where three frequencies are equally near the
  least). It is the same expression on both paths: the solver minimises what the
  independent check computes. A dip of |1 + L| between the 14 frequencies is missed, as
  by the rows.
* ``limit_cycle_amplitude``: the fin amplitude (deg) of the largest stable limit cycle of
  the chain's clearance, by harmonic balance, the requirement row's value
  (:func:`~optdesign.problem.loop_margins.limit_cycle_amplitudes`). It is a root of
  the balance with no smooth form (a cycle appears or vanishes where a phase crossover of
  L_d passes -1), so it exists on the NumPy path only, for the population methods; every
  formulation that needs a smooth form refuses it
  (:func:`~optdesign.problem.objective_refusals.smooth_form_refusal`, with the reason
  :data:`~optdesign.problem.objectives.LIMIT_CYCLE_NOT_SMOOTH`).

A single design's evaluation reads every objective, so it computes the cycles (shared with
the requirement's row through the per-plant cache when the problem has one).

Both are 0 at the grid angles that carry no loop row: they bound nothing there, and the
``max`` over the grid is the max over the loop's angles.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.problem.evaluation import RowsOnDemand
from optdesign.problem.loop import loop_angles, loop_gains, picked, plant_grid, population_size
from optdesign.problem.loop_margins import (
    limit_cycle_amplitudes,
    on_grid,
    soft_least_return_difference,
)


def _grid_width(q) -> int:
    return len(np.ravel(q.phi))


def sensitivity_peak(q) -> Any:
    """The objective's grid expression: 1 / the soft least |1 + L| at the loop's angles,
    0 at the other grid angles (module docstring); None without ``[loop]``."""
    if q.problem.spec.loop is None:
        return None
    idx = loop_angles(q.problem)
    n = _grid_width(q)
    grid = picked(plant_grid(q), idx, n)
    peak = 1.0 / soft_least_return_difference(q, grid, loop_gains(q), idx)
    if m.is_symbolic(peak):
        import casadi as ca

        column = ca.SX.zeros(n, 1)
        values = ca.vec(peak)
        for k, i in enumerate(idx):
            column[int(i)] = values[k]
        return column
    pop = population_size(q)
    values = np.broadcast_to(np.asarray(peak, dtype=float).reshape(pop, -1), (pop, len(idx)))
    out = np.zeros((pop, n))
    out[:, idx] = values
    return out if pop > 1 else out[0]


def limit_cycle_amplitude(q) -> RowsOnDemand | None:
    """The objective's grid rows on the NumPy path (deg; module docstring), computed when
    read, for a single design as for a population (a search that ranks by another
    objective pays no harmonic balance); None without ``[loop]`` and on the solver path."""
    if q.problem.spec.loop is None or m.is_symbolic(q.ratio):
        return None
    idx = loop_angles(q.problem)
    # the requirement's rows, built on first read (a single design's are eager)
    return on_grid(lambda: limit_cycle_amplitudes(q, idx), population_size(q), idx, _grid_width(q))
