"""CasADi ``nlpsol`` back-end (Ipopt by default; sqpmethod and others by plugin name).

The solver is built once per NLP and reused across starts (warm start with primal and
dual values). It returns a :class:`Result` with the status mapped from the plugin's
return status, the violated constraints by name and amount, and the active ones.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import casadi as ca
import numpy as np

from optdesign.formulations.nlp import NLP
from optdesign.solvers.result import ConstraintReport, Result, SolutionStatus, TerminationCondition

#: Ipopt defaults: quiet, tight tolerances (the tests compare optima to 1e-4 relative and
#: constraints to 1e-6). Converging starts need well under 100 iterations; a start still
#: running at 500 is stuck near a toggle position, and multistart has better ones.
IPOPT_DEFAULTS: dict[str, Any] = {
    "print_level": 0,
    "sb": "yes",
    "tol": 1e-10,
    "constr_viol_tol": 1e-9,
    "acceptable_tol": 1e-7,
    "max_iter": 500,
    "mu_strategy": "adaptive",
}

_IPOPT_STATUS = {
    "Solve_Succeeded": (TerminationCondition.CONVERGED, "optimal"),
    "Solved_To_Acceptable_Level": (TerminationCondition.ACCEPTABLE, "optimal"),
    "Feasible_Point_Found": (TerminationCondition.CONVERGED, "feasible"),
    "Infeasible_Problem_Detected": (TerminationCondition.INFEASIBLE, "infeasible"),
    "Maximum_Iterations_Exceeded": (TerminationCondition.MAX_ITERATIONS, "max_iterations"),
    "Maximum_CpuTime_Exceeded": (TerminationCondition.MAX_TIME, "time_limit"),
    "Maximum_WallTime_Exceeded": (TerminationCondition.MAX_TIME, "time_limit"),
    "Diverging_Iterates": (TerminationCondition.UNBOUNDED, "failed"),
    "User_Requested_Stop": (TerminationCondition.INTERRUPTED, "failed"),
    "Restoration_Failed": (TerminationCondition.NUMERICAL_ERROR, "failed"),
    "Error_In_Step_Computation": (TerminationCondition.NUMERICAL_ERROR, "failed"),
    "Invalid_Number_Detected": (TerminationCondition.NUMERICAL_ERROR, "failed"),
    "Search_Direction_Becomes_Too_Small": (TerminationCondition.NUMERICAL_ERROR, "failed"),
}

#: Feasibility tolerance (scaled rows) for reports.
FEAS_TOL = 1e-6


class CasadiNLPSolver:
    """A reusable CasADi NLP solver for one :class:`NLP`.

    Parameters
    ----------
    nlp
        The formulation.
    plugin
        ``"ipopt"`` (default), ``"sqpmethod"``, ...
    options
        Plugin options (Ipopt options go in flat, e.g. ``{"hessian_approximation":
        "limited-memory"}``; others as CasADi expects them).
    """

    def __init__(self, nlp: NLP, plugin: str = "ipopt", options: Mapping[str, Any] | None = None):
        self.nlp = nlp
        self.plugin = plugin
        opts: dict[str, Any] = {"print_time": False}
        if plugin == "ipopt":
            ipopt = dict(IPOPT_DEFAULTS)
            ipopt.update(options or {})
            opts["ipopt"] = ipopt
        else:
            opts.update(options or {})
        self.options = opts
        self.solver = ca.nlpsol("optdesign", plugin, {"x": nlp.z, "f": nlp.f, "g": nlp.g}, opts)
        self.g_fun = ca.Function("g", [nlp.z], [nlp.g])
        self.values_fun = ca.Function(
            "values", [nlp.z], [ca.vertcat(*nlp.objective_values.values())]
        )

    @property
    def name(self) -> str:
        return self.plugin

    def solve(
        self,
        x0: np.ndarray | None = None,
        z0: np.ndarray | None = None,
        lam_x0: np.ndarray | None = None,
        lam_g0: np.ndarray | None = None,
    ) -> Result:
        """Solve from design ``x0`` (or scaled ``z0``); duals warm-start if given."""
        nlp = self.nlp
        z0 = nlp.start(x0, z0)
        args: dict[str, Any] = {
            "x0": z0,
            "lbx": nlp.lbz,
            "ubx": nlp.ubz,
            "lbg": nlp.lbg,
            "ubg": nlp.ubg,
        }
        if lam_x0 is not None:
            args["lam_x0"] = lam_x0
        if lam_g0 is not None:
            args["lam_g0"] = lam_g0
        t0 = time.perf_counter()
        try:
            sol = self.solver(**args)
            error = ""
        except RuntimeError as exc:  # CasADi raises on evaluation errors it cannot recover
            sol, error = None, str(exc).splitlines()[0]
        wall = time.perf_counter() - t0
        stats = self.solver.stats()
        if sol is None:
            return Result(
                "failed",
                float("nan"),
                {},
                self.plugin,
                f"nlp-{nlp.form}",
                wall,
                TerminationCondition.ERROR,
                SolutionStatus.NO_SOLUTION,
                message=error,
            )
        z = np.asarray(sol["x"], dtype=float).ravel()
        return self.result_from(z, sol, stats, wall)

    def result_from(self, z, sol, stats, wall) -> Result:
        nlp = self.nlp
        return_status = str(stats.get("return_status", ""))
        term, status = _IPOPT_STATUS.get(
            return_status,
            (
                TerminationCondition.CONVERGED
                if stats.get("success")
                else TerminationCondition.UNKNOWN,
                "optimal" if stats.get("success") else "failed",
            ),
        )
        g = np.asarray(self.g_fun(z), dtype=float).ravel()
        lam_g = np.asarray(sol["lam_g"], dtype=float).ravel()
        violated, active = self.reports(g, lam_g)
        max_viol = max(
            (
                r.amount / max(1.0, abs(r.upper if r.upper is not None else r.lower))
                for r in violated
            ),
            default=0.0,
        )
        if status in ("optimal", "feasible") and violated:
            status, term = "infeasible", TerminationCondition.INFEASIBLE
        if status in ("max_iterations", "time_limit", "failed") and not violated:
            sol_status = SolutionStatus.FEASIBLE
        elif status == "optimal":
            sol_status = SolutionStatus.OPTIMAL
        elif status == "feasible":
            sol_status = SolutionStatus.FEASIBLE
        else:
            sol_status = SolutionStatus.INFEASIBLE if violated else SolutionStatus.NO_SOLUTION
        values = np.asarray(self.values_fun(z), dtype=float).ravel()
        objectives = dict(zip(nlp.objective_values, values.tolist(), strict=True))
        x = nlp.x_from_z(z)
        iters = stats.get("iter_count")
        n_evals = {
            k.removeprefix("n_call_"): int(v)
            for k, v in stats.items()
            if k.startswith("n_call_") and isinstance(v, int | float)
        }
        return Result(
            status=status,
            objective=float(np.asarray(sol["f"]).ravel()[0] * nlp.f_scale),
            design=dict(zip(nlp.design_names, x.tolist(), strict=True)),
            solver=self.plugin,
            formulation=f"nlp-{nlp.form}",
            wall_time_s=wall,
            termination=term,
            solution_status=sol_status,
            message=return_status,
            objectives=objectives,
            iterations=int(iters) if iters is not None else None,
            n_evals=n_evals,
            violated=violated,
            active=active,
            max_violation=float(max_viol),
            raw={
                "z": z,
                "lam_x": np.asarray(sol["lam_x"], dtype=float).ravel(),
                "lam_g": lam_g,
            },
        )

    def reports(self, g: np.ndarray, lam_g: np.ndarray):
        """Violated and active constraint rows, in the constraints' own units."""
        nlp = self.nlp
        g = np.asarray(g, dtype=float).ravel()
        lo_all = np.asarray(nlp.lbg, dtype=float)
        hi_all = np.asarray(nlp.ubg, dtype=float)
        # Vectorised screening (a Python loop over the ~550 rows cost ~5 ms a solve);
        # reports are built only for the violated and active rows, in row order.
        flo, fhi, fg = np.isfinite(lo_all), np.isfinite(hi_all), np.isfinite(g)
        with np.errstate(invalid="ignore"):
            amounts = np.maximum(np.where(flo, lo_all - g, 0.0), np.where(fhi, g - hi_all, 0.0))
            is_viol = ~fg | (amounts > FEAS_TOL)
            is_act = ~is_viol & ((flo & (g - lo_all < FEAS_TOL)) | (fhi & (hi_all - g < FEAS_TOL)))
        violated, active = [], []
        for k in np.flatnonzero(is_viol | is_act):
            name = nlp.g_names[k]
            s = nlp.g_scale[k]
            lo, hi = lo_all[k], hi_all[k]
            raw = g[k] * s
            lo_raw = None if not np.isfinite(lo) else lo * s
            hi_raw = None if not np.isfinite(hi) else hi * s
            amount = amounts[k]
            violation = float(max(amount, 0.0) * s) if amount > FEAS_TOL else 0.0
            rep = ConstraintReport(name, float(raw), lo_raw, hi_raw, violation, nlp.g_units[k])
            if is_viol[k]:
                if not fg[k]:
                    rep.amount = float("inf")
                violated.append(rep)
            else:
                active.append(rep)
        return violated, active
