"""Solve a design problem: NLP with seeded multistart, checked on the NumPy path.

This is the main job of optdesign (``optdesign solve FILE``). The best start is
re-evaluated independently (:func:`optdesign.studies.verify.verify_design`); a result is
``optimal`` only when the solver converged *and* the check passes.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from optdesign.formulations.nlp import build_nlp
from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.casadi_nlp import CasadiNLPSolver
from optdesign.solvers.multistart import multistart, sobol_starts
from optdesign.solvers.result import Result, SolutionStatus, TerminationCondition
from optdesign.studies.verify import verify_design


def make_nlp_solve(
    problem: DesignProblem,
    plugin: str = "ipopt",
    options: Mapping[str, Any] | None = None,
    objective: str | None = None,
    form: str = "epigraph",
) -> Callable[[np.ndarray], Result]:
    """Build the NLP and its solver once; return x0 -> Result (picklable factory)."""
    nlp = build_nlp(problem, objective=objective, form=form)
    merged = dict(problem.spec.solver.ipopt) if plugin == "ipopt" else {}
    merged.update(options or {})
    return CasadiNLPSolver(nlp, plugin, merged).solve


def solve_nlp(
    problem: DesignProblem,
    starts: int | None = None,
    seed: int | None = None,
    workers: int = 1,
    plugin: str = "ipopt",
    options: Mapping[str, Any] | None = None,
    objective: str | None = None,
    x0: np.ndarray | None = None,
) -> Result:
    """Multistart NLP solve of ``problem``.

    Parameters
    ----------
    starts
        Number of starts (default: the problem file's ``solver.starts``); the first is
        ``x0`` or the declared start, the others scrambled-Sobol points in the bounds.
    seed
        Seed of the Sobol sequence (default: the problem file's ``solver.seed``).
    workers
        Local processes for the starts.
    plugin, options
        CasADi nlpsol plugin and its options.
    objective
        Objective to minimise (default: the problem's first).
    """
    n_starts = starts if starts is not None else problem.spec.solver.starts
    seed = seed if seed is not None else problem.spec.solver.seed
    first = problem.start() if x0 is None else np.asarray(x0, dtype=float)
    pts = [first]
    if n_starts > 1:
        pts += list(sobol_starts(problem.lower(), problem.upper(), n_starts - 1, seed))
    solve = make_nlp_solve(problem, plugin, options, objective)
    result = multistart(
        solve,
        np.array(pts),
        workers=workers,
        factory=make_nlp_solve,
        factory_args=(problem, plugin, options, objective),
        seed=seed,
    )
    return finish(problem, result, objective)


def optimal_ranges(
    problem: DesignProblem, result: Result, rel: float = 1e-6, objective: str | None = None
) -> dict[str, tuple[float, float]]:
    """Range of each free variable over the (near-)optimal set.

    Minimises and maximises each variable subject to the requirements and to the objective
    staying within ``rel`` of the optimum, warm-started at the optimum. A wide range means
    the optimum does not fix that variable (e.g. the lead p in a backlash problem, or the
    size of a ripple-optimal linkage, since ripple is invariant when R, l, n, p scale
    together). Variables whose searches fail keep their optimal value on that side.
    """
    objective = objective or problem.objective_names[0]
    limit = result.objective + rel * max(abs(result.objective), 1e-12)
    x_opt = np.array([result.design[v.name] for v in problem.free])
    ranges = {}
    for var in problem.free:
        ends = []
        for sign in (1.0, -1.0):
            nlp = build_nlp(problem, objective={var.name: sign}, epsilon={objective: limit})
            r = CasadiNLPSolver(nlp, options={"max_iter": 200}).solve(x_opt)
            ok = r.success and r.max_violation <= 1e-6
            ends.append(r.design[var.name] if ok else result.design[var.name])
        lo, hi = min(ends), max(ends)
        ranges[var.name] = (
            float(min(lo, result.design[var.name])),
            float(max(hi, result.design[var.name])),
        )
    return ranges


def finish(problem: DesignProblem, result: Result, objective: str | None = None) -> Result:
    """Check the result on the NumPy path, fill every objective and the full design."""
    objective = objective or problem.objective_names[0]
    result.extra["objective_name"] = objective
    result.extra["problem"] = problem.name
    result.extra["mechanism"] = problem.mechanism_kind
    if not result.design:
        return result
    x = np.array([result.design[v.name] for v in problem.free])
    ok, violated, objectives = verify_design(problem, x)
    result.verified = ok
    result.objectives = {k: float(v) for k, v in objectives.items()}
    result.design = {**problem.fixed_values, **result.design}
    if result.success and not ok:
        # The solver claims success but the independent check disagrees: not a design.
        result.status = "infeasible"
        result.termination = TerminationCondition.INFEASIBLE
        result.solution_status = SolutionStatus.INFEASIBLE
        result.violated = violated
        result.message += " (independent check failed)"
    elif not result.success and not result.violated:
        result.violated = violated
    return result
