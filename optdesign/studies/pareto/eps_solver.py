"""The epsilon-constraint solver of a front: ``min target s.t. others <= eps``.

Every solve of a front - the anchors' multistarts, the tie-breaks, the sweep points, a
weighted sum - is one formulation (:func:`optdesign.formulations.nlp.solve.formulation_for` of the
front's objectives) with the target and the epsilon limits passed per solve, so each
back-end is built once per process and any point's solution and multipliers can start
any other solve.

The back-ends of each role are the solver registry's
(:data:`~optdesign.solvers.registry.FRONT_SOLVERS`), with the options each back-end
declares (:class:`~optdesign.solvers.registry.SolverHints`). The primary back-end is
CasADi's sqpmethod with its sweep options (a limited-memory Hessian and qpOASES: several
times faster per solve than Ipopt on these NLPs, about twice SLSQP's speed, with no SciPy
import; benchmarks/README.md, "A front's primary: sqpmethod, each solve on a memory of
its own"); a start it does not solve (failure, or an iterate that violates a row) is
solved again by the fallback, Ipopt (exact Hessian), from the same start. ``method`` =
``"slsqp"`` sweeps with SciPy's SLSQP instead. The lexicographic tie-breaks use the tie
back-end (Ipopt) with its restart options. ``method`` = the fallback (``"ipopt"``) uses
it throughout, warm-started primal and dual with its warm-start options.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from optdesign.errors import ProblemError
from optdesign.formulations.nlp.solve import formulation_for, solver_for
from optdesign.problem.design_problem import DesignProblem
from optdesign.programs.nlp import NLP, Start
from optdesign.solvers.registry import FRONT_SOLVERS, solver_hints
from optdesign.solvers.result import Result
from optdesign.studies.pareto.records import PointRecord

#: The sweep back-ends a caller may name (``solver=``).
METHODS = FRONT_SOLVERS.choices


class EpsSolver:
    """All solves of one front (see the module docstring).

    Parameters
    ----------
    problem
        The design problem.
    objectives
        The front's objectives: the formulation's objective set.
    method
        The primary back-end (default: the registry's front primary, sqpmethod, with the
        fallback's solves behind it; or SLSQP), or the fallback (Ipopt) throughout.
    """

    def __init__(
        self, problem: DesignProblem, objectives: Sequence[str], method: str | None = None
    ):
        method = method or FRONT_SOLVERS.primary
        if method not in METHODS:
            raise ProblemError(f"solver {method!r}: use one of {', '.join(METHODS)}")
        self.problem = problem
        self.objectives = tuple(sorted(objectives))
        self.method = method
        #: a start the primary does not solve goes to the fallback
        self.has_fallback = method != FRONT_SOLVERS.fallback
        self.nlp: NLP = formulation_for(problem, self.objectives)

    @property
    def fingerprint(self) -> str:
        return self.nlp.fingerprint

    def backend(self, use: str = "primary"):
        """The back-end for ``use``: ``"primary"`` (with its sweep options; the fallback
        as primary is warm-started), ``"fallback"``, ``"tie"`` (with its restart options)
        or ``"warm"`` (the fallback with its warm-start options)."""
        p, roles = self.problem, FRONT_SOLVERS
        if use == "primary" and self.has_fallback:
            return solver_for(
                p, self.method, solver_hints(self.method).sweep_options, self.objectives
            )
        if use == "tie":
            return solver_for(
                p, roles.tie, solver_hints(roles.tie).restart_options, self.objectives
            )
        if use == "warm" or use == "primary":
            warm = solver_hints(roles.fallback).warm_start_options
            return solver_for(p, roles.fallback, warm, self.objectives)
        return solver_for(p, roles.fallback, None, self.objectives)

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

        With a primary back-end other than the fallback and ``fallback``, a start the
        primary does not solve is solved again by the fallback from the same primal
        start; ``result.details.fallback`` then holds the primary's message.
        ``use="fallback"`` or ``"tie"`` picks that back-end directly.
        """
        bounds = self.nlp.bounds(eps={k: v for k, v in eps.items() if np.isfinite(v)})
        warm = use is None and not self.has_fallback
        backend = self.backend(use or ("warm" if warm else "primary"))
        if self.has_fallback or use is not None:
            # The primary takes a primal start only (SLSQP takes no dual one, and
            # sqpmethod's L-BFGS gains nothing from it), and a tie-break's duals belong to
            # another target.
            start = Start(start.z0)
        result = backend.solve(start, target, bounds)
        if fallback and use is None and self.has_fallback and not result.success:
            first = result
            result = self.backend("fallback").solve(Start(start.z0), target, bounds)
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
