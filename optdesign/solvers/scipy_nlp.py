"""SciPy back-ends behind the common :class:`Result`: SLSQP and trust-constr on an
:class:`~optdesign.programs.nlp.NLP` (derivatives exact from CasADi or by finite
differences), and differential evolution on a vectorised NumPy objective.

- :class:`ScipyNLPSolver` turns the NLP into one CasADi Function for f, grad f, g and
  jac g (and, for trust-constr, the Hessians of f and of lam' g), or hands SciPy only f
  and g when ``derivatives="fd"`` (SLSQP then differences itself; trust-constr uses 2-point
  gradients and BFGS Hessians). A wall-time limit is enforced inside the function
  evaluations, so every method stops, whatever its own callbacks support.
- :func:`differential_evolution` is the global reference: it sees only a vectorised
  ``objective(X) -> (value, violation)`` (population rows), typically
  :meth:`DesignProblem.evaluate`, and handles catalogue variables as integer indices.

A signal during a solve is raised as :class:`optdesign.interrupts.Interrupted`, never
turned into a failed start (:func:`optdesign.interrupts.solver_call`: CasADi's
evaluations inside SciPy's callbacks may report it as a ``RuntimeError``).

None of this knows a mechanism.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar

import casadi as ca
import numpy as np
import scipy.optimize as so

from optdesign.interrupts import solver_call
from optdesign.programs.nlp import NLP, Bounds, Start, Target
from optdesign.solvers.base import failed_result, make_result, resolve
from optdesign.solvers.blas import one_blas_thread, rescan_blas
from optdesign.solvers.result import Result, SolutionStatus, TerminationCondition
from optdesign.tolerances import FEASIBILITY_TOL


class _TimeUp(Exception):
    """Raised from inside a function evaluation when the wall-time limit is reached."""


class ScipyNLPSolver:
    """SLSQP or trust-constr on an NLP in scaled variables (the one SciPy NLP back-end).

    - With exact derivatives, f, grad f, g and jac g come from one CasADi Function
      evaluated once per point (SciPy asks for them at the same point); the Hessians of
      trust-constr are separate Functions.
    - SLSQP's multipliers (SciPy >= 1.16 returns them) are mapped to CasADi's sign
      convention in ``raw["lam_g"]`` (``> 0`` at an active upper bound, ``< 0`` at an
      active lower bound); SciPy returns no bound multipliers, so ``raw["lam_x"]`` is
      zero, and trust-constr's ``raw["lam_g"]`` is zero too. There is no dual warm start.

    Parameters
    ----------
    nlp
        The formulation (epigraph or naive).
    method
        ``"SLSQP"`` or ``"trust-constr"``.
    derivatives
        ``"exact"`` (CasADi gradients, Jacobians and, for trust-constr, Hessians) or
        ``"fd"`` (finite differences; trust-constr then uses BFGS Hessians).
    options
        SciPy ``options`` (``maxiter``, ``ftol``/``gtol`` ...), merged over the defaults.
    time_limit
        Wall-time limit of one solve (s); the last iterate is returned as
        ``time_limit``.

    Notes
    -----
    ``n_evals`` counts SciPy's requests (``f``, ``grad_f``, ``g``, ``jac_g``, ``hess_f``,
    ``hess_g``, the names the benchmark summary reads) and, with exact derivatives, the
    combined CasADi evaluations (``fgj``).

    The best point of a solve is kept as it goes (the start and every iterate: the
    feasible one of least objective, else the least violation, rows within
    :data:`~optdesign.tolerances.FEASIBILITY_TOL`). A solve that does not converge - the
    time limit, the iteration limit, a SciPy failure - returns that point, never a line
    search's last trial or an iterate worse than one it passed (SLSQP's last point after
    "Positive directional derivative for linesearch" may be far outside the feasible
    set, with an epigraph variable thousands below the objective it bounds).

    SLSQP has no restoration phase: from a start where a user's mechanism does not
    assemble (its guarded model then gives huge values: a backlash of 1.5e11 deg at the
    middle of a six-bar's bounds) its linearised rows are incompatible (exit 4), and a
    quasi-Newton matrix spoilt on the way ends a run at "Positive directional derivative
    for linesearch" (exit 8), often near a solution. After these exits (and the singular
    LSQ subproblems, 5 and 6) it starts again with a fresh matrix from the best feasible
    point (from the run's last point while it has found none: the start was where it
    failed), its epigraph variables tightened, at most :attr:`RESTARTS` times, never twice
    from one point; the iteration and time limits count every run.
    """

    DEFAULTS: ClassVar[dict[str, dict[str, Any]]] = {
        "SLSQP": {"maxiter": 500, "ftol": 1e-10},
        "trust-constr": {"maxiter": 2000, "gtol": 1e-8, "xtol": 1e-10},
    }

    #: SLSQP's exit statuses after which it starts again from the best point (4 inequality
    #: constraints incompatible, 5 and 6 singular matrix E or C in the LSQ subproblem, 8
    #: positive directional derivative for linesearch).
    RESTART_EXITS: ClassVar[tuple[int, ...]] = (4, 5, 6, 8)

    #: At most this many restarts in one solve.
    RESTARTS: ClassVar[int] = 3

    def __init__(
        self,
        nlp: NLP,
        method: str = "SLSQP",
        derivatives: str = "exact",
        options: Mapping[str, Any] | None = None,
        time_limit: float = math.inf,
    ):
        if method not in self.DEFAULTS:
            raise ValueError(f"method {method!r}: use 'SLSQP' or 'trust-constr'")
        if derivatives not in ("exact", "fd"):
            raise ValueError(f"derivatives {derivatives!r}: use 'exact' or 'fd'")
        self.nlp = nlp
        self.method = method
        self.derivatives = derivatives
        self.options = {**self.DEFAULTS[method], **(options or {})}
        self.time_limit = time_limit
        z, p, f, g = nlp.z, nlp.p, nlp.f, nlp.g
        self.f_fun = ca.Function("f", [z, p], [f])
        self.g_fun = ca.Function("g", [z, p], [g])
        if derivatives == "exact":
            self.fgj_fun = ca.Function("fgj", [z, p], [f, ca.gradient(f, z), g, ca.jacobian(g, z)])
            if method == "trust-constr":
                lam = ca.SX.sym("lam", g.shape[0])
                self.hess_f_fun = ca.Function("hess_f", [z, p], [ca.hessian(f, z)[0]])
                self.hess_g_fun = ca.Function(
                    "hess_g", [z, p, lam], [ca.hessian(ca.dot(lam, g), z)[0]]
                )
        self.n_evals: dict[str, int] = {}
        # One-point caches: the exact (f, grad f, g, jac g) and, with finite differences,
        # g (SLSQP asks for its inequality and equality rows at the same point).
        self._cache: dict[str, tuple[bytes, Any]] = {}
        self._p = np.zeros(nlp.p.shape[0])
        rescan_blas()  # SciPy's OpenBLAS, for one_blas_thread (imported with this module)

    @property
    def name(self) -> str:
        return f"scipy-{self.method.lower()}-{self.derivatives}"

    # --- counted, time-limited evaluations -------------------------------------------------
    def _tick(self, key: str, z) -> None:
        self.n_evals[key] = self.n_evals.get(key, 0) + 1
        if time.perf_counter() - self._t0 > self.time_limit:
            raise _TimeUp

    def _cached(self, kind: str, z) -> Any:
        """``fgj`` -> (f, grad f, g, jac g) or ``g`` -> g at ``z``, evaluated once per point."""
        z = np.asarray(z, dtype=float)
        key = z.tobytes()
        hit = self._cache.get(kind)
        if hit is not None and hit[0] == key:
            return hit[1]
        if kind == "fgj":
            f, gf, g, jg = self.fgj_fun(z, self._p)
            val: Any = (
                float(f),
                np.asarray(gf, dtype=float).ravel(),
                np.asarray(g, dtype=float).ravel(),
                np.asarray(ca.densify(jg), dtype=float),
            )
            self.n_evals["fgj"] = self.n_evals.get("fgj", 0) + 1
        else:
            val = np.asarray(self.g_fun(z, self._p), dtype=float).ravel()
        self._cache[kind] = (key, val)
        return val

    def _f(self, z):
        self._tick("f", z)
        if self.derivatives == "exact":
            return self._cached("fgj", z)[0]
        return float(self.f_fun(z, self._p))

    # The cached arrays are handed out as copies: SciPy may keep or modify what it gets.
    def _grad(self, z):
        self._tick("grad_f", z)
        return self._cached("fgj", z)[1].copy()

    def _g(self, z):
        self._tick("g", z)
        if self.derivatives == "exact":
            return self._cached("fgj", z)[2].copy()
        return self._cached("g", z).copy()

    def _jac(self, z):
        self._tick("jac_g", z)
        return self._cached("fgj", z)[3].copy()

    def _hess_f(self, z):
        self._tick("hess_f", z)
        return np.asarray(ca.densify(self.hess_f_fun(z, self._p)), dtype=float)

    def _hess_g(self, z, v):
        self._tick("hess_g", z)
        return np.asarray(ca.densify(self.hess_g_fun(z, self._p, v)), dtype=float)

    # --- the best point of a solve -----------------------------------------------------
    def _rank(self, z: np.ndarray) -> tuple[int, float]:
        """``(0, f)`` at a point that meets every row (the rows are scaled: within
        FEASIBILITY_TOL, as :func:`~optdesign.solvers.base.make_result` reads them),
        else ``(1, largest violation)``; lower is better."""
        if self.derivatives == "exact":
            f, _, g, _ = self._cached("fgj", z)
        else:
            f, g = float(self.f_fun(z, self._p)), self._cached("g", z)
        lb, ub = self._lbg, self._ubg
        with np.errstate(invalid="ignore"):
            amounts = np.maximum(
                np.where(np.isfinite(lb), lb - g, 0.0), np.where(np.isfinite(ub), g - ub, 0.0)
            )
        viol = float(np.max(amounts, initial=0.0)) if np.isfinite(g).all() else math.inf
        if viol <= FEASIBILITY_TOL and math.isfinite(f):
            return 0, float(f)
        return 1, viol if math.isfinite(viol) else math.inf

    def _track(self, z) -> None:
        """Keep ``z`` if it is the best point of the solve so far."""
        z = np.array(z, dtype=float)
        rank = self._rank(z)
        if self._best is None or rank < self._best[0]:
            self._best = (rank, z)

    def _iterate(self, x, *_state) -> None:
        """SciPy's callback after each iteration: ``(x)`` from SLSQP, ``(x, state)`` from
        trust-constr (SciPy 1.16's SLSQP knows no ``intermediate_result`` form)."""
        self._track(x)

    def _tightened(self, z: np.ndarray) -> np.ndarray:
        """``z`` with its epigraph variables at their tightest values at its design (the
        maxima and minima they bound), within their bounds: a restart's start."""
        nlp = self.nlp
        n = nlp.n_design
        if nlp.aux_init is None or len(z) == n:
            return z
        aux = np.asarray(nlp.aux_init(z[:n], self._theta), dtype=float).ravel()
        aux = np.where(np.isfinite(aux), aux, z[n:])
        return np.clip(np.concatenate([z[:n], aux]), self._lbz, self._ubz)

    def _minimize(self, z0: np.ndarray, kwargs: dict[str, Any]) -> tuple[Any, int, str]:
        """SciPy's run from ``z0``, restarted after the exits of :attr:`RESTART_EXITS`
        (SLSQP) from the best feasible point, or from the run's last point while none is
        feasible (a start is never repeated: a run is deterministic); (its result,
        iterations of all runs, a note on the restarts for the message)."""
        self._track(z0)
        res = so.minimize(self._f, z0, **kwargs)
        iters = int(res.get("nit", 0))
        if self.method != "SLSQP":
            return res, iters, ""
        maxiter = int(kwargs["options"].get("maxiter", 100))
        first, starts = str(res.message), [z0]
        while (
            res.status in self.RESTART_EXITS
            and len(starts) <= self.RESTARTS
            and iters < maxiter
            and self._best is not None
        ):
            feasible = self._best[0][0] == 0
            z = self._best[1] if feasible else np.asarray(res.x, dtype=float)
            z = self._tightened(z)
            if any(np.array_equal(z, s) for s in starts):
                break  # nowhere new to start from
            starts.append(z)
            options = {**kwargs["options"], "maxiter": maxiter - iters}
            res = so.minimize(self._f, z, **{**kwargs, "options": options})
            iters += int(res.get("nit", 0))
        note = ""
        if len(starts) > 1:
            times = "once" if len(starts) == 2 else f"{len(starts) - 1} times"
            note = f" (restarted {times} after: {first})"
        return res, iters, note

    @staticmethod
    def _split_rows(lb: np.ndarray, ub: np.ndarray) -> tuple[np.ndarray, ...]:
        """Rows of SLSQP's ``h(z) = 0`` and ``g(z) >= 0``: one per finite bound."""
        both = np.isfinite(lb) & np.isfinite(ub) & (lb == ub)
        eq = np.flatnonzero(both)
        lo = np.flatnonzero(np.isfinite(lb) & ~both)
        hi = np.flatnonzero(np.isfinite(ub) & ~both)
        return eq, lo, hi

    def _constraints(self, lb: np.ndarray, ub: np.ndarray, rows: tuple[np.ndarray, ...]) -> Any:
        exact = self.derivatives == "exact"
        if self.method == "trust-constr":
            if exact:
                return [so.NonlinearConstraint(self._g, lb, ub, jac=self._jac, hess=self._hess_g)]
            return [so.NonlinearConstraint(self._g, lb, ub, jac="2-point", hess=so.BFGS())]
        eq, lo, hi = rows

        def ineq(z):
            g = self._g(z)
            return np.concatenate([g[lo] - lb[lo], ub[hi] - g[hi]])

        def ineq_jac(z):
            J = self._jac(z)
            return np.vstack([J[lo], -J[hi]])

        cons = [{"type": "ineq", "fun": ineq, **({"jac": ineq_jac} if exact else {})}]
        if len(eq):
            # SciPy puts the equality rows first (in its multipliers too), whatever the order.
            cons.append(
                {
                    "type": "eq",
                    "fun": lambda z: self._g(z)[eq] - lb[eq],
                    **({"jac": lambda z: self._jac(z)[eq]} if exact else {}),
                }
            )
        return cons

    @one_blas_thread()
    def solve(
        self, start: Start | Any, target: Target | str | None = None, bounds: Bounds | None = None
    ) -> Result:
        """Solve from ``start`` for ``target`` within ``bounds`` (multipliers of the start
        are ignored: SciPy takes no dual warm start).

        Returns
        -------
        Result
            Status from SciPy's (``optimal``, ``max_iterations``, ``infeasible``,
            ``failed``, or ``time_limit``), ``infeasible`` if an ``optimal`` point
            violates a row.
        """
        nlp = self.nlp
        start, target, bounds = resolve(nlp, start, target, bounds)
        self._p = nlp.params(target, bounds.parameters)
        self._cache = {}
        lbz, ubz = np.asarray(bounds.lbz, dtype=float), np.asarray(bounds.ubz, dtype=float)
        lb, ub = np.asarray(bounds.lbg, dtype=float), np.asarray(bounds.ubg, dtype=float)
        rows = self._split_rows(lb, ub)
        # Aux variables may have infinite bounds: SciPy takes +-inf in Bounds.
        z0 = np.clip(start.z0, lbz, ubz)
        self.n_evals = {}
        self._lbz, self._ubz, self._lbg, self._ubg = lbz, ubz, lb, ub
        self._theta = nlp.parameter_values(bounds.parameters)
        self._best: tuple[tuple[int, float], np.ndarray] | None = None
        self._t0 = time.perf_counter()
        exact = self.derivatives == "exact"
        kwargs: dict[str, Any] = {
            "method": self.method,
            "bounds": so.Bounds(lbz, ubz),
            "constraints": self._constraints(lb, ub, rows),
            "options": dict(self.options),
            "callback": self._iterate,
        }
        if self.method == "trust-constr":
            kwargs["jac"] = self._grad if exact else "2-point"
            kwargs["hess"] = self._hess_f if exact else so.BFGS()
        else:
            kwargs["jac"] = self._grad if exact else None
        lam_g = np.zeros(len(lb))
        try:
            with solver_call():
                res, iters, note = self._minimize(z0, kwargs)
            z, message = np.asarray(res.x, dtype=float), str(res.message) + note
            status, term = self._status(res)
            if status != "optimal" and self._best is not None and self._best[0] < self._rank(z):
                z = self._best[1]  # not converged: the best point it passed
            elif self.method == "SLSQP":
                lam_g = self._lam_g(res, len(lb), rows)
        except _TimeUp:
            # the best point so far, not the last one evaluated (a line search's trial)
            z = self._best[1] if self._best is not None else z0
            iters, message = None, f"wall-time limit {self.time_limit:g} s reached"
            status, term = "time_limit", TerminationCondition.MAX_TIME
        except (ValueError, np.linalg.LinAlgError, RuntimeError) as exc:
            wall = time.perf_counter() - self._t0
            return failed_result(
                self.name, nlp, target, f"{type(exc).__name__}: {exc}", wall, self.n_evals
            )
        wall = time.perf_counter() - self._t0
        return make_result(
            self.name,
            nlp,
            target,
            bounds,
            z,
            np.zeros(len(z)),
            lam_g,
            status,
            term,
            message,
            iters,
            dict(self.n_evals),
            wall,
        )

    @staticmethod
    def _lam_g(res, m: int, rows: tuple[np.ndarray, ...]) -> np.ndarray:
        """SLSQP's multipliers as CasADi's ``lam_g`` (zero if SciPy returned none)."""
        eq, lo, hi = rows
        lam_g = np.zeros(m)
        mult = np.asarray(res.get("multipliers", np.zeros(0)), dtype=float).ravel()
        if len(mult) == len(eq) + len(lo) + len(hi):
            # SciPy: equalities first, then the inequalities (lower rows, then upper rows,
            # as built in _constraints); its multipliers are >= 0 for g(z) >= 0, CasADi's
            # are the gradient signs of the bound that is active.
            lam_g[eq] = -mult[: len(eq)]
            lam_g[lo] -= mult[len(eq) : len(eq) + len(lo)]
            lam_g[hi] += mult[len(eq) + len(lo) :]
        return lam_g

    def _status(self, res) -> tuple[str, TerminationCondition]:
        if self.method == "SLSQP":
            if res.status == 0:
                return "optimal", TerminationCondition.CONVERGED
            if res.status == 9:
                return "max_iterations", TerminationCondition.MAX_ITERATIONS
            if res.status == 4:  # inequality constraints incompatible
                return "infeasible", TerminationCondition.INFEASIBLE
            return "failed", TerminationCondition.NUMERICAL_ERROR
        # trust-constr: 1 gtol (KKT met), 2 xtol (steps too small: accepted as converged
        # when feasible, the gap metric tells the rest), 0 maxiter.
        if res.status == 1:
            return "optimal", TerminationCondition.CONVERGED
        if res.status == 2:
            return "optimal", TerminationCondition.ACCEPTABLE
        if res.status == 0:
            return "max_iterations", TerminationCondition.MAX_ITERATIONS
        return "failed", TerminationCondition.NUMERICAL_ERROR


def differential_evolution(
    evaluate: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
    lower: np.ndarray,
    upper: np.ndarray,
    names: Sequence[str],
    catalogues: Mapping[int, Sequence[float]] | None = None,
    seed: int = 0,
    popsize: int = 15,
    maxiter: int = 300,
    tol: float = 1e-8,
    time_limit: float = math.inf,
) -> Result:
    """Global reference: SciPy differential evolution on a vectorised objective.

    Parameters
    ----------
    evaluate
        ``X (pop, n) -> (objective (pop,), violation (pop,))``, violation 0 when
        feasible (e.g. from :meth:`DesignProblem.evaluate`).
    lower, upper, names
        Box and names of the free variables.
    catalogues
        Column -> catalogue values; those columns are searched as integer indices.
    seed, popsize, maxiter, tol
        SciPy options (``polish`` is off: the result is DE's own).
    time_limit
        Wall-time limit (s), checked between generations.

    Returns
    -------
    Result
        ``optimal`` when the population converged to a feasible point (no optimality
        proof: a reference), ``feasible`` when stopped by the time or generation limit at
        a feasible point (``termination`` says which), ``infeasible`` otherwise.
    """
    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    catalogues = {k: np.asarray(v, dtype=float) for k, v in (catalogues or {}).items()}
    lo, hi = lower.copy(), upper.copy()
    integrality = np.zeros(len(lower), dtype=bool)
    for k, vals in catalogues.items():
        lo[k], hi[k], integrality[k] = 0.0, len(vals) - 1.0, True

    def to_design(U: np.ndarray) -> np.ndarray:
        X = np.array(U, dtype=float, copy=True)
        for k, vals in catalogues.items():
            X[:, k] = vals[np.clip(np.rint(X[:, k]).astype(int), 0, len(vals) - 1)]
        return X

    counts = {"f": 0, "populations": 0}
    cache: dict[str, Any] = {}

    def _eval(U: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # SciPy asks for the objective and then the constraint of the same population:
        # evaluate once.
        if U.shape[0] == 0:  # SciPy asks for the energies of no feasible member
            return np.zeros(0), np.zeros(0)
        key = U.tobytes()
        if cache.get("key") != key:
            f, v = evaluate(to_design(U))
            counts["f"] += U.shape[0]
            counts["populations"] += 1
            cache.update(
                key=key,
                f=np.where(np.isfinite(f), f, 1e300),
                v=np.nan_to_num(v, nan=1e300, posinf=1e300),
            )
        return cache["f"], cache["v"]

    def func(UT: np.ndarray) -> np.ndarray:
        U = np.atleast_2d(UT.T) if UT.ndim == 2 else UT[None, :]
        return _eval(U)[0]

    def cons(UT: np.ndarray) -> np.ndarray:
        U = np.atleast_2d(UT.T) if UT.ndim == 2 else UT[None, :]
        return _eval(U)[1][None, :]

    t0 = time.perf_counter()
    timed_out = {"flag": False}

    def callback(*_args, **_kw) -> bool:
        if time.perf_counter() - t0 > time_limit:
            timed_out["flag"] = True
            return True
        return False

    with solver_call():
        res = so.differential_evolution(
            func,
            so.Bounds(lo, hi),
            constraints=so.NonlinearConstraint(cons, -np.inf, 0.0),
            integrality=integrality if catalogues else None,
            seed=seed,
            popsize=popsize,
            maxiter=maxiter,
            tol=tol,
            polish=False,
            vectorized=True,
            updating="deferred",
            callback=callback,
        )
    wall = time.perf_counter() - t0
    X = to_design(np.asarray(res.x, dtype=float)[None, :])
    f, v = evaluate(X)
    feasible = bool(np.isfinite(f[0]) and v[0] <= 0.0)
    # DE proves nothing either way: "optimal" means its population converged; stopped by
    # the time or generation limit, its best feasible member is still a design
    # ("feasible"; the benchmark's gap says how good), an infeasible one is not.
    if timed_out["flag"]:
        status, term = "feasible", TerminationCondition.MAX_TIME
    elif res.success:
        status, term = "optimal", TerminationCondition.CONVERGED
    else:
        status, term = "feasible", TerminationCondition.MAX_ITERATIONS
    if not feasible:
        status, term = "infeasible", TerminationCondition.INFEASIBLE
    return Result(
        status=status,
        objective=float(f[0]),
        design=dict(zip(names, X[0].tolist(), strict=True)),
        solver="scipy-de",
        formulation="numpy",
        wall_time_s=wall,
        termination=term,
        solution_status=SolutionStatus.FEASIBLE if feasible else SolutionStatus.INFEASIBLE,
        message=str(res.message),
        iterations=int(res.nit),
        n_evals=dict(counts),
        max_violation=float(v[0]),
    )
