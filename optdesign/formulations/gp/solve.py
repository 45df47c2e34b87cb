"""Solve a design problem as a geometric program, certify it, and compare with the NLP.

The GP uses first-order Hertz flattening (b^2/D); the exact model is the NLP's. The
result carries both: the GP optimum with its dual certificate, the exact NLP optimum of
the same problem (warm-started from the GP design), and the relative gap between them.
"""

from __future__ import annotations

import time

import numpy as np

from optdesign.errors import ProblemError
from optdesign.formulations.gp.details import ExactNLP, GPDetails, GPRows
from optdesign.formulations.nlp.solution import has_multipliers
from optdesign.formulations.nlp.solve import finish, solve_nlp
from optdesign.formulations.reference import attach_reference, reference_design
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.request import SolveRequest
from optdesign.programs.gp import GPData, build_gp
from optdesign.solvers.details import GPTiming
from optdesign.solvers.registry import default_solver, make_solver, solver_for_kind
from optdesign.solvers.result import Globality, Result


def require_gp(problem: DesignProblem, objective: str | None = None) -> GPData:
    """The GP of ``problem``; raise ProblemError naming what breaks DGP form otherwise."""
    gp = build_gp(problem, objective)
    if not gp.is_gp:
        raise ProblemError(f"formulation='gp': {not_gp(problem, gp)}")
    return gp


def not_gp(problem: DesignProblem, gp: GPData) -> str:
    """Why ``problem`` is not a geometric program: what breaks DGP form in ``gp``."""
    return f"problem {problem.name!r} is not a geometric program: " + "; ".join(
        gp.explain().splitlines()
    )


def solve_gp_problem(
    problem: DesignProblem,
    objective: str | None = None,
    compare_nlp: bool = True,
    nlp_starts: int | None = None,
    seed: int | None = None,
    solver: str | None = None,
) -> Result:
    """GP solve of ``problem`` with certificate, exact check and exact-NLP comparison.

    Parameters
    ----------
    objective
        Objective to minimise (default: the problem's first).
    compare_nlp
        Also solve the exact NLP (exact Hertz), warm-started from the GP design, and
        report its optimum and the gap (``details.gp.nlp_exact``, ``details.gp.gap_gp_nlp_rel``).
    nlp_starts, seed
        Starts of that NLP (default: the GP design alone - a local refinement of the GP's
        certified optimum, whose gap to it is reported; a global search there would look
        again for what the certificate already covers, up to the model difference).
    solver
        Registered GP back-end (:func:`optdesign.solver_names` ``("gp")``; None: the
        registry's default for a GP).
    """
    objective = objective or problem.objective_names[0]
    t0 = time.perf_counter()
    gp = require_gp(problem, objective)
    t_trace = time.perf_counter() - t0
    backend = make_solver(gp, solver.lower() if solver else default_solver("gp"))
    if gp.infeasible:
        result = Result(
            status="infeasible",
            objective=float("nan"),
            design={},
            solver=backend.name,
            formulation="gp",
            wall_time_s=t_trace,
            message="rows that no positive design can meet: " + "; ".join(gp.infeasible[:5]),
        )
        return finish(problem, result, objective)
    result = backend.solve()
    details = result.details["gp"] = GPDetails.of(result.details.get("gp"))
    details.timing = details.timing or GPTiming()
    details.timing.trace_s = t_trace
    details.rows = GPRows(len(gp.objective_rows), len(gp.rows), gp.n_rows_before_pruning)
    result.notes.append(
        "GP model: first-order Hertz flattening b^2/D and ISO 286 formulas (posynomials); "
        "the independent check and 'objectives at this design' use the exact model"
    )
    gp_objective = result.objective
    result = finish(problem, result, objective)
    cert = result.certificate
    if cert is not None:
        result.globality = Globality(
            proved=True,
            basis=f"for the GP model, which is convex: dual bound {cert.lower_bound:.8g}, "
            f"relative gap {cert.gap_rel:.1e}; the exact model (exact Hertz) is checked at "
            "this design, not optimised",
        )
        result.notes.append(
            f"GP certificate: dual bound {cert.lower_bound:.8g} <= optimum <= "
            f"{cert.objective:.8g} (relative gap {cert.gap_rel:.2e})"
        )
    if compare_nlp and result.design:
        x0 = np.array([result.design[v.name] for v in problem.free])
        nlp = solve_nlp(problem, objective=objective, starts=nlp_starts or 1, seed=seed, x0=x0)
        gap = (gp_objective - nlp.objective) / abs(nlp.objective) if nlp.success else float("nan")
        details.nlp_exact = ExactNLP(
            status=nlp.status,
            objective=nlp.objective,
            design={v.name: nlp.design.get(v.name) for v in problem.free},
            wall_time_s=nlp.wall_time_s,
            starts=nlp.multistart.n_starts if nlp.multistart else 1,
        )
        details.gap_gp_nlp_rel = gap
        if nlp.success and has_multipliers(nlp):
            from optdesign.formulations.nlp.sensitivities import nlp_sensitivities

            result.sensitivities = nlp_sensitivities(problem, nlp)
            if result.sensitivities:
                result.notes.append(
                    "sensitivities: of the exact NLP's optimum, from Ipopt's multipliers"
                )
        exact_at_gp = result.objectives.get(objective, float("nan"))
        result.notes.append(
            f"exact NLP (exact Hertz) optimum {nlp.objective:.8g} ({nlp.status}, "
            f"{nlp.wall_time_s:.3f} s); GP optimum {gp_objective:.8g}: gap {100 * gap:+.4f} %; "
            f"exact model at the GP design {exact_at_gp:.8g}"
        )
    return result


def gp_applies(problem: DesignProblem, request: SolveRequest) -> bool | str:
    """The ``gp`` formulation's predicate: the problem is a geometric program in the
    request's objective (else what breaks DGP form)."""
    gp = build_gp(problem, request.objective)
    return gp.is_gp or not_gp(problem, gp)


def solve_gp_formulation(problem: DesignProblem, request: SolveRequest) -> Result:
    """``formulation="gp"``: GP with certificate and the exact NLP beside it."""
    reference_design(problem)  # validate [reference] before solving
    named = request.solver
    solver = solver_for_kind(named, "gp")
    result = solve_gp_problem(
        problem,
        objective=request.objective,
        nlp_starts=request.starts,
        seed=request.seed,
        solver=solver,
    )
    if named and named != solver:
        result.notes.append(f"solver {named} solves NLPs: the GP was solved by {solver}")
    return attach_reference(problem, result)
