"""The NLP path of a solve: the problem's NLP and solver back-ends built once per process
(thread-safe caches), the multistart from Sobol starts, the independent check of the
best point on the NumPy path (:func:`finish`) and the ranges of the optimal set.

Shared by every formulation and study that solves an NLP (the ``nlp`` formulation, whose
predicate and solve are :func:`nlp_applies` and :func:`solve_nlp_formulation`, the
catalogue's nodes, the robust and GP formulations' exact NLP, the diagnosis, the fronts);
the formulation registry (:mod:`optdesign.formulations.registry`) and
:func:`~optdesign.studies.solve.solve` sit above it.
"""

from __future__ import annotations

import json
import threading
from collections import OrderedDict
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from optdesign.errors import ProblemError
from optdesign.formulations.reference import attach_reference
from optdesign.formulations.verify import nan_notes, verify_design
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.objective_refusals import smooth_form_refusal
from optdesign.problem.request import SolveRequest
from optdesign.programs.nlp import NLP, VAR, build_nlp, with_rows
from optdesign.runtime.inherited_map import map_inherited
from optdesign.search.global_phase import default_max_starts, global_search, search_globality
from optdesign.search.starts import TiltedStarts, problem_evaluator
from optdesign.solvers.multistart import sobol_starts
from optdesign.solvers.phase_one import LeastViolation, PhaseOneSolver, supports
from optdesign.solvers.registry import default_solver, make_solver, solver_hints
from optdesign.solvers.result import (
    Result,
    SolutionStatus,
    TerminationCondition,
)
from optdesign.solvers.solved_point import SOLVED_STATUSES
from optdesign.tolerances import FEASIBILITY_TOL, OBJECTIVE_TIE_TOL

# --- formulation and solver caches ------------------------------------------------------
_NLPS: OrderedDict[tuple, NLP] = OrderedDict()
_SOLVERS: OrderedDict[tuple, Any] = OrderedDict()
_PHASE_ONE: OrderedDict[tuple, Any] = OrderedDict()
_CACHE_SIZE = 16

#: CasADi's symbolic layer is not thread-safe and its solvers release the GIL: two threads
#: of a threaded Dask worker building at once crashed the process. Every build holds this
#: lock, and each thread gets its own solvers (a solver object is not re-entrant); the
#: main thread's entries carry no thread id, so forked workers inherit them.
_BUILD_LOCK = threading.RLock()


def _remember(cache: OrderedDict, key: tuple, build: Callable[[], Any]) -> Any:
    owner = (
        "main" if threading.current_thread() is threading.main_thread() else threading.get_ident()
    )
    key = (owner, *key)
    with _BUILD_LOCK:
        if key in cache:
            cache.move_to_end(key)
            return cache[key]
        value = build()
        cache[key] = value
        while len(cache) > _CACHE_SIZE:
            cache.popitem(last=False)
        return value


def formulation_for(
    problem: DesignProblem,
    objectives: tuple[str, ...] | None = None,
    form: str = "epigraph",
    first_order: bool = False,
) -> NLP:
    """The NLP of ``problem`` for an objective set, built once per process and problem
    state (the cache key is the problem's token, which changes with every edit)."""
    objectives = tuple(objectives or problem.objective_names)
    key = (problem.token, objectives, form, first_order)
    return _remember(_NLPS, key, lambda: build_nlp(problem, objectives, form, first_order))


def solver_for(
    problem: DesignProblem,
    name: str | None = None,
    options: Mapping[str, Any] | None = None,
    objectives: tuple[str, ...] | None = None,
    form: str = "epigraph",
):
    """The back-end ``name`` (None: the registry's default for an NLP) of the problem's
    NLP, built once per process and NLP, shared by every start, range and front point.
    Keyed on the NLP's content (its fingerprint), not on the problem object: a problem
    loaded again, or a copy that changes nothing the NLP holds, reuses the back-end
    (building CasADi's ``nlpsol`` costs more than a start: benchmarks/README.md, "Figures behind comments in the code")."""
    name = name or default_solver("nlp")
    nlp = formulation_for(problem, objectives, form)
    opts = dict(solver_options(problem, name))
    opts.update(options or {})
    key = (nlp.fingerprint, name, json.dumps(opts, sort_keys=True, default=str))
    return _remember(_SOLVERS, key, lambda: make_solver(nlp, name, opts))


def rows_solver_for(backend, rows: Sequence[int], options: Mapping[str, Any], solver: str):
    """The back-end ``solver`` (its registry name, as ``backend`` was built by
    :func:`solver_for`) of ``backend``'s NLP with only the constraint rows ``rows``
    (:func:`~optdesign.programs.nlp.with_rows`; a catalogue node on every other grid
    angle), with ``options``: built once per process, NLP, rows and options, as
    :func:`solver_for` builds the whole NLP's (every search of a front, each with its
    own node solver, shares it)."""
    nlp = backend.nlp
    opts = dict(options)
    rows = tuple(int(k) for k in rows)
    key = (
        nlp.fingerprint,
        "rows",
        rows,
        solver,
        json.dumps(opts, sort_keys=True, default=str),
    )
    return _remember(_SOLVERS, key, lambda: make_solver(with_rows(nlp, rows), solver, opts))


def phase_one_for(
    problem: DesignProblem, backend, options: Mapping[str, Any] | None = None
) -> Callable[[], PhaseOneSolver] | None:
    """The phase-1 solver (least violation) of a back-end's NLP, built on first use and
    once per process and NLP, with the Ipopt options of the problem file and ``options``
    (a user's ``max_iter = 0`` stops it as it stops the solve); None for a back-end that
    is not CasADi's Ipopt (:func:`~optdesign.solvers.phase_one.supports`)."""
    if not supports(backend):
        return None
    nlp = backend.nlp
    opts = {**solver_options(problem, backend.name), **(options or {})}
    key = (nlp.fingerprint, json.dumps(opts, sort_keys=True, default=str))
    return lambda: _remember(_PHASE_ONE, key, lambda: PhaseOneSolver(nlp, opts))


def solver_options(problem: DesignProblem, name: str | None = None) -> dict[str, Any]:
    """The problem file's own options of back-end ``name`` (None: the default NLP
    back-end), from the table its registry entry declares (``[solver] ipopt = {...}``),
    checked as the back-end checks them, before any work."""
    hints = solver_hints(name)
    if hints.file_options is None:
        return {}
    options = dict(getattr(problem.spec.solver, hints.file_options) or {})
    hints.check_options(options, f"solver.{hints.file_options}")
    return options


# --- the NLP path -----------------------------------------------------------------------
def start_points(problem: DesignProblem, n_starts: int, seed: int, x0=None) -> np.ndarray:
    """A plain multistart's starts: ``x0`` (or the declared start, else the middle of the
    bounds) first, then scrambled-Sobol points of the whole box (the robust formulation's
    and a catalogue node's starts; the NLP's are the global search's)."""
    first = problem.start() if x0 is None else np.asarray(x0, dtype=float)
    pts = [first]
    if n_starts > 1:
        pts += list(sobol_starts(problem.lower(), problem.upper(), n_starts - 1, seed))
    return np.array(pts)


def own_starts(problem: DesignProblem, x0=None) -> list[np.ndarray]:
    """The starts a search solves before its random draws: ``x0`` when given, else the
    problem's declared start when it declares one (none: every start is a draw)."""
    if x0 is not None:
        return [np.asarray(x0, dtype=float)]
    if any(v.start is not None for v in problem.free):
        return [problem.start()]
    return []


def tilted_starts(problem: DesignProblem, objective: str, seed: int) -> TiltedStarts:
    """The global search's random starts for ``objective`` (judged on the NumPy path)."""
    known = objective in problem.objectives
    evaluate = problem_evaluator(problem, objective if known else None)
    return TiltedStarts(evaluate, problem.lower(), problem.upper(), seed)


def planned_starts(problem: DesignProblem, starts: int | None = None) -> int:
    """The most starts of a search: ``starts``, else the problem file's ``[solver]
    starts``, else chosen from the number of free variables."""
    if starts is not None:
        return int(starts)
    if problem.spec.solver.starts is not None:
        return int(problem.spec.solver.starts)
    return default_max_starts(len(problem.free))


def solve_nlp(
    problem: DesignProblem,
    objective: str | None = None,
    starts: int | None = None,
    seed: int | None = None,
    workers: int = 1,
    solver: str | None = None,
    options: Mapping[str, Any] | None = None,
    x0: np.ndarray | None = None,
    agree: int | None = None,
    time_limit: float | None = None,
    target_odds: float | None = None,
) -> Result:
    """The global search for the NLP optimum of ``problem`` (:mod:`optdesign.search`).

    Parameters
    ----------
    objective
        Objective to minimise (default: the problem's first).
    starts, seed
        The most starts and the seed of their draws (default: the problem file's
        ``[solver]``; no ``starts`` there: chosen from the number of free variables).
    workers
        Local processes for the starts.
    solver, options
        Registered back-end (None: the registry's default for an NLP) and its options.
    x0
        A start of the caller's, solved first (default: the declared start, if any).
    agree
        The search stops when the odds of a better optimum say so and at least this many
        starts reached the best value (default: the problem file's ``[solver] agree``, 3;
        0: the odds never stop it, every start runs).
    time_limit
        Wall-clock seconds for the search: no start begins after it, and a solve of a
        back-end that declares deadline options (Ipopt) stops at it (status
        ``time_limit``); other back-ends finish the start they are in.
    target_odds
        Also stop only once the estimated probability of a better optimum is at most
        this (None: Boender and Rinnooy Kan's rule alone).
    """
    _no_catalogue(problem, "nlp")
    objective = objective or problem.objective_names[0]
    objectives = _objective_set(problem, objective)
    seed = seed if seed is not None else problem.spec.solver.seed
    agree = agree if agree is not None else problem.spec.solver.agree
    watch = solver_hints(solver).deadline_options
    if time_limit is not None and watch:
        options = {**(options or {}), **watch}
    backend = solver_for(problem, solver, options, objectives)
    own = own_starts(problem, x0)
    cap = planned_starts(problem, starts)
    stand_in = search_stand_in(problem) if cap >= THIN_FROM_STARTS else problem
    search = backend if stand_in is problem else solver_for(stand_in, solver, options, objectives)
    target = search.nlp.target(objective)
    target_index = search.nlp.targets.index(objective)
    polish = None
    if stand_in is not problem:
        full = backend.nlp.target(objective)

        def polish(x0: np.ndarray, end: Result) -> Result:
            # a failed start's end point may lie far from the problem's least violated
            # point: the problem starts where the failed start did
            x = np.array([end.design[v.name] for v in problem.free]) if end.success else x0
            return checked_start(problem, backend.solve(backend.nlp.start(x0=x), full), objective)

    phase_one = phase_one_for(problem, search, options)
    least_violation = None
    if phase_one is not None:

        def least_violation(x0: np.ndarray, end: Result | None) -> LeastViolation:
            z0 = search.nlp.z_from_x(x0) if end is None else end.raw["z"]
            return phase_one().solve(z0, target=target)

    result = global_search(
        lambda x: checked_start(stand_in, search.solve(x, target), objective),
        tilted_starts(problem, objective, seed),
        own=own,
        max_starts=cap,
        agree=agree,
        target=target_odds,
        workers=workers,
        seed=seed,
        time_limit=time_limit,
        parallel_map=map_inherited,
        abs_tol=SOLVER_RESOLUTION * float(search.nlp.target_scales[target_index]),
        polish=polish,
        least_violation=least_violation,
    )
    if polish is not None and result.multistart is not None:
        result.multistart.search_points = len(stand_in.phi)
        result.multistart.grid_points = len(problem.phi)
    result = refine(problem, backend, result, objective)
    result.globality = search_globality(result.multistart)
    return finish(problem, result, objective)


#: Grid angles of the stand-in on which a search solves its starts (about; a subset of the
#: problem's angles): a start's cost grows with the rows, one or more per grid angle, and
#: the local optima of a thinned grid lie next to the problem's, where each is polished.
SEARCH_POINTS = 13

#: A problem with fewer grid angles than this is searched on its own grid.
THIN_ABOVE = 2 * SEARCH_POINTS

#: A search allowed fewer starts than this solves the problem itself: the stand-in's
#: solver (built once per problem state, 60-100 ms) costs more than a few cheaper starts
#: save (10-20 ms each on the shipped problems).
THIN_FROM_STARTS = 8


def search_points(points: int) -> int:
    """The grid angles of a search's stand-in for a problem of ``points`` angles: every
    k-th angle, ends included, k a divisor of ``points - 1`` giving the count nearest to
    :data:`SEARCH_POINTS` (at least 9); ``points`` itself when the grid is small or no
    divisor fits."""
    if points < THIN_ABOVE:
        return points
    counts = [(points - 1) // k + 1 for k in range(2, points) if (points - 1) % k == 0]
    fits = [c for c in counts if 9 <= c < points]
    return min(fits, key=lambda c: (abs(c - SEARCH_POINTS), -c)) if fits else points


_STAND_INS: OrderedDict[tuple, DesignProblem] = OrderedDict()


def search_stand_in(problem: DesignProblem) -> DesignProblem:
    """The problem on a subset of its grid angles (:func:`search_points`), on which the
    global search solves its starts before it polishes their optima on the problem
    itself; the problem itself when its grid is small. Built once per problem state."""
    points = len(problem.phi)
    thinned = search_points(points)
    if thinned == points:
        return problem
    return _remember(
        _STAND_INS,
        (problem.token,),
        lambda: problem.with_requirement("deflection.points", thinned),
    )


#: What a local solve resolves of an objective, relative to the objective's scale (the
#: formulation divides it by its value at the scales' design): two starts whose values
#: differ by less are counted as one optimum by the search's odds.
SOLVER_RESOLUTION = 1e-6

#: An optimum whose value is below this fraction of its objective's scale is solved once
#: more from itself with the objective scaled to 1 there (:func:`refine`).
REFINE_BELOW = 0.01


def refine(problem: DesignProblem, backend, result: Result, objective: str) -> Result:
    """The best start solved once more, warm, with its objective divided by its own value,
    when that value is far below the objective's scale (a ripple of 1e-4 where the scale,
    taken at the middle of the bounds, is 0.1): the solver's tolerance then holds the
    value to its own relative precision, not to the scale's. The refined point replaces
    the start's only when it is checked and no worse; the search's record stays."""
    nlp = backend.nlp
    if not result.success or objective not in nlp.targets or "z" not in result.raw:
        return result
    scale = float(nlp.target_scales[nlp.targets.index(objective)])
    value = float(result.objective)
    if not (np.isfinite(value) and 0.0 < abs(value) < REFINE_BELOW * scale):
        return result
    weight = scale / abs(value)
    again = backend.solve(nlp.start(z0=result.raw["z"]), nlp.target({objective: weight}))
    again.objective = again.objective / weight
    again = checked_start(problem, again, objective)
    if not again.success or again.objective > value:
        return result
    again.multistart, again.notes = result.multistart, result.notes
    again.wall_time_s += result.wall_time_s
    return again


#: A start whose solver value and NumPy model value of the objective differ by more than
#: this (relative) did not end at an optimum: the solver's bound variable is not tight.
BOUND_TIGHT_TOL = 1e-4


def checked_start(problem: DesignProblem, result: Result, objective: str) -> Result:
    """One start's result judged on the NumPy path, as the best one is
    (:func:`finish`): a design the check refuses is no success ("independent check
    failed"); a success whose solver value is not the model's objective (an epigraph
    variable left above the function it bounds: a stationary point of the formulation,
    not of the problem) is no success either; otherwise its objective is the model's
    value, so that starts are ranked and counted by the value every report shows."""
    if not result.design:
        return result
    x = np.array([result.design[v.name] for v in problem.free])
    ok, violated, objectives = verify_design(problem, x)
    result.verified = ok
    if not result.success:  # its end point still tells whether a feasible design exists
        return result
    value = float(objectives.get(objective, np.nan))
    if not ok:
        _refuse(result, " (independent check failed)")
        result.violated = violated
    elif np.isfinite(value):
        if abs(result.objective - value) > BOUND_TIGHT_TOL * max(abs(value), 1e-12):
            _refuse(
                result,
                f" (bound not tight: the solver's value {result.objective:.6g}, the model's "
                f"{value:.6g})",
                TerminationCondition.NUMERICAL_ERROR,
                "failed",
            )
        else:
            result.objective = value
    return result


def _refuse(
    result: Result,
    why: str,
    termination: TerminationCondition = TerminationCondition.INFEASIBLE,
    status: str = "infeasible",
) -> None:
    result.status = status
    result.termination = termination
    result.solution_status = SolutionStatus.INFEASIBLE
    result.message += why


def _objective_set(problem: DesignProblem, objective: str) -> tuple[str, ...]:
    names = problem.objective_names
    return tuple(names if objective in names else [objective, *names])


def _no_catalogue(problem: DesignProblem, name: str) -> None:
    reason = nlp_applies(problem)
    if reason is not True:
        raise ProblemError(f"formulation={name!r}: {reason}")


def continuous_only(problem: DesignProblem, advice: str) -> bool | str:
    """True when every free variable is continuous, else the reason, ending in
    ``advice``: a predicate of the formulations that solve no catalogue variable."""
    disc = [v.name for v in problem.free if v.discrete]
    return not disc or f"variables {', '.join(disc)} take catalogue values; {advice}"


def nlp_applies(problem: DesignProblem, request: SolveRequest | None = None) -> bool | str:
    """The ``nlp`` formulation's predicate: True unless the objective has no smooth form
    or a variable takes catalogue values (then the reason)."""
    refusal = smooth_form_refusal(problem, requested_objective(problem, request), "the NLP")
    return refusal or continuous_only(problem, "use formulation='catalogue' or formulation='auto'")


def requested_objective(problem: DesignProblem, request: SolveRequest | None) -> str:
    """The objective a request minimises (the problem's first without a request; ``""``
    for a problem that declares none, e.g. a stand-in of a test)."""
    if request is not None and request.objective:
        return request.objective
    names = getattr(problem, "objective_names", None)
    return names[0] if names else ""


def solve_nlp_formulation(problem: DesignProblem, request: SolveRequest) -> Result:
    """``formulation="nlp"``: the multistart NLP of the request, checked against the
    file's reference design when it has one."""
    result = solve_nlp(
        problem,
        objective=request.objective,
        starts=request.starts,
        seed=request.seed,
        workers=request.workers,
        solver=request.solver,
        options=request.options,
        agree=request.agree,
        time_limit=request.time_limit,
        target_odds=request.target_odds,
    )
    return attach_reference(problem, result)


def optimal_ranges(
    problem: DesignProblem,
    result: Result,
    rel: float = OBJECTIVE_TIE_TOL,
    solver: str | None = None,
    options: Mapping[str, Any] | None = None,
) -> dict[str, tuple[float, float]]:
    """Range of each free variable over the (near-)optimal set.

    Minimises and maximises each variable subject to the requirements and to the
    objective staying within ``rel`` of the optimum, with the same solver as the optimum
    (the objective's epsilon row carries the limit), started at the optimum. A wide range
    means the optimum does not fix that variable (e.g. the lead p in a backlash problem,
    or the size of a ripple-optimal linkage, since ripple is invariant when R, l, n, p
    scale together). A search that fails keeps the optimal value on its side.
    """
    objective = result.objective_name or problem.objective_names[0]
    hints = solver_hints(solver)
    warm_options = hints.range_options or hints.warm_start_options
    warm = warm_options is not None and "lam_g" in result.raw
    if warm:
        # Primal and dual start at the optimum (benchmarks/README.md, "Overhead").
        options = {**warm_options, **(options or {})}
    backend = solver_for(problem, solver, options, _objective_set(problem, objective))
    nlp = backend.nlp
    limit = result.objective + rel * max(abs(result.objective), 1e-12)
    bounds = nlp.bounds(eps={objective: limit})
    x_opt = np.array([result.design[v.name] for v in problem.free])
    if warm:
        raw = result.raw
        start = nlp.start(z0=raw["z"], lam_x0=raw["lam_x"], lam_g0=raw["lam_g"])
    elif "z" in result.raw:
        start = nlp.start(z0=result.raw["z"])
    else:
        start = nlp.start(x0=x_opt)
    ranges = {}
    for var in problem.free:
        ends = []
        for sign in (1.0, -1.0):
            r = backend.solve(start, {VAR + var.name: sign}, bounds)
            ok = r.success and r.max_violation <= FEASIBILITY_TOL
            ends.append(r.design[var.name] if ok else result.design[var.name])
        opt = result.design[var.name]
        ranges[var.name] = (float(min(*ends, opt)), float(max(*ends, opt)))
    return ranges


def finish(problem: DesignProblem, result: Result, objective: str | None = None) -> Result:
    """Check the result on the NumPy path, fill every objective and the full design."""
    result.objective_name = result.objective_name or objective or problem.objective_names[0]
    result.problem = problem.name
    result.mechanism = problem.mechanism_name
    result.problem_object = problem
    if not result.design:
        return result
    x = np.array([result.design[v.name] for v in problem.free])
    claimed = result.status in SOLVED_STATUSES  # the solver's word, checked below
    ok, violated, objectives = verify_design(problem, x)
    result.verified = ok
    result.notes += nan_notes(problem, objectives, violated)
    result.objectives = {k: float(v) for k, v in objectives.items()}
    value = result.objectives.get(result.objective_name, np.nan)
    if ok and np.isfinite(value):  # one value everywhere: the model's, which was checked
        result.objective = float(value)
    result.design = {**problem.fixed_values, **result.design}
    if claimed and not ok:
        # The solver claims success but the independent check disagrees: not a design.
        result.status = "infeasible"
        result.termination = TerminationCondition.INFEASIBLE
        result.solution_status = SolutionStatus.INFEASIBLE
        result.violated = violated
        result.message += " (independent check failed)"
    elif not claimed and not result.violated:
        result.violated = violated
    return result
