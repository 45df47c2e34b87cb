"""The NLP formulation of a design problem on CasADi, built once per objective set.

Decision vector ``z`` = scaled free design variables (each mapped to [0, 1] by its
bounds, so the bounds stay true bounds) followed by auxiliary epigraph variables.

- ``"spread"`` objectives (ratio ripple) become lo <= i(phi_k) <= hi with the smooth
  value (hi - lo)/(hi + lo); ``"max"`` objectives (worst-case backlash, peak torque)
  become theta(phi_k) <= t with value t; an objective that is a root of the model (the
  loop's ``bandwidth_period``) bounds its t by implicit rows instead, smooth rows that
  hold exactly when t bounds it (``ObjectiveInfo.bound_rows``);
- every constraint block is divided by a typical magnitude so that one tolerance fits
  all; the scales come from the middle of the bounds, never from a declared start;
- the objective is a *parameter*: ``f = sum_k p_k v_k`` over the targets (every objective
  of the set, then every design variable), so one solver serves a single-objective
  solve, the ranges of the optimal set (min/max of a variable), the points of a Pareto
  front and a weighted sum; each objective of the set also has an epsilon row
  ``v_k <= eps_k`` whose limit is passed per solve (:meth:`NLP.bounds`).

``form="naive"`` hands mmax/mmin straight to the solver instead (non-smooth; kept to show
why the epigraph form exists, see benchmarks).
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

import casadi as ca
import numpy as np

from optdesign import math as m
from optdesign.errors import ProblemError
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.objective_refusals import smooth_form_refusal, unavailable_objective
from optdesign.problem.objectives import piece_rows

#: Prefix of the targets that are design variables (``"var:R"``).
VAR = "var:"


@dataclass(frozen=True)
class Bounds:
    """What one solve fixes: variable and constraint bounds (scaled, as the solver sees
    them) and the values of the problem's parameters (None: their defaults)."""

    lbz: np.ndarray
    ubz: np.ndarray
    lbg: np.ndarray
    ubg: np.ndarray
    parameters: np.ndarray | None = None


@dataclass(frozen=True)
class Start:
    """Where a solve starts: the scaled vector and, for a warm start, multipliers."""

    z0: np.ndarray
    lam_x0: np.ndarray | None = None
    lam_g0: np.ndarray | None = None


@dataclass(frozen=True)
class Target:
    """What a solve minimises: ``sum_k c_k v_k`` over named targets (objectives, or
    ``"var:NAME"`` for a design variable)."""

    coefficients: tuple[tuple[str, float], ...]

    @property
    def name(self) -> str:
        if len(self.coefficients) == 1 and self.coefficients[0][1] == 1.0:
            return self.coefficients[0][0]
        return "weighted_sum"


@dataclass
class NLP:
    """min f(z; p) s.t. lbg <= g(z) <= ubg, lbz <= z <= ubz, in scaled variables.

    Attributes
    ----------
    z, f, g, p
        CasADi symbols/expressions; ``p`` weights the targets.
    lbz, ubz, lbg, ubg
        Default bounds (epsilon rows at their requirement limits or +inf).
    g_names, g_units, g_scale
        Row names, units and the divisor applied to each row (raw = scaled * g_scale).
    n_design, x_lo, x_span, design_names
        ``x = x_lo + x_span * z[:n_design]``.
    aux_names
        Names of the auxiliary (epigraph) variables.
    targets, target_scales
        Names of the weights at the head of ``p`` and the typical magnitude of each value.
    param_names, param_defaults
        The problem's parameters (values fixed per solve, e.g. a catalogue item's load
        rating) at the tail of ``p``, and their default values.
    objective_values
        Objective name -> expression of its (unscaled) value, for reports.
    eps_rows
        Objective name -> row index of its epsilon row.
    default_target
        The objective minimised when a solve names none.
    """

    z: Any
    f: Any
    g: Any
    p: Any
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
    targets: list[str]
    target_scales: np.ndarray
    objective_values: dict[str, Any]
    eps_rows: dict[str, int]
    default_target: str
    form: str
    aux_init: Any = None  # CasADi Function zd -> aux start values
    param_names: list[str] = field(default_factory=list)
    param_defaults: np.ndarray = field(default_factory=lambda: np.zeros(0))
    limits: dict[str, float] = field(default_factory=dict)

    # --- targets -------------------------------------------------------------------------
    def target(self, spec: str | Mapping[str, float] | Target | None = None) -> Target:
        """A :class:`Target` from a name, a name -> coefficient mapping or None (default)."""
        if isinstance(spec, Target):
            return spec
        coefs = (
            {self.default_target: 1.0}
            if spec is None
            else ({spec: 1.0} if isinstance(spec, str) else dict(spec))
        )
        for name in coefs:
            if name not in self.targets:
                raise ProblemError(
                    f"objective {name!r} is not in this formulation (available: "
                    f"{', '.join(t for t in self.targets if not t.startswith(VAR))})"
                )
        return Target(tuple((k, float(v)) for k, v in coefs.items()))

    def params(self, target: Target, parameters: np.ndarray | None = None) -> np.ndarray:
        """The vector ``p`` of a solve: the weights of ``target`` (each value divided by its
        scale, so that f is ~1 at the middle of the bounds), then the problem's
        parameters (``parameters``, default: their defaults)."""
        w = np.zeros(len(self.targets))
        for name, c in target.coefficients:
            k = self.targets.index(name)
            w[k] += c / self.target_scales[k]
        values = self.param_defaults if parameters is None else np.asarray(parameters, float)
        return np.concatenate([w, values])

    def parameter_vector(self, values: Mapping[str, float] | None) -> np.ndarray | None:
        """The parameters' vector from name -> value (the rest at their defaults)."""
        if not values:
            return None
        out = self.param_defaults.copy()
        for name, v in values.items():
            out[self.param_names.index(name)] = float(v)
        return out

    @property
    def theta(self):
        """The parameters' symbols (the tail of ``p``)."""
        return self.p[len(self.targets) :]

    def parameter_values(self, parameters: np.ndarray | None) -> np.ndarray:
        return self.param_defaults if parameters is None else np.asarray(parameters, float)

    @cached_property
    def values_fun(self) -> ca.Function:
        """(z, theta) -> every target's value (objectives, then design variables)."""
        x = self.x_lo + self.x_span * self.z[: self.n_design]
        exprs = [*self.objective_values.values(), *[x[k] for k in range(self.n_design)]]
        return ca.Function("target_values", [self.z, self.theta], [ca.vertcat(*exprs)])

    @cached_property
    def g_fun(self) -> ca.Function:
        """(z, theta) -> the constraint rows."""
        return ca.Function("g", [self.z, self.theta], [self.g])

    def objective_reads(self, target: Target) -> tuple[set[int], set[int]]:
        """Which design variables and parameters the value of ``target`` depends on,
        structurally (CasADi's sparsity of its derivatives): positions in
        :attr:`design_names` and in :attr:`param_names`. An epigraph's auxiliary variable
        reads what the rows that hold it read (a minimax objective's envelope, an
        implicit epigraph's rows). A term multiplied by zero still counts: the answer
        may say "depends" where the value does not, never the other way."""
        zd, za = self.z[: self.n_design], self.z[self.n_design :]
        theta = self.theta
        exprs, aux = [], set()
        for name, _ in target.coefficients:
            if name.startswith(VAR):
                exprs.append(zd[self.design_names.index(name[len(VAR) :])])
                continue
            expr = ca.SX(self.objective_values[name])
            aux |= set(_columns(expr, za))
            exprs.append(expr)
        if aux:
            g = ca.SX(self.g)
            rows, cols = ca.jacobian_sparsity(g, za).get_triplet()
            exprs += [
                g[r] for r in sorted({r for r, c in zip(rows, cols, strict=True) if c in aux})
            ]
        total = ca.vertcat(*exprs) if exprs else ca.SX(0)
        return set(_columns(total, zd)), set(_columns(total, theta))

    def objective_of(self, target: Target, values: np.ndarray) -> float:
        """``sum c_k v_k`` from the vector of target values."""
        return float(sum(c * values[self.targets.index(k)] for k, c in target.coefficients))

    # --- bounds and starts -------------------------------------------------------------------
    def bounds(
        self,
        eps: Mapping[str, float] | None = None,
        box: Mapping[str, tuple[float, float]] | None = None,
        parameters: Mapping[str, float] | None = None,
    ) -> Bounds:
        """Bounds of a solve: epsilon limits ``eps`` (name -> upper limit of that
        objective, tightened by the requirement's own limit), a sub-box ``box`` of
        design variables (name -> (lower, upper), internal units) and values of the
        problem's parameters (name -> value)."""
        lbz, ubz, ubg = self.lbz, self.ubz, self.ubg
        if eps:
            ubg = ubg.copy()
            for name, value in eps.items():
                if name not in self.eps_rows:
                    raise ProblemError(
                        f"epsilon bound on {name!r}: not an objective of this formulation "
                        f"({', '.join(self.eps_rows)})"
                    )
                row = self.eps_rows[name]
                limit = min(float(value), self.limits.get(name, np.inf))
                ubg[row] = limit / self.g_scale[row]
        if box:
            lbz, ubz = lbz.copy(), ubz.copy()
            for name, (lo, hi) in box.items():
                k = self.design_names.index(name)
                lbz[k] = (lo - self.x_lo[k]) / self.x_span[k]
                ubz[k] = (hi - self.x_lo[k]) / self.x_span[k]
        return Bounds(lbz, ubz, self.lbg, ubg, self.parameter_vector(parameters))

    def x_from_z(self, z) -> np.ndarray:
        z = np.asarray(z, dtype=float).ravel()
        # within the declared bounds: Ipopt relaxes its bounds by ~1e-8 (relative to the
        # scaled variable), which over a span of 1e12 mm put a diameter 1e4 mm below 0
        x = self.x_lo + self.x_span * z[: self.n_design]
        return np.clip(x, self.x_lo, self.x_lo + self.x_span)

    def z_from_x(self, x, parameters: np.ndarray | None = None) -> np.ndarray:
        """Full start vector from a design: aux variables set to their tightest values
        (with the parameters' values of the solve, default: their defaults)."""
        x = np.asarray(x, dtype=float).ravel()
        zd = (x - self.x_lo) / self.x_span
        if not self.aux_names:
            return zd
        aux = np.asarray(self.aux_init(zd, self.parameter_values(parameters)), dtype=float)
        return np.concatenate([zd, aux.ravel()])

    def start(self, x0=None, z0=None, lam_x0=None, lam_g0=None, parameters=None) -> Start:
        """A :class:`Start` from the design ``x0`` or the scaled vector ``z0``."""
        if z0 is None:
            if x0 is None:
                raise ValueError("give x0 or z0")
            z0 = self.z_from_x(x0, parameters)
        return Start(np.asarray(z0, dtype=float).ravel(), _vec(lam_x0), _vec(lam_g0))

    @cached_property
    def fingerprint(self) -> str:
        """Content hash of the formulation (functions, bounds, names): the identity of
        stores and caches, equal in every process that builds the same problem."""
        fun = ca.Function("nlp", [self.z, self.p], [self.f, self.g])
        h = hashlib.sha1(fun.serialize().encode())
        for arr in (self.lbz, self.ubz, self.lbg, self.ubg, self.g_scale, self.target_scales):
            h.update(np.ascontiguousarray(arr, dtype=float).tobytes())
        h.update("\0".join([*self.g_names, *self.targets, *self.aux_names]).encode())
        return h.hexdigest()[:16]


def with_rows(nlp: NLP, keep: Sequence[int]) -> NLP:
    """The NLP with only the constraint rows ``keep`` (indices, in order): the same
    variables, objective and parameters with fewer rows, hence a relaxation (its optimum
    is never above the NLP's). Every objective's epsilon row must be kept."""
    rows = sorted({int(k) for k in keep})
    at = {row: k for k, row in enumerate(rows)}
    missing = [name for name, row in nlp.eps_rows.items() if row not in at]
    if missing:
        raise ValueError(f"with_rows: the epsilon rows of {', '.join(missing)} must be kept")
    idx = np.asarray(rows, dtype=int)
    return replace(
        nlp,
        g=ca.vertcat(*[nlp.g[k] for k in rows]) if rows else ca.SX(0, 1),
        lbg=nlp.lbg[idx],
        ubg=nlp.ubg[idx],
        g_names=[nlp.g_names[k] for k in rows],
        g_units=[nlp.g_units[k] for k in rows],
        g_scale=nlp.g_scale[idx],
        eps_rows={name: at[row] for name, row in nlp.eps_rows.items()},
    )


def _columns(expr, symbols) -> list[int]:
    """The positions of ``symbols`` (a vector of CasADi symbols) that ``expr`` depends on."""
    if not symbols.numel():
        return []
    _, cols = ca.jacobian_sparsity(ca.SX(expr), symbols).get_triplet()
    return sorted(set(cols))


def _vec(v) -> np.ndarray | None:
    return None if v is None else np.asarray(v, dtype=float).ravel()


@dataclass
class ConstraintRows:
    """Constraint rows lower/scale <= expr/scale <= upper/scale, with names and units.

    Every row is divided by a typical magnitude (its bound, or its size at the middle of
    the bounds) so that one solver tolerance fits all; ``scales`` keeps the divisors so
    that reports give values in the constraint's own unit.
    """

    exprs: list[Any] = field(default_factory=list)
    lbg: list[float] = field(default_factory=list)
    ubg: list[float] = field(default_factory=list)
    names: list[str] = field(default_factory=list)
    units: list[str] = field(default_factory=list)
    scales: list[float] = field(default_factory=list)

    def add(self, expr, lo, hi, scale, name, labels, unit) -> None:
        """Add ``lo <= expr <= hi`` (element-wise), each row named ``name[label]``."""
        # dense: a structural zero (e.g. a user's x/0 at phi = 0) is a row too
        expr = ca.densify(ca.vec(ca.SX(expr)))
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


def typical(value) -> float:
    """Largest finite magnitude of ``value`` (1 when none): a row's or value's scale."""
    a = np.abs(np.asarray(value, dtype=float))
    # NaN where a model is undefined at the scales' design; all NaN: no scale (no warning)
    v = np.nanmax(a) if a.size and not np.isnan(a).all() else np.nan
    return float(v) if np.isfinite(v) and v > 0 else 1.0


#: The lower bound of an implicit epigraph's variable (:attr:`ObjectiveTerm.bound_rows`),
#: as a fraction of its scale: its rows may divide by it (a period is a frequency's
#: inverse), so it stays positive.
BOUND_ROWS_FLOOR = 1e-3

#: Designs tried for the scales when the middle of the bounds does not assemble.
SCALE_SAMPLE = 64


def scales_design(problem: DesignProblem) -> np.ndarray:
    """Where the formulation takes its scales: the middle of the bounds, unless a model
    is undefined there (a linkage that does not assemble: NaN), then the least violated
    of :data:`SCALE_SAMPLE` fixed random designs (the same for every solve), so that a
    user's linkage that assembles only in part of its box still gets the scales of a
    design that exists. A declared start never changes the scales."""
    mid = problem.midpoint()
    if not problem.free:
        return mid
    with np.errstate(all="ignore"):
        ev = problem.evaluate(mid)
    if np.isfinite(ev.violation) and all(np.isfinite(v) for v in ev.objectives.values()):
        return mid
    lo, hi = problem.lower(), problem.upper()
    sample = lo + np.random.default_rng(0).random((SCALE_SAMPLE, len(lo))) * (hi - lo)
    with np.errstate(all="ignore"):
        ev = problem.evaluate(sample)
    finite = np.all(
        [np.isfinite(np.asarray(v, dtype=float)) for v in ev.objectives.values()], axis=0
    )
    violation = np.where(finite, np.nan_to_num(ev.violation, nan=np.inf), np.inf)
    best = int(np.argmin(violation))
    return sample[best] if np.isfinite(violation[best]) else mid


def numeric_value(term) -> float:
    """The value of an objective term of one design on the NumPy path."""
    e = np.asarray(term.expr, dtype=float)
    if term.kind == "spread":
        return float(m.grid_spread(e.ravel()))
    if term.kind == "max":
        return float(np.max(e))
    return float(e.ravel()[0])


def build_nlp(
    problem: DesignProblem,
    objectives: Sequence[str] | str | None = None,
    form: str = "epigraph",
    first_order: bool = False,
) -> NLP:
    """Build the NLP of ``problem`` for the objective set ``objectives``.

    Parameters
    ----------
    objectives
        Objectives the formulation can minimise or bound (default: the problem's); the
        first is the default target. Every design variable is a target too.
    form
        ``"epigraph"`` (smooth, default) or ``"naive"`` (max/min in the objective).
    first_order
        First-order Hertz flattening (to compare with the GP formulation).
    """
    if form not in ("epigraph", "naive"):
        raise ProblemError(f"formulation form {form!r}: use 'epigraph' or 'naive'")
    if objectives is None:
        objectives = problem.objective_names
    elif isinstance(objectives, str):
        objectives = [objectives]
    names: list[str] = []
    for name in [*objectives, *problem.objective_limits()]:
        if name not in names:
            names.append(name)
    refusal = smooth_form_refusal(problem, names, "an NLP")
    if refusal:
        raise ProblemError(refusal)

    free = problem.free
    n = len(free)
    x_lo, x_hi = problem.lower(), problem.upper()
    x_span = x_hi - x_lo
    zd = ca.SX.sym("z", n)
    x = x_lo + x_span * zd
    defaults = problem.parameters()
    theta = ca.SX.sym("theta", len(defaults))
    design = problem.design_dict([x[k] for k in range(n)])
    design.update(problem.parameter_design(dict(zip(defaults, ca.vertsplit(theta), strict=True))))
    ex = problem.expressions(design, guarded=True, first_order=first_order)
    mid = scales_design(problem)
    with np.errstate(all="ignore"):  # the scales' design may lie where a model is undefined
        ref = problem.expressions(problem.design_dict(mid), first_order=first_order)
    for name in names:
        if name not in ex.objectives:
            raise unavailable_objective(problem, name, ex.objectives)

    aux: list[tuple[Any, float]] = []  # (symbol, scale)
    aux_names: list[str] = []
    aux_lb: list[float] = []
    aux_ub: list[float] = []
    aux_start: list[Any] = []  # expressions of zd giving the tightest aux values
    rows = ConstraintRows()
    values: dict[str, Any] = {}
    scales: dict[str, float] = {}
    for name in names:
        term = ex.objectives[name]
        expr = term.expr
        scale = typical(ref.objectives[name].expr)
        scales[name] = typical(numeric_value(ref.objectives[name]))
        if term.bound_rows is not None:
            # an implicit epigraph (a root of the model, no expression of the design):
            # t bounds the objective exactly when its rows hold; the naive form has no
            # max to hand the solver, so it poses the same rows
            t = ca.SX.sym(f"{name}_max")
            aux.append((t, scales[name]))
            aux_names.append(f"{name}_max")
            aux_lb.append(BOUND_ROWS_FLOOR * scales[name])
            aux_ub.append(np.inf)
            aux_start.append(ca.mmax(expr) / scales[name])
            values[name] = t
            bound, labels = term.bound_rows(t)
            rows.add(bound, 0.0, None, 1.0, f"{name}_envelope", labels, "")
        elif term.kind == "scalar":
            values[name] = expr
        elif form == "naive":
            values[name] = m.grid_spread(ca.SX(expr)) if term.kind == "spread" else ca.mmax(expr)
        elif term.kind == "spread":
            lo, hi = ca.SX.sym(f"{name}_lo"), ca.SX.sym(f"{name}_hi")
            aux += [(lo, scale), (hi, scale)]
            aux_names += [f"{name}_lo", f"{name}_hi"]
            aux_lb += [0.0, 1e-6]
            aux_ub += [np.inf, np.inf]
            aux_start += [ca.mmin(expr) / scale, ca.mmax(expr) / scale]
            values[name] = m.spread(lo, hi)
            rows.add(
                expr - lo, 0.0, None, scale, f"{name}_lower_envelope", problem.phi_labels, term.unit
            )
            rows.add(
                hi - expr, 0.0, None, scale, f"{name}_upper_envelope", problem.phi_labels, term.unit
            )
        else:  # max
            t = ca.SX.sym(f"{name}_max")
            aux.append((t, scale))
            aux_names.append(f"{name}_max")
            aux_lb.append(-np.inf)
            aux_ub.append(np.inf)
            aux_start.append(ca.mmax(expr) / scale)
            values[name] = t
            for piece, labels in piece_rows(expr, term.pieces, problem.phi_labels):
                rows.add(t - piece, 0.0, None, scale, f"{name}_envelope", labels, term.unit)

    # Constraint blocks of the requirements.
    ref_blocks = {b.name: b for b in ref.constraints}
    for block in ex.constraints:
        if block.lower is None and block.upper is None:
            continue
        bound = max(abs(block.lower or 0.0), abs(block.upper or 0.0))
        scale = bound if bound > 0 else typical(ref_blocks[block.name].expr)
        for piece, labels in piece_rows(block.expr, block.pieces, block.labels):
            rows.add(piece, block.lower, block.upper, scale, block.name, labels, block.unit)
    limits = problem.objective_limits()
    eps_rows = {}
    for name in names:
        eps_rows[name] = len(rows.names)
        rows.add(
            values[name],
            None,
            limits.get(name),
            scales[name],
            f"{name}_max",
            [""],
            ex.objectives[name].unit,
        )

    # Objective: the parameter-weighted sum of the target values.
    targets = [*names, *(VAR + v.name for v in free)]
    target_scales = np.array(
        [scales[k] for k in names] + [abs(v) if abs(v) > 1e-12 else 1.0 for v in mid]
    )
    w = ca.SX.sym("w", len(targets))
    f_raw = ca.SX(0)
    for k, name in enumerate(names):
        f_raw += w[k] * values[name]
    for k in range(n):
        f_raw += w[len(names) + k] * x[k]

    # Substitute the aux symbols by scaled decision variables za (aux = scale * za).
    za = ca.SX.sym("za", len(aux))
    g_all = rows.g()
    if aux:
        sym_vec = ca.vertcat(*[a for a, _ in aux])
        rep = ca.vertcat(*[s * za[k] for k, (_, s) in enumerate(aux)])
        g_all = ca.substitute(g_all, sym_vec, rep)
        f_raw = ca.substitute(ca.SX(f_raw), sym_vec, rep)
        values = {k: ca.substitute(ca.SX(v), sym_vec, rep) for k, v in values.items()}
    z = ca.vertcat(zd, za)
    aux_lb_s = [lb / s if np.isfinite(lb) else lb for lb, (_, s) in zip(aux_lb, aux, strict=True)]
    aux_ub_s = [ub / s if np.isfinite(ub) else ub for ub, (_, s) in zip(aux_ub, aux, strict=True)]
    aux_init = ca.Function("aux_init", [zd, theta], [ca.vertcat(*aux_start)]) if aux_start else None
    # Common subexpression elimination: the blocks share the mechanism's subexpressions
    # (model functions return shared nodes, but derived rows repeat arithmetic).
    f_out, g_all, *value_list = ca.cse([ca.SX(f_raw), g_all, *(ca.SX(v) for v in values.values())])
    return NLP(
        z=z,
        f=f_out,
        g=g_all,
        p=ca.vertcat(w, theta),
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
        targets=targets,
        target_scales=target_scales,
        objective_values=dict(zip(values, value_list, strict=True)),
        eps_rows=eps_rows,
        default_target=names[0] if names else "",
        form=form,
        aux_init=aux_init,
        limits={k: float(v) for k, v in limits.items()},
        param_names=list(defaults),
        param_defaults=np.array(list(defaults.values()), dtype=float),
    )
