"""What the loop's requirement rows and objectives share (docs/loop.md): the margins'
frequencies and the smooth least return difference |1 + L| over them (the rows
``phase_margin`` and ``modulus_margin``, the objective ``sensitivity_peak``), and the
largest stable limit cycle of the chain's clearance at each loop angle (the row and the
objective ``limit_cycle_amplitude``), with the per-design rows of the NumPy path's checks.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.models import loop_linear as ll
from optdesign.models.loop_backlash import limit_cycles
from optdesign.models.loop_plant import Controller, DrivePlant
from optdesign.problem.evaluation import RowsOnDemand
from optdesign.problem.loop import (
    CACHED_PLANTS,
    LoopGains,
    PlantGrid,
    drive_plants_of,
    population_size,
    resonance_frequency,
    response,
)

#: The margins' frequencies about the drive's mode: w_r (1 + RESONANCE_STEP j), j = -3..3
#: (the mode's dip of |1 + L| is a few % of w_r wide at 5 % damping; 4 % steps missed
#: the shipped optimum's minimum by 2 %, these by 0.3 %).
RESONANCE_STEP = 0.02
#: The power p of the smooth minimum (sum x^-p)^(-1/p) of |1 + L|^2 over the frequencies:
#: it is below the least |1 + L| by at most a factor n^(1/2p), n the frequencies equally
#: near it (three: 0.9 %; p = 16 gave 3.5 %, enough to move a design across a limit).
SOFT_MIN_POWER = 64
#: Frequencies the harmonic balance samples to bracket L_d's phase crossovers: over the
#: loop's span of about five decades, 400 a decade (8000, the model's default, gives the
#: same cycles at the shipped problem's seven angles, nine times slower).
CYCLE_POINTS = 2000


def reference_frequency(spec) -> float:
    """f_ref (Hz), the middle of the margins' grid: the required bandwidth, else the
    bandwidth the gains are placed for, else 10 Hz."""
    req, loop = spec.requirements, spec.loop
    if req.bandwidth_min is not None:
        return req.bandwidth_min
    if loop is not None and loop.bandwidth is not None:
        return loop.bandwidth
    return 10.0


def margin_frequencies(spec) -> np.ndarray:
    """The margins' fixed frequencies (rad/s): f_ref x 2^(k/2), k = -2 ... 4 (half an
    octave apart from f_ref / 2 to 4 f_ref, around the loop's crossover;
    :func:`reference_frequency`)."""
    f = reference_frequency(spec)
    return 2.0 * np.pi * f * 2.0 ** (np.arange(-2, 5) / 2.0)


def soft_least_return_difference(q, grid: PlantGrid, gains: LoopGains, idx) -> Any:
    """The smooth lower bound of min |1 + L(jw)| over the margins' frequencies and about
    w_r (see the module's docstring), at the loop's angles ``idx``: (sum_k x_k^-p)^(-1/2p)
    of x_k = |1 + L_k|^2, summed as a log-sum-exp shifted by its largest term (the shift
    cancels in the value and its derivatives; unshifted, x^-p overflows where |1 + L| is
    small)."""
    p = SOFT_MIN_POWER
    w_r = resonance_frequency(q, idx)
    around = [w_r * (1.0 + RESONANCE_STEP * j) for j in range(-3, 4)]
    z = [
        -p * m.log(ll.return_difference_squared(response(grid, gains, w)) + 1e-300)
        for w in (*margin_frequencies(q.problem.spec), *around)
    ]
    top = z[0]
    for zk in z[1:]:
        top = m.fmax(top, zk)
    total = 0.0
    for zk in z:
        total = total + m.exp(zk - top)
    return m.exp(-(top + m.log(total)) / (2.0 * p))


@lru_cache(maxsize=CACHED_PLANTS)
def _largest_cycle(plant: DrivePlant, loop: Controller) -> float:
    return float(np.degrees(limit_cycles(plant, loop, CYCLE_POINTS).largest_stable_fin_amplitude))


def limit_cycle_amplitudes(q, idx: np.ndarray) -> np.ndarray | RowsOnDemand:
    """The fin amplitude (deg) of the largest stable limit cycle the chain's clearance
    sustains at each loop angle ``idx``, by harmonic balance
    (:func:`optdesign.models.loop_backlash.limit_cycles`; 0 where there is none), NumPy,
    one row per design of a population (NaN for a design whose drive is no plant)."""
    return per_plant_rows(q, idx, _largest_cycle)


def on_grid(
    make_rows: Callable[[], np.ndarray | RowsOnDemand], designs: int, idx: np.ndarray, width: int
) -> RowsOnDemand:
    """Rows at the loop's angles ``idx`` placed on the grid's ``width`` angles, 0 at the
    others (they bound nothing), computed when read: ``make_rows()`` (one design's array,
    or a population's :class:`RowsOnDemand`) is called on the first read only."""
    held: list = []

    def rows_of(chosen: np.ndarray) -> np.ndarray:
        if not held:
            held.append(make_rows())
        rows = held[0]
        if isinstance(rows, RowsOnDemand):
            at = rows.rows_of(chosen)
        else:
            at = np.asarray(rows, dtype=float).reshape(1, -1)
        out = np.zeros((len(chosen), width))
        out[:, idx] = at
        return out

    return RowsOnDemand(rows_of, designs, width)


def per_plant_rows(q, idx: np.ndarray, fn) -> np.ndarray | RowsOnDemand:
    """``fn(plant, loop)`` at each loop angle ``idx`` of each design of the NumPy
    quantities ``q``: an array for one design, :class:`RowsOnDemand` for a population
    (NaN for a design whose drive is no plant)."""
    # a population's rows are screened: computed for the designs that pass every other
    # row only (optdesign.problem.evaluation), which spares a global search's start
    # sample a harmonic balance per design and angle
    drives: list = []

    def rows_of(designs: np.ndarray) -> np.ndarray:
        if not drives:
            drives.extend(drive_plants_of(q, idx, strict=False))
        return np.array(
            [
                [np.nan] * len(idx)
                if drives[i] is None
                else [fn(p, drives[i][1]) for p in drives[i][0]]
                for i in designs
            ],
            dtype=float,
        ).reshape(len(designs), len(idx))

    pop = population_size(q)
    rows = RowsOnDemand(rows_of, pop, len(idx))
    return np.asarray(rows) if pop == 1 else rows
