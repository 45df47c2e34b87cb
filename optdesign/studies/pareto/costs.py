"""What each limit costs at a point of a front, from the point's own solve.

A point of an epsilon front is the optimum of ``min target s.t. others <= eps`` (the
record's ``target`` and ``eps``) on the front's one formulation, and its record keeps that
solve's multipliers. The envelope theorem of :mod:`optdesign.formulations.nlp.sensitivities` holds
there as at a single optimum: each cost is d(target)/d(limit) with the other objectives
held at the point's epsilon bounds (the front moves; the point keeps its trade-off). An
epsilon row enters with the bound it had in that solve, ``min(eps, the requirement's own
limit)``: a requirement that caps an objective (``ripple_max``) costs only where it, not
the epsilon bound, binds.

SLSQP (a front's sweep with ``solver="slsqp"``) returns the rows' multipliers but none of
the bounds (``lam_x`` zero). They follow from stationarity, ``grad f + J' lam_g + lam_x =
0``: at a variable on a bound ``lam_x = -(grad f + J' lam_g)``, with the sign of that
bound. What stationarity leaves at the other variables tells whether the multipliers are
those of a KKT point at all (:data:`KKT_TOL`); when they are not, the costs are not shown.

A point whose costs cannot be known says why (:attr:`PointCosts.why`): a point of
NSGA-II (no gradient solver, no multipliers), of a weighted sum (its multipliers price the
weighted sum, not one objective), of a catalogue front (its record keeps none), or one
read back from a file.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import partial
from types import SimpleNamespace
from typing import Any

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.result import Sensitivity

#: Largest stationarity residual ``|grad f + J' lam_g + lam_x|`` (scaled problem, relative
#: to ``max(1, |grad f|)``) at which the multipliers are taken as a KKT point's. SLSQP's
#: points of the shipped problems leave ~1e-6.
KKT_TOL = 1e-3

#: A scaled variable this close to a bound (its span is 1) sits on it.
ON_BOUND = 1e-7


@dataclass
class PointCosts:
    """The costs of one front point's limits.

    Attributes
    ----------
    target
        The objective the point's solve minimised (the costs are of it).
    held
        The other objectives held at their epsilon bounds in that solve (internal units).
    sensitivities
        Ranked as :func:`~optdesign.formulations.nlp.sensitivities.from_multipliers` ranks them.
    why
        Why the costs cannot be known ("" when they are).
    basis
        Whose multipliers the costs come from: the point's own solve, or its problem
        solved again by the NLP back-end from its design (:func:`_resolved`).
    """

    target: str = ""
    held: dict[str, float] = field(default_factory=dict)
    sensitivities: list[Sensitivity] = field(default_factory=list)
    why: str = ""
    basis: str = "this point's own solve"


def point_costs(problem: DesignProblem, objectives: Sequence[str], point: Any) -> PointCosts:
    """The costs at ``point`` (a :class:`~optdesign.studies.pareto.front.FrontPoint` of a
    front of ``objectives`` on ``problem``), or why they cannot be known."""
    return front_costs(problem, objectives, [point])[0]


def front_costs(
    problem: DesignProblem, objectives: Sequence[str], points: Sequence[Any]
) -> list[PointCosts]:
    """:func:`point_costs` of each of ``points``, their models evaluated together (one
    NumPy population per moved requirement and target,
    :func:`~optdesign.formulations.nlp.sensitivities.from_multipliers_many`)."""
    from optdesign.formulations.nlp.sensitivities import from_multipliers_many
    from optdesign.formulations.nlp.solve import formulation_for

    out: list[PointCosts] = []
    pending: dict[str, list[tuple[PointCosts, Any, Any]]] = {}
    for point in points:
        costs = PointCosts(target=point.target, held=dict(point.eps))
        out.append(costs)
        raw = getattr(point, "multipliers", None)
        if point.kind == "nsga2":
            costs.why = "NSGA-II evolves its designs without a gradient solver: no multipliers"
        elif point.kind == "weighted_sum":
            costs.why = "its multipliers price the weighted sum of the objectives, not one of them"
        elif raw is None:
            costs.why = "the point's record keeps no multipliers of its solve"
        if costs.why:
            continue
        try:
            prepared = _prepared(problem, objectives, point, raw, costs)
        except Exception as exc:  # a report: never lose the page for a point's costs
            _failed(costs, exc)
            continue
        if prepared is not None:
            pending.setdefault(costs.target, []).append((costs, *prepared))
    if pending:
        nlp = formulation_for(problem, tuple(sorted(objectives)))
    for target, items in pending.items():
        solved = [s for _, s, _ in items]
        models = [m for _, _, m in items]
        try:
            found = from_multipliers_many(problem, solved, nlp, target, target, models)
        except Exception as exc:  # a report: never lose the page for the points' costs
            for costs, _, _ in items:
                _failed(costs, exc)
            continue
        for (costs, _, _), sensitivities in zip(items, found, strict=True):
            costs.sensitivities = sensitivities
    return out


def _failed(costs: PointCosts, exc: Exception) -> None:
    text = " ".join(str(exc).split())[:200]
    costs.sensitivities = []
    costs.why = f"they could not be computed ({type(exc).__name__}: {text})"


def _prepared(
    problem: DesignProblem, objectives: Sequence[str], point: Any, raw: Any, costs: PointCosts
) -> tuple[Any, Any] | None:
    """The point's solve as the envelope theorem reads it (design, multipliers, value) and
    its row model, from the point's multipliers ``raw``; None when they cannot serve
    (``costs.why`` says why)."""
    from optdesign.formulations.nlp.sensitivities import _RowModel
    from optdesign.formulations.nlp.solve import formulation_for

    target, eps = costs.target, costs.held
    nlp = formulation_for(problem, tuple(sorted(objectives)))
    if raw.nlp != nlp.fingerprint or len(raw.lam_g) != len(nlp.g_names):
        costs.why = "its multipliers belong to another formulation than the front's"
        return None
    lam_x = np.asarray(raw.lam_x, dtype=float)
    lam_g = np.asarray(raw.lam_g, dtype=float)
    derived, residual = bound_multipliers(
        nlp, target, nlp.bounds(eps=eps), np.asarray(raw.z, dtype=float), lam_g
    )
    design = point.design
    if residual > KKT_TOL:
        again = _resolved(problem, objectives, nlp, target, eps, raw.z, point.objectives[target])
        if again is None:
            costs.why = (
                f"its solve's multipliers do not satisfy the optimality conditions "
                f"(residual {residual:.2g} of the scaled gradient), nor did a solve again "
                "from its design end at its value or just below"
            )
            return None
        design, lam_g, lam_x, lower = again
        costs.basis = (
            "its problem solved again from its design (the front's solve left multipliers "
            f"that miss the optimality conditions by {residual:.2g}"
            + (f"; the solve again ended {lower:.2g} lower" if lower > SAME_POINT else "")
            + ")"
        )
    elif not lam_x.any():  # the back-end returned no bound multipliers (SLSQP)
        lam_x = derived
    solved = SimpleNamespace(
        raw={"lam_g": lam_g, "lam_x": lam_x},
        design=design,
        objective=point.objectives[target],
    )
    return solved, partial(_RowModel, nlp, target, eps=eps)


#: A point's value and its solve again from its design agree within this (relative):
#: the multipliers of the second solve are then the point's.
SAME_POINT = 1e-6

#: A solve again that ends lower than the point by at most this (relative) improved a
#: point its front's solver left short of its optimum (SLSQP's tie-breaks at an anchor):
#: its costs are shown, saying by how much it ended lower.
NEARBY = 1e-3


def _resolved(
    problem: DesignProblem,
    objectives: Sequence[str],
    nlp: Any,
    target: str,
    eps: dict[str, float],
    z: Any,
    value: float,
) -> tuple[dict[str, float], np.ndarray, np.ndarray, float] | None:
    """The point's problem (``target`` with the others held at ``eps``) solved again from
    its ``z`` by the default NLP back-end, when that back-end returns multipliers and
    ends at the point's ``value`` or at most :data:`NEARBY` below it: (design, lam_g,
    lam_x, how much lower, relative); else None."""
    from optdesign.formulations.nlp.solution import nlp_solution
    from optdesign.formulations.nlp.solve import solver_for
    from optdesign.solvers.registry import default_solver, solver_hints

    name = default_solver("nlp")
    if not solver_hints(name).multipliers:
        return None
    backend = solver_for(problem, name, None, tuple(sorted(objectives)))
    if backend.nlp.fingerprint != nlp.fingerprint:
        return None
    r = backend.solve(nlp.start(z0=np.asarray(z, dtype=float)), target, nlp.bounds(eps=eps))
    solution = nlp_solution(r)
    if not r.success or solution is None or not np.isfinite(r.objective):
        return None
    scale = max(abs(value), 1e-300)
    if r.objective > value + SAME_POINT * scale or r.objective < value - NEARBY * scale:
        return None
    return (
        dict(r.design),
        solution.lam_g,
        solution.lam_x,
        (value - r.objective) / scale,
    )


_KKT: dict[str, Any] = {}


def bound_multipliers(
    nlp: Any, target: str, bounds: Any, z: np.ndarray, lam_g: np.ndarray
) -> tuple[np.ndarray, float]:
    """The bound multipliers that stationarity gives at ``z`` with the rows' ``lam_g``
    (CasADi's signs: > 0 on an upper bound, < 0 on a lower one) and the residual that
    stationarity leaves, relative to ``max(1, |grad f|)`` (scaled problem)."""
    import casadi as ca

    fun = _KKT.get(nlp.fingerprint)
    if fun is None:  # one per formulation: the gradient and the rows' Jacobian in z
        fun = ca.Function(
            "kkt", [nlp.z, nlp.p], [ca.gradient(nlp.f, nlp.z), ca.jacobian(nlp.g, nlp.z)]
        )
        _KKT[nlp.fingerprint] = fun
    grad, jac = fun(z, nlp.params(nlp.target(target), bounds.parameters))
    grad = np.asarray(grad.full(), dtype=float).ravel()
    r = grad + np.asarray(jac.full(), dtype=float).T @ lam_g
    # a bound takes the part of the gradient that pushes through it, and only that part
    upper = (z >= bounds.ubz - ON_BOUND) & (r < 0)
    lower = (z <= bounds.lbz + ON_BOUND) & (r > 0)
    lam_x = np.where(upper | lower, -r, 0.0)
    left = r + lam_x
    return lam_x, float(np.max(np.abs(left), initial=0.0) / max(1.0, np.max(np.abs(grad))))
