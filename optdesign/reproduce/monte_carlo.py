"""Monte Carlo of the transmission error and its sensitivity ranking ([L16], Fig. 5-6).

Draws every :class:`~optdesign.models.error_budget.ErrorSource` from its distribution with a
``numpy.random.Generator`` seeded by the caller, maps each draw to the output through
:func:`optdesign.models.error_budget.contribution` (the NumPy path of the same model
functions the deterministic budget uses; evaluated once per chunk as a gain, exact since
every term is linear in its uncertain input) and sums. Vectorised over samples, in chunks so
that memory stays bounded (one float64 array per chunk and source).

Reproducibility: the same seed, sources, sample count and chunk size give bit-identical
results (the chunk size fixes the order of the draws).

Sensitivity ranking (Fig. 6b): each source's share of the mean-square output error,
E[c_k^2] / sum_j E[c_j^2], with c_k the source's contribution at the output. Unlike a
variance share it also ranks fixed systematic terms (backlash), which the paper ranks
among the main factors; the variance share is reported beside it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from optdesign.errors import InputError
from optdesign.models.error_budget import ErrorSource, gains


@dataclass
class MonteCarloResult:
    """Summary of a Monte Carlo run (output units: rad with a mechanism, mm without)."""

    n: int
    seed: int | None
    mean: float
    std: float
    abs_max: float
    mean_square_share: dict[str, float] = field(default_factory=dict)
    variance_share: dict[str, float] = field(default_factory=dict)
    samples: np.ndarray | None = None

    def quantile(self, q: float) -> float:
        """Quantile of the output error (needs ``keep_samples=True``)."""
        if self.samples is None:
            raise InputError("keep_samples", "run with keep_samples=True to get quantiles")
        return float(np.quantile(self.samples, q))

    def ranking(self) -> list[tuple[str, float]]:
        """Sources by decreasing mean-square share (fractions summing to 1)."""
        return sorted(self.mean_square_share.items(), key=lambda kv: -kv[1])


def run_monte_carlo(
    sources: Sequence[ErrorSource],
    n: int,
    seed: int | None,
    mechanism=None,
    phi: float | None = 0.0,
    phi_range: tuple[float, float] | None = None,
    chunk: int = 1_000_000,
    keep_samples: bool = False,
    **kwargs,
) -> MonteCarloResult:
    """Sample the output error ``n`` times.

    Parameters
    ----------
    sources
        The error sources (models.error_budget).
    n
        Number of samples.
    seed
        Seed of ``numpy.random.default_rng``.
    mechanism
        A mechanism (CrankSlider, ShiftingFork) to map nut-side errors to the output
        angle, or None for a screw on its own (pass p, i_a, theta in ``kwargs``).
    phi
        Deflection (rad) at which to evaluate, if ``phi_range`` is None.
    phi_range
        (lo, hi) in rad: draw the deflection of each sample uniformly over the stroke
        instead (the error over the whole stroke).
    chunk
        Samples per vectorised block.
    keep_samples
        Keep the output array (for quantiles and histograms).
    """
    if not isinstance(n, int | np.integer) or n < 2:
        raise InputError("n", f"needs at least 2 samples, got {n!r}")
    if not sources:
        raise InputError("sources", "at least one error source is needed")
    if chunk < 1:
        raise InputError("chunk", f"must be >= 1, got {chunk!r}")
    if phi_range is not None and mechanism is None:
        raise InputError("phi_range", "sampling the deflection needs a mechanism")
    rng = np.random.default_rng(seed)
    k = len(sources)
    s1 = np.zeros(k)  # sum of contributions per source
    s2 = np.zeros(k)  # sum of squared contributions per source
    y1 = y2 = 0.0
    y_abs = 0.0
    kept = np.empty(n) if keep_samples else None
    done = 0
    while done < n:
        nc = min(chunk, n - done)
        if phi_range is not None:
            ph = rng.uniform(phi_range[0], phi_range[1], nc)
        else:
            ph = phi
        y = np.zeros(nc)
        # contribution() is linear in the value: evaluate the kinematics once per chunk.
        g = gains(sources, mechanism, ph, **kwargs)
        for j, src in enumerate(sources):
            c = src.sample(rng, nc)
            c *= g[j]
            s1[j] += c.sum()
            s2[j] += np.dot(c, c)
            y += c
        y1 += y.sum()
        y2 += np.dot(y, y)
        y_abs = max(y_abs, float(np.max(np.abs(y))))
        if kept is not None:
            kept[done : done + nc] = y
        done += nc
    mean = y1 / n
    var = max(y2 / n - mean**2, 0.0) * n / (n - 1)
    ms = s2 / n
    vk = np.maximum(ms - (s1 / n) ** 2, 0.0)
    names = [s.name for s in sources]
    ms_share = ms / ms.sum() if ms.sum() > 0 else np.zeros(k)
    v_share = vk / vk.sum() if vk.sum() > 0 else np.zeros(k)
    return MonteCarloResult(
        n=n,
        seed=seed,
        mean=float(mean),
        std=float(np.sqrt(var)),
        abs_max=y_abs,
        mean_square_share=dict(zip(names, map(float, ms_share), strict=True)),
        variance_share=dict(zip(names, map(float, v_share), strict=True)),
        samples=kept,
    )


def plot_ranking(result: MonteCarloResult, path: Path, title: str = "") -> Path:
    """Bar plot of the sensitivity ranking in percent (like [L16] Fig. 6b)."""
    from optdesign.plots import new_figure, save_figure

    ranked = result.ranking()
    fig = new_figure((7, 3.5), dpi=100)
    ax = fig.subplots()
    ax.bar([r[0] for r in ranked], [100 * r[1] for r in ranked], color="tab:blue")
    ax.set_ylabel("share of mean-square error (%)")
    ax.set_title(title or "Sensitivity ranking (Monte Carlo)")
    ax.tick_params(axis="x", rotation=30)
    return save_figure(fig, path)
