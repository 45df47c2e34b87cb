"""Exact catalogue optimum: enumeration or branch and bound over NLP relaxations.

Each node is the problem's NLP (built once) with the catalogue variables restricted to a
sub-range (branch and bound) or fixed to one item (enumeration, and the leaves of the
tree), solved by a small seeded multistart. The continuous relaxation (every catalogue
variable free between its first and last item) is solved first; its optimum is the
bound reported beside the discrete optimum.

What "exact" rests on: the node NLPs are non-convex and solved locally (multistart), so
the bound of a node is the best local optimum found, not a proven global one. A node
whose relaxation is under-estimated (missed global optimum) can be pruned wrongly;
enumeration has the same dependence on each fixed-item solve. The test compares the two
on the shipped catalogue problem. The branch and bound itself (warm nodes, first
incumbents, implied infeasible boxes) is :mod:`optdesign.formulations.catalogue.bnb`; Bonmin
as the other search, :mod:`optdesign.formulations.catalogue.minlp`.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Mapping, Sequence
from typing import Any

from optdesign.errors import ProblemError
from optdesign.formulations.catalogue.bnb import PRUNE_TOL as PRUNE_TOL
from optdesign.formulations.catalogue.bnb import RELAXED, InfeasibleBoxes, trusted_value
from optdesign.formulations.catalogue.bnb import branch_and_bound_warm as branch_and_bound
from optdesign.formulations.catalogue.bnb import cannot_improve as cannot_improve
from optdesign.formulations.catalogue.bnb import fixed_box as _fixed
from optdesign.formulations.catalogue.details import CatalogueCombination, CatalogueDetails
from optdesign.formulations.catalogue.discrete import (
    discrete_variables,
    n_combinations,
    nearest_item,
)
from optdesign.formulations.catalogue.node_solver import NODE_STARTS as NODE_STARTS
from optdesign.formulations.catalogue.node_solver import RETRY_STARTS as RETRY_STARTS
from optdesign.formulations.catalogue.node_solver import NodeSolver as NodeSolver
from optdesign.formulations.catalogue.node_solver import no_item as _no_item
from optdesign.formulations.nlp.solve import finish, requested_objective
from optdesign.formulations.reference import attach_reference, reference_design
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.objective_refusals import smooth_form_refusal
from optdesign.problem.parameters import without_impossible_items
from optdesign.problem.request import SolveRequest
from optdesign.solvers.multistart import (
    improves,
)
from optdesign.solvers.registry import default_solver, solver_hints, solver_names
from optdesign.solvers.result import Globality, Result

#: ``method="auto"`` enumerates when the catalogues make at most this many combinations.
ENUMERATE_MAX = 16


def enumerate_catalogue(
    ns: NodeSolver, x_hint=None, floor: float | None = None
) -> tuple[Result | None, list[CatalogueCombination]]:
    """Solve every combination of catalogue items; the best and the table of all.
    ``floor``: the relaxation's value (a combination that reaches it is settled)."""
    dvars = discrete_variables(ns.problem)
    table, best = [], None
    for combo in itertools.product(*(v.values for v in dvars)):
        items = {v.name: float(c) for v, c in zip(dvars, combo, strict=True)}
        r = ns.solve(_fixed(items), x_hint, floor=floor)
        table.append(CatalogueCombination(items, r.status, r.objective))
        # a tie (within PRUNE_TOL) keeps the earlier combination, as branch and bound does
        if r.success and (best is None or improves(r.objective, best.objective, PRUNE_TOL)):
            best = r
    return best, table


def minlp_back_end(solver: str | None) -> str:
    """The MINLP back-end of method ``"minlp"``: ``solver`` when it declares a MINLP
    solve (:attr:`~optdesign.solvers.registry.SolverHints.minlp`), the first registered
    one when ``solver`` is None; ProblemError naming them otherwise."""
    known = [n for n in solver_names("nlp") if solver_hints(n).minlp]
    if solver is None and known:
        return known[0]
    if solver in known:
        return solver
    raise ProblemError(
        f"catalogue method minlp: back-end {solver!r} solves no MINLP "
        f"(those that do: {', '.join(known) or 'none registered'})"
    )


def solve_catalogue(
    problem: DesignProblem,
    method: str = "auto",
    starts: int | None = None,
    seed: int | None = None,
    objective: str | None = None,
    solver: str | None = None,
    options: Mapping[str, Any] | None = None,
    eps: Mapping[str, float] | None = None,
    incumbents: Sequence[Mapping[str, float]] = (),
    memo: InfeasibleBoxes | None = None,
    ties: bool = True,
    workers: int = 1,
    agree: int | None = None,
    thinned_nodes: bool = True,
    thinned_starts: bool = True,
    objectives: Sequence[str] = (),
    first_solver: bool = True,
) -> Result:
    """Exact catalogue optimum of ``problem`` with its continuous-relaxation bound.

    Parameters
    ----------
    method
        ``"enumerate"``, ``"bnb"``, ``"minlp"`` or ``"auto"`` (enumerate up to
        :data:`ENUMERATE_MAX` combinations, branch and bound above; ``"minlp"`` when
        ``solver`` is a MINLP back-end). ``"minlp"``: the MINLP back-end (``solver``, or
        the first registered one) picks the items, with ``options`` its own
        (:mod:`optdesign.formulations.catalogue.minlp`); the default NLP back-end solves the
        relaxation and the items' node NLP.
    solver, options
        The NLP back-end of every node and its options (default: the registry's).
    starts, seed
        Multistart of each node NLP (default: the problem file's ``solver``; ``starts``
        at most 4 per node, the first start being the parent's optimum).
    eps
        Upper limits on other objectives (name -> limit): a point of an
        epsilon-constraint front over catalogue designs.
    incumbents
        Designs (name -> value) whose catalogue items are tried first, the best feasible
        one being the search's first incumbent (e.g. a front's neighbouring optima).
    memo
        Boxes proved infeasible by earlier searches of the same problem and node
        settings (shared by a front's points; see :mod:`optdesign.formulations.catalogue.bnb`).
    ties
        Decide a tie between combinations by their items, so that the design reported
        does not depend on the search's path (default). False when only the optimal
        value is wanted (the first stage of a lexicographic solve): the branch and bound
        then prunes the ties (:func:`~optdesign.formulations.catalogue.bnb.branch_and_bound_warm`).
    workers
        Local processes for each node's starts (:meth:`NodeSolver.on_workers`): the same
        nodes, values and answer as one worker.
    agree
        A node's multistart stops once this many starts agree on the best value (default:
        the problem file's ``[solver] agree``; 0: every start).
    thinned_nodes
        Solve a branch-and-bound node that holds several item combinations with the rows
        of every other grid angle only (:meth:`NodeSolver.relaxed_backend`): a relaxation
        of the node, cheaper per start, whose value still bounds the node's; each leaf on
        the whole grid. Only with ``ties``: a search that prunes a node whose bound ties
        with the incumbent (``ties`` False, an anchor's first stage) prunes none on a
        thinned bound, which lies below the tie wherever the objective peaks between the
        kept angles.
    thinned_starts
        Solve every other start (a leaf's, a node's of an anchor's first stage) on the
        thinned grid first and keep its point when it meets every row left out
        (:meth:`NodeSolver._solve_checked`): a KKT point of the node's own NLP; otherwise
        solve the node's NLP from there.
    objectives
        Other objectives the node NLP holds (as targets, unbounded unless in ``eps``):
        a front passes both of its objectives to each of its searches, so that the
        anchors, tie-breaks and points share one NLP and its solvers, built once.
    first_solver
        Let the node back-end's first solver (:class:`~optdesign.solvers.registry.NodeFirst`,
        Ipopt's: CasADi's sqpmethod) try the starts of the nodes on their thinned grid
        (:mod:`~optdesign.formulations.catalogue.first_solver`): its converged points
        kept, its phase 1's certificates of local infeasibility taken as verdicts, the
        other starts solved again by the back-end. A leaf's first start, whose design is
        reported unless another start beats it, is the back-end's alone, and a start of
        the first solver that beats it is solved again by the back-end from its point.

    Returns
    -------
    Result
        ``details.catalogue``: method, items chosen, relaxation bound and design, node
        counts (and the table of every combination when enumerating).
    """
    t0 = time.perf_counter()
    if not discrete_variables(problem):
        raise ProblemError("formulation='catalogue': no variable takes catalogue values")
    # Items proved impossible from closed forms cost no node: the search runs without them.
    problem, excluded = without_impossible_items(problem)
    if any(not v.values for v in discrete_variables(problem)):
        result = _no_item(
            solver or default_solver("nlp"),
            "no catalogue item can meet the requirements: " + "; ".join(excluded),
        )
        result.notes.append("excluded before the search: " + "; ".join(excluded))
        return result
    dvars = discrete_variables(problem)
    n_comb = n_combinations(problem)
    minlp_solver, minlp_options = None, None
    if method == "minlp" or (method == "auto" and solver_hints(solver).minlp):
        # A MINLP back-end picks the items (its options: its own); the default NLP
        # back-end solves the relaxation bound and the chosen items' node NLP.
        minlp_solver, minlp_options = minlp_back_end(solver), options
        method, solver, options = "minlp", None, None
    elif method == "auto":
        method = "enumerate" if n_comb <= ENUMERATE_MAX else "bnb"
    if method not in ("enumerate", "bnb", "minlp"):
        raise ProblemError(f"catalogue method {method!r}: use auto, enumerate, bnb or minlp")
    n_starts = (
        starts
        if starts is not None
        else min(problem.spec.solver.starts or NODE_STARTS, NODE_STARTS)
    )
    seed = seed if seed is not None else problem.spec.solver.seed
    agree = agree if agree is not None else problem.spec.solver.agree
    ns = NodeSolver(
        problem,
        objective,
        n_starts,
        seed,
        solver,
        options,
        eps,
        workers=workers,
        agree=agree,
        thinned=thinned_nodes and ties,
        checked=thinned_starts,
        objectives=objectives,
        first=first_solver,
    )
    with ns.on_workers():
        ns.memo = memo
        if memo is not None:  # the angles the front's earlier searches learnt
            ns.learned_angles = frozenset(memo.learned_angles)
        # the proofs of this search (a front's memo, or this search's own, which it does not
        # read: a single search solves the nodes it always did), for the optimum's
        # neighbouring items (studies.catalogue_sensitivity)
        ns.proofs = (
            memo
            if memo is not None
            else InfeasibleBoxes({v.name: (v.lower, v.upper) for v in dvars})
        )
        root = ns.solve({}, relaxed=method not in ("enumerate", "minlp"))
        info = CatalogueDetails(
            method=method,
            combinations=n_comb,
            variables={v.name: list(v.values) for v in dvars},
            relaxation_bound=root.objective if root.success else None,
            relaxation_status=root.status,
            relaxation_design={k: root.design.get(k) for k in ns.names} if root.design else {},
            relaxation_angles=root.details.get(RELAXED),
            starts_per_node=n_starts,
        )
        if method == "enumerate":
            best, info.enumerated = enumerate_catalogue(
                ns, ns.x_of(root), trusted_value(root, ns.starts)
            )
        elif method == "minlp":
            from optdesign.formulations.catalogue.minlp import solve_minlp

            best, info.minlp = solve_minlp(ns, minlp_solver, minlp_options)
        else:
            best, stats = branch_and_bound(ns, root, incumbents, ties=ties)
            info.nodes, info.pruned = stats["nodes"], stats["pruned"]
            info.infeasible, info.leaves = stats["infeasible"], stats["leaves"]
            info.seeded = stats["seeded"]
            info.warm_fallbacks, info.implied_infeasible = ns.n_cold, ns.n_implied
        info.nlp_solves, info.thinned_solves = ns.n_solves, ns.n_thinned
        info.checked_starts, info.resolved_starts = ns.n_checked, ns.n_resolved
        if ns.n_first:
            info.first_solver = ns.first.solver if ns.first is not None else None
            info.first_starts, info.first_failed = ns.n_first, ns.n_first_failed
            info.first_certified = ns.n_first_certified
        info.learned_angles = sorted(ns.learned_angles, key=_angle_degrees)
        info.infeasible_boxes = ns.proofs.proofs
        wall = time.perf_counter() - t0
        if best is None:
            # Infeasible only when the continuous relaxation (every catalogue range at once)
            # has no feasible point either; otherwise the search failed to find one.
            relaxed_ok = root.success
            result = Result(
                status="failed" if relaxed_ok else "infeasible",
                objective=float("nan"),
                design={},
                solver=ns.solver,
                formulation=f"catalogue-{method}",
                wall_time_s=wall,
                message=(
                    "no catalogue combination gave a feasible design although the continuous "
                    "relaxation is feasible (more starts may find one)"
                    if relaxed_ok
                    else "the continuous relaxation has no feasible design"
                ),
            )
            result.details["catalogue"] = info
            if excluded:
                result.notes.append("excluded before the search: " + "; ".join(excluded))
            return finish(problem, result, objective)
        best.formulation = f"catalogue-{method}"
        best.wall_time_s = wall
        # Snap to the exact items (the NLP holds them within its bound tolerance).
        for v in dvars:
            best.design[v.name] = nearest_item(best.design[v.name], v.values)[0]
        info.items = {v.name: best.design[v.name] for v in dvars}
        if root.success:
            info.gap_to_relaxation_rel = (best.objective - root.objective) / abs(root.objective)
        best.details["catalogue"] = info
        best.bound = root.objective if root.success else None
        items = ", ".join(f"{v.name} = {best.design[v.name]:g} {v.unit}".rstrip() for v in dvars)
        on = (
            ""
            if info.relaxation_angles is None
            else f" on {info.relaxation_angles} of the {len(problem.phi)} grid angles"
        )
        bound = (
            f"continuous relaxation bound {root.objective:.8g}{on} (discrete optimum "
            f"{100 * (info.gap_to_relaxation_rel or 0.0):+.3f} % above it)"
            if root.success
            else f"continuous relaxation: {root.status}"
        )
        how = f"{method} ({info.minlp.solver} {info.minlp.algorithm})" if info.minlp else method
        best.notes.append(
            f"catalogue items chosen: {items}; {bound}; {how}, {info.nlp_solves} NLP solves"
            + _grid_note(info)
        )
        if excluded:
            best.notes.append("excluded before the search: " + "; ".join(excluded))
        return finish(problem, best, objective)


def _grid_note(info: CatalogueDetails) -> str:
    """What the summary says of the solves on every other grid angle (and on the angles
    learnt where rows were missed): the relaxed nodes, and the starts solved there first
    (kept where their point met every row), e.g. `` (on every other grid angle and at
    phi=+15.0deg: 18 node solves; 4 starts first, kept: their points met every row)``;
    empty when there were none."""
    parts = []
    if info.thinned_solves:
        parts.append(f"{info.thinned_solves} node solves")
    if info.checked_starts:
        parts.append(f"{info.checked_starts} starts first, kept: their points met every row")
    if info.resolved_starts:
        parts.append(f"{info.resolved_starts} starts first, then on the whole grid")
    if info.first_starts:
        failed = info.first_failed
        again = failed - info.first_certified
        parts.append(
            f"{info.first_starts} starts of nodes with several item combinations by "
            f"{info.first_solver} first"
            + (
                f" ({failed} not solved: {info.first_certified} certified locally "
                f"infeasible by its phase 1, {again} solved again by the node's back-end)"
                if failed
                else ""
            )
        )
    if not parts:
        return ""
    grid = "every other grid angle"
    if info.learned_angles:
        grid += " and at " + ", ".join(info.learned_angles)
    return f" (on {grid}: {'; '.join(parts)})"


def _angle_degrees(label: str) -> float:
    """The angle of a grid label ``phi=+15.0deg``, for sorting."""
    return float(label.removeprefix("phi=").removesuffix("deg"))


def relaxation_bound(result: Result) -> float:
    """The continuous relaxation's optimum recorded in a catalogue result (NaN if none)."""
    return float("nan") if result.bound is None else float(result.bound)


def catalogue_applies(problem: DesignProblem, request: SolveRequest | None = None) -> bool | str:
    """The ``catalogue`` formulation's predicate: some free variable takes catalogue
    values and the objective has a smooth form (its nodes are NLPs)."""
    if not discrete_variables(problem):
        return "no variable takes catalogue values"
    objective = requested_objective(problem, request)
    return (
        smooth_form_refusal(problem, objective, "the catalogue search (its nodes are NLPs)") or True
    )


def solve_catalogue_formulation(problem: DesignProblem, request: SolveRequest) -> Result:
    """``formulation="catalogue"``: the exact catalogue optimum and its relaxation bound."""
    reference_design(problem)
    result = solve_catalogue(
        problem,
        starts=request.starts,
        seed=request.seed,
        objective=request.objective,
        solver=request.solver,
        options=request.options,
        workers=request.workers,
        agree=request.agree,
    )
    result.globality = catalogue_globality(result)
    return attach_reference(problem, result)


def catalogue_globality(result: Result) -> Globality:
    """What a catalogue optimum's search covers: every item combination, each by a
    local multistart of its continuous variables (no proof of those)."""
    details = result.details.catalogue
    if details is None:
        return Globality(basis="no catalogue search")
    how = {"enumerate": "enumerated", "bnb": "bounded by branch and bound"}.get(
        details.method, "chosen by a MINLP back-end"
    )
    return Globality(
        basis=f"the {details.combinations} item combinations {how}; the continuous "
        f"variables of each by a {details.starts_per_node}-start local multistart"
    )


def is_on_catalogue(problem: DesignProblem, design: Mapping[str, float]) -> bool:
    """Every catalogue variable of ``design`` equals one of its items."""
    return all(
        any(math.isclose(design[v.name], c, rel_tol=1e-12, abs_tol=1e-12) for c in v.values)
        for v in discrete_variables(problem)
    )
