"""Scrambled Sobol' points without importing ``scipy.stats``.

``scipy.stats.qmc`` pulls in all of ``scipy.stats`` (much of a short ``optdesign solve``
command's time: benchmarks/README.md, "Figures behind comments in the code") for a handful of points. This module draws the same
points as ``scipy.stats.qmc.Sobol(d, scramble=True, seed=seed).random_base2(m)``
(Joe-Kuo direction numbers read from SciPy's own data file, linear matrix scrambling
and a digital shift from ``numpy.random.default_rng(seed)`` in SciPy's order), so the
multistart starts are unchanged; ``tests/test_sobol.py`` compares them with SciPy's.
When SciPy's data file is not where this module expects it, SciPy is used.
"""

from __future__ import annotations

import importlib.util
import os
from functools import lru_cache

import numpy as np

#: Bits of the generator (SciPy's default).
BITS = 30


@lru_cache(maxsize=1)
def _direction_numbers() -> tuple[np.ndarray, np.ndarray] | None:
    spec = importlib.util.find_spec("scipy")  # locates SciPy without importing it
    locations = list(spec.submodule_search_locations or []) if spec else []
    for base in locations:
        path = os.path.join(base, "stats", "_sobol_direction_numbers.npz")
        if os.path.exists(path):
            with np.load(path) as data:
                return np.asarray(data["poly"]), np.asarray(data["vinit"])
    return None


def _direction_matrix(d: int, poly: np.ndarray, vinit: np.ndarray) -> list[list[int]]:
    """Direction numbers v[k][j] (Joe and Kuo 2008, section 2), left-aligned on BITS."""
    v = [[1] * BITS for _ in range(d)]
    for k in range(1, d):
        p = int(poly[k])
        deg = p.bit_length() - 1
        row = [int(x) for x in vinit[k, :deg]] + [0] * (BITS - deg)
        for j in range(deg, BITS):
            new = row[j - deg]
            pow2 = 1
            for i in range(deg):
                pow2 <<= 1
                if (p >> (deg - 1 - i)) & 1:
                    new ^= pow2 * row[j - i - 1]
            row[j] = new
        v[k] = row
    return [[x << (BITS - 1 - j) for j, x in enumerate(row)] for row in v]


@lru_cache(maxsize=64)
def sobol_points(d: int, m: int, seed: int) -> np.ndarray:
    """``2**m`` scrambled Sobol' points in [0, 1)^d, equal to SciPy's for the same seed.

    The points depend on ``(d, m, seed)`` alone, and a catalogue search draws the same
    ones for each of its nodes: they are kept (read-only; ``sobol_starts`` scales a copy).

    Parameters
    ----------
    d
        Dimension.
    m
        log2 of the number of points.
    seed
        Seed of ``numpy.random.default_rng`` (the scrambling).
    """
    tables = _direction_numbers()
    if tables is None or d > len(tables[0]):
        from scipy.stats import qmc

        pts = qmc.Sobol(d, scramble=True, seed=seed).random_base2(m)
        pts.flags.writeable = False
        return pts
    v = _direction_matrix(d, *tables)
    rng = np.random.default_rng(seed)
    # Same draws, same order as SciPy: the shift bits, then the lower-triangular matrices.
    shift_bits = rng.integers(0, 2, size=(d, BITS), dtype=np.uint32)
    ltm = np.tril(rng.integers(0, 2, size=(d, BITS, BITS), dtype=np.uint32))
    shift = [sum(int(b) << j for j, b in enumerate(row)) for row in shift_bits]
    weights = [1 << (BITS - 1 - j) for j in range(BITS)]
    sv = []
    for k in range(d):
        np.fill_diagonal(ltm[k], 1)
        rows = [sum(w for w, b in zip(weights, ltm[k, p], strict=True) if b) for p in range(BITS)]
        scrambled = []
        for vkj in v[k]:
            # Bit p of the result is the parity of (row p of L) & v, p counted from the top.
            scrambled.append(
                sum(((bin(rows[p] & vkj).count("1") & 1) << (BITS - 1 - p)) for p in range(BITS))
            )
        sv.append(scrambled)
    n = 2**m
    out = np.empty((n, d))
    quasi = list(shift)
    scale = 1.0 / 2**BITS
    out[0] = np.array(quasi) * scale
    for i in range(1, n):
        c, low = i - 1, 0  # the lowest zero bit of i - 1 picks the direction number
        while c & 1:
            c >>= 1
            low += 1
        quasi = [q ^ sv[k][low] for k, q in enumerate(quasi)]
        out[i] = np.array(quasi) * scale
    out.flags.writeable = False
    return out
