"""Quality measures of a Pareto front (all objectives minimised).

- :func:`non_dominated`: mask of the points no other point dominates;
- :func:`hypervolume`: pymoo's HV indicator, with the reference point
  :func:`reference_point` = nadir + 10 % of the front's range in each objective unless
  given (compare fronts only with one common reference point);
- :func:`spacing`: Schott's spacing, the standard deviation of each point's nearest
  neighbour distance (0 = evenly spread), in objectives normalised by the front's range;
- :func:`spread`: Deb's Delta (2 objectives; 0 = evenly spread and reaching the extremes).
"""

from __future__ import annotations

from typing import Any

import numpy as np


def non_dominated(F: np.ndarray) -> np.ndarray:
    """Boolean mask of the non-dominated rows of ``F``.

    Rows equal to 1e-9 relative are one point (two solves that reach the same design, a
    catalogue front's epsilon limit that does not bind, differ by rounding only): the
    first row of them is kept, and a row is dominated only by a row that is not such a
    duplicate - so rounding never decides which of two equal points stays.
    """
    F = np.asarray(F, dtype=float)
    n = len(F)
    keep = np.isfinite(F).all(axis=1)
    for i in range(n):
        if not keep[i]:
            continue
        same = np.isclose(F, F[i], rtol=1e-9, atol=0.0).all(axis=1)
        le = (F <= F[i]).all(axis=1)
        lt = (F < F[i]).any(axis=1)
        if (le & lt & keep & ~same).any():
            keep[i] = False
            continue
        same[: i + 1] = False
        keep &= ~same
    return keep


def reference_point(F: np.ndarray, margin: float = 0.1) -> np.ndarray:
    """Nadir of ``F`` plus ``margin`` times its range in each objective."""
    F = np.asarray(F, dtype=float)
    lo, hi = F.min(axis=0), F.max(axis=0)
    span = np.where(hi > lo, hi - lo, np.maximum(np.abs(hi), 1e-12))
    return hi + margin * span


def hypervolume(F: np.ndarray, ref: np.ndarray | None = None) -> float:
    """Hypervolume dominated by ``F`` up to ``ref`` (pymoo ``HV``)."""
    from pymoo.indicators.hv import HV

    F = np.asarray(F, dtype=float)
    if len(F) == 0:
        return 0.0
    ref = reference_point(F) if ref is None else np.asarray(ref, dtype=float)
    return float(HV(ref_point=ref)(F))


def _normalised(F: np.ndarray, bounds: tuple[np.ndarray, np.ndarray] | None) -> np.ndarray:
    lo, hi = (F.min(axis=0), F.max(axis=0)) if bounds is None else bounds
    span = np.where(hi > lo, hi - lo, 1.0)
    return (F - lo) / span


def spacing(F: np.ndarray, bounds: tuple[np.ndarray, np.ndarray] | None = None) -> float:
    """Schott's spacing of the normalised front (L1 nearest-neighbour distances)."""
    F = np.asarray(F, dtype=float)
    if len(F) < 3:
        return 0.0
    Z = _normalised(F, bounds)
    D = np.abs(Z[:, None, :] - Z[None, :, :]).sum(axis=-1)
    np.fill_diagonal(D, np.inf)
    d = D.min(axis=1)
    return float(np.std(d, ddof=1))


def spread(
    F: np.ndarray,
    extremes: np.ndarray | None = None,
    bounds: tuple[np.ndarray, np.ndarray] | None = None,
) -> float:
    """Deb's spread Delta of a 2-objective front (normalised objectives).

    ``extremes`` (2 x 2: the true extreme points) adds their distance to the front's ends,
    normalised in the front's frame (``bounds``, else the front's range); without it
    only the evenness of the consecutive gaps counts. For more objectives the
    same formula is applied to nearest-neighbour distances (a common generalisation).
    """
    F = np.asarray(F, dtype=float)
    if len(F) < 3:
        return 0.0
    # one frame for the front and the extremes (normalised in their own frame, two
    # extremes always land on the corners, and their distances would always be 0)
    frame = (F.min(axis=0), F.max(axis=0)) if bounds is None else bounds
    Z = _normalised(F, frame)
    if F.shape[1] == 2:
        order = np.argsort(Z[:, 0])
        Z = Z[order]
        d = np.linalg.norm(np.diff(Z, axis=0), axis=1)
        if extremes is not None:
            E = _normalised(np.asarray(extremes, dtype=float), frame)
            E = E[np.argsort(E[:, 0])]
            d_f = float(np.linalg.norm(Z[0] - E[0]))
            d_l = float(np.linalg.norm(Z[-1] - E[-1]))
        else:
            d_f = d_l = 0.0
    else:
        D = np.linalg.norm(Z[:, None, :] - Z[None, :, :], axis=-1)
        np.fill_diagonal(D, np.inf)
        d = D.min(axis=1)
        d_f = d_l = 0.0
    mean = d.mean()
    denom = d_f + d_l + len(d) * mean
    return float((d_f + d_l + np.abs(d - mean).sum()) / denom) if denom > 0 else 0.0


def front_metrics(F: np.ndarray, ref: np.ndarray | None = None) -> dict[str, Any]:
    """Hypervolume (with its reference point), spacing, spread and the number of
    non-dominated points of ``F``."""
    F = np.asarray(F, dtype=float)
    if len(F) == 0:
        return {"n_points": 0, "n_nondominated": 0, "hypervolume": 0.0}
    mask = non_dominated(F)
    P = F[mask]
    ref = reference_point(P) if ref is None else np.asarray(ref, dtype=float)
    return {
        "n_points": len(F),
        "n_nondominated": int(mask.sum()),
        "hypervolume": hypervolume(P, ref),
        "reference_point": ref.tolist(),
        "spacing": spacing(P),
        "spread": spread(P),
    }
