"""Test plug-ins with multimodal design landscapes, each with an independent reference."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def first_passing(
    draws: np.ndarray, passes: Callable[[np.ndarray], np.ndarray], n: int, chunk: int
) -> list[int]:
    """The indices of the first ``n`` rows of ``draws`` that ``passes`` (a row mask of a
    block of rows) accepts, judged ``chunk`` rows at a time until ``n`` pass: the rows
    judging all of them at once would give, for a fraction of the model evaluations (the
    test modules draw their designs when they are collected, in every worker). Fewer
    than ``n`` when too few pass."""
    found: list[int] = []
    for start in range(0, len(draws), chunk):
        with np.errstate(all="ignore"):
            ok = passes(draws[start : start + chunk])
        found += [start + int(i) for i in np.flatnonzero(ok)]
        if len(found) >= n:
            break
    return found[:n]
