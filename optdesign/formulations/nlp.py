"""The NLP formulation of a design problem on CasADi.

Decision vector ``z`` = scaled free design variables (each mapped to [0, 1] by its
bounds, so the bounds stay true bounds) followed by auxiliary epigraph variables.

- ``"spread"`` objectives (ratio ripple) become lo <= i(phi_k) <= hi with the smooth
  objective (hi - lo)/(hi + lo);
- ``"max"`` objectives (worst-case backlash, peak torque) become theta(phi_k) <= t, min t;
- every constraint block is divided by a typical magnitude so that one tolerance fits all.

``form="naive"`` hands mmax/mmin straight to the solver instead (non-smooth; kept to show
why the epigraph form exists, see benchmarks). Multiple objectives combine by weights
(weighted sum) and/or by epsilon-constraints on the others (Pareto fronts).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from optdesign.errors import ProblemError
from optdesign.problem.design_problem import DesignProblem


@dataclass
class NLP:
    """min f(z) s.t. lbg <= g(z) <= ubg, lbz <= z <= ubz, in scaled variables.

    Attributes
    ----------
    z, f, g
        CasADi symbols/expressions.
    g_names, g_units, g_scale
        Row names, units and the divisor applied to each row (raw = scaled * g_scale).
    n_design
        Number of design entries at the head of ``z``; ``x = x_lo + x_span * z``.
    objective_values
        Name -> expression of each objective's value (unscaled), for reports.
    f_scale
        The objective is ``value / f_scale``.
    """

    z: Any
    f: Any
    g: Any
    lbz: np.ndarray
    ubz: np.ndarray
    lbg: np.ndarray
    ubg: np.ndarray
    g_names: list[str]
    g_units: list[str]
    g_scale: np.ndarray
    n_design: int
    x_lo: np.ndarray
    x_span: np.ndarray
    design_names: list[str]
    aux_names: list[str]
    objective_values: dict[str, Any]
    objective: str
    f_scale: float
    form: str
    aux_init: Any = None  # CasADi Function x -> aux start values
    extra: dict[str, Any] = field(default_factory=dict)

    def x_from_z(self, z) -> np.ndarray:
        z = np.asarray(z, dtype=float).ravel()
        return self.x_lo + self.x_span * z[: self.n_design]

    def start(self, x0=None, z0=None) -> np.ndarray:
        """The solver's start vector: ``z0`` as given, else built from the design ``x0``."""
        if z0 is not None:
            return np.asarray(z0, dtype=float).ravel()
        if x0 is None:
            raise ValueError("give x0 or z0")
        return self.z_from_x(x0)

    def z_from_x(self, x) -> np.ndarray:
        """Full start vector from a design: aux variables set to their tightest values."""
        x = np.asarray(x, dtype=float).ravel()
        zd = (x - self.x_lo) / self.x_span
        if not self.aux_names:
            return zd
        aux = np.asarray(self.aux_init(zd), dtype=float).ravel()
        return np.concatenate([zd, aux])


@dataclass
class ConstraintRows:
    """Constraint rows lower/scale <= expr/scale <= upper/scale, with their names and units.

    Every row is divided by a typical magnitude (its bound, or its size at the start
    design) so that one solver tolerance fits all; ``scales`` keeps the divisors so that
    reports give values in the constraint's own unit.
    """

    exprs: list[Any] = field(default_factory=list)
    lbg: list[float] = field(default_factory=list)
    ubg: list[float] = field(default_factory=list)
    names: list[str] = field(default_factory=list)
    units: list[str] = field(default_factory=list)
    scales: list[float] = field(default_factory=list)

    def add(self, expr, lo, hi, scale, name, labels, unit) -> None:
        """Add ``lo <= expr <= hi`` (element-wise), each row named ``name[label]``."""
        expr = ca.vec(ca.SX(expr))
        k = expr.shape[0]
        self.exprs.append(expr / scale)
        self.lbg.extend([-np.inf if lo is None else lo / scale] * k)
        self.ubg.extend([np.inf if hi is None else hi / scale] * k)
        labs = labels if len(labels) == k else [str(j) for j in range(k)]
        self.names.extend([f"{name}[{lab}]" if lab else name for lab in labs])
        self.units.extend([unit] * k)
        self.scales.extend([scale] * k)

    def g(self):
        """All rows as one CasADi column."""
        return ca.vertcat(*self.exprs) if self.exprs else ca.SX(0, 1)


def build_nlp(
    problem: DesignProblem,
    objective: str | Mapping[str, float] | None = None,
    epsilon: Mapping[str, float] | None = None,
    form: str = "epigraph",
    first_order: bool = False,
    normalise: Mapping[str, tuple[float, float]] | None = None,
) -> NLP:
    """Build the NLP of ``problem``.

    Parameters
    ----------
    objective
        Objective name, or name -> weight for a weighted sum (default: the problem's
        first objective).
    epsilon
        name -> upper limit of other objectives (epsilon-constraint method).
    form
        ``"epigraph"`` (smooth, default) or ``"naive"`` (max/min in the objective).
    first_order
        First-order Hertz flattening (to compare with the GP formulation).
    normalise
        name -> (ideal, nadir) used to scale the objectives of a weighted sum.
    """
    if form not in ("epigraph", "naive"):
        raise ProblemError(f"formulation form {form!r}: use 'epigraph' or 'naive'")
    if objective is None:
        objective = problem.objective_names[0]
    weights = {objective: 1.0} if isinstance(objective, str) else dict(objective)
    epsilon = dict(epsilon or {})
    for name, limit in problem.objective_limits().items():
        epsilon[name] = min(limit, epsilon.get(name, np.inf))

    free = problem.free
    n = len(free)
    x_lo, x_hi = problem.lower(), problem.upper()
    x_span = x_hi - x_lo
    zd = ca.SX.sym("z", n)
    x = x_lo + x_span * zd
    design = problem.design_dict([x[k] for k in range(n)])
    ex = problem.expressions(design, guarded=True, first_order=first_order)

    # Typical magnitudes at the start design (NumPy path of the same expressions).
    start_eval = problem.expressions(problem.design_dict(problem.start()), first_order=first_order)

    aux: list[Any] = []
    aux_names: list[str] = []
    aux_lb: list[float] = []
    aux_ub: list[float] = []
    aux_start: list[Any] = []  # expressions of zd giving the tightest aux values
    rows = ConstraintRows()
    add_rows = rows.add

    def typical(value) -> float:
        v = np.nanmax(np.abs(np.asarray(value, dtype=float)))
        return float(v) if np.isfinite(v) and v > 0 else 1.0

    values: dict[str, Any] = {}
    # An ordered list, not a set: the order of the aux variables and rows must be the same
    # in every process, so that solutions and multipliers can warm-start other workers.
    free_names = {v.name for v in free}
    wanted = []
    for name in [*weights, *epsilon]:
        if name in free_names:
            # a design variable as objective: ranges of non-unique optima (studies.solve)
            values[name] = design[name]
        elif name not in wanted:
            wanted.append(name)
    for name in wanted:
        if name not in ex.objectives:
            raise ProblemError(
                f"objective {name!r} is not available for this problem "
                f"(available: {', '.join(ex.objectives)})"
            )
    for name in wanted:
        term = ex.objectives[name]
        expr = term.expr
        scale = typical(start_eval.objectives[name].expr)
        if term.kind == "scalar":
            values[name] = expr
        elif form == "naive":
            if term.kind == "spread":
                hi, lo = ca.mmax(expr), ca.mmin(expr)
                values[name] = (hi - lo) / (hi + lo)
            else:
                values[name] = ca.mmax(expr)
        elif term.kind == "spread":
            lo, hi = ca.SX.sym(f"{name}_lo"), ca.SX.sym(f"{name}_hi")
            aux += [(lo, scale), (hi, scale)]
            aux_names += [f"{name}_lo", f"{name}_hi"]
            aux_lb += [0.0, 1e-6]
            aux_ub += [np.inf, np.inf]
            aux_start += [ca.mmin(expr) / scale, ca.mmax(expr) / scale]
            values[name] = (hi - lo) / (hi + lo)
            add_rows(
                expr - lo, 0.0, None, scale, f"{name}_lower_envelope", problem.phi_labels, term.unit
            )
            add_rows(
                hi - expr, 0.0, None, scale, f"{name}_upper_envelope", problem.phi_labels, term.unit
            )
        else:  # max
            t = ca.SX.sym(f"{name}_max")
            aux_names.append(f"{name}_max")
            aux_lb.append(-np.inf)
            aux_ub.append(np.inf)
            aux_start.append(ca.mmax(expr) / scale)
            values[name] = t
            add_rows(t - expr, 0.0, None, scale, f"{name}_envelope", problem.phi_labels, term.unit)
            aux.append((t, scale))

    # Constraint blocks of the requirements.
    start_blocks = {b.name: b for b in start_eval.constraints}
    for block in ex.constraints:
        if block.lower is None and block.upper is None:
            continue
        bound = max(abs(block.lower or 0.0), abs(block.upper or 0.0))
        scale = bound if bound > 0 else typical(start_blocks[block.name].expr)
        add_rows(block.expr, block.lower, block.upper, scale, block.name, block.labels, block.unit)
    for name, limit in epsilon.items():
        scale = typical(_numeric_value(start_eval.objectives[name])) or 1.0
        add_rows(values[name], None, limit, scale, f"{name}_max", [""], ex.objectives[name].unit)

    # Objective: weighted sum of (optionally normalised) values, scaled to ~1 at the start.
    f_raw = 0
    for name, w in weights.items():
        v = values[name]
        if normalise and name in normalise:
            ideal, nadir = normalise[name]
            v = (v - ideal) / max(nadir - ideal, 1e-12)
        f_raw = f_raw + w * v

    # Substitute the aux symbols by scaled decision variables za (aux = scale * za).
    za = ca.SX.sym("za", len(aux))
    syms = [a for a, _ in aux]
    scaled = [s * za[k] for k, (_, s) in enumerate(aux)]
    g_all = rows.g()
    if syms:
        sym_vec = ca.vertcat(*syms)
        rep = ca.vertcat(*scaled)
        g_all = ca.substitute(g_all, sym_vec, rep)
        f_raw = ca.substitute(ca.SX(f_raw), sym_vec, rep)
        values = {k: ca.substitute(ca.SX(v), sym_vec, rep) for k, v in values.items()}
    z = ca.vertcat(zd, za)
    f_start = _start_objective(f_raw, z, zd, aux_start, problem, x_lo, x_span)
    f_scale = abs(f_start) if np.isfinite(f_start) and abs(f_start) > 1e-12 else 1.0
    aux_lb_s = [lb / s if np.isfinite(lb) else lb for lb, (_, s) in zip(aux_lb, aux, strict=True)]
    aux_ub_s = [ub / s if np.isfinite(ub) else ub for ub, (_, s) in zip(aux_ub, aux, strict=True)]
    aux_init = ca.Function("aux_init", [zd], [ca.vertcat(*aux_start)]) if aux_start else None
    # Common subexpression elimination: the model builds each constraint block from its
    # own copy of the mechanism's expressions, so the same subexpressions appear many
    # times (cs_min_backlash: 15 900 SX instructions for g, 4 200 after). Same values, but
    # ~3x faster evaluations and derivative generation (Ipopt set-up 0.36 -> 0.14 s).
    f_out, g_all, *value_list = ca.cse([ca.SX(f_raw / f_scale), g_all, *values.values()])
    values = dict(zip(values, value_list, strict=True))
    return NLP(
        z=z,
        f=f_out,
        g=g_all,
        lbz=np.concatenate([np.zeros(n), aux_lb_s]),
        ubz=np.concatenate([np.ones(n), aux_ub_s]),
        lbg=np.array(rows.lbg),
        ubg=np.array(rows.ubg),
        g_names=rows.names,
        g_units=rows.units,
        g_scale=np.array(rows.scales),
        n_design=n,
        x_lo=x_lo,
        x_span=x_span,
        design_names=[v.name for v in free],
        aux_names=aux_names,
        objective_values=values,
        objective=objective if isinstance(objective, str) else "weighted_sum",
        f_scale=f_scale,
        form=form,
        aux_init=aux_init,
    )


def _numeric_value(term) -> float:
    e = np.asarray(term.expr, dtype=float)
    if term.kind == "spread":
        return float((e.max() - e.min()) / (e.max() + e.min()))
    return float(e.max())


def _start_objective(f_raw, z, zd, aux_start, problem, x_lo, x_span) -> float:
    zd0 = (problem.start() - x_lo) / x_span
    if aux_start:
        aux0 = ca.Function("a0", [zd], [ca.vertcat(*aux_start)])(zd0)
        z0 = ca.vertcat(ca.DM(zd0), aux0)
    else:
        z0 = ca.DM(zd0)
    try:
        return float(ca.Function("f0", [z], [f_raw])(z0))
    except RuntimeError:
        return 1.0
