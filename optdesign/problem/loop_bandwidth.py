"""The objective ``bandwidth_period``: 1 / the least closed-loop bandwidth over the loop's
angles (docs/loop.md, "The bandwidth as an objective").

The bandwidth f_k at loop angle k is a root: the first frequency where |T_k(j 2 pi f)|^2
falls to half its static value. It has no closed form, but it has a smooth epigraph.
Where |T_k| falls monotonically up to f_k, a period t bounds the objective,
max_k 1 / f_k <= t, exactly when every loop angle still passes half the power at 1 / t:

    |T_k(j 2 pi / t)|^2 / |T_k(j 2 pi / (t 10^4))|^2 - 1/2 >= 0   for every k

which is the requirement row ``bandwidth`` (:func:`~optdesign.problem.loop.
bandwidth_ratio`) at f = 1 / t. The NLP minimises t subject to these rows
(:attr:`~optdesign.problem.objectives.ObjectiveInfo.bound_rows`). The NumPy path computes
the exact value, the least root of |T_k| (:func:`optdesign.models.loop_linear.bandwidth`),
so the solver's t is checked against it (``checked_start``: a t below the exact period,
where |T| dips under half power before f = 1 / t and rises again, is refused as "bound not
tight"). That check is where the monotonicity is verified, design by design.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.models import loop_linear as ll
from optdesign.models.loop_plant import Controller, DrivePlant
from optdesign.problem.evaluation import RowsOnDemand
from optdesign.problem.loop import (
    CACHED_PLANTS,
    bandwidth_ratio,
    loop_angles,
    loop_gains,
    picked,
    plant_grid,
    population_size,
)
from optdesign.problem.loop_margins import on_grid, per_plant_rows

#: |T|^2 over its static value at the bandwidth: half the power.
HALF_POWER = 0.5

#: The solver's start for t: the rigid drive's second-order period, times this (a start on
#: the feasible side, since the chain's compliance and the current loop's lag slow the
#: loop below the rigid estimate).
START_MARGIN = 1.1


@lru_cache(maxsize=CACHED_PLANTS)
def _bandwidth(plant: DrivePlant, loop: Controller) -> float:
    # frozen records: the same plant met again (sensitivities, a front's neighbours) is
    # answered from the cache, as the loop's stability and cycles are
    return ll.bandwidth(plant, loop)


def _period(plant: DrivePlant, loop: Controller) -> float:
    """1 / f (s) of the loop at one plant."""
    return 2.0 * math.pi / _bandwidth(plant, loop)


def _exact_periods(q) -> np.ndarray | RowsOnDemand:
    """1 / f_k (s) at the loop's angles, 0 at the other grid angles (they bound nothing),
    one row per design; NaN at the loop's angles for a design whose drive is no plant. A population's rows are
    computed when read (a root finding per design and angle)."""
    idx = loop_angles(q.problem)
    width = len(np.ravel(q.phi))
    rows = on_grid(lambda: per_plant_rows(q, idx, _period), population_size(q), idx, width)
    return np.asarray(rows) if rows.designs == 1 else rows


def _rigid_periods(q) -> Any:
    """The rigid drive's second-order period 1 / f_b over the grid, times
    :data:`START_MARGIN`: the solver's start for t (docs/loop.md, "The linear loop")."""
    grid, gains = plant_grid(q), loop_gains(q)
    J = grid.motor_inertia_at_fin + grid.fin_inertia
    K = m.fmax(grid.ratio * gains.kp + grid.hinge_spring, 1e-9 * J)
    zeta = (grid.ratio * gains.kd + grid.fin_damping) / (2.0 * m.sqrt(K * J))
    a = 1.0 - 2.0 * zeta**2
    w_b = m.sqrt(K / J) * m.sqrt(a + m.sqrt(a * a + 1.0))
    return START_MARGIN * 2.0 * math.pi / w_b


def bandwidth_period(q) -> Any:
    """The objective's grid expression: on the NumPy path the exact 1 / f_k at the loop's
    angles (0 elsewhere), whose max is 1 / min_k f_k; on the solver path the start for the
    epigraph variable (:func:`_rigid_periods`). None without ``[loop]``."""
    if q.problem.spec.loop is None:
        return None
    return _rigid_periods(q) if m.is_symbolic(q.ratio) else _exact_periods(q)


def bandwidth_period_rows(q, t) -> tuple[Any, list[str]]:
    """The rows, each >= 0, that hold exactly when the period ``t`` (s) bounds the
    objective (module docstring), at the loop's angles, with their labels."""
    idx = loop_angles(q.problem)
    grid = picked(plant_grid(q), idx, len(q.phi))
    ratio = bandwidth_ratio(q, grid, loop_gains(q), 1.0 / t)
    return ratio - HALF_POWER, [q.problem.phi_labels[i] for i in idx]
