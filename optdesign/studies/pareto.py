"""Pareto fronts of a design problem: epsilon-constraint (default), weighted sum, and
NSGA-II as a baseline.

Epsilon-constraint with two objectives ``[A, B]``: minimise ``B`` subject to ``A <= eps``.
The anchors come first: each objective minimised from seeded multistart, then a
lexicographic tie-break (the other objective minimised with the first held at its
optimum), because an individual optimum is often not unique (the ripple of a crank-slider
is invariant to scaling R, l, n, p together) and only the tie-broken point is on the front.
The sweep then runs from anchor to anchor, each point warm-started, primal and dual, from
its neighbour. By default (``spacing="arc"``) each epsilon is predicted from the
neighbour's multiplier of the epsilon row (the local slope dB/dA) so that the points are
evenly spread along the front (L1 arc length in objectives normalised by the anchors) -
an adaptive-spacing epsilon method, dense where the front bends; ``spacing="uniform"``
spaces epsilon evenly instead. A point that fails, gets worse while its epsilon loosens,
or jumps in design space is re-solved from Sobol starts (multistart only there).

With three objectives ``[A, B, C]``: rows ``A <= e1`` (e1 evenly spaced); the head of each
row is ``min B s.t. A <= e1`` (the smallest feasible e2), then ``min C s.t. A <= e1,
B <= e2`` for e2 evenly spaced from there to B's nadir, each row a warm-started chain.

Solvers: one formulation per process (:func:`_target_nlp`); every point, the sweep and
the anchors' multistarts are solved by SLSQP with exact CasADi derivatives, warm from the
neighbour's design, with Ipopt for any start SLSQP does not solve; the tie-breaks -
degenerate by construction - by Ipopt. An anchor's multistart stops once ``agree`` (3)
starts agree on the best value; its record says how many starts ran and agreed.
(``solver="ipopt"``, ``agree=None`` give the former Ipopt-only, all-starts computation.)

Every point is checked on the NumPy path (:func:`optdesign.studies.verify.verify_design`,
plus the epsilon bounds) to 1e-6 relative; a point that fails the check is kept with
status ``infeasible`` and left out of the front, as are dominated points.

Points are tasks of :func:`optdesign.studies.runner.run_tasks`: written to a JSONL store
as they finish, resumable, on local processes or a Dask cluster. Parallel strategy (two
objectives): one task graph - the anchors' multistarts side by side, their tie-breaks,
then two warm-started chains, one from each anchor, created as records come in
(:class:`_TwoChains`) so that they meet wherever they meet and no worker waits for a
fixed share; the formulation is built once before the workers are forked
(:func:`prebuild_solvers`), each worker builds its solvers once (per-process cache).
Three objectives: anchors first, then the rows side by side.
"""

from __future__ import annotations

import hashlib
import json
import math
import tempfile
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from optdesign.errors import ProblemError
from optdesign.formulations.nlp import NLP, build_nlp
from optdesign.problem.design_problem import DesignProblem, relative_violation
from optdesign.solvers.casadi_nlp import CasadiNLPSolver
from optdesign.solvers.multistart import best_of, sobol_starts
from optdesign.solvers.result import Result
from optdesign.solvers.scipy_nlp import ScipyNLPSolver
from optdesign.studies.front_metrics import front_metrics, non_dominated
from optdesign.studies.runner import cached, forks_workers, process_pool, run_tasks
from optdesign.studies.solve import finish
from optdesign.studies.verify import VERIFY_TOL

#: Ipopt options of warm-started sweep points: take the neighbour's multipliers and start
#: close to the central path instead of pushing the point back into the interior.
WARM_OPTIONS: dict[str, Any] = {
    "warm_start_init_point": "yes",
    "warm_start_bound_push": 1e-9,
    "warm_start_bound_frac": 1e-9,
    "warm_start_slack_bound_push": 1e-9,
    "warm_start_slack_bound_frac": 1e-9,
    "warm_start_mult_bound_push": 1e-9,
    "mu_init": 1e-6,
}

#: Ipopt options of the lexicographic tie-breaks. Their start is an optimum of the
#: objective fixed before, so it is feasible (to the slack) and close to the tie-break's
#: optimum: a small initial barrier parameter and bound push keep Ipopt there instead of
#: pushing it back into the interior. Measured on cs_min_backlash from 6 multistart
#: optima: the backlash anchor's tie-break took 25-48 iterations (default options: 62-101,
#: and 500 = failure from one start), the ripple anchor's 22-41 (default 22-40), same
#: optima to 1e-8.
TIE_OPTIONS: dict[str, Any] = {"mu_init": 1e-5, "bound_push": 1e-6, "bound_frac": 1e-6}

#: SLSQP options of the sweeps (over ScipyNLPSolver's defaults): a start still running
#: at 200 iterations is handed to Ipopt rather than left to the benchmark default 500.
SLSQP_OPTIONS: dict[str, Any] = {"maxiter": 200}

#: CasADi's symbolic layer is not thread-safe and ``nlpsol`` releases the GIL: two threads
#: of a threaded Dask worker building solvers at once crashed the process (segfault in
#: nlpsol, seen in tests/test_pareto.py's Dask test). Every symbolic construction in this
#: module (formulations, solver set-up) holds this lock; solves run unlocked.
_CASADI_LOCK = threading.RLock()

#: Relative slack on the anchor values in lexicographic tie-breaks and at the sweep ends.
ANCHOR_SLACK = 1e-7


@dataclass
class FrontPoint:
    """One point of a front.

    Attributes
    ----------
    objectives
        Every objective of the problem at the design (NumPy path).
    design
        The full design (fixed and free variables).
    status
        Solver status after the independent check (``optimal``, ``feasible``,
        ``infeasible``, ``failed``, ...).
    active
        Names of the active constraint rows (requirements and epsilon bounds).
    method
        The front method that produced it.
    verified
        Result of the independent NumPy check (None if not checked).
    eps
        The epsilon bounds (or weights) that defined the point.
    id
        Task id in the store.
    """

    objectives: dict[str, float]
    design: dict[str, float]
    status: str
    active: list[str]
    method: str
    verified: bool | None = None
    eps: dict[str, float] = field(default_factory=dict)
    id: str = ""
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        return self.status in ("optimal", "feasible") and self.verified is not False

    def to_dict(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "method": self.method,
            "status": self.status,
            "verified": self.verified,
            "objectives": self.objectives,
            "design": self.design,
            "eps": self.eps,
            "active": self.active,
            "extra": self.extra,
        }


@dataclass
class Front:
    """A Pareto front: its non-dominated successful points, the rest, and its metrics.

    Attributes
    ----------
    objectives
        The front's objective names.
    points
        Successful, verified, non-dominated points (sorted by the first objective).
    rejected
        Failed, infeasible or dominated points, each with ``extra["rejected"]``.
    metrics
        :func:`optdesign.studies.front_metrics.front_metrics` of ``points``.
    wall_time_s
        Wall time of the whole method (anchors included).
    """

    objectives: list[str]
    method: str
    points: list[FrontPoint]
    rejected: list[FrontPoint] = field(default_factory=list)
    metrics: dict[str, Any] = field(default_factory=dict)
    wall_time_s: float = 0.0
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def F(self) -> np.ndarray:
        """Objective values, one row per point."""
        return np.array(
            [[p.objectives[k] for k in self.objectives] for p in self.points], dtype=float
        ).reshape(-1, len(self.objectives))

    def to_dict(self) -> dict[str, Any]:
        return _clean(
            {
                "method": self.method,
                "objectives": self.objectives,
                "metrics": self.metrics,
                "wall_time_s": self.wall_time_s,
                "info": self.info,
                "points": [p.to_dict() for p in self.points],
                "rejected": [p.to_dict() for p in self.rejected],
            }
        )


def _clean(obj):
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    if isinstance(obj, float | np.floating) and not math.isfinite(float(obj)):
        return None
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


# --- building blocks run inside workers -----------------------------------------------
def problem_key(problem: DesignProblem) -> str:
    """Short hash identifying a problem's content (cache and store keys)."""
    return hashlib.sha1(problem.spec.model_dump_json().encode()).hexdigest()[:12]


class EpsSolver:
    """``min target s.t. other objectives <= eps`` built once; eps changes per solve.

    The epsilon rows are built with an infinite limit and their upper bounds are set per
    solve, so one solver serves the anchors' multistarts, the tie-breaks and the whole
    sweep (and its warm starts). The primary solver is SLSQP with exact CasADi first
    derivatives (:class:`~optdesign.solvers.scipy_nlp.ScipyNLPSolver`: ~0.03 s to
    build, 3-6x faster per solve than Ipopt on these NLPs); a start it does not solve
    (SLSQP reports failure, or the iterate violates a row) is solved again by Ipopt
    (exact Hessian) from the same start, that solver being built only when first needed.
    The lexicographic tie-breaks always use Ipopt (``use="tie"``), see
    :func:`_anchor_task`. ``method="ipopt"`` uses Ipopt throughout (``warm`` then selects
    the warm-start options), as before.
    """

    def __init__(
        self,
        problem: DesignProblem,
        target: str | Mapping[str, float],
        eps_names: Sequence[str],
        warm: bool = False,
        options: Mapping[str, Any] | None = None,
        normalise: Mapping[str, tuple[float, float]] | None = None,
        method: str = "slsqp",
    ):
        if method not in ("slsqp", "ipopt"):
            raise ProblemError(f"solver {method!r}: use 'slsqp' or 'ipopt'")
        self.problem = problem
        self.method = method
        with _CASADI_LOCK:
            self.nlp = _target_nlp(problem, target, eps_names, normalise)
        self.base_ubg = self.nlp.ubg.copy()
        self.rows = {k: self.nlp.g_names.index(f"{k}_max") for k in eps_names}
        self.limits = problem.objective_limits()
        self.ipopt_options = dict(problem.spec.solver.ipopt)
        if warm and method == "ipopt":
            self.ipopt_options.update(WARM_OPTIONS)
        self.ipopt_options.update(options or {})
        self._ipopt: CasadiNLPSolver | None = None
        self._ipopt_tie: CasadiNLPSolver | None = None
        self._slsqp: ScipyNLPSolver | None = None
        self.z_names = list(self.nlp.design_names) + list(self.nlp.aux_names)
        self.signature = hashlib.sha1(
            json.dumps([self.z_names, list(self.nlp.g_names)]).encode()
        ).hexdigest()[:16]

    @property
    def solver(self) -> CasadiNLPSolver | ScipyNLPSolver:
        """The primary solver (built on first use, like :attr:`ipopt`: a worker that only
        runs this NLP's tie-break never builds its SLSQP functions)."""
        if self.method == "ipopt":
            return self.ipopt
        if self._slsqp is None:
            with _CASADI_LOCK:
                self._slsqp = ScipyNLPSolver(self.nlp, "SLSQP", "exact", SLSQP_OPTIONS)
        return self._slsqp

    @property
    def ipopt(self) -> CasadiNLPSolver:
        """The Ipopt solver of the same NLP (built on first use: ~0.15 s, exact Hessian)."""
        if self._ipopt is None:
            with _CASADI_LOCK:
                self._ipopt = CasadiNLPSolver(self.nlp, "ipopt", self.ipopt_options)
        return self._ipopt

    @property
    def ipopt_tie(self) -> CasadiNLPSolver:
        """Ipopt with :data:`TIE_OPTIONS` (lexicographic tie-breaks; built on first use)."""
        if self._ipopt_tie is None:
            with _CASADI_LOCK:
                self._ipopt_tie = CasadiNLPSolver(
                    self.nlp, "ipopt", {**self.ipopt_options, **TIE_OPTIONS}
                )
        return self._ipopt_tie

    def set_eps(self, eps: Mapping[str, float]) -> None:
        ubg = self.base_ubg.copy()
        for k, v in eps.items():
            limit = min(float(v), self.limits.get(k, np.inf))
            ubg[self.rows[k]] = limit / self.nlp.g_scale[self.rows[k]]
        # Both solvers hold this same NLP object and read its bounds at every solve.
        self.nlp.ubg = ubg

    def warm_args(self, raw: Mapping[str, Any] | None, x: np.ndarray | None) -> dict[str, Any]:
        """Solver start from a neighbour's raw solution, else from x.

        Primal and dual when the neighbour solved this same NLP (same variables and rows,
        :attr:`signature`: every target of a front derives from one formulation, whose
        order is the same in every process); the design and bound multipliers, aligned
        by name, when only the variables match (e.g. the other anchor's tie-break);
        constraint multipliers are never partial: a zero for a missing epsilon row made
        Ipopt fail.
        """
        if raw and raw.get("nlp") == self.signature:
            return {
                "z0": _vector(raw["z"]),
                "lam_x0": _vector(raw["lam_x"]),
                "lam_g0": _vector(raw["lam_g"]),
            }
        if raw and set(raw.get("z_names", [])) == set(self.z_names):
            zi = [raw["z_names"].index(k) for k in self.z_names]
            return {"z0": _vector(raw["z"])[zi], "lam_x0": _vector(raw["lam_x"])[zi]}
        return {"x0": np.asarray(x if x is not None else self.problem.start(), dtype=float)}

    def solve(
        self, eps: Mapping[str, float], fallback: bool = True, use: str | None = None, **start
    ) -> Result:
        """Solve with the epsilon bounds ``eps`` from ``start`` (``x0`` or ``z0``...).

        With SLSQP as primary solver and ``fallback``, a start SLSQP does not solve is
        solved again by Ipopt from the same primal start (without SLSQP's partial
        multipliers); ``result.extra["fallback"]`` then holds SLSQP's message.
        ``use="ipopt"`` solves with Ipopt directly, ``use="tie"`` with Ipopt and
        :data:`TIE_OPTIONS`.
        """
        self.set_eps(eps)
        if use in ("ipopt", "tie"):
            result = (self.ipopt_tie if use == "tie" else self.ipopt).solve(**start)
            fallback = False
        else:
            result = self.solver.solve(**start)
        if fallback and self.method == "slsqp" and not result.success:
            primal = {k: v for k, v in start.items() if k in ("x0", "z0")}
            first = result
            result = self.ipopt.solve(**primal)
            result.extra["fallback"] = f"{first.status}: {first.message}"
            result.wall_time_s += first.wall_time_s
        if result.raw:
            # Names of the variables (a few) and a signature of variables and rows (~550
            # row names were two thirds of every record and of every task sent to a worker).
            result.raw["z_names"] = self.z_names
            result.raw["nlp"] = self.signature
        return result


def _target_nlp(
    problem: DesignProblem,
    target: str | Mapping[str, float],
    eps_names: Sequence[str],
    normalise: Mapping[str, tuple[float, float]] | None = None,
) -> NLP:
    """``min target s.t. eps_names <= inf`` (bounds set per solve), from one formulation.

    Every solver of a front (each objective as target, the others as epsilon rows) is
    derived from one :func:`build_nlp` of the front's objectives, built once per process:
    the same variables and rows (an unused epsilon row has an infinite bound), only the
    objective differs. One formulation build (~0.1 s) per process instead of one per
    target - with 2 workers each worker needs both targets for the anchors and
    tie-breaks - and any point's solution and multipliers can start another target's
    solve.
    """
    if not isinstance(target, str) or normalise:
        return build_nlp(
            problem, objective=target, epsilon={k: np.inf for k in eps_names}, normalise=normalise
        )
    names = sorted({target, *eps_names})
    base = cached(
        ("front-nlp", problem_key(problem), tuple(names)),
        lambda: build_nlp(problem, objective=names[0], epsilon={k: np.inf for k in names}),
    )
    value = base.objective_values[target]
    # Objective scaled to ~1 at the start design, as build_nlp scales its objective.
    f0 = float(ca.Function("f0", [base.z], [value])(base.z_from_x(problem.start())))
    f_scale = abs(f0) if np.isfinite(f0) and abs(f0) > 1e-12 else 1.0
    return replace(
        base,
        f=value / f_scale,
        f_scale=f_scale,
        objective=target,
        lbg=base.lbg.copy(),
        ubg=base.ubg.copy(),
        lbz=base.lbz.copy(),
        ubz=base.ubz.copy(),
    )


def _eps_solver(
    problem: DesignProblem,
    target,
    eps_names: Sequence[str],
    warm: bool = False,
    normalise=None,
    method: str = "slsqp",
) -> EpsSolver:
    eps_names = sorted(eps_names)  # one solver per NLP, whatever order the caller names
    # SLSQP takes no dual warm start: one solver per NLP serves cold and warm solves.
    warm = bool(warm) and method == "ipopt"
    key = (
        "eps",
        problem_key(problem),
        json.dumps(target, sort_keys=True),
        tuple(eps_names),
        warm,
        json.dumps(normalise, sort_keys=True),
        method,
    )
    return cached(
        key,
        lambda: EpsSolver(problem, target, eps_names, warm, normalise=normalise, method=method),
    )


def _record(
    problem: DesignProblem,
    result: Result,
    target: str,
    eps: Mapping[str, float],
    extra: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """Check a result independently and turn it into a JSON-able store record."""
    result = finish(problem, result, target)
    status = result.status
    x = [result.design[v.name] for v in problem.free] if result.design else None
    if result.design and result.objectives:
        # The epsilon bounds are constraints of this point: check them on the NumPy path too.
        for k, v in eps.items():
            if np.isfinite(v) and relative_violation(result.objectives[k], None, v) > VERIFY_TOL:
                status = "infeasible"
                result.verified = False
    active = sorted(
        {r.name for r in result.active if "_envelope[" not in r.name},
        key=lambda s: (s.split("[")[0], s),
    )
    raw = result.raw or {}
    rec = _clean(
        {
            "status": status,
            "verified": result.verified,
            "message": result.message,
            "x": x,
            "design": result.design,
            "objectives": result.objectives,
            "target": target,
            "eps": {k: v for k, v in eps.items() if np.isfinite(v)},
            "active": active,
            "violated": [r.name for r in result.violated][:20],
            "wall_time_s": result.wall_time_s,
            "iterations": result.iterations,
            "solver": result.solver,
            **({"fallback": result.extra["fallback"]} if result.extra.get("fallback") else {}),
            **dict(extra or {}),
        }
    )
    # The raw vectors (~550 multipliers) bypass the recursive _clean: it cost ~2 ms a point.
    rec["raw"] = {
        k: _json_vector(v) if k in ("z", "lam_x", "lam_g") else _clean(v) for k, v in raw.items()
    }
    return rec


def _json_vector(v) -> list | dict:
    """A float vector as a JSON-able list (non-finite entries as None, like _clean), or,
    when most entries are exactly zero (SLSQP's multipliers of inactive rows), as
    ``{"size", "index", "value"}`` of the nonzero ones: same values, ~20x smaller."""
    a = np.asarray(v, dtype=float).ravel()
    nz = np.flatnonzero(a != 0.0)
    if 2 * len(nz) < len(a):
        return {"size": len(a), "index": nz.tolist(), "value": _finite_list(a[nz])}
    return _finite_list(a)


def _finite_list(a: np.ndarray) -> list:
    out = a.tolist()
    if not np.isfinite(a).all():
        out = [x if math.isfinite(x) else None for x in out]
    return out


def _vector(obj) -> np.ndarray:
    """Inverse of :func:`_json_vector` (None -> nan)."""
    if isinstance(obj, dict):
        a = np.zeros(int(obj["size"]))
        a[np.asarray(obj["index"], dtype=int)] = np.asarray(obj["value"], dtype=float)
        return a
    return np.asarray(obj, dtype=float)


def _ok(rec: Mapping[str, Any] | None) -> bool:
    return bool(rec) and rec["status"] in ("optimal", "feasible") and rec.get("verified") is True


def _multistart_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """Individual optimum of ``order[0]`` by seeded multistart (first half of an anchor).

    Solves ``min order[0] s.t. order[1:] <= inf`` with the same (cached) solver the
    tie-break of another anchor uses, so a worker builds each NLP once. With
    ``task["agree"] = k`` the multistart stops as soon as k successful starts agree on the
    best value (within :func:`best_of`'s 1e-6 relative); the record's ``multistart`` says
    how many starts were planned, how many ran and how many agreed. If no start succeeds
    with SLSQP, the starts are solved again with Ipopt fallback.
    """
    problem: DesignProblem = task["problem"]
    order: list[str] = task["order"]
    method = task.get("solver", "slsqp")
    agree = task.get("agree")
    t0 = time.perf_counter()
    others = order[1:]
    solver = _eps_solver(problem, order[0], others, method=method)
    free_eps = {k: np.inf for k in others}
    pts = [problem.start()]
    if task["starts"] > 1:
        pts += list(
            sobol_starts(problem.lower(), problem.upper(), task["starts"] - 1, task["seed"])
        )
    results: list[Result] = []
    n_at_best = 0
    for x0 in pts:
        # No per-start Ipopt fallback: a start that fails is just a failed start.
        results.append(solver.solve(free_eps, fallback=False, x0=x0))
        best, n_at_best = best_of(results)
        if agree and n_at_best >= agree:
            break
    n_solves = len(results)
    if n_at_best == 0 and method == "slsqp":
        results = []
        for x0 in pts:
            results.append(solver.solve(free_eps, x0=x0))
            best, n_at_best = best_of(results)
            if agree and n_at_best >= agree:
                break
        n_solves += len(results)
    best, n_at_best = best_of(results)
    rec = _record(problem, best, order[0], {})
    rec["multistart"] = {
        "n_starts": len(results),
        "n_planned": len(pts),
        "n_at_best": n_at_best,
        "agree": agree,
        "stopped_early": len(results) < len(pts),
    }
    rec.update(
        kind="anchor-multistart",
        order=order,
        n_solves=n_solves,
        wall_time_s=time.perf_counter() - t0,
    )
    return rec


def _tie_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """Lexicographic tie-breaks from a multistart optimum (second half of an anchor).

    An individual optimum is often not unique (the ripple of a crank-slider is invariant
    to scaling R, l, n, p together): ``order[1]`` is minimised with ``order[0]`` held at
    its optimum (plus :data:`ANCHOR_SLACK`), then ``order[2]`` with both held, ...
    """
    problem: DesignProblem = task["problem"]
    order: list[str] = task["order"]
    method = task.get("solver", "slsqp")
    t0 = time.perf_counter()
    rec = dict(deps[task["multistart"]])
    n_solves = rec["n_solves"]  # the anchor's record counts every solve behind it
    fixed: dict[str, float] = {}
    for k, name in enumerate(order[1:], start=1):
        if not _ok(rec):
            break
        prev = order[k - 1]
        fixed[prev] = rec["objectives"][prev] * (1 + ANCHOR_SLACK) + 1e-12
        rest = [o for o in order if o not in fixed and o != name]
        tie = _eps_solver(problem, name, [*fixed, *rest], method=method)
        # The tie-break's feasible set is (almost) the set of optima of the objectives
        # fixed before: degenerate, and SLSQP was measured to stall there or stop 2e-4
        # short of Ipopt's value (cs_min_backlash, anchor backlash). Ipopt solves it.
        res = tie.solve({**fixed, **{o: np.inf for o in rest}}, x0=np.asarray(rec["x"]), use="tie")
        n_solves += 1
        cand = _record(problem, res, name, fixed)
        # The start is feasible for the tie-break (the bound is its own value plus slack):
        # a result worse than the start is a solver failure, not a tie-break (default
        # Ipopt once returned ripple 0.99996 "optimal" from a start at 0.0555).
        start_value = rec["objectives"][name]
        if _ok(cand) and cand["objectives"][name] <= start_value * (1 + 1e-9) + 1e-15:
            cand["multistart"] = rec["multistart"]
            rec = cand
    rec["kind"] = "anchor"
    rec["order"] = order
    rec["n_solves"] = n_solves
    rec["wall_time_s"] = time.perf_counter() - t0
    return rec


def _design_distance(problem: DesignProblem, a, b) -> float:
    span = problem.upper() - problem.lower()
    return float(np.max(np.abs((np.asarray(a) - np.asarray(b)) / span)))


def _arc_eps(task: Mapping[str, Any], nb: Mapping[str, Any] | None) -> dict[str, float]:
    """Epsilon of the next point of an arc-length sweep (two objectives A, B).

    In objectives normalised by the anchors' ranges, the L1 arc length of a monotone
    front from anchor A to a point is ``(a - a0)/ra + (b0 - b)/rb`` (total 2). The next
    epsilon is predicted so that the point lands at arc position ``task["arc"]``: a Newton
    step with the front's local slope dB/dA = -multiplier of the epsilon row (the
    neighbour's duals), so points are evenly spread along the front, dense where it bends.
    """
    f = task["frame"]
    a, b = task["eps_name"], task["target"]
    lo, hi = f["a_lo"], f["a_hi"]
    if nb is None or not _ok(nb):
        return {a: float(task["fallback_eps"])}
    a1, b1 = nb["objectives"][a], nb["objectives"][b]
    s1 = (a1 - f["a0"]) / f["ra"] + (f["b0"] - b1) / f["rb"]
    slope = nb.get("slope")
    slope = abs(slope) if slope is not None and np.isfinite(slope) else f["rb"] / f["ra"]
    ds_da = 1.0 / f["ra"] + slope / f["rb"]
    # Never step more than the whole remaining gap, never less than a tiny fraction.
    step = (task["arc"] - s1) / ds_da
    base = max(a1, nb["eps"].get(a, a1)) if step > 0 else min(a1, nb["eps"].get(a, a1))
    eps = float(np.clip(base + step, lo, hi))
    return {a: eps}


def _row_eps(task: Mapping[str, Any], head: Mapping[str, Any] | None) -> dict[str, float]:
    """Epsilon of a three-objective grid point: B between its row head's B and B_max."""
    b = task["b_name"]
    lo = head["objectives"][b] * (1 + ANCHOR_SLACK) + 1e-12 if _ok(head) else task["b_hi"]
    lo = min(lo, task["b_hi"])
    return {**task["eps_row"], b: float(lo + task["frac"] * (task["b_hi"] - lo))}


def _eps_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """One epsilon-constraint point, warm-started from its neighbour (``task["warm"]``)."""
    problem: DesignProblem = task["problem"]
    target: str = task["target"]
    t0 = time.perf_counter()
    nb = deps.get(task.get("warm") or "", None)
    if "eps" in task:
        eps: dict[str, float] = dict(task["eps"])
    elif "row_head" in task:
        eps = _row_eps(task, deps.get(task["row_head"]))
    else:
        eps = _arc_eps(task, nb)
    method = task.get("solver", "slsqp")
    solver = _eps_solver(problem, target, list(eps), warm=True, method=method)
    n_solves = 1
    if nb is not None and _ok(nb):
        start = solver.warm_args(nb.get("raw"), np.asarray(nb["x"]))
        rec = _record(problem, solver.solve(eps, **start), target, eps)
    else:
        rec = _record(problem, solver.solve(eps, x0=problem.start()), target, eps)
    retry, why = False, ""
    if not _ok(rec):
        retry, why = True, "failed"
    elif nb is not None and _ok(nb):
        looser = all(eps[k] >= nb["eps"].get(k, -np.inf) for k in eps)
        t_nb, t = nb["objectives"][target], rec["objectives"][target]
        if looser and t > t_nb * (1 + 1e-6) + 1e-12:
            retry, why = True, "worse than its neighbour with a looser bound"
        elif task.get("jump", 0.2) is not None and _design_distance(
            problem, rec["x"], nb["x"]
        ) > task.get("jump", 0.2):
            retry, why = True, "jump in design space"
    n_cold = max(task.get("retry_starts", 0) if retry else 0, task.get("extra_starts", 0))
    if n_cold > 0:
        # Seeded per point, so a resumed or parallel run draws the same starts.
        cold = _eps_solver(problem, target, list(eps), method=method)
        pts = sobol_starts(
            problem.lower(), problem.upper(), n_cold, task.get("seed", 0) + 7919 * task["index"]
        )
        if nb is not None and nb.get("x") is not None:
            pts = np.vstack([np.asarray(nb["x"]), pts])
        for x0 in pts:
            cand = _record(problem, cold.solve(eps, x0=x0), target, eps)
            n_solves += 1
            if _ok(cand) and (
                not _ok(rec) or cand["objectives"][target] < rec["objectives"][target]
            ):
                rec = cand
    rec["slope"] = _slope(problem, target, eps, rec, method) if _ok(rec) else None
    rec.update(
        kind="eps",
        warm=task.get("warm"),  # the neighbour it started from (which chain computed it)
        retried=why,
        n_solves=n_solves,
        wall_time_s=time.perf_counter() - t0,
    )
    return rec


def _slope(problem, target, eps, rec, method: str = "slsqp") -> float | None:
    """dB/dA at the point from the multiplier of the (single) epsilon row."""
    if len(eps) != 1:
        return None
    (a,) = eps
    solver = _eps_solver(problem, target, [a], warm=True, method=method)
    raw = rec.get("raw") or {}
    if raw.get("nlp") != solver.signature:
        return None
    row = solver.rows[a]
    lam = float(_vector(raw["lam_g"])[row])
    return -abs(lam) * solver.nlp.f_scale / solver.nlp.g_scale[row]


class WeightedSolver:
    """``min sum_k w_k (f_k - ideal_k)/(nadir_k - ideal_k)``, built once for all weights.

    The weights are extra decision variables fixed by their bounds (Ipopt treats fixed
    variables as parameters), so one solver serves every weight vector and the sweep
    warm-starts from its neighbour.
    """

    def __init__(
        self,
        problem: DesignProblem,
        objectives: Sequence[str],
        normalise: Mapping[str, tuple[float, float]],
    ):
        import casadi as ca

        self.problem = problem
        self.objectives = list(objectives)
        base = build_nlp(
            problem, objective=objectives[0], epsilon={k: np.inf for k in objectives[1:]}
        )
        w = ca.SX.sym("w", len(objectives))
        f = 0
        for k, name in enumerate(objectives):
            ideal, nadir = normalise[name]
            f = f + w[k] * (base.objective_values[name] - ideal) / max(nadir - ideal, 1e-300)
        self.base = base
        self.nlp = replace(
            base,
            z=ca.vertcat(base.z, w),
            f=f,
            lbz=np.concatenate([base.lbz, np.zeros(len(objectives))]),
            ubz=np.concatenate([base.ubz, np.zeros(len(objectives))]),
            f_scale=1.0,
            objective="weighted_sum",
        )
        self.solver = CasadiNLPSolver(self.nlp, "ipopt", dict(problem.spec.solver.ipopt))
        self.z_names = [*base.design_names, *base.aux_names, *(f"w_{k}" for k in objectives)]

    def solve(self, weights: Mapping[str, float], x0=None, z0=None) -> Result:
        wv = np.array([weights[k] for k in self.objectives], dtype=float)
        nw = len(wv)
        self.solver.nlp.lbz = np.concatenate([self.base.lbz, wv])
        self.solver.nlp.ubz = np.concatenate([self.base.ubz, wv])
        if z0 is None:
            z0 = np.concatenate([self.base.z_from_x(x0), wv])
        else:
            z0 = np.concatenate([np.asarray(z0, dtype=float)[:-nw], wv])
        result = self.solver.solve(z0=z0)
        if result.raw:
            result.raw["z_names"] = self.z_names
        return result


def _locked(build, *args):
    with _CASADI_LOCK:
        return build(*args)


def _ws_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """One weighted-sum point (normalised objectives), started from its neighbour."""
    problem: DesignProblem = task["problem"]
    weights: dict[str, float] = task["weights"]
    t0 = time.perf_counter()
    normalise = {k: tuple(v) for k, v in task["normalise"].items()}
    objectives = list(weights)
    key = ("ws", problem_key(problem), tuple(objectives), json.dumps(normalise, sort_keys=True))
    solver = cached(key, lambda: _locked(WeightedSolver, problem, objectives, normalise))
    nb = deps.get(task.get("warm") or "", None)
    raw = (nb or {}).get("raw") or {}
    if _ok(nb) and raw.get("z_names") == solver.z_names:
        res = solver.solve(weights, z0=_vector(raw["z"]))
    else:
        x0 = nb["x"] if _ok(nb) else task["x0"]
        res = solver.solve(weights, x0=np.asarray(x0, dtype=float))
    rec = _record(problem, res, objectives[0], {})
    rec.update(kind="weighted_sum", weights=weights, n_solves=1)
    rec["wall_time_s"] = time.perf_counter() - t0
    return rec


# --- front assembly ---------------------------------------------------------------------
def _check_objectives(problem: DesignProblem, objectives: Sequence[str]) -> list[str]:
    objectives = list(objectives)
    if len(objectives) not in (2, 3):
        raise ProblemError(f"--objectives: give two or three objectives, got {objectives}")
    if len(set(objectives)) != len(objectives):
        raise ProblemError(f"--objectives: repeated objective in {objectives}")
    ex = problem.expressions(problem.design_dict(problem.start()))
    for k in objectives:
        if k not in ex.objectives:
            raise ProblemError(
                f"--objectives: {k!r} is not an objective of {problem.name} "
                f"(available: {', '.join(ex.objectives)})"
            )
    return objectives


def _store(out: Path | str | None, name: str) -> Path:
    base = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix="optdesign-pareto-"))
    base.mkdir(parents=True, exist_ok=True)
    return base / f"{name}.jsonl"


def _run_key(problem: DesignProblem, **settings) -> str:
    text = json.dumps({"problem": problem_key(problem), **settings}, sort_keys=True, default=str)
    return hashlib.sha1(text.encode()).hexdigest()[:16]


def _point(rec: Mapping[str, Any], method: str) -> FrontPoint:
    return FrontPoint(
        objectives=dict(rec.get("objectives") or {}),
        design=dict(rec.get("design") or {}),
        status=rec["status"],
        active=list(rec.get("active") or []),
        method=method,
        verified=rec.get("verified"),
        eps=dict(rec.get("eps") or rec.get("weights") or {}),
        id=rec.get("id", ""),
        extra={
            k: rec[k]
            for k in ("message", "retried", "n_solves", "wall_time_s", "iterations", "violated")
            if k in rec
        },
    )


def make_front(
    points: Sequence[FrontPoint],
    objectives: Sequence[str],
    method: str,
    wall_time_s: float = 0.0,
    info: Mapping[str, Any] | None = None,
) -> Front:
    """Filter failed and dominated points, sort by the first objective, compute metrics."""
    objectives = list(objectives)
    good = [p for p in points if p.success and all(k in p.objectives for k in objectives)]
    rejected = []
    for p in points:
        if p not in good:
            p.extra["rejected"] = "failed" if not p.success else "missing objective"
            rejected.append(p)
    F = np.array([[p.objectives[k] for k in objectives] for p in good], dtype=float)
    F = F.reshape(-1, len(objectives))
    mask = non_dominated(F) if len(F) else np.zeros(0, dtype=bool)
    kept = []
    for p, keep in zip(good, mask, strict=True):
        if keep:
            kept.append(p)
        else:
            p.extra["rejected"] = "dominated or duplicate"
            rejected.append(p)
    kept.sort(key=lambda p: tuple(p.objectives[k] for k in objectives))
    front = Front(
        objectives, method, kept, rejected, wall_time_s=wall_time_s, info=dict(info or {})
    )
    front.metrics = front_metrics(front.F)
    front.metrics["n_failed"] = sum(1 for p in points if not p.success)
    return front


def _front_task(task: Mapping[str, Any], deps: Mapping[str, Any]) -> dict[str, Any]:
    """The one task function of a front's run: dispatches on ``task["kind"]``."""
    return _TASK_KINDS[task["kind"]](task, deps)


_TASK_KINDS: dict[str, Callable[[Mapping[str, Any], Mapping[str, Any]], dict[str, Any]]] = {
    "anchor-multistart": _multistart_task,
    "anchor": _tie_task,
    "eps": _eps_task,
}


def anchor_tasks(
    problem: DesignProblem,
    objectives: Sequence[str],
    starts: int,
    seed: int,
    solver: str = "slsqp",
    agree: int | None = None,
) -> list[dict[str, Any]]:
    """Two tasks per objective: its multistart (``anchor-{name}-ms``), then its
    lexicographic tie-breaks (``anchor-{name}``, the anchor). The multistarts come first
    in the list, so that with several workers they run side by side."""
    m = len(objectives)
    ms, ties = [], []
    for k, name in enumerate(objectives):
        order = [name] + [objectives[(k + j) % m] for j in range(1, m)]
        common = {"problem": problem, "order": order, "solver": solver}
        ms.append(
            {
                **common,
                "id": f"anchor-{name}-ms",
                "kind": "anchor-multistart",
                "starts": starts,
                "seed": seed,
                "agree": agree,
            }
        )
        ties.append(
            {
                **common,
                "id": f"anchor-{name}",
                "kind": "anchor",
                "multistart": f"anchor-{name}-ms",
                "after": [f"anchor-{name}-ms"],
            }
        )
    return ms + ties


def _check_anchor(rec: Mapping[str, Any], name: str) -> None:
    if not _ok(rec):
        raise ProblemError(
            f"anchor {name}: no verified optimum of {name} found (status {rec['status']}, "
            f"violated: {', '.join(rec.get('violated', [])) or 'none reported'})"
        )


def compute_anchors(
    problem: DesignProblem,
    objectives: Sequence[str],
    store: Path,
    workers: int = 1,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool | str = False,
    starts: int | None = None,
    seed: int | None = None,
    key: str | None = None,
    on_record: Callable | None = None,
    solver: str = "slsqp",
    agree: int | None = None,
    pool=None,
) -> dict[str, dict[str, Any]]:
    """Lexicographic anchors (one per objective), run as tasks of ``store``.

    ``solver`` is the primary NLP solver (``"slsqp"`` with Ipopt fallback, or
    ``"ipopt"``); ``agree`` stops each anchor's multistart once that many starts agree on
    the best value (None: run every start).
    """
    starts = starts if starts is not None else problem.spec.solver.starts
    seed = seed if seed is not None else problem.spec.solver.seed
    done = run_tasks(
        anchor_tasks(problem, objectives, starts, seed, solver, agree),
        _front_task,
        store,
        workers,
        scheduler,
        resume,
        progress,
        key,
        on_record,
        pool=pool,
    )
    for name in objectives:
        _check_anchor(done[f"anchor-{name}"], name)
    return {name: done[f"anchor-{name}"] for name in objectives}


class _TwoChains:
    """The tasks of a two-objective sweep, decided as records come in (``expand`` of
    :func:`run_tasks`).

    Two warm-started chains: one ascends from anchor A (points 0, 1, ...), the other
    descends from anchor B (n-1, n-2, ...). A finished point adds its successor unless
    the other chain has it already, so the chains meet wherever they meet: with two
    workers, the chain whose anchor is ready first does more points, instead of a worker
    idling while the other anchor's tie-break runs. With one worker they alternate and
    meet in the middle (deterministic). With ``split`` the chains meet at that index
    whatever the timing: the same front for any number of workers, at the price of the
    balance.

    Arc spacing (default) normalises the objectives by a frame taken from anchor A and
    anchor B's *multistart* optimum: chain A can then start while B's tie-break (an Ipopt
    solve and its build, the longest step of the anchors) still runs. B's tie-break only
    lowers A's value at B's optimum (on cs_min_backlash, ripple 0.05594 -> 0.05550), so
    the frame's range of A is ~1 % wider than the front's; the last point (epsilon = A at
    the tie-broken anchor B) is exact. Uniform or explicit epsilon values need both
    tie-broken anchors before the first point.
    """

    def __init__(
        self,
        objectives: Sequence[str],
        n: int,
        name: str,
        common: Mapping[str, Any],
        spacing: str,
        eps_values: Sequence[float] | None,
        split: int | None = None,
    ):
        self.a, self.b = objectives
        self.split = split
        self.n, self.name, self.common, self.spacing = n, name, dict(common), spacing
        self.eps_values = None if eps_values is None else [float(v) for v in eps_values]
        self.frame: dict[str, float] | None = None
        self.claimed: set[int] = set()
        self.tasks: list[dict[str, Any]] = []

    def __call__(
        self, task: Mapping[str, Any], record: Mapping[str, Any], done: Mapping[str, Any]
    ) -> list[dict[str, Any]]:
        a, b, n = self.a, self.b, self.n
        tie_a, ms_b, tie_b = f"anchor-{a}", f"anchor-{b}-ms", f"anchor-{b}"
        new: list[dict[str, Any]] = []
        if self.frame is None and tie_a in done and ms_b in done:
            arc = self.spacing == "arc" and self.eps_values is None
            if arc or tie_b in done:  # uniform or explicit epsilon need B's tie-break
                _check_anchor(done[tie_a], a)
                far = done[ms_b] if arc else done[tie_b]
                _check_anchor(far, b)
                self._make_frame(done[tie_a], far, done.get(tie_b))
                new.append(self._point(0, +1, tie_a, done))
        if self.frame is not None and tie_b in done and n - 1 not in self.claimed:
            _check_anchor(done[tie_b], b)
            new.append(self._point(n - 1, -1, tie_b, done))
        if task.get("kind") == "eps" and task["id"].startswith(f"{self.name}-"):
            # The ascending chain stops before n-1: that point's epsilon is A at the
            # tie-broken anchor B, which the descending chain starts from.
            j = task["index"] + task["dir"]
            # With a fixed split the ascending chain owns 0..split-1, the other the rest.
            own = self.split is None or (j < self.split) == (task["dir"] > 0)
            if 0 < j < n - 1 and j not in self.claimed and own:
                new.append(self._point(j, task["dir"], task["id"], done))
        return new

    def _make_frame(self, anchor_a, far_b, tie_b) -> None:
        a, b = self.a, self.b
        lo = anchor_a["objectives"][a] * (1 + ANCHOR_SLACK) + 1e-12
        hi = far_b["objectives"][a]
        if self.eps_values is None and self.spacing == "uniform":
            hi = tie_b["objectives"][a]
            self.eps_values = [float(v) for v in np.linspace(lo, hi, self.n)]
        self.frame = {
            "a0": anchor_a["objectives"][a],
            "b0": anchor_a["objectives"][b],
            "ra": max(hi - anchor_a["objectives"][a], 1e-300),
            "rb": max(anchor_a["objectives"][b] - far_b["objectives"][b], 1e-300),
            "a_lo": lo,
            "a_hi": max(hi, lo),
        }

    def _point(self, i: int, d: int, warm: str, done: Mapping[str, Any]) -> dict[str, Any]:
        a, n, f = self.a, self.n, self.frame
        assert f is not None
        self.claimed.add(i)
        task = {
            **self.common,
            "id": f"{self.name}-{i:04d}",
            "kind": "eps",
            "target": self.b,
            "warm": warm,
            "after": [warm],
            "index": i,
            "dir": d,
        }
        if self.eps_values is not None:
            task["eps"] = {a: self.eps_values[i]}
        elif i == 0:
            task["eps"] = {a: f["a_lo"]}
        elif i == n - 1:
            task["eps"] = {a: done[f"anchor-{self.b}"]["objectives"][a]}
        else:
            task.update(
                eps_name=a,
                arc=i * 2.0 / max(n - 1, 1),
                frame=f,
                fallback_eps=float(f["a_lo"] + (f["a_hi"] - f["a_lo"]) * i / (n - 1)),
            )
        self.tasks.append(task)
        return task


def prebuild_solvers(problem: DesignProblem, objectives: Sequence[str], method: str) -> None:
    """Build, in this process, the formulation every target of a front derives from (and
    each target's :class:`EpsSolver` around it), before a pool of local workers is
    started: forked workers inherit them (see :func:`optdesign.studies.runner.cached`)
    instead of each building its own copy of the ~0.1 s formulation. The solvers' own
    functions (SLSQP ~0.02 s, Ipopt ~0.1 s) are built in the workers, side by side, on
    first use."""
    if not forks_workers():
        return  # spawned workers would not inherit anything
    for target in objectives:
        _eps_solver(problem, target, [o for o in objectives if o != target], method=method)


def epsilon_constraint_front(
    problem: DesignProblem,
    objectives: Sequence[str],
    n_points: int = 50,
    out: Path | str | None = None,
    workers: int = 1,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool | str = False,
    starts: int | None = None,
    seed: int | None = None,
    retry_starts: int = 4,
    extra_starts: int = 0,
    spacing: str = "arc",
    eps_values: Sequence[float] | None = None,
    name: str = "epsilon",
    on_record: Callable | None = None,
    solver: str = "slsqp",
    agree: int | None = 3,
    deterministic: bool = False,
) -> Front:
    """Epsilon-constraint front of two or three objectives.

    Parameters
    ----------
    objectives
        ``[A, B]``: min B s.t. A <= eps; ``[A, B, C]``: min C s.t. A <= e1, B <= e2.
    n_points
        Points of the sweep (2 objectives), or about that many grid points (3).
    out
        Folder of the JSONL store ``{name}.jsonl`` (default: a temporary folder).
    workers, scheduler
        Local processes, or a Dask scheduler address (see :func:`run_tasks`).
    resume
        Continue from the store without recomputing finished points.
    starts, seed
        Multistart of the anchors (default: the problem file's).
    retry_starts
        Sobol starts for a point that fails, gets worse as its bound loosens, or jumps.
    extra_starts
        Sobol starts solved at every point besides the warm start (reference fronts).
    spacing
        Two objectives: ``"arc"`` (default) places the points evenly along the front (L1
        arc length in normalised objectives, predicted from the neighbour's multiplier);
        ``"uniform"`` spaces epsilon evenly (sparse where the front is steep).
    eps_values
        Explicit epsilon values of A (two objectives; overrides ``spacing``).
    solver
        ``"slsqp"`` (default): SciPy SLSQP with exact CasADi derivatives, warm from the
        neighbour's design, Ipopt (built on first use) for a start SLSQP does not solve;
        ``"ipopt"``: Ipopt throughout, warm-started primal and dual.
    agree
        Anchor multistart stops once this many starts agree on the best value (None:
        always all ``starts``); each anchor record says how many ran and agreed.
    deterministic
        Two objectives: the chains meet in the middle whatever the timing, so the front
        is the same for any number of workers and an interrupted run resumes to exactly
        the uninterrupted front; slower with several workers (the chain from the anchor
        finished first cannot take over the other's points).

    Notes
    -----
    Two objectives run as one task graph (:class:`_TwoChains`): the anchors' multistarts,
    their tie-breaks and the two chains of the sweep, each task starting as soon as what
    it needs is in. With one worker the chains alternate and the front is deterministic.
    With several (and ``deterministic=False``) the chains meet where timing makes them
    meet; each chain predicts its own epsilon values, so the points near the meeting
    point move a little from run to run along the same front (measured on
    cs_min_backlash, 30 points: objectives within 0.5 %, hypervolume within 2e-5
    relative), and a resumed run is such a front too.
    """
    objectives = _check_objectives(problem, objectives)
    if spacing not in ("arc", "uniform"):
        raise ProblemError(f"spacing {spacing!r}: use 'arc' or 'uniform'")
    if eps_values is not None:
        n_points = len(eps_values)
    if n_points < 2:
        raise ProblemError(f"--points: a front needs at least 2 points, got {n_points}")
    t0 = time.perf_counter()
    store = _store(out, name)
    starts = starts if starts is not None else problem.spec.solver.starts
    seed = seed if seed is not None else problem.spec.solver.seed
    key = _run_key(
        problem,
        layout=2,  # anchor and chain task ids of this version
        objectives=objectives,
        n=n_points,
        starts=starts,
        seed=seed,
        retry=retry_starts,
        extra=extra_starts,
        spacing=spacing,
        eps=None if eps_values is None else list(eps_values),
        solver=solver,
        agree=agree,
        deterministic=deterministic,
    )
    common = {
        "solver": solver,
        "problem": problem,
        "retry_starts": retry_starts,
        "extra_starts": extra_starts,
        "seed": seed,
    }
    if workers > 1 and scheduler is None:
        prebuild_solvers(problem, objectives, solver)
    label = f"{name}: points" if progress else False
    with process_pool(workers if scheduler is None else 1) as pool:
        if len(objectives) == 2:
            split = n_points // 2 if deterministic else None
            sweep = _TwoChains(objectives, n_points, name, common, spacing, eps_values, split)
            done = run_tasks(
                anchor_tasks(problem, objectives, starts, seed, solver, agree),
                _front_task,
                store,
                workers,
                scheduler,
                resume,
                label,
                key,
                on_record,
                pool=pool,
                expand=sweep,
            )
            tasks = sweep.tasks
            # _TwoChains checked every anchor before starting a chain from it.
            anchors = {k: done[f"anchor-{k}"] for k in objectives}
        else:
            # Three objectives: the rows need every anchor (the nadir of B), so the
            # anchors run first, then the rows in parallel.
            anchors = compute_anchors(
                problem,
                objectives,
                store,
                workers,
                scheduler,
                resume,
                f"{name}: anchors" if progress else False,
                starts,
                seed,
                key,
                on_record,
                solver=solver,
                agree=agree,
                pool=pool,
            )
            tasks = _three_objective_tasks(anchors, objectives, n_points, name, common)
            done = run_tasks(
                tasks,
                _front_task,
                store,
                workers,
                scheduler,
                True,  # the anchors are in the store already
                label,
                key,
                on_record,
                pool=pool,
                known={f"anchor-{k}": rec for k, rec in anchors.items()},
            )
    pts = [_point(done[t["id"]], name) for t in sorted(tasks, key=lambda t: t["index"])]
    info = {
        "anchors": {k: rec["objectives"] for k, rec in anchors.items()},
        "store": str(store),
        "spacing": "explicit" if eps_values is not None else spacing,
        # An anchor's record counts its multistart's solves too.
        "n_solves": sum(done[t["id"]].get("n_solves", 0) for t in tasks)
        + sum(rec.get("n_solves", 0) for rec in anchors.values()),
        "n_retried": sum(1 for t in tasks if done[t["id"]].get("retried")),
    }
    return make_front(pts, objectives, name, time.perf_counter() - t0, info)


def _three_objective_tasks(
    anchors: Mapping[str, Mapping[str, Any]],
    objectives: Sequence[str],
    n_points: int,
    name: str,
    common: Mapping[str, Any],
) -> list[dict[str, Any]]:
    """Row tasks of a three-objective front ``[A, B, C]``.

    Row r fixes A <= e1[r]. Its head (min B s.t. A <= e1, a chain along e1 from anchor A)
    gives the smallest feasible e2 of the row, so that the row's grid e2 in [B_min(e1),
    B_max] holds no infeasible corner; each row is then a warm-started chain of
    min C s.t. A <= e1, B <= e2 from the tightest e2 up.
    """
    a, b, c = objectives
    n_side = max(2, math.ceil(math.sqrt(n_points)))
    lo_a = anchors[a]["objectives"][a] * (1 + ANCHOR_SLACK) + 1e-12
    hi_a = max(r["objectives"][a] for r in anchors.values())
    hi_b = max(r["objectives"][b] for r in anchors.values())
    tasks: list[dict[str, Any]] = []
    prev = f"anchor-{a}"
    for r, v1 in enumerate(np.linspace(lo_a, hi_a, n_side)):
        head = {
            **common,
            "id": f"{name}-{r:03d}-head",
            "kind": "eps",
            "target": b,
            "eps": {a: float(v1), c: np.inf},
            "warm": prev,
            "after": [prev],
            "index": r * (n_side + 1),
            "head": True,
        }
        tasks.append(head)
        prev, row_prev = head["id"], head["id"]
        for k in range(n_side):
            task = {
                **common,
                "id": f"{name}-{r:03d}-{k:03d}",
                "kind": "eps",
                "target": c,
                "eps_row": {a: float(v1)},
                "row_head": head["id"],
                "b_name": b,
                "b_hi": float(hi_b),
                "frac": k / (n_side - 1),
                "warm": row_prev,
                "after": sorted({row_prev, head["id"]}),
                "index": r * (n_side + 1) + k + 1,
                "jump": None,  # grid steps are large: jumps are expected
            }
            tasks.append(task)
            row_prev = task["id"]
    return tasks


def weighted_sum_front(
    problem: DesignProblem,
    objectives: Sequence[str],
    n_points: int = 50,
    out: Path | str | None = None,
    workers: int = 1,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool | str = False,
    starts: int | None = None,
    seed: int | None = None,
    on_record: Callable | None = None,
) -> Front:
    """Weighted sum of the normalised objectives (ideal 0, nadir 1), weights evenly
    spaced. It finds only the convex hull of the front: points in non-convex parts are
    missed whatever the weights (which the comparison plot shows)."""
    objectives = _check_objectives(problem, objectives)
    t0 = time.perf_counter()
    store = _store(out, "weighted_sum")
    key = _run_key(problem, objectives=objectives, n=n_points, starts=starts, seed=seed, ws=1)
    anchors = compute_anchors(
        problem, objectives, store, workers, scheduler, resume, False, starts, seed, key
    )
    F = np.array([[r["objectives"][k] for k in objectives] for r in anchors.values()])
    ideal, nadir = F.min(axis=0), F.max(axis=0)
    normalise = {k: (float(ideal[j]), float(nadir[j])) for j, k in enumerate(objectives)}
    m = len(objectives)
    if m == 2:
        W = [(w, 1 - w) for w in np.linspace(0.0, 1.0, n_points)]
    else:
        side = max(2, math.ceil((math.sqrt(8 * n_points + 1) - 1) / 2))
        W = [
            (i / (side - 1), j / (side - 1), 1 - (i + j) / (side - 1))
            for i in range(side)
            for j in range(side - i)
        ]
    tasks, prev = [], f"anchor-{objectives[-1]}"
    for i, w in enumerate(W):
        # Zero weights make ties (the anchors' non-uniqueness); a tiny floor breaks them.
        weights = {k: float(max(wk, 1e-4)) for k, wk in zip(objectives, w, strict=True)}
        tasks.append(
            {
                "id": f"ws-{i:04d}",
                "problem": problem,
                "weights": weights,
                "normalise": normalise,
                "warm": prev,
                "after": [prev],
                "x0": anchors[objectives[-1]]["x"],
            }
        )
        prev = tasks[-1]["id"]
    done = run_tasks(
        tasks, _ws_task, store, 1, None, True, "weighted sum" if progress else False, key, on_record
    )
    pts = [_point(done[t["id"]], "weighted_sum") for t in tasks]
    return make_front(pts, objectives, "weighted_sum", time.perf_counter() - t0)


# --- NSGA-II baseline ----------------------------------------------------------------------
def _pymoo_problem(problem: DesignProblem, objectives: Sequence[str]):
    from pymoo.core.problem import Problem

    ev0 = problem.evaluate(problem.start()[None, :])
    n_con = len(ev0["constraints"])

    class _Vectorised(Problem):
        def __init__(self):
            super().__init__(
                n_var=len(problem.free),
                n_obj=len(objectives),
                n_ieq_constr=n_con,
                xl=problem.lower(),
                xu=problem.upper(),
            )

        def _evaluate(self, X, out, *args, **kwargs):
            ev = problem.evaluate(X)
            out["F"] = np.column_stack(
                [np.nan_to_num(ev["objectives"][k], nan=1e6, posinf=1e6) for k in objectives]
            )
            G = []
            for values, lo, hi in ev["constraints"].values():
                # G <= 0 feasible: the largest signed relative violation of the block.
                v = np.asarray(values, dtype=float).reshape(len(X), -1)
                g = np.full(v.shape, -np.inf)
                if lo is not None:
                    g = np.maximum(g, (lo - v) / max(1.0, abs(lo)))
                if hi is not None:
                    g = np.maximum(g, (v - hi) / max(1.0, abs(hi)))
                G.append(np.nan_to_num(g.max(axis=1), nan=1e6))
            out["G"] = np.column_stack(G)

    return _Vectorised()


def nsga2_front(
    problem: DesignProblem,
    objectives: Sequence[str],
    pop_size: int = 100,
    generations: int = 500,
    seed: int = 0,
    progress: bool = False,
) -> Front:
    """NSGA-II (pymoo) on the NumPy path of the same problem; its final non-dominated
    feasible population, each point checked with the same independent check."""
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.optimize import minimize

    objectives = _check_objectives(problem, objectives)
    t0 = time.perf_counter()
    res = minimize(
        _pymoo_problem(problem, objectives),
        NSGA2(pop_size=pop_size),
        ("n_gen", generations),
        seed=seed,
        verbose=False,
    )
    wall = time.perf_counter() - t0
    pts = []
    X = np.atleast_2d(res.X) if res.X is not None else np.zeros((0, len(problem.free)))
    if len(X):
        ev = problem.evaluate(X)
        for j, x in enumerate(X):
            ok = bool(ev["violation"][j] <= VERIFY_TOL)
            pts.append(
                FrontPoint(
                    objectives={k: float(v[j]) for k, v in ev["objectives"].items()},
                    design={**problem.fixed_values, **problem.design_dict(x)},
                    status="feasible" if ok else "infeasible",
                    active=[],
                    method="nsga2",
                    verified=ok,
                    id=f"nsga2-{j:04d}",
                )
            )
    for p in pts:
        p.design = {k: float(v) for k, v in p.design.items()}
    return make_front(
        pts,
        objectives,
        "nsga2",
        wall,
        {"pop_size": pop_size, "generations": generations, "seed": seed},
    )


# --- convenience ---------------------------------------------------------------------------
METHODS: dict[str, Callable[..., Front]] = {
    "epsilon": epsilon_constraint_front,
    "uniform": lambda *a, **k: epsilon_constraint_front(*a, spacing="uniform", name="uniform", **k),
    "weighted_sum": weighted_sum_front,
}


# --- files ----------------------------------------------------------------------------------
def front_rows(front: Front, problem: DesignProblem, rejected: bool = False) -> list[dict]:
    """One dict per point: objectives, free design variables, status, method, active."""
    rows = []
    pts = front.points + (front.rejected if rejected else [])
    for p in pts:
        row: dict[str, Any] = {"method": p.method, "id": p.id}
        for k in front.objectives:
            row[k] = p.objectives.get(k, float("nan"))
        for v in problem.free:
            row[v.name] = p.design.get(v.name, float("nan"))
        row["status"] = p.status
        row["verified"] = p.verified
        row["on_front"] = p in front.points
        row["active"] = ";".join(p.active)
        rows.append(row)
    return rows


def write_front_csv(
    front: Front | Sequence[Front], problem: DesignProblem, path: Path | str
) -> Path:
    """``front.csv``: one row a point (objectives, design variables, status, ...)."""
    import csv
    import io

    from optdesign.storage import atomic_write_text

    fronts = [front] if isinstance(front, Front) else list(front)
    rows = [r for f in fronts for r in front_rows(f, problem, rejected=True)]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fields = list(rows[0]) if rows else ["method"]
    with io.StringIO() as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.12g}" if isinstance(v, float) else v) for k, v in r.items()})
        return atomic_write_text(path, fh.getvalue())


def read_front_csv(path: Path | str, objectives: Sequence[str]) -> np.ndarray:
    """Objective values of the on-front rows of a ``front.csv``."""
    import csv

    with Path(path).open() as fh:
        rows = [r for r in csv.DictReader(fh) if r.get("on_front", "True") == "True"]
    return np.array([[float(r[k]) for k in objectives] for r in rows], dtype=float)


def write_front_json(fronts: Sequence[Front], path: Path | str, **meta) -> Path:
    """``front.json``: every front with its points, rejected points and metrics."""
    from optdesign.storage import atomic_write_text

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(_clean({**meta, "fronts": [f.to_dict() for f in fronts]}), indent=1)
    return atomic_write_text(path, text)
