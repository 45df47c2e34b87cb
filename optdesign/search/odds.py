"""The odds that a multistart has missed a better optimum: Boender and Rinnooy Kan's
Bayesian estimates from the number of starts and of distinct local optima they reached.

The model (Boender and Rinnooy Kan, "Bayesian stopping rules for multistart global
optimization methods", Math. Programming 37, 1987): the starts are independent draws from
one distribution; the design space splits into K regions of attraction, one per local
optimum, whose shares of that distribution are uniform on the simplex; K has a uniform
(improper) prior on 1, 2, ... After ``n`` starts that reached ``w`` distinct optima, the
posterior of K is

    P(K = k | n, w)  proportional to  k! (k - 1)! / ((k - w)! (n + k - 1)!),   k >= w,

proper when n >= w + 2. Its closed forms (the tests sum the posterior to check them):

- the expected number of optima, E[K] = w (n - 1) / (n - w - 2) (n >= w + 3);
- the expected share of the start distribution held by the regions not yet reached,
  E[Omega] = w (w + 1) / (n (n - 1)): the probability that the next start reaches an
  optimum not seen yet.

Their stopping rule ends the search when E[K] - w, the expected number of optima not yet
seen, falls below one half (:data:`UNSEEN_LIMIT`).

**The probability that a better optimum exists** is E[Omega]: the best optimum is taken to
lie in a region with a chance proportional to the region's share of the starts. The
starts of :mod:`optdesign.search.starts` are tilted toward low objective values, which is
what makes a good optimum's region large under them. The other reading - the best is any
of the K with equal chance, whatever its region's size - gives w / (n - 1)
(:attr:`Odds.p_better_any`), which does not fall below 1 % before a hundred starts even
when every start agrees; it is kept as the cautious figure. ``benchmarks/global_search``
measures both against many seeds of mechanisms with several optima.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from optdesign.solvers.multistart import tie_width
from optdesign.solvers.result import Odds
from optdesign.tolerances import OBJECTIVE_TIE_TOL

#: Boender and Rinnooy Kan's rule: stop once fewer than this many optima are expected unseen.
UNSEEN_LIMIT = 0.5


def odds(starts: int, optima: int) -> Odds:
    """The posterior estimates after ``starts`` counted starts reached ``optima``
    distinct local optima (see the module's docstring)."""
    n, w = int(starts), int(optima)
    if w < 0 or n < w:
        raise ValueError(f"odds: {w} optima cannot come from {n} starts")
    if w == 0:
        return Odds(n, 0, math.inf, 1.0, 1.0)
    expected = w * (n - 1) / (n - w - 2) if n >= w + 3 else math.inf
    if n < w + 2:  # the posterior is improper: nothing can be said yet
        return Odds(n, w, expected, 1.0, 1.0)
    unseen_share = w * (w + 1) / (n * (n - 1))
    return Odds(n, w, expected, min(1.0, unseen_share), min(1.0, w / (n - 1)))


def settled(o: Odds, target: float | None = None) -> bool:
    """Whether a search may stop on these odds: Boender and Rinnooy Kan's rule (fewer than
    :data:`UNSEEN_LIMIT` optima expected unseen) and, with ``target``, an estimated
    probability of a better optimum at most ``target``."""
    if o.optima == 0 or not o.expected_optima - o.optima < UNSEEN_LIMIT:
        return False
    return target is None or o.p_better <= target


def distinct_optima(
    values: Sequence[float], rel_tol: float = OBJECTIVE_TIE_TOL, abs_tol: float = 0.0
) -> list[float]:
    """The distinct local optima among converged starts' values, best first: sorted values
    chained while each is within ``rel_tol`` (relative) or ``abs_tol`` (absolute: what the
    local solver resolves, its tolerance on the value's scale) of the group's first. The
    values are objectives for an optimum, least violations for a verdict of
    infeasibility."""
    out: list[float] = []
    for v in sorted(v for v in values if math.isfinite(v)):
        if not out or v > out[-1] + max(tie_width(out[-1], rel_tol), abs_tol):
            out.append(v)
    return out
