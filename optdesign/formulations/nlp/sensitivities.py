"""What each requirement costs: sensitivities of an NLP optimum to every requirement and
every active variable bound, from the solver's multipliers.

At a KKT point of ``min v(x; p) s.t. lo(p) <= g(x; p) <= hi(p)`` the envelope theorem
gives the derivative of the optimal value with respect to any parameter ``p`` of the
problem (a requirement's limit, a load, the stroke):

    dv*/dp = dv/dp + sum_i mu_i * (dg_i/dp - db_i/dp)

with ``b_i`` the bound of row ``i`` that binds (upper when ``mu_i > 0``, lower when
``mu_i < 0``: CasADi's sign convention) and ``mu_i`` the multiplier of the row *in the
problem's own units*. The NLP (:mod:`optdesign.programs.nlp`) divides the objective
by its typical value ``T`` and each row by its scale ``s_i``; Ipopt's ``lam_g`` belongs to
that scaled problem, so ``mu_i = lam_g_i * T / s_i`` (the scaling changes neither the
feasible set nor the optimum, so the multipliers of the unscaled problem are these).

The partial derivatives ``dg/dp`` are central differences of the model on the NumPy path
at the fixed optimum (no re-solve): a requirement can enter the rows as a limit, as a
load (the hinge moment scales every force) or through the grid (the stroke), and the
difference of the model covers all of them alike. The epigraph rows that carry a
``max``/``spread`` objective (``t - theta_k >= 0``) contribute through their model part
only: the auxiliary ``t`` is the same on both sides of the difference.

A bound of a design variable ``x_k = x_lo + x_span * z_k`` binds with ``lam_x``; its
multiplier in the problem's units is ``lam_x * T / x_span`` and ``dv*/d(bound) = -mu``.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.evaluation import population_rows
from optdesign.problem.parameters import (
    MOVED_SIZE,
    limit_shown,
    limit_value,
    moved_copy,
    perturbed,
    requirement_paths,
)
from optdesign.problem.request import SolveRequest
from optdesign.solvers.result import Result, Sensitivity

#: Relative step of the central differences of the model (a smooth function evaluated,
#: not solved: the error is O(step^2) and roundoff ~1e-16/step).
STEP = 1e-5

#: Sensitivities whose log-sensitivity (or, for a zero limit or objective, whose effect
#: of a 1 % change relative to the objective) is below this are left out: not binding.
NEGLIGIBLE = 1e-6


def nlp_sensitivities(problem: DesignProblem, result: Result, nlp=None) -> list[Sensitivity]:
    """The sensitivities of an NLP optimum (``result`` of :func:`solve_nlp` with Ipopt's
    multipliers in ``result.raw``), ranked by the size of their log-sensitivity (what
    costs most first); empty when the result carries no multipliers. ``nlp``: the
    formulation that solved it (default: the problem's own)."""
    from optdesign.formulations.nlp.solve import _objective_set, formulation_for

    raw = result.raw
    if not result.success or "lam_g" not in raw or "lam_x" not in raw:
        return []
    objective = result.objective_name or problem.objective_names[0]
    if nlp is None:
        nlp = formulation_for(problem, _objective_set(problem, objective))
    return from_multipliers(
        problem, result, nlp, objective, objective, lambda mu: _RowModel(nlp, objective, mu)
    )


def from_multipliers(
    problem: DesignProblem,
    result: Result,
    nlp: Any,
    target: str,
    objective: str,
    row_model: Any,
) -> list[Sensitivity]:
    """The envelope theorem at an optimum of ``nlp`` (its multipliers in ``result.raw``):
    d(optimum)/d(limit) = the multipliers times the rows' derivative in the limit at the
    fixed optimum. ``target``: the NLP's objective target whose scale undoes Ipopt's
    scaling; ``objective``: the name the records carry; ``row_model(mu)``: the rows'
    value (``.value(problem, x)``) weighted by the unscaled multipliers ``mu``. Ranked by
    the size of the log-sensitivity (what costs most first); empty without multipliers."""
    return from_multipliers_many(problem, [result], nlp, target, objective, [row_model])[0]


def from_multipliers_many(
    problem: DesignProblem,
    results: Sequence[Result],
    nlp: Any,
    target: str,
    objective: str,
    row_models: Sequence[Any],
) -> list[list[Sensitivity]]:
    """:func:`from_multipliers` of several optima of one ``nlp`` (a front's points), each
    with its row model. The rows of every optimum are evaluated together, one NumPy
    population per moved requirement, where each optimum's own evaluation would cost as
    much as all of them; the records are those of one optimum at a time."""
    T = nlp.target_scales[nlp.targets.index(target)]
    out: list[list[Sensitivity]] = [[] for _ in results]
    ready: list[tuple[int, np.ndarray, float, Any, np.ndarray]] = []
    for j, (result, row_model) in enumerate(zip(results, row_models, strict=True)):
        raw = result.raw
        lam_g = np.asarray(raw["lam_g"], dtype=float)
        lam_x = np.asarray(raw["lam_x"], dtype=float)
        if len(lam_g) != len(nlp.g_names) or len(lam_x) != len(nlp.lbz):
            continue
        x = np.array([result.design[v.name] for v in problem.free])
        rows = row_model(lam_g * T / nlp.g_scale)
        if isinstance(rows, _RowModel):
            _implicit_rows(problem, nlp, x, rows)
        ready.append((j, x, float(result.objective), rows, lam_x))
    if not ready:
        return out
    X = np.array([x for _, x, _, _, _ in ready])
    models = [rows for _, _, _, rows, _ in ready]
    # a row model that can reuse the design's evaluation (the NLP's rows) moves a limit
    # that changes no model function without evaluating the model again
    reuse = all(isinstance(rows, _RowModel) for rows in models)

    def values(q: DesignProblem) -> list[float]:
        if reuse:
            return [r.total(ev) for r, ev in zip(models, _evaluate_many(q, X), strict=True)]
        return [r.value(q, x) for r, x in zip(models, X, strict=True)]

    evaluated = _evaluate_many(problem, X) if reuse else None
    base = (
        values(problem)
        if evaluated is None
        else [r.total(ev) for r, ev in zip(models, evaluated, strict=True)]
    )
    found: list[list[tuple[Sensitivity, float]]] = [[] for _ in ready]
    shown: dict[str, Any] = {}  # each limit as read, once for every optimum
    for path, p in requirement_paths(problem):
        h = STEP * max(abs(p), 1e-9)
        try:
            moved = [moved_copy(problem, path, p + h), moved_copy(problem, path, p - h)]
        except Exception:  # a step the schema refuses (a band's min at its max): skip it
            continue
        limits = None if evaluated is None else moved_limits(problem, path, p + h, p - h)
        if limits is not None and evaluated is not None:
            pairs = list(zip(models, evaluated, strict=True))
            ups = [r.total(ev.with_limits(limits[0])) for r, ev in pairs]
            downs = [r.total(ev.with_limits(limits[1])) for r, ev in pairs]
        else:
            ups, downs = values(moved[0]), values(moved[1])
        name = f"requirements.{path}"
        for i, (up, down) in enumerate(zip(ups, downs, strict=True)):
            if not (math.isfinite(up) and math.isfinite(down) and math.isfinite(base[i])):
                continue
            if name not in shown:
                shown[name] = limit_shown(problem, name, p)
            slope = (up - down) / (2 * h)
            found[i].append(_record(problem, objective, name, p, slope, ready[i][2], shown[name]))
    for i, (j, _, v, _, lam_x) in enumerate(ready):
        for k, var in enumerate(problem.free):
            lam = float(lam_x[k])
            if lam == 0.0 or var.discrete:  # a catalogue variable is held at its item
                continue
            side = "upper" if lam > 0 else "lower"
            bound = var.upper if lam > 0 else var.lower
            d = -lam * T / nlp.x_span[k]
            found[i].append(
                _record(problem, objective, f"variables.{var.name}.{side}", bound, d, v)
            )
        kept = [s for s, effect in found[i] if abs(effect) > NEGLIGIBLE * max(abs(v), 1e-300)]
        # ranked by the size of the effect to 6 digits, then by name: two limits that cost
        # the same (the two ends of a symmetric stroke) keep one order whatever the last
        # digits of the solve that gave their multipliers
        kept.sort(key=lambda s: (-float(f"{abs(s.log_sensitivity or 0.0):.6g}"), s.name))
        out[j] = kept
    return out


def _evaluate_many(problem: DesignProblem, X: np.ndarray) -> list[_Evaluated]:
    """The rows of ``problem`` at each design of ``X`` (one per row), from one NumPy
    evaluation of the population. The first design's rows are checked against its own
    evaluation: a block whose shape could be read two ways (a grid row as long as the
    population) sends every design to its own evaluation instead."""
    own = _evaluate_one(problem, X[0])
    if len(X) == 1:
        return [own]
    pop = len(X)
    with np.errstate(all="ignore"):
        ex = problem.expressions(problem.design_dict(X))
    limits = problem.objective_limits()
    per: list[tuple[dict, dict]] = [({}, {}) for _ in range(pop)]
    for name, term in ex.objectives.items():
        e = np.asarray(term.expr, dtype=float)
        if term.kind == "scalar" and e.shape == (pop,):
            e = e[:, None]
        rows = population_rows(e, pop)
        for (blocks, scalars), row in zip(per, rows, strict=True):
            _objective_rows(blocks, scalars, name, term.kind, np.ravel(row))
    for block in ex.constraints:
        rows = population_rows(np.asarray(block.expr, dtype=float), pop)
        for (blocks, _), row in zip(per, rows, strict=True):
            blocks[block.name] = (np.ravel(row), block.lower, block.upper)
    out = [_Evaluated(blocks, scalars, limits) for blocks, scalars in per]
    if not _same_evaluation(own, out[0]):
        return [own, *(_evaluate_one(problem, x) for x in X[1:])]
    return out


def _evaluate_one(problem: DesignProblem, x: np.ndarray) -> _Evaluated:
    """The model's blocks and scalar objectives at design ``x``, with their limits."""
    with np.errstate(all="ignore"):
        ex = problem.expressions(problem.design_dict(x))
        blocks, scalars = _blocks(ex)
    return _Evaluated(blocks, scalars, problem.objective_limits())


def _same_evaluation(a: _Evaluated, b: _Evaluated) -> bool:
    if a.blocks.keys() != b.blocks.keys() or a.scalars.keys() != b.scalars.keys():
        return False
    same = all(
        a.blocks[k][0].shape == b.blocks[k][0].shape
        and np.allclose(a.blocks[k][0], b.blocks[k][0], rtol=1e-12, atol=0.0, equal_nan=True)
        for k in a.blocks
    )
    return same and all(
        np.isclose(a.scalars[k], b.scalars[k], rtol=1e-12, atol=0.0, equal_nan=True)
        for k in a.scalars
    )


def _record(
    problem: DesignProblem,
    objective: str,
    path: str,
    p: float,
    dvdp: float,
    v: float,
    limit: Any = None,
) -> tuple[Sensitivity, float]:
    """The record of ``dv*/dp`` at limit ``p`` (both internal), in the user's units
    (``limit``: the limit as read, :func:`limit_shown`, when the caller has it)."""
    from optdesign.display.shown import objective_shown

    if limit is None:
        limit = limit_shown(problem, path, p)
    factor = limit.value / p if p != 0 and limit.value else 1.0
    obj = objective_shown(problem, objective, v)
    obj_factor = obj.value / v if v != 0 else objective_shown(problem, objective, 1.0).value
    log = dvdp * p / v if v != 0 else None
    record = Sensitivity(
        name=path,
        objective=objective,
        limit=float(limit.value),
        unit=limit.unit,
        d_objective_d_limit=float(dvdp * obj_factor / factor),
        objective_unit=obj.unit,
        log_sensitivity=None if log is None else float(log),
    )
    return record, float(dvdp * p * 0.01) if p != 0 else float(dvdp)


class _RowModel:
    """The Lagrangian's parameter-dependent part at a fixed design: ``v(p)`` for a
    scalar objective plus ``sum mu_i (g_i(p) - b_i(p))`` over the NLP's rows, from the
    NumPy path (rows matched to the NLP's by block name and order). ``eps``: the epsilon
    bounds of the solve (a front's point), which :meth:`NLP.bounds` tightened each
    epsilon row to; a bound of the front's is no requirement and moves with none."""

    def __init__(self, nlp, objective: str, mu: np.ndarray, eps: Mapping[str, float] | None = None):
        self.nlp = nlp
        self.objective = objective
        self.mu = mu
        self.eps = dict(eps or {})
        self.rows = np.flatnonzero(mu != 0.0)
        eps_rows = set(nlp.eps_rows.values())
        self.eps_name = {row: name for name, row in nlp.eps_rows.items()}
        # (block name, index within the block) of every row the NLP has, in its order
        self.where: list[tuple[str, int]] = []
        seen: dict[str, int] = {}
        for i, name in enumerate(nlp.g_names):
            base = name.split("[", 1)[0] if i not in eps_rows else name
            k = seen.get(base, 0)
            seen[base] = k + 1
            self.where.append((base, k))

    def value(self, problem: DesignProblem, x: np.ndarray) -> float:
        return self.total(self.evaluate(problem, x))

    def evaluate(self, problem: DesignProblem, x: np.ndarray) -> _Evaluated:
        """The model's blocks and scalar objectives at design ``x``, with their limits."""
        return _evaluate_one(problem, x)

    def total(self, ev: _Evaluated) -> float:
        """``v(p) + sum mu_i (g_i - b_i)`` from an evaluation."""
        total = 0.0
        if self.objective in ev.scalars:
            total += ev.scalars[self.objective]
        for i in self.rows:
            mu = float(self.mu[i])
            if i in self.eps_name:
                name = self.eps_name[i]
                g = ev.scalars.get(name, 0.0)
                hi = ev.limits.get(name)
                if name in self.eps and (hi is None or self.eps[name] < hi):
                    hi = None  # the epsilon bound binds: a constant, no requirement's
                lo = None
            else:
                base, k = self.where[i]
                values, lo, hi = ev.blocks[base]
                # a block posed as its smooth pieces (ConstraintBlock.pieces) has one row
                # per piece and angle in the NLP, one per angle here: the piece's row
                # reads the block's value, their max, which the active piece equals
                g = float(values[k % values.size])
            b = hi if mu > 0 else lo
            total += mu * (g - (b if b is not None and math.isfinite(b) else 0.0))
        return total


@dataclass(frozen=True)
class _Evaluated:
    """The rows of a problem at one design: block name -> (values, lower, upper), the
    scalar objectives' values, the objectives' limits."""

    blocks: dict[str, tuple[np.ndarray, Any, Any]]
    scalars: dict[str, float]
    limits: dict[str, float]

    def with_limits(self, other: _Limits) -> _Evaluated:
        """The same values under another problem's limits."""
        blocks = {
            name: (values, *other.blocks.get(name, (lo, hi)))
            for name, (values, lo, hi) in self.blocks.items()
        }
        return _Evaluated(blocks, self.scalars, other.objectives)


@dataclass(frozen=True)
class _Limits:
    """A problem's limits: block name -> (lower, upper), and the objectives' limits."""

    blocks: dict[str, tuple[Any, Any]]
    objectives: dict[str, float]


#: Relative step of the difference that gives an implicit epigraph row's slope in t.
IMPLICIT_STEP = 1e-6


def _implicit_rows(problem: DesignProblem, nlp: Any, x: np.ndarray, rows: _RowModel) -> None:
    """Read the active rows of an implicit epigraph (``ObjectiveInfo.bound_rows``: rows
    g_k(t) >= 0 that hold iff t bounds the objective's value e_k at angle k) as a ``max``
    objective's rows t - e_k >= 0. The NumPy model has e_k, not g_k; at the optimum
    g_k(e_k) = 0, so at fixed t dg_k/dp = -(dg_k/dt) de_k/dp: the row's multiplier times
    dg_k/dt (a central difference at t = e_k) acting on -e_k (the objective's envelope
    block, matched by the row's angle) gives the envelope theorem's term exactly."""
    implicit = [
        name
        for name in nlp.targets
        if name in problem.objectives and problem.objectives[name].bound_rows is not None
    ]
    ex = q = None
    for name in implicit:
        head = f"{name}_envelope["
        active = [i for i in rows.rows if nlp.g_names[i].startswith(head)]
        if not active:
            continue
        if ex is None:
            with np.errstate(all="ignore"):
                ex = problem.expressions(problem.design_dict(x))
            q = ex.quantities
            rows.mu = rows.mu.copy()
        values = np.ravel(np.asarray(ex.objectives[name].expr, dtype=float))
        bound_rows = problem.objectives[name].bound_rows
        for i in active:
            label = nlp.g_names[i][len(head) : -1]
            k = problem.phi_labels.index(label)
            t, h = values[k], IMPLICIT_STEP * values[k]
            up, labels = bound_rows(q, t + h)
            down, _ = bound_rows(q, t - h)
            j = labels.index(label)
            slope = (np.ravel(up)[j] - np.ravel(down)[j]) / (2.0 * h)
            rows.mu[i] *= slope
            rows.where[i] = (f"{name}_envelope", k)


def _objective_rows(blocks: dict, scalars: dict, name: str, kind: str, e: np.ndarray) -> None:
    """An objective's epigraph rows (the NLP's envelope rows read its values) and, for a
    scalar one, its value."""
    blocks[f"{name}_lower_envelope"] = (e, 0.0, None)
    blocks[f"{name}_upper_envelope"] = (-e, 0.0, None)
    blocks[f"{name}_envelope"] = (-e, 0.0, None)
    if kind == "scalar":
        scalars[name] = float(e[0])


def _blocks(ex) -> tuple[dict[str, tuple[np.ndarray, Any, Any]], dict[str, float]]:
    blocks: dict[str, tuple[np.ndarray, Any, Any]] = {}
    scalars: dict[str, float] = {}
    for name, term in ex.objectives.items():
        _objective_rows(blocks, scalars, name, term.kind, np.ravel(np.asarray(term.expr, float)))
    for block in ex.constraints:
        blocks[block.name] = (
            np.ravel(np.asarray(block.expr, dtype=float)),
            block.lower,
            block.upper,
        )
    return blocks, scalars


#: Whether moving a requirement changes only limits (no model function), and the moved
#: problems' limits, by (problem state, path, values).
_LIMIT_ONLY: OrderedDict[tuple[str, str, float, float], tuple[_Limits, _Limits] | None] = (
    OrderedDict()
)


def moved_limits(
    problem: DesignProblem, path: str, up: float, down: float
) -> tuple[_Limits, _Limits] | None:
    """The limits of ``problem`` with requirement ``path`` at ``up`` and at ``down``, when
    that move changes no model function (the rows' values and the objectives are equal at
    two designs, and the limits do not depend on the design); None when it does (a
    requirement the physics reads: a hinge moment, a stroke)."""
    key = (problem.token, path, float(up), float(down))
    if key not in _LIMIT_ONLY:
        _LIMIT_ONLY[key] = _limits_if_only_limits(problem, path, up, down)
        while len(_LIMIT_ONLY) > MOVED_SIZE:
            _LIMIT_ONLY.popitem(last=False)
    return _LIMIT_ONLY[key]


def _limits_if_only_limits(
    problem: DesignProblem, path: str, up: float, down: float
) -> tuple[_Limits, _Limits] | None:
    lo, hi = problem.lower(), problem.upper()
    designs = [lo + 0.5 * (hi - lo), lo + 0.3 * (hi - lo)]
    with np.errstate(all="ignore"):
        own = [_blocks(problem.expressions(problem.design_dict(x)))[0] for x in designs]
    found = []
    for q in (moved_copy(problem, path, up), moved_copy(problem, path, down)):
        limits = None
        for x, mine in zip(designs, own, strict=True):
            with np.errstate(all="ignore"):
                theirs, _ = _blocks(q.expressions(q.design_dict(x)))
            if mine.keys() != theirs.keys():
                return None
            for name, (values, _, _) in theirs.items():
                if not np.array_equal(values, mine[name][0], equal_nan=True):
                    return None
            here = {name: (b[1], b[2]) for name, b in theirs.items()}
            if limits is not None and not _same_limits(limits, here):
                return None  # a limit that moves with the design is a function of it
            limits = here
        found.append(_Limits(limits, q.objective_limits()))
    return found[0], found[1]


def _same_limits(a: dict[str, tuple[Any, Any]], b: dict[str, tuple[Any, Any]]) -> bool:
    def same(u: Any, v: Any) -> bool:
        if u is None or v is None:
            return u is v
        return bool(np.array_equal(np.asarray(u, float), np.asarray(v, float), equal_nan=True))

    return a.keys() == b.keys() and all(
        same(a[k][0], b[k][0]) and same(a[k][1], b[k][1]) for k in a
    )


def finite_difference(
    problem: DesignProblem, result: Result, name: str, rel: float = 1e-3
) -> tuple[float, float]:
    """d(optimal objective)/d(limit) of ``result`` by re-solves: the limit ``name`` moved
    by ``rel`` (relative) to both sides, each re-solved from the optimum (one start; four,
    the optimum first, where that one fails), central difference; returns (derivative in internal units, the limit's internal
    value). The check of :func:`nlp_sensitivities` (tests, benchmarks)."""
    from optdesign.formulations.nlp.solve import solve_nlp

    p = limit_value(problem, name)
    h = rel * max(abs(p), 1e-9)
    x0 = np.array([result.design[v.name] for v in problem.free])
    values = []
    for q in (p + h, p - h):
        other = perturbed(problem, name, q)
        r = solve_nlp(other, result.objective_name or None, starts=1, x0=x0)
        if not r.success:  # from the optimum alone it may stall: a few more starts
            r = solve_nlp(other, result.objective_name or None, starts=4, x0=x0)
        if not r.success:
            raise RuntimeError(f"{name} = {q:g}: the re-solve ended {r.status}")
        values.append(r.objective)
    return (values[0] - values[1]) / (2 * h), p


def nlp_evidence(problem: DesignProblem, result: Result, request: SolveRequest) -> None:
    """What an NLP optimum's neighbourhood says, as ``request`` asks: what each
    requirement costs (from the back-end's multipliers) and the range of each variable
    over the near-optimal set. Only for a continuous NLP's result (its own rows and
    multipliers); a failure is a note, never the loss of the optimum."""
    from optdesign.formulations.nlp.solution import has_multipliers
    from optdesign.formulations.nlp.solve import optimal_ranges

    solver, options = request.solver, request.options
    continuous = result.formulation.startswith("nlp") and not any(v.discrete for v in problem.free)
    if not (result.success and continuous):
        return
    if request.sensitivities and has_multipliers(result, solver):
        try:
            result.sensitivities = nlp_sensitivities(problem, result)
        except Exception as exc:  # a report, not the result: never lose the optimum
            result.notes.append(f"sensitivities not computed: {exc}")
    if request.ranges and result.design and "z" in result.raw:
        try:
            result.ranges = optimal_ranges(problem, result, solver=solver, options=options)
        except Exception as exc:  # a report, not the result: never lose the optimum
            result.notes.append(f"ranges of the optimal set not computed: {exc}")
