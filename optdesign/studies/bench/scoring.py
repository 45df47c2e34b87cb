"""How a benchmark scores its configurations: the gap of each run to the best known value,
Dolan-More performance profiles, and per-configuration statistics."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from optdesign.solvers.solved_point import SOLVED_STATUSES
from optdesign.studies.bench.rows import BenchRow

#: A run solved an instance when it succeeded and its gap is at most this (relative).
SOLVED_GAP = 1e-4

#: Floor of the gap measure in the gap profile (a gap of 0 counts as this).
GAP_FLOOR = 1e-6


def add_gaps(rows: list[BenchRow]) -> list[BenchRow]:
    """Objective gap of every successful row to the best known value of its instance.

    Single objective: ``(f - f_best) / max(|f_best|, 1e-12)`` with ``f_best`` the least
    objective of the successful runs. Fronts: ``1 - HV / HV_best`` with one reference
    point per instance (nadir of all successful fronts + 10 % of their range). Failed
    rows get ``gap = None``.
    """
    by_inst: dict[str, list[BenchRow]] = {}
    for r in rows:
        r.gap, r.best_known = None, None
        if r.applicable:
            by_inst.setdefault(r.instance, []).append(r)
    for inst_rows in by_inst.values():
        ok = [r for r in inst_rows if r.success]
        if not ok:
            continue
        if any(r.is_front for r in ok):
            from optdesign.studies.pareto.metrics import hypervolume, reference_point

            allF = np.vstack([np.asarray(r.front, dtype=float) for r in ok])
            ref = reference_point(allF)
            hv = {id(r): float(hypervolume(np.asarray(r.front, dtype=float), ref)) for r in ok}
            best = max(hv.values())
            for r in ok:
                r.hypervolume = hv[id(r)]
                r.best_known = best
                r.gap = max(0.0, 1.0 - hv[id(r)] / best) if best > 0 else 0.0
            continue
        best = min(float(r.objective) for r in ok)  # type: ignore[arg-type]
        for r in inst_rows:
            r.best_known = best
        for r in ok:
            r.gap = (float(r.objective) - best) / max(abs(best), 1e-12)  # type: ignore[arg-type]
    return rows


def performance_profile(table: np.ndarray, taus: np.ndarray, floor: float = 0.0) -> np.ndarray:
    """Dolan-More performance profile.

    Parameters
    ----------
    table
        (n_instances, n_configs) measure, lower is better (time, gap); ``inf`` = failed,
        ``nan`` = not applicable (left out of that configuration's denominator).
    taus
        Ratios at which to evaluate the profile (>= 1).
    floor
        Measures below ``floor`` count as ``floor`` (the gap of the best run is 0).

    Returns
    -------
    ndarray
        (n_configs, n_taus): fraction of each configuration's applicable instances whose
        ratio ``t_{p,s} / min_s t_{p,s}`` is at most tau (0 where no configuration solved
        the instance).
    """
    T = np.asarray(table, dtype=float)
    applicable = ~np.isnan(T)
    M = np.where(applicable, np.maximum(T, floor), np.inf)
    best = M.min(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(np.isfinite(best) & (best > 0), M / best, np.where(M == best, 1.0, np.inf))
    ratio = np.where(np.isfinite(M), ratio, np.inf)
    taus = np.asarray(taus, dtype=float)
    n_app = applicable.sum(axis=0)
    rho = np.zeros((T.shape[1], len(taus)))
    for s in range(T.shape[1]):
        if n_app[s] == 0:
            rho[s] = np.nan
            continue
        r = ratio[applicable[:, s], s]
        rho[s] = (r[:, None] <= taus[None, :]).sum(axis=0) / n_app[s]
    return rho


def measure_table(
    rows: Sequence[BenchRow], configs: Sequence[str], measure: str
) -> tuple[list[str], np.ndarray]:
    """(instances, table) of ``measure`` ("time" or "gap"): inf for failures, nan where a
    configuration did not apply."""
    instances = sorted({r.instance for r in rows if r.applicable})
    idx = {k: i for i, k in enumerate(instances)}
    cidx = {c: j for j, c in enumerate(configs)}
    T = np.full((len(instances), len(configs)), np.nan)
    for r in rows:
        if not r.applicable or r.config not in cidx or r.instance not in idx:
            continue
        if measure == "time":
            v = float(r.time_s) if r.success else np.inf
        else:
            v = float(r.gap) if r.success and r.gap is not None else np.inf
        T[idx[r.instance], cidx[r.config]] = v
    return instances, T


@dataclass
class ConfigStats:
    """One configuration's statistics over the runs it applied to (``bench_stats.json``
    holds :func:`dataclasses.asdict` of it).

    Attributes
    ----------
    runs
        Applicable runs.
    success_rate, solved_rate
        Fractions of the runs that succeeded, and that succeeded with gap <=
        :data:`SOLVED_GAP` (nan without runs).
    median_time_s, median_gap
        Medians over the successful runs (nan without one).
    failures
        Status -> number of failed runs (``"check failed"``: the solver claimed success,
        the independent check did not).
    """

    runs: int
    success_rate: float
    solved_rate: float
    median_time_s: float
    median_gap: float
    failures: dict[str, int] = field(default_factory=dict)


def config_stats(rows: Sequence[BenchRow], configs: Sequence[str]) -> dict[str, ConfigStats]:
    """Per configuration: runs, success rate, solved rate (gap <= SOLVED_GAP), median time
    of successful runs, median gap, failure reasons."""
    stats = {}
    for c in configs:
        rs = [r for r in rows if r.config == c and r.applicable]
        ok = [r for r in rs if r.success]
        solved = [r for r in ok if r.gap is not None and r.gap <= SOLVED_GAP]
        reasons: dict[str, int] = {}
        for r in rs:
            if not r.success:
                st = str(r.status)
                if st in SOLVED_STATUSES:
                    st = "check failed"  # the solver claimed success, the NumPy check did not
                reasons[st] = reasons.get(st, 0) + 1
        stats[c] = ConfigStats(
            runs=len(rs),
            success_rate=len(ok) / len(rs) if rs else float("nan"),
            solved_rate=len(solved) / len(rs) if rs else float("nan"),
            median_time_s=float(np.median([r.time_s for r in ok])) if ok else float("nan"),
            median_gap=float(np.median([r.gap for r in ok])) if ok else float("nan"),
            failures=reasons,
        )
    return stats


def best_config(stats: Mapping[str, ConfigStats]) -> str | None:
    """The best configuration among those run on the most instances: highest solved rate,
    ties broken by median time. (A configuration that applies to a subset only, such as
    the GP on the fork instances, is not crowned on that easier subset.)"""
    most = max((s.runs for s in stats.values()), default=0)
    cands = [
        (c, s)
        for c, s in stats.items()
        if s.runs == most and most and math.isfinite(s.median_time_s)
    ]
    if not cands:
        return None
    return min(cands, key=lambda cs: (-round(cs[1].solved_rate, 9), cs[1].median_time_s))[0]


def paired_time_ratio(rows: Sequence[BenchRow], config: str, best: str) -> tuple[float, int]:
    """Median over the instances both configurations solved successfully of
    time(config) / time(best), and the number of such instances."""
    t: dict[tuple[str, str], float] = {
        (r.instance, r.config): float(r.time_s)
        for r in rows
        if r.success and r.config in (config, best)
    }
    ratios = [
        t[(i, config)] / t[(i, best)]
        for (i, c) in t
        if c == config and (i, best) in t and t[(i, best)] > 0
    ]
    return (float(np.median(ratios)) if ratios else float("nan")), len(ratios)
