"""A catalogue node's start tried by its back-end's first solver
(:class:`~optdesign.solvers.registry.NodeFirst`; Ipopt's: CasADi's sqpmethod) on the
thinned grid, before the back-end itself (:meth:`~optdesign.formulations.catalogue.
node_solver.NodeSolver._thinned_solve`).

- It converges: its point is kept (``raw[FIRST_SOLVER] = KEPT``). From the parent's or a
  neighbour's optimum it takes 8-14 iterations where Ipopt takes ~22, at a fifth of the
  cost.
- It does not: the least violation of the node's rows is minimised from the same start
  by the same plugin (:class:`~optdesign.solvers.phase_one.PhaseOneSolver`). A positive
  minimum (:data:`~optdesign.solvers.phase_one.CERTIFY_ABOVE`) certifies that no feasible
  design lies near the start: the start's verdict of local infeasibility
  (``CERTIFIED``), the same evidence as Ipopt's own verdict (a converged minimum of the
  infeasibility), for about half its cost, the failed try included. A node needs two
  such verdicts, Ipopt's or these, to be called infeasible (:meth:`~optdesign.
  formulations.catalogue.node_solver.NodeSolver.verdicts_decide`).
- Otherwise (a feasible point found, or no convergence) the node's back-end solves the
  start from the same point (``SOLVED_AGAIN``), as it would have alone.
"""

from __future__ import annotations

import json

import numpy as np

from optdesign.formulations.nlp.solve import _PHASE_ONE, _remember, rows_solver_for
from optdesign.programs.nlp import Bounds, Target
from optdesign.solvers.phase_one import PhaseOneSolver
from optdesign.solvers.registry import NodeFirst, nlpsol_options
from optdesign.solvers.result import Result

#: The key of a start's ``raw`` record when the first solver tried it.
FIRST_SOLVER = "first_solver"
#: Its values: the first solver's point kept; its phase 1 certified a positive least
#: violation (the start's verdict); the node's back-end solved the start again.
KEPT, CERTIFIED, SOLVED_AGAIN = "kept", "phase 1", "solved again"


def first_try(
    backend, first: NodeFirst, rows, box: Bounds, x0: np.ndarray, target: Target
) -> Result | None:
    """The start ``x0`` of a node on its thinned grid (``rows`` of ``backend``'s NLP,
    bounds ``box``) by the first solver: its converged point, or the certified verdict of
    its phase 1 (see the module's text); None when the node's back-end must solve it."""
    quick = rows_solver_for(backend, rows, first.options, first.solver)
    start = quick.nlp.start(x0=x0, parameters=box.parameters)
    found = quick.solve(start, target, box)
    if found.success:
        found.raw[FIRST_SOLVER] = KEPT
        return found
    least = _phase_one(quick, first).solve(start.z0, box, target=target)
    if least.certified:
        verdict = least.result
        verdict.raw[FIRST_SOLVER] = CERTIFIED
        verdict.wall_time_s = (verdict.wall_time_s or 0.0) + (found.wall_time_s or 0.0)
        return verdict
    return None


def prepare(backend, first: NodeFirst, rows) -> None:
    """Build the first solver of ``rows`` and its phase-1 problem now (before forked
    workers inherit them, each of which would otherwise build its own)."""
    quick = rows_solver_for(backend, rows, first.options, first.solver)
    _phase_one(quick, first)


def _phase_one(quick, first: NodeFirst) -> PhaseOneSolver:
    """The phase-1 problem of the first solver's NLP on its plugin, built once per
    process, NLP and options."""
    key = (quick.nlp.fingerprint, first.solver, json.dumps(first.options, sort_keys=True))
    options = nlpsol_options(first.solver, first.options)
    return _remember(
        _PHASE_ONE, key, lambda: PhaseOneSolver(quick.nlp, options, plugin=first.solver)
    )
