"""The least violation of an NLP's rows (a phase-1 problem) on Ipopt (or another of
CasADi's nlpsol plugins).

For an :class:`~optdesign.programs.nlp.NLP` with rows ``lbg <= g(z) <= ubg`` this
builds, once, the problem

    min t  s.t.  g(z) - wu t <= ubg,  g(z) + wl t >= lbg,  lbz <= z <= ubz,  t >= 0

whose weights ``wu``, ``wl`` (one per finite upper and lower row side) are parameters of
each call, as are the bounds and the problem's parameters. Two uses:

- every weight 1: ``t`` is the largest violation of the scaled rows, and a positive local
  minimum is a certificate that no feasible design lies near the start (what the global
  search asks of a start that failed, :mod:`optdesign.search.global_phase`);
- every weight 1, on sqpmethod: a catalogue node's starts that sqpmethod, its first
  solver, did not solve (:mod:`optdesign.formulations.catalogue.node_solver`);
- weights ``1 / scale`` on one requirement's rows and 0 elsewhere: ``t`` is the
  relaxation of that requirement, in its own unit, that the others allow - the smallest
  one, found by a single solve where a bisection on feasibility needs a dozen
  (:mod:`optdesign.formulations.nlp.relaxation`); weights on several requirements' rows give the
  smallest relaxation of them together.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from optdesign.programs.nlp import NLP, Bounds, Target
from optdesign.safe_io import refuse_file_options, without_option_files
from optdesign.solvers.base import make_result
from optdesign.solvers.blas import one_blas_thread
from optdesign.solvers.casadi_nlp import IPOPT_DEFAULTS
from optdesign.solvers.deadline import DEADLINE_OPTION
from optdesign.solvers.nlpsol_call import NlpsolFunction
from optdesign.solvers.result import Result, TerminationCondition

#: A least violation above this (scaled rows: about relative to each limit) is a
#: certificate of infeasibility; at or below it the point found is a feasible design as
#: far as the rows' tolerance goes (ten times the solver's own tolerance on them, so that
#: a point Ipopt calls feasible is never certified infeasible).
CERTIFY_ABOVE = 1e-6

#: Iterations of a phase-1 solve (unless the caller's options say otherwise): the converging
#: ones need far fewer, and one that does not converge gives no evidence, so it should
#: cost little.
PHASE_ONE_MAX_ITER = 300

#: Return statuses that end at a minimum of ``t`` (Ipopt's; sqpmethod's first).
_CONVERGED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


def supports(backend: Any) -> bool:
    """Whether ``backend`` (an NLP back-end) is CasADi's Ipopt, whose NLP this module's
    phase-1 problem is built on."""
    return getattr(backend, "plugin", None) == "ipopt" and hasattr(backend, "options")


@dataclass
class LeastViolation:
    """One phase-1 solve: ``value`` the least ``t`` found (NaN when the solve did not
    converge), ``status`` Ipopt's return status, ``z`` the NLP's vector at it and
    ``result`` that point as a :class:`~optdesign.solvers.result.Result` of the NLP (its
    rows, violated and active, against the bounds of the call)."""

    value: float
    status: str
    z: np.ndarray
    result: Result

    @property
    def converged(self) -> bool:
        return self.status in _CONVERGED and np.isfinite(self.value)

    @property
    def certified(self) -> bool:
        """A converged positive least violation: no feasible design near the start."""
        return self.converged and self.value > CERTIFY_ABOVE

    @property
    def feasible(self) -> bool:
        """The solve found a design that meets every weighted row."""
        return self.converged and self.value <= CERTIFY_ABOVE

    @property
    def hard_rows_infeasible(self) -> bool:
        """Ipopt proved the rows of weight 0 (and the bounds) cannot hold together."""
        return self.status == "Infeasible_Problem_Detected"


@dataclass(frozen=True)
class _Sides:
    """A phase-1 problem: ``upper`` and ``lower`` the rows (indices) whose upper and
    lower sides it holds, with a weight of ``t`` each."""

    upper: np.ndarray
    lower: np.ndarray
    solver: NlpsolFunction

    @staticmethod
    def build(
        nlp: NLP, upper: np.ndarray, lower: np.ndarray, plugin: str, settings: dict
    ) -> _Sides:
        up, lo = np.flatnonzero(upper), np.flatnonzero(lower)
        t = ca.SX.sym("t")
        wu = ca.SX.sym("wu", up.size)
        wl = ca.SX.sym("wl", lo.size)
        g = nlp.g
        rows = ca.vertcat(g[up.tolist()] - wu * t, g[lo.tolist()] + wl * t)
        problem = {"x": ca.vertcat(nlp.z, t), "p": ca.vertcat(nlp.theta, wu, wl), "f": t, "g": rows}
        return _Sides(up, lo, NlpsolFunction("optdesign_phase1", plugin, problem, settings))


class PhaseOneSolver:
    """The phase-1 problem of ``nlp``, built once and solved many times.

    Parameters
    ----------
    nlp
        The formulation whose rows are relaxed.
    options
        Ipopt options over :data:`~optdesign.solvers.casadi_nlp.IPOPT_DEFAULTS` (the
        problem file's and the caller's, as for the NLP itself); another plugin's own
        options, complete (e.g. :func:`~optdesign.solvers.registry.nlpsol_options`).
    plugin
        CasADi's nlpsol plugin: ``"ipopt"`` (default) or ``"sqpmethod"`` (each solve on a
        memory of its own, :mod:`optdesign.solvers.nlpsol_call`).
    """

    def __init__(self, nlp: NLP, options: Mapping[str, Any] | None = None, plugin: str = "ipopt"):
        self.nlp = nlp
        self.plugin = plugin
        opts = {k: v for k, v in (options or {}).items() if k != DEADLINE_OPTION}
        if plugin == "ipopt":
            ipopt = {**IPOPT_DEFAULTS, "max_iter": PHASE_ONE_MAX_ITER, **opts}
            settings = {"print_time": False, "ipopt": ipopt}
        else:
            refuse_file_options(opts, "options")
            settings = {"print_time": False, **opts}
        self._settings = without_option_files(settings)
        #: One phase-1 problem per set of limited row sides (upper rows, lower rows); the
        #: NLP's own is built now, another only for a call that limits more sides (an
        #: epsilon limit, ``NLP.bounds(eps=...)``, on a row the NLP leaves unlimited).
        self._problems: dict[bytes, _Sides] = {}
        self._own = self._sides(np.isfinite(nlp.ubg), np.isfinite(nlp.lbg))

    def _sides(self, upper: np.ndarray, lower: np.ndarray) -> _Sides:
        """The phase-1 problem whose rows are the ``upper`` and ``lower`` (masks) sides."""
        key = np.concatenate([upper, lower]).tobytes()
        if key not in self._problems:
            self._problems[key] = _Sides.build(self.nlp, upper, lower, self.plugin, self._settings)
        return self._problems[key]

    def weights(
        self,
        rows: np.ndarray | None = None,
        per_row: np.ndarray | None = None,
        sides: _Sides | None = None,
    ):
        """(wu, wl): weight ``per_row[k]`` (default 1) on rows ``rows`` (default: all),
        0 on the others, for the limited sides of each row (``sides``: default the
        NLP's own)."""
        sides = sides or self._own
        m = len(self.nlp.g_names)
        w = np.zeros(m)
        chosen = np.arange(m) if rows is None else np.asarray(rows, dtype=int)
        w[chosen] = 1.0 if per_row is None else np.asarray(per_row, dtype=float)
        return w[sides.upper], w[sides.lower]

    @one_blas_thread()
    def solve(
        self,
        z0: np.ndarray,
        bounds: Bounds | None = None,
        rows: np.ndarray | None = None,
        per_row: np.ndarray | None = None,
        target: Target | None = None,
    ) -> LeastViolation:
        """The least ``t`` from ``z0`` (the NLP's vector) within ``bounds`` (default: the
        NLP's), the weights on ``rows`` (default: every row, weight 1)."""
        nlp = self.nlp
        bounds = bounds if bounds is not None else nlp.bounds()
        theta = nlp.parameter_values(bounds.parameters)
        z0 = np.clip(np.asarray(z0, dtype=float).ravel(), bounds.lbz, bounds.ubz)
        lbg = np.asarray(bounds.lbg, dtype=float)
        ubg = np.asarray(bounds.ubg, dtype=float)
        # the NLP's limited sides, and any this call adds (a side it frees stays, open)
        sides = self._sides(
            np.isfinite(nlp.ubg) | np.isfinite(ubg), np.isfinite(nlp.lbg) | np.isfinite(lbg)
        )
        wu, wl = self.weights(rows, per_row, sides)
        g0 = np.asarray(nlp.g_fun(z0, theta), dtype=float).ravel()
        t0 = _start_t(g0, lbg, ubg, sides.upper, sides.lower, wu, wl)
        m_u = sides.upper.size
        args = {
            "x0": np.append(z0, t0),
            "p": np.concatenate([theta, wu, wl]),
            "lbx": np.append(bounds.lbz, 0.0),
            "ubx": np.append(bounds.ubz, np.inf),
            "lbg": np.concatenate([np.full(m_u, -np.inf), lbg[sides.lower]]),
            "ubg": np.concatenate([ubg[sides.upper], np.full(sides.lower.size, np.inf)]),
        }
        started = time.perf_counter()
        try:
            sol, stats = sides.solver(**args)
        except RuntimeError as exc:  # an evaluation CasADi cannot recover from
            wall = time.perf_counter() - started
            return self._point(z0, np.nan, "failed", str(exc).splitlines()[0], bounds, target, wall)
        wall = time.perf_counter() - started
        status = str(stats.get("return_status", ""))
        x = np.asarray(sol["x"], dtype=float).ravel()
        lam = np.asarray(sol["lam_g"], dtype=float).ravel()
        lam_g = np.zeros(len(nlp.g_names))
        np.add.at(lam_g, sides.upper, lam[:m_u])
        np.add.at(lam_g, sides.lower, lam[m_u:])
        value = float(x[-1]) if status in _CONVERGED else np.nan
        out = self._point(x[:-1], value, status, status, bounds, target, wall, lam_g)
        out.result.iterations = stats.get("iter_count")
        return out

    def _point(
        self,
        z: np.ndarray,
        value: float,
        status: str,
        message: str,
        bounds: Bounds,
        target: Target | None,
        wall: float,
        lam_g: np.ndarray | None = None,
    ) -> LeastViolation:
        nlp = self.nlp
        lam_g = np.zeros(len(nlp.g_names)) if lam_g is None else lam_g
        found = status in _CONVERGED and value <= CERTIFY_ABOVE
        result = make_result(
            self.plugin,
            nlp,
            nlp.target(target),
            bounds,
            z,
            np.zeros(z.size),
            lam_g,
            "feasible" if found else "infeasible",
            TerminationCondition.CONVERGED if found else TerminationCondition.INFEASIBLE,
            f"least violation {value:.6g} (phase 1: {message})",
            None,
            {},
            wall,
        )
        return LeastViolation(value, status, z, result)


def _start_t(
    g: np.ndarray,
    lbg: np.ndarray,
    ubg: np.ndarray,
    upper: np.ndarray,
    lower: np.ndarray,
    wu: np.ndarray,
    wl: np.ndarray,
) -> float:
    """The least ``t`` the weighted rows need at the start (a feasible start for ``t``)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        over = np.where(wu > 0, (g[upper] - ubg[upper]) / wu, 0.0)
        under = np.where(wl > 0, (lbg[lower] - g[lower]) / wl, 0.0)
    need = np.concatenate([over, under, [0.0]])
    need = need[np.isfinite(need)]
    return float(np.max(need)) + 1e-3 if need.size else 1.0
