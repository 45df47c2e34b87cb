"""The epsilon-constraint solver of a front: ``min target s.t. others <= eps``.

Every solve of a front - the anchors' multistarts, the tie-breaks, the sweep points, a
weighted sum - is one formulation (:func:`optdesign.studies.nlp_solve.formulation_for` of the
front's objectives) with the target and the epsilon limits passed per solve, so each
back-end is built once per process and any point's solution and multipliers can start
any other solve.

The primary back-end is SLSQP with exact CasADi first derivatives (~0.03 s to build,
3-6x faster per solve than Ipopt on these NLPs); a start it does not solve (failure, or
an iterate that violates a row) is solved again by Ipopt (exact Hessian) from the same
start. The lexicographic tie-breaks use Ipopt with :data:`TIE_OPTIONS`. ``method="ipopt"``
uses Ipopt throughout, warm-started primal and dual with :data:`WARM_OPTIONS`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from optdesign.errors import ProblemError
from optdesign.formulations.nlp import NLP, Start
from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.casadi_nlp import IPOPT_WARM
from optdesign.solvers.result import Result
from optdesign.studies.nlp_solve import formulation_for, solver_for
from optdesign.studies.pareto.records import PointRecord

#: Ipopt options of warm-started sweep points: take the neighbour's multipliers and start
#: close to the central path instead of pushing the point back into the interior.
WARM_OPTIONS: dict[str, Any] = IPOPT_WARM

#: Ipopt options of the lexicographic tie-breaks. Their start is an optimum of the
#: objective fixed before, so it is feasible (to the slack) and close to the tie-break's
#: optimum: a small initial barrier parameter and bound push keep Ipopt there instead of
#: pushing it back into the interior (cs_min_backlash, backlash anchor: 25-48 iterations
#: instead of 62-101, and no failure from any of 6 multistart optima).
TIE_OPTIONS: dict[str, Any] = {"mu_init": 1e-5, "bound_push": 1e-6, "bound_frac": 1e-6}

#: SLSQP options of the sweeps: a start still running at 200 iterations goes to Ipopt.
SLSQP_OPTIONS: dict[str, Any] = {"maxiter": 200}

METHODS = ("slsqp", "ipopt")


class EpsSolver:
    """All solves of one front (see the module docstring).

    Parameters
    ----------
    problem
        The design problem.
    objectives
        The front's objectives: the formulation's objective set.
    method
        ``"slsqp"`` (SLSQP, Ipopt fallback) or ``"ipopt"``.
    """

    def __init__(self, problem: DesignProblem, objectives: Sequence[str], method: str = "slsqp"):
        if method not in METHODS:
            raise ProblemError(f"solver {method!r}: use one of {', '.join(METHODS)}")
        self.problem = problem
        self.objectives = tuple(sorted(objectives))
        self.method = method
        self.nlp: NLP = formulation_for(problem, self.objectives)

    @property
    def fingerprint(self) -> str:
        return self.nlp.fingerprint

    def backend(self, use: str = "primary"):
        """The back-end for ``use``: ``"primary"``, ``"ipopt"``, ``"tie"`` or ``"warm"``."""
        p = self.problem
        if use == "primary" and self.method == "slsqp":
            return solver_for(p, "slsqp", SLSQP_OPTIONS, self.objectives)
        if use == "tie":
            return solver_for(p, "ipopt", TIE_OPTIONS, self.objectives)
        if use == "warm" or (use == "primary" and self.method == "ipopt"):
            return solver_for(p, "ipopt", WARM_OPTIONS, self.objectives)
        return solver_for(p, "ipopt", None, self.objectives)

    def start_from(self, neighbour: PointRecord | None, x=None) -> Start:
        """A start from a neighbour's record: primal and dual when it solved this same
        formulation, else its design, else ``x`` (default: the problem's start)."""
        nlp = self.nlp
        if (
            neighbour is not None
            and neighbour.raw is not None
            and neighbour.raw.nlp == self.fingerprint
        ):
            raw = neighbour.raw
            return nlp.start(z0=raw.z, lam_x0=raw.lam_x, lam_g0=raw.lam_g)
        if neighbour is not None and neighbour.x is not None:
            return nlp.start(x0=np.asarray(neighbour.x, dtype=float))
        return nlp.start(x0=np.asarray(x if x is not None else self.problem.start(), dtype=float))

    def solve(
        self,
        target: str,
        eps: Mapping[str, float],
        start: Start,
        fallback: bool = True,
        use: str | None = None,
    ) -> Result:
        """``min target s.t. eps`` from ``start``.

        With SLSQP as primary back-end and ``fallback``, a start SLSQP does not solve is
        solved again by Ipopt from the same primal start; ``result.details.fallback``
        then holds SLSQP's message. ``use="ipopt"`` or ``"tie"`` picks Ipopt directly.
        """
        bounds = self.nlp.bounds(eps={k: v for k, v in eps.items() if np.isfinite(v)})
        warm = use is None and self.method == "ipopt"
        backend = self.backend(use or ("warm" if warm else "primary"))
        if self.method == "slsqp" or use is not None:
            # SLSQP takes no dual start, and a tie-break's duals belong to another target.
            start = Start(start.z0)
        result = backend.solve(start, target, bounds)
        if fallback and use is None and self.method == "slsqp" and not result.success:
            first = result
            result = self.backend("ipopt").solve(Start(start.z0), target, bounds)
            result.details.fallback = f"{first.status}: {first.message}"
            result.wall_time_s += first.wall_time_s
        return result

    def slope(self, target: str, eps_name: str, record: PointRecord) -> float | None:
        """d(target)/d(eps_name) at a point, from the multiplier of the epsilon row."""
        if record.raw is None or record.raw.nlp != self.fingerprint:
            return None
        nlp = self.nlp
        row = nlp.eps_rows[eps_name]
        lam = float(record.raw.lam_g[row])
        scale = nlp.target_scales[nlp.targets.index(target)]
        return -abs(lam) * scale / nlp.g_scale[row]
