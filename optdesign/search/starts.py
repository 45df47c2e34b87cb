"""Where the local searches start: independent draws tilted toward good designs.

Each start is the best of ``m`` points of a scrambled Sobol' sample of the bounds, judged
on the NumPy path in one vectorised evaluation (a thousand designs cost milliseconds).
"Best" is the merit :func:`merit_order` gives: designs that (nearly) meet every
requirement first, by objective, then the rest by how far they violate one. The starts
are independent draws from one distribution - the best of ``m`` uniform points - which is
what the odds of :mod:`optdesign.search.odds` assume; the distribution puts more of its
weight on low objective values than a uniform start does, so the region of attraction of
a good optimum is larger under it and fewer starts find it.

``m`` grows with the dimension (:func:`tilt`): a start in seven variables is chosen
among more points than one in three. Chunk ``k`` of the starts is drawn from its own
Sobol' sample (seed derived from the search's seed and ``k``), so a search that needs
more starts draws them without changing the ones it has, and any prefix of the starts is
the same whatever the number of workers.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from optdesign.solvers.sobol import sobol_points

#: Designs whose largest relative violation is at most this count as nearly feasible
#: when a start is picked: the local solver closes such a gap in a few steps.
NEAR_FEASIBLE = 0.05

#: Points sampled per start, per free variable (rounded up to a power of two).
POINTS_PER_DIMENSION = 4

#: Starts drawn per chunk: a search that needs more draws a new chunk.
CHUNK = 16

#: Population evaluator: designs (one per row) -> (objective, largest relative violation).
Evaluate = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


def tilt(dimension: int) -> int:
    """Points sampled per start: :data:`POINTS_PER_DIMENSION` per free variable, rounded
    up to a power of two (at least 4), so that each start's points form a Sobol' net."""
    return 2 ** max(2, math.ceil(math.log2(max(1, POINTS_PER_DIMENSION * dimension))))


def merit_order(objective: np.ndarray, violation: np.ndarray) -> np.ndarray:
    """Indices of the designs from best to worst: nearly feasible ones
    (violation <= :data:`NEAR_FEASIBLE`) by objective, then the others by violation; a
    NaN objective or violation sorts last. Ties keep the sample's order."""
    objective = np.asarray(objective, dtype=float)
    violation = np.nan_to_num(np.asarray(violation, dtype=float), nan=np.inf)
    usable = (violation <= NEAR_FEASIBLE) & np.isfinite(objective)
    first = np.where(usable, 0, np.where(np.isfinite(violation), 1, 2))
    second = np.where(usable, objective, np.where(np.isfinite(violation), violation, 0.0))
    return np.lexsort((np.arange(len(first)), second, first))


def chunk_seed(seed: int, chunk: int) -> int:
    """The Sobol' scrambling seed of chunk ``chunk`` of a search seeded ``seed``."""
    return (int(seed) * 1_000_003 + 7919 * int(chunk)) % (2**32)


def tilted_chunk(
    evaluate: Evaluate,
    lower: np.ndarray,
    upper: np.ndarray,
    seed: int,
    chunk: int,
    size: int = CHUNK,
    per_start: int | None = None,
) -> np.ndarray:
    """Starts ``chunk * size`` to ``(chunk + 1) * size - 1`` of a search: each the best of
    ``per_start`` (default :func:`tilt`) points of the chunk's own Sobol' sample."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    d = len(lower)
    m = per_start or tilt(d)
    n = size * m
    power = math.ceil(math.log2(n))
    unit = sobol_points(d, power, chunk_seed(seed, chunk))[:n]
    points = lower + unit * (upper - lower)
    objective, violation = evaluate(points)
    starts = np.empty((size, d))
    for k in range(size):
        group = slice(k * m, (k + 1) * m)
        best = merit_order(objective[group], violation[group])[0]
        starts[k] = points[group][best]
    return starts


class TiltedStarts:
    """The starts of one search, drawn a chunk at a time and kept: ``starts[:n]`` is the
    same list however many were asked before."""

    def __init__(
        self,
        evaluate: Evaluate,
        lower: np.ndarray,
        upper: np.ndarray,
        seed: int,
        per_start: int | None = None,
    ) -> None:
        self._evaluate = evaluate
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        self.seed = int(seed)
        self.per_start = per_start or tilt(len(self.lower))
        self._drawn: list[np.ndarray] = []

    def first(self, n: int) -> np.ndarray:
        """The first ``n`` starts (one per row)."""
        while sum(len(c) for c in self._drawn) < n:
            self._drawn.append(
                tilted_chunk(
                    self._evaluate,
                    self.lower,
                    self.upper,
                    self.seed,
                    len(self._drawn),
                    CHUNK,
                    self.per_start,
                )
            )
        if not self._drawn:
            return np.empty((0, len(self.lower)))
        return np.vstack(self._drawn)[:n]


def problem_evaluator(problem, objective: str | None) -> Evaluate:
    """The population evaluator of ``problem``'s ``objective`` on the NumPy path: one call
    of ``problem.evaluate`` for the whole population (no CasADi, no solver). With no
    objective (a target the problem does not name, such as a weighted sum) every design
    scores 0 and the starts are picked by their violation alone."""

    def evaluate(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ev = problem.evaluate(points)
        violation = np.asarray(ev.violation, dtype=float).reshape(-1)
        if objective is None:
            return np.zeros_like(violation), violation
        values = np.asarray(ev.objectives[objective], dtype=float).reshape(-1)
        return values, violation

    return evaluate
