"""A node of the catalogue search: the problem's NLP (built once) with the catalogue
variables restricted to a box, solved by a small seeded multistart whose starts may run
on forked workers (:class:`NodeSolver`). The search over the boxes is
:mod:`optdesign.formulations.catalogue.search` and :mod:`optdesign.formulations.catalogue.bnb`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import replace
from typing import Any

import numpy as np

from optdesign.formulations.catalogue.bnb import RELAXED, trusted
from optdesign.formulations.catalogue.discrete import (
    discrete_variables,
)
from optdesign.formulations.catalogue.first_solver import (
    CERTIFIED,
    FIRST_SOLVER,
    KEPT,
    SOLVED_AGAIN,
    first_try,
    prepare,
)
from optdesign.formulations.catalogue.thinned_grid import (
    missed_angles,
    thinned_angles,
    thinned_rows,
)
from optdesign.formulations.nlp.solve import (
    _objective_set,
    rows_solver_for,
    solver_for,
    solver_options,
)
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.drive import box_has_item
from optdesign.programs.nlp import Bounds
from optdesign.runtime.inherited_map import InheritedWorkers, map_serial
from optdesign.solvers.base import on_every_row
from optdesign.solvers.multistart import (
    best_of,
    improves,
    outcome_counts,
    sobol_starts,
    start_outcome,
)
from optdesign.solvers.registry import default_solver, solver_hints
from optdesign.solvers.result import MultistartInfo, Result
from optdesign.tolerances import OBJECTIVE_TIE_TOL

#: The key of a start's ``raw`` record when it was solved on the thinned grid first
#: (:meth:`NodeSolver._solve_checked`): ``"kept"`` or ``"solved again"``.
THINNED_START = "thinned_start"
#: The key of a checked start's ``raw`` record that lists the grid angles (labels) of the
#: rows left out that its thinned point missed (:meth:`NodeSolver._solve_checked`).
MISSED_ANGLES = "missed_angles"

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
    makes a feasible problem look infeasible. Two starts that both end with a verdict of
    local infeasibility - the back-end's own, or its first solver's certified least
    violation (:mod:`~optdesign.formulations.catalogue.first_solver`) - end the
    multistart (:meth:`verdicts_decide`): the node is infeasible on those two starts
    (over the catalogue instance family, no later start or retry ever found a feasible
    point after two such verdicts: benchmarks/README.md, "Catalogue searches"). The
    starts on the node's thinned grid are tried by the back-end's first solver
    (sqpmethod for Ipopt), a leaf's first start excepted. As the problem's own
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
        thinned: bool = True,
        checked: bool = True,
        objectives: Sequence[str] = (),
        first: bool = True,
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
        # the problem's objectives, then every other one named (``objectives``, the
        # epsilon limits', this one's) in one order, so that searches of other targets
        # and limits over the same objectives share one NLP and its solvers
        names = _objective_set(problem, self.objective)
        others = sorted({*objectives, *self.eps, *names} - set(problem.objective_names))
        names = tuple(dict.fromkeys([*problem.objective_names, *others]))
        solver = self.solver = solver or default_solver("nlp")
        asked = bool(options)  # the caller's own options for the node back-end
        node = solver_hints(solver).node_options
        if node is not None:
            # The back-end's node options (infeasible boxes are common; a node still
            # counts as infeasible only once all its starts say so, and RETRY_STARTS
            # more unless verdicts_decide), then the problem file's own options, then
            # the caller's.
            options = {**node, **solver_options(problem, solver), **(options or {})}
        self.backend = solver_for(problem, solver, options, names)
        # the options solver_for built the backend with, for the relaxed backend's
        self._options = {**solver_options(problem, solver), **(options or {})}
        # the solver of the thinned grid, built on first use (see :meth:`relaxed_backend`;
        # False: the grid is not thinned), and its rows
        self._thinned = None
        self._thinned_rows: tuple[int, ...] = ()
        #: grid angles (labels) the thinned grid keeps besides its own: those where a
        #: checked start's point missed a row left out (:meth:`_solve_checked`); the
        #: thinned solver is built again for them before the next node
        self.learned_angles: frozenset[str] = frozenset()
        self._thinned_for: frozenset[str] | None = None
        self._regrids = 0
        #: (checked, resolved) starts before the thinned grid last changed
        self._counted_from = (0, 0)
        #: nodes of several item combinations are solved on the thinned grid (relaxations)
        self.thinned_nodes = bool(thinned)
        #: every other start first on the thinned grid, kept when its point meets every row
        #: (:meth:`_solve_checked`)
        self.checked = bool(checked)
        self.verdicts = solver_hints(solver).infeasible_verdicts
        #: the back-end that tries each start on the thinned grid first (``first``, the
        #: node back-end declares one and the caller set none of its options: a cap or a
        #: tolerance asked of the back-end is not the first solver's; :meth:`_thinned_solve`),
        #: else None
        self.first = solver_hints(solver).node_first if first and not asked else None
        self.nlp = self.backend.nlp
        self.target = self.nlp.target(self.objective)
        self.starts = max(1, starts)
        self.seed = seed
        self.names = [v.name for v in problem.free]
        self.n_solves = 0
        self.n_thinned = 0  # of those, on the thinned grid (relaxations)
        #: starts solved on the thinned grid whose point met every row (no solve on the
        #: whole grid), and those solved again on the whole grid from there
        self.n_checked = 0
        self.n_resolved = 0
        #: starts the first solver tried, those it did not solve, and of those the ones
        #: its phase 1 certified infeasible
        self.n_first = 0
        self.n_first_failed = 0
        self.n_first_certified = 0
        self.n_polished = 0  # leaves whose first solver's best start Ipopt solved again
        self.relaxed_angles = 0  # the thinned grid's angles, once built
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
        if self.thinned_backend() and self.first is not None:
            # the first solver and its phase 1 too (each worker would build its own)
            prepare(self.backend, self.first, self._thinned_rows)
        with InheritedWorkers(self._solve_start, self.workers) as workers:
            self._workers = workers
            try:
                yield
            finally:
                self._workers = None

    def thinned_backend(self):
        """The solver of the node NLP with the rows of every other grid angle only
        (:func:`thinned_angles`: 31 of 61), and of the angles this search learnt
        (:attr:`learned_angles`; built again when they change). Only rows are left out -
        the objective, the variables, the targets and every row not tied to one angle (a
        mean ratio, the nut travel, the life, the epsilon rows) are the node's own - so
        its optimum is a relaxation of the node's, never above it, at a lower cost per
        start (Ipopt's time per iteration follows the rows). (The stand-in problem of the
        NLP's global search, a problem on fewer angles, is not one: its grid's mean ratio
        is another number.) None when the grid is not thinned, or when rows are left free
        by index (the diagnosis)."""
        if self._thinned is None or (self._thinned and self._thinned_for != self.learned_angles):
            keep = thinned_rows(self.problem, self.nlp, self.learned_angles)
            if keep is None or self.free_rows.size:
                self._thinned = False
            else:
                self._thinned = rows_solver_for(self.backend, keep, self._options, self.solver)
                self._thinned_rows = tuple(keep)
                self._thinned_for = self.learned_angles
                kept = {self.problem.phi_labels[k] for k in thinned_angles(len(self.problem.phi))}
                self.relaxed_angles = len(kept | self.learned_angles)
        return self._thinned or None

    def relaxed_backend(self):
        """The thinned grid's solver (:meth:`thinned_backend`) for a node that holds more
        than one item combination, when such nodes may be relaxed (``thinned``): its
        value bounds the box's, which is all a node of the search needs. None otherwise."""
        return self.thinned_backend() if self.thinned_nodes else None

    def _mode(self, backend) -> str:
        """How a node's starts are solved: ``"relaxed"`` (on the thinned grid's back-end,
        ``backend``), ``"checked"`` (:meth:`_solve_checked`) or ``"whole"``. Checked while
        it pays: while no more of this solver's checked starts were solved again than were
        kept since the thinned grid last changed. A start solved again names the angles
        of the rows its thinned point missed (a peak between the kept angles: of a lock
        force, a bearing pressure), and the next nodes' thinned grid keeps them, at most
        :data:`MAX_REGRIDS` times a search; where the misses go on at new angles, the
        starts are solved on the whole grid. Decided here, in this process, per node
        and from the nodes before it: any number of workers solves the same starts the
        same way."""
        if backend is not self.backend:
            return "relaxed"
        checked, resolved = self._counted_from
        if (
            self.checked
            and self.n_resolved - resolved <= self.n_checked - checked
            and self.thinned_backend()
        ):
            return "checked"
        return "whole"

    def _solve_start(self, item: tuple[Bounds, np.ndarray, str, tuple[int, ...], bool]) -> Result:
        box, x0, mode, rows, quick = item
        if mode in ("relaxed", "checked"):
            # the node's thinned grid (a worker process builds it once for these rows;
            # here it is the one built already)
            backend = rows_solver_for(self.backend, rows, self._options, self.solver)
        if mode == "relaxed":
            # with_rows keeps the targets: the node's target serves both back-ends
            return self._thinned_solve(backend, rows, box, x0, quick)
        if mode == "checked":
            return self._solve_checked(backend, np.asarray(rows, dtype=int), box, x0, quick)
        return self.backend.solve(
            self.backend.nlp.start(x0=x0, parameters=box.parameters), self.target, box
        )

    def _solve_checked(
        self, thinned, rows: np.ndarray, box: Bounds, x0: np.ndarray, quick: bool = False
    ) -> Result:
        """One start of a node solved on the whole grid, first on the thinned grid.

        The thinned solve's point is kept when it meets every row left out within the
        back-end's own constraint tolerance (:func:`~optdesign.solvers.base.on_every_row`):
        it is then a KKT point of the node's NLP, what a solve on every row could have
        returned, at about half the cost per iteration and often in fewer iterations.
        Otherwise the node's NLP is solved from that point (a row between the kept
        angles binds: a few iterations more). A thinned start that ends otherwise is
        the start's outcome: the back-end's verdict of local infeasibility (no point
        near it meets the kept rows, so none meets them all), or a stop (iteration
        limit, error) that leaves the node to its other starts and retries, as on the
        whole grid. ``raw[THINNED_START]`` says which (``"kept"``,
        ``"solved again"``), ``raw[MISSED_ANGLES]`` where the rows it missed lie."""
        tbox = replace(box, lbg=np.asarray(box.lbg)[rows], ubg=np.asarray(box.ubg)[rows])
        first = self._thinned_solve(thinned, rows, tbox, x0, quick)
        lifted, met = on_every_row(first, self.nlp, rows, self.target, box)
        tried = {FIRST_SOLVER: first.raw[FIRST_SOLVER]} if FIRST_SOLVER in first.raw else {}
        if met or not first.success:
            lifted.raw.update({THINNED_START: "kept", **tried})
            return lifted
        result = self.backend.solve(self.nlp.start(z0=first.raw["z"]), self.target, box)
        result.raw.update({THINNED_START: "solved again", **tried})
        result.raw[MISSED_ANGLES] = missed_angles(self.nlp, first.raw["z"], box, rows)
        result.wall_time_s = (result.wall_time_s or 0.0) + (first.wall_time_s or 0.0)
        if result.iterations is not None and first.iterations is not None:
            result.iterations += first.iterations
        return result

    def _thinned_solve(
        self, thinned, rows, box: Bounds, x0: np.ndarray, quick: bool = False
    ) -> Result:
        """A start on the thinned grid (``thinned``: its back-end, ``box``: its bounds):
        with ``quick``, by the first solver (:attr:`first`, :func:`~optdesign.
        formulations.catalogue.first_solver.first_try`): its point, or its phase 1's
        verdict of local infeasibility; otherwise by ``thinned`` from the same start.
        ``raw[FIRST_SOLVER]`` says which."""
        if quick and self.first is not None:
            tried = first_try(self.backend, self.first, rows, box, x0, self.target)
            if tried is not None:
                return tried
        result = thinned.solve(
            thinned.nlp.start(x0=x0, parameters=box.parameters), self.target, box
        )
        if quick and self.first is not None:
            result.raw[FIRST_SOLVER] = SOLVED_AGAIN
        return result

    def _item(
        self, box: Bounds, x0, backend, own: bool = False
    ) -> tuple[Bounds, np.ndarray, str, tuple[int, ...], bool]:
        """A start as :meth:`_solve_start` takes it (here or in a worker process): the
        box, the point, how it is solved (:meth:`_mode`), the thinned grid's rows and
        whether the first solver tries it: not when ``own`` (a leaf's first start, whose
        design is the one reported unless another start beats it)."""
        mode = self._mode(backend)
        rows = () if mode == "whole" else self._thinned_rows
        quick = self.first is not None and mode != "whole" and not own
        return box, np.asarray(x0, dtype=float), mode, rows, quick

    def _starts(
        self,
        box: Bounds,
        points,
        stop: Callable[[list[Result]], bool],
        backend,
        leaf: bool,
        offset: int,
    ) -> list[Result]:
        """The node's starts ``offset`` on (``points``), in order, up to ``stop``: a
        leaf's first start by the node back-end alone (:meth:`_item`)."""
        items = [
            self._item(box, p, backend, leaf and offset + k == 0) for k, p in enumerate(points)
        ]
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
        relaxed: bool = False,
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
        ``relaxed``: a box of more than one item combination may be solved on the thinned
        grid (:meth:`relaxed_backend`): its value bounds the box's from below, which is
        all a node of the search needs; a leaf is always solved on the problem itself.
        """
        nodes = None if self.memo is None else self.memo.nodes
        if self.memo is not None and (
            self.memo.known_infeasible(bounds, self.eps)
            or (nodes is not None and nodes.infeasible(bounds, self.eps))
        ):
            self.n_implied += 1
            return no_item(self.backend.name, "infeasible: a wider box was at looser limits")
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
            return no_item(self.backend.name, "no catalogue item in this box")
        params = self.problem.parameter_values(node)
        one = all(lo_ == hi_ for lo_, hi_ in node.values())
        backend = (None if one or not relaxed else self.relaxed_backend()) or self.backend
        box = backend.nlp.bounds(eps=self.eps, box=bounds, parameters=params)
        if self.free_rows.size:
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
            results.append(self._solve_start(self._item(box, pts.pop(0), backend, one)))
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

            new = self._starts(box, points, stop, backend, one, len(before))
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
        if backend is not self.backend:
            self.n_thinned += len(results)
        self._note_checks(results)
        best, n_at_best = best_of(results)
        if one and best.success and best.raw.get(FIRST_SOLVER) == KEPT:
            best = self._polished(best, box)
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
        if backend is not self.backend:
            best.details[RELAXED] = self.relaxed_angles
        if nodes is not None:
            # its value and result only when trusted (a full multistart, or at its floor)
            ok = best.success and trusted(best, self.starts)
            value, kept = (best.objective, best) if ok else (None, None)
            if backend is not self.backend:
                kept = None  # a relaxation's value bounds the box; its result is no optimum
            x = self.x_of(best) if best.success else None
            nodes.add(bounds, self.eps, self.objective, value, x, kept)
        return best

    def _polished(self, best: Result, box: Bounds) -> Result:
        """A leaf's best start when the first solver found it (it beat the back-end's
        own first start beyond the tie): solved again by the node's back-end from its
        point, so that the design reported carries the back-end's tolerances and
        multipliers; the first solver's point when that solve does not converge."""
        again = self.backend.solve(self.nlp.start(z0=best.raw["z"]), self.target, box)
        self.n_solves += 1
        self.n_polished += 1
        return again if again.success else best

    def _note_checks(self, results: Sequence[Result]) -> None:
        """Count a node's checked starts (kept, or solved again: two NLP solves), its
        starts tried by the first solver (those it did not solve: two NLP solves), and
        learn the angles where the solved-again ones missed a row (:meth:`_mode`)."""
        missed: set[str] = set()
        for r in results:
            first = r.raw.get(FIRST_SOLVER)
            self.n_first += first is not None
            if first in (SOLVED_AGAIN, CERTIFIED):  # two NLP solves
                self.n_first_failed += 1
                self.n_first_certified += first == CERTIFIED
                self.n_solves += 1
            how = r.raw.get(THINNED_START)
            self.n_checked += how == "kept"
            if how == "solved again":
                self.n_resolved += 1
                self.n_solves += 1
                missed.update(r.raw.get(MISSED_ANGLES, ()))
        if missed - self.learned_angles and self._regrids < MAX_REGRIDS:
            # the next nodes' thinned grid keeps them, and its checks are counted afresh;
            # so do the next searches of a front (its memo)
            self.learned_angles |= missed
            self._regrids += 1
            self._counted_from = (self.n_checked, self.n_resolved)
            if self.memo is not None:
                self.memo.learned_angles |= missed

    def verdicts_decide(self, results: Sequence[Result]) -> bool:
        """Whether the starts so far call a node infeasible, without its other starts
        and the retries: at least two starts, every one ended with the back-end's own
        verdict of local infeasibility
        (:attr:`~optdesign.solvers.registry.SolverHints.infeasible_verdicts`), or with
        its first solver's phase 1 certifying a positive least violation
        (:mod:`~optdesign.formulations.catalogue.first_solver`). A start
        stopped by its iteration limit or an error, or a solved point that fails the
        check, leaves the node to its other starts and the retries; a node solver of one
        start (the neighbouring items of an optimum, the diagnosis) decides on its start
        and the first retry."""
        return (
            len(results) >= 2
            and bool(self.verdicts)
            and all(
                r.message in self.verdicts or r.raw.get(FIRST_SOLVER) == CERTIFIED for r in results
            )
        )

    def x_of(self, result: Result) -> np.ndarray | None:
        if not result.design:
            return None
        return np.array([result.design[n] for n in self.names])


#: Times a search adds to its thinned grid the angles where its checked starts missed a
#: row (each change builds one more solver, ~0.05 s, once per process and row set).
MAX_REGRIDS = 3


def no_item(solver: str, message: str) -> Result:
    """An infeasible node with nothing solved: ``message`` says why."""
    return Result(
        status="infeasible",
        objective=float("nan"),
        solver=solver,
        formulation="catalogue",
        message=message,
    )
