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
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import Any

import numpy as np

from optdesign.errors import ProblemError
from optdesign.formulations.catalogue.bnb import PRUNE_TOL as PRUNE_TOL
from optdesign.formulations.catalogue.bnb import InfeasibleBoxes, trusted, trusted_value
from optdesign.formulations.catalogue.bnb import branch_and_bound_warm as branch_and_bound
from optdesign.formulations.catalogue.bnb import cannot_improve as cannot_improve
from optdesign.formulations.catalogue.bnb import fixed_box as _fixed
from optdesign.formulations.catalogue.details import CatalogueCombination, CatalogueDetails
from optdesign.formulations.catalogue.discrete import (
    discrete_variables,
    n_combinations,
    nearest_item,
)
from optdesign.formulations.nlp.solve import _objective_set, finish, solver_for, solver_options
from optdesign.formulations.reference import attach_reference, reference_design
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.drive import box_has_item
from optdesign.problem.parameters import without_impossible_items
from optdesign.problem.request import SolveRequest
from optdesign.programs.nlp import Bounds
from optdesign.runtime.inherited_map import InheritedWorkers, map_serial
from optdesign.solvers.multistart import (
    best_of,
    improves,
    outcome_counts,
    sobol_starts,
    start_outcome,
)
from optdesign.solvers.registry import default_solver, solver_hints, solver_names
from optdesign.solvers.result import Globality, MultistartInfo, Result
from optdesign.tolerances import OBJECTIVE_TIE_TOL

#: ``method="auto"`` enumerates when the catalogues make at most this many combinations.
ENUMERATE_MAX = 16


#: Starts per node when neither the caller nor the problem file sets them.
NODE_STARTS = 4

#: Sobol starts a node tries before it is called infeasible, when its own starts fail.
RETRY_STARTS = 4


class NodeSolver:
    """Solve the problem's NLP on a sub-box of the catalogue variables.

    One solver (:func:`optdesign.formulations.nlp.solve.solver_for`) serves every node: a node
    only passes its own variable bounds. A node's starts are the hint (or the problem's
    start) and the Sobol points of the solver's ``seed``. A node whose starts all fail is
    tried again from :data:`RETRY_STARTS` Sobol points of ``seed + 1`` (points it has not
    tried) before it counts as infeasible, so a poor
    first start (e.g. a declared one) that stops at an iteration limit or an error never
    makes a feasible problem look infeasible. Two starts that both end with the back-end's
    own verdict of local infeasibility (:meth:`verdicts_decide`) end the multistart: the
    node is infeasible on those two starts (over the catalogue instance family, no later
    start or retry ever found a feasible point after two such verdicts:
    benchmarks/README.md, "Catalogue searches"). As the problem's own
    multistart, a node's multistart stops once :attr:`agree` starts agree on the best
    value (the file's ``[solver] agree``, 3 by default, through :func:`solve_catalogue`;
    over the same cases no later start beat a value that 3 starts agreed on:
    ``benchmarks/catalogue_agreement.py``).
    """

    def __init__(
        self,
        problem: DesignProblem,
        objective: str | None = None,
        starts: int = 3,
        seed: int = 0,
        solver: str | None = None,
        options: Mapping[str, Any] | None = None,
        eps: Mapping[str, float] | None = None,
        free_rows: tuple[int, ...] = (),
        workers: int = 1,
        agree: int = 0,
    ):
        self.problem = problem
        #: A node's multistart stops once this many of its starts agree on the best value
        #: (0: every start), as the problem's own multistart does (``[solver] agree``).
        self.agree = max(0, int(agree))
        #: Local processes for a node's starts, inside :meth:`on_workers` (see there).
        self.workers = max(1, int(workers))
        self._workers: InheritedWorkers | None = None
        #: Constraint rows left unbounded at every node (a requirement dropped, to find
        #: which catalogue items the others allow: the diagnosis of an infeasible problem).
        self.free_rows = np.asarray(free_rows, dtype=int)
        self.objective = objective or problem.objective_names[0]
        self.eps = dict(eps or {})
        names = _objective_set(problem, self.objective)
        names = tuple(dict.fromkeys([*names, *sorted(self.eps)]))
        solver = self.solver = solver or default_solver("nlp")
        node = solver_hints(solver).node_options
        if node is not None:
            # The back-end's node options (infeasible boxes are common; a node still
            # counts as infeasible only once all its starts say so, and RETRY_STARTS
            # more unless verdicts_decide), then the problem file's own options, then
            # the caller's.
            options = {**node, **solver_options(problem, solver), **(options or {})}
        self.backend = solver_for(problem, solver, options, names)
        self.verdicts = solver_hints(solver).infeasible_verdicts
        self.nlp = self.backend.nlp
        self.target = self.nlp.target(self.objective)
        self.starts = max(1, starts)
        self.seed = seed
        self.names = [v.name for v in problem.free]
        self.n_solves = 0
        #: warm nodes that fell back to the multistart; nodes proved infeasible by the memo
        self.n_cold = 0
        self.n_implied = 0
        self.n_reused = 0  # nodes whose optimum under looser limits meets these limits
        #: boxes proved infeasible (shared by the searches of one front), read before a
        #: node is solved and written when one is proved; None: no memo
        self.memo = None
        #: where this search's own proofs are recorded besides (never read by it: a
        #: single search keeps its nodes; the optimum's neighbouring items read them)
        self.proofs = None

    @contextmanager
    def on_workers(self) -> Iterator[None]:
        """Inside it, a node's starts run on :attr:`workers` local processes forked once
        (they inherit the built solver). Each node keeps its serial answer: its starts
        in their order up to the one that settles it or the verdicts that end it
        (:class:`~optdesign.runtime.inherited_map.InheritedWorkers`), so any number of
        workers solves the same nodes to the same values and records."""
        if self.workers <= 1:
            yield
            return
        with InheritedWorkers(self._solve_start, self.workers) as workers:
            self._workers = workers
            try:
                yield
            finally:
                self._workers = None

    def _solve_start(self, item: tuple[Bounds, np.ndarray]) -> Result:
        box, x0 = item
        return self.backend.solve(
            self.nlp.start(x0=x0, parameters=box.parameters), self.target, box
        )

    def _starts(self, box: Bounds, points, stop: Callable[[list[Result]], bool]) -> list[Result]:
        items = [(box, np.asarray(p, dtype=float)) for p in points]
        if self._workers is None:
            return map_serial(self._solve_start, items, stop)
        return self._workers.map(items, stop)

    def solve(
        self,
        bounds: Mapping[str, tuple[float, float]],
        x_hint=None,
        warm: bool = False,
        prunes: Callable[[float], bool] | None = None,
        fallback: bool = True,
        floor: float | None = None,
    ) -> Result:
        """Best of the multistart on the box where ``bounds`` replace the catalogue
        variables' ranges; ``x_hint`` (e.g. the parent's optimum, clipped) is the first start.

        ``warm``: the hint alone decides when its solve succeeds with a value that
        ``prunes`` (the search's pruning test) would not prune; a failed hint, or a value
        that would prune the node, runs the rest of the multistart (and its retries) as
        a cold node does, so infeasibility and pruning rest on the same starts as before.
        ``fallback=False``: the warm start's result whatever it is (a first incumbent's
        value, which only needs to be feasible).
        A multistart also ends once :attr:`agree` of its starts agree on the best value
        (``multistart.stopped_early``, its value then trusted as a full multistart's).
        ``floor``: a lower bound on the node's value that the search trusts (its parent's
        relaxation value, when :func:`~optdesign.formulations.catalogue.bnb.trusted`); the box
        is a sub-box of the parent's, its item data no more favourable, so no start can
        end below it. A start that reaches it (within the tie tolerance) ends the
        multistart: the node's value is settled (``multistart.stopped_early``), whether
        the search would prune it or not.
        """
        nodes = None if self.memo is None else self.memo.nodes
        if self.memo is not None and (
            self.memo.known_infeasible(bounds, self.eps)
            or (nodes is not None and nodes.infeasible(bounds, self.eps))
        ):
            self.n_implied += 1
            return _no_item(self.backend.name, "infeasible: a wider box was at looser limits")
        if nodes is not None:
            # an earlier search's optimum of this box under looser limits that meets these
            # (the optimum here too), else its least value (a floor) and optimum (a start)
            reused = nodes.reuse(bounds, self.eps, self.objective)
            if reused is not None:
                self.n_reused += 1
                return reused
            earlier = nodes.lower_bound(bounds, self.eps, self.objective)
            if earlier is not None:
                floor = earlier if floor is None else max(floor, earlier)
            earlier_x = nodes.start(bounds, self.objective)
            x_hint = earlier_x if earlier_x is not None else x_hint
        lo, hi = self.problem.lower().copy(), self.problem.upper().copy()
        for name, (a, b) in bounds.items():
            k = self.names.index(name)
            lo[k], hi[k] = a, b
        node = {
            v.name: bounds.get(v.name, (v.lower, v.upper)) for v in discrete_variables(self.problem)
        }
        if not box_has_item(self.problem, node):
            # e.g. a (d0, p) box that holds no screw of the catalogue: nothing to solve
            return _no_item(self.backend.name, "no catalogue item in this box")
        params = self.problem.parameter_values(node)
        box = self.nlp.bounds(eps=self.eps, box=bounds, parameters=params)
        if self.free_rows.size:
            from dataclasses import replace

            lbg, ubg = np.array(box.lbg, dtype=float), np.array(box.ubg, dtype=float)
            lbg[self.free_rows], ubg[self.free_rows] = -np.inf, np.inf
            box = replace(box, lbg=lbg, ubg=ubg)
        first = self.problem.start() if x_hint is None else np.asarray(x_hint, dtype=float)
        pts = [np.clip(first, lo, hi)]
        if self.starts > 1:
            pts += list(sobol_starts(lo, hi, self.starts - 1, self.seed))
        n_planned = len(pts)

        def at_floor(r: Result) -> bool:
            return floor is not None and r.success and not improves(floor, r.objective)

        def agreed(rs: list[Result]) -> bool:
            return bool(self.agree) and len(rs) > 1 and best_of(rs)[1] >= self.agree

        results: list[Result] = []
        if warm and x_hint is not None:
            results.append(self._solve_start((box, pts.pop(0))))
            first_ok = results[0]
            if first_ok.success and (
                prunes is None or not prunes(first_ok.objective) or at_floor(first_ok)
            ):
                pts = []  # the warm start decides this node
            elif not fallback:
                self.n_solves += 1
                return first_ok
            else:
                self.n_cold += 1

        def run(points) -> bool:
            """Solve from ``points`` in order, stopping at a start that settles the node
            (True: it reached the floor, or ``agree`` starts agree on the best value) or
            once the starts so far decide it infeasible (verdicts_decide)."""
            before = list(results)

            def stop(new: list[Result]) -> bool:
                done = before + new
                return at_floor(new[-1]) or agreed(done) or self.verdicts_decide(done)

            new = self._starts(box, points, stop)
            results.extend(new)
            return bool(new) and (at_floor(new[-1]) or agreed(results))

        settled = bool(results) and at_floor(results[0])
        if not settled:
            settled = run(pts)
        if not any(r.success for r in results):
            if not self.verdicts_decide(results):
                run(sobol_starts(lo, hi, RETRY_STARTS, self.seed + 1))
            if not any(r.success for r in results):
                if self.memo is not None:
                    self.memo.add_infeasible(bounds, self.eps)
                if self.proofs is not None and self.proofs is not self.memo:
                    self.proofs.add_infeasible(bounds, self.eps)
        self.n_solves += len(results)
        best, n_at_best = best_of(results)
        outcomes = [start_outcome(r) for r in results]
        best.multistart = MultistartInfo(
            len(results),
            sum(r.success for r in results),
            n_at_best,
            OBJECTIVE_TIE_TOL,
            [r.objective for r in results],
            self.seed,
            outcomes=outcomes,
            failed=outcome_counts(outcomes),
            n_planned=n_planned,
            stopped_early=settled,
        )
        if nodes is not None:
            # its value and result only when trusted (a full multistart, or at its floor)
            ok = best.success and trusted(best, self.starts)
            value, kept = (best.objective, best) if ok else (None, None)
            x = self.x_of(best) if best.success else None
            nodes.add(bounds, self.eps, self.objective, value, x, kept)
        return best

    def verdicts_decide(self, results: Sequence[Result]) -> bool:
        """Whether the starts so far call a node infeasible, without its other starts
        and the retries: at least two starts, every one ended with the back-end's own
        verdict of local infeasibility
        (:attr:`~optdesign.solvers.registry.SolverHints.infeasible_verdicts`). A start
        stopped by its iteration limit or an error, or a solved point that fails the
        check, leaves the node to its other starts and the retries; a node solver of one
        start (the neighbouring items of an optimum, the diagnosis) decides on its start
        and the first retry."""
        return (
            len(results) >= 2
            and bool(self.verdicts)
            and all(r.message in self.verdicts for r in results)
        )

    def x_of(self, result: Result) -> np.ndarray | None:
        if not result.design:
            return None
        return np.array([result.design[n] for n in self.names])


def _no_item(solver: str, message: str) -> Result:
    return Result(
        status="infeasible",
        objective=float("nan"),
        solver=solver,
        formulation="catalogue",
        message=message,
    )


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
        problem, objective, n_starts, seed, solver, options, eps, workers=workers, agree=agree
    )
    with ns.on_workers():
        ns.memo = memo
        # the proofs of this search (a front's memo, or this search's own, which it does not
        # read: a single search solves the nodes it always did), for the optimum's
        # neighbouring items (studies.catalogue_sensitivity)
        ns.proofs = (
            memo
            if memo is not None
            else InfeasibleBoxes({v.name: (v.lower, v.upper) for v in dvars})
        )
        root = ns.solve({})
        info = CatalogueDetails(
            method=method,
            combinations=n_comb,
            variables={v.name: list(v.values) for v in dvars},
            relaxation_bound=root.objective if root.success else None,
            relaxation_status=root.status,
            relaxation_design={k: root.design.get(k) for k in ns.names} if root.design else {},
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
        info.nlp_solves = ns.n_solves
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
        bound = (
            f"continuous relaxation bound {root.objective:.8g} (discrete optimum "
            f"{100 * (info.gap_to_relaxation_rel or 0.0):+.3f} % above it)"
            if root.success
            else f"continuous relaxation: {root.status}"
        )
        how = f"{method} ({info.minlp.solver} {info.minlp.algorithm})" if info.minlp else method
        best.notes.append(
            f"catalogue items chosen: {items}; {bound}; {how}, {info.nlp_solves} NLP solves"
        )
        if excluded:
            best.notes.append("excluded before the search: " + "; ".join(excluded))
        return finish(problem, best, objective)


def relaxation_bound(result: Result) -> float:
    """The continuous relaxation's optimum recorded in a catalogue result (NaN if none)."""
    return float("nan") if result.bound is None else float(result.bound)


def catalogue_applies(problem: DesignProblem, request: SolveRequest | None = None) -> bool | str:
    """The ``catalogue`` formulation's predicate: some free variable takes catalogue
    values (the objective does not matter)."""
    return bool(discrete_variables(problem)) or "no variable takes catalogue values"


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
