"""Geometric-programming (GP) formulation of a design problem, and its DGP diagnosis.

A design problem is a GP when, after the change of variables ``y = log x``, every
objective and constraint row is a posynomial bounded above (or a monomial bounded on
either side). Two things make that true for some of optdesign's problems: Hertz
flattening taken to first order (b^2/D, a monomial) and the ISO 286 fit formulas
(posynomials in D, :mod:`optdesign.models.fits`).

**How the expressions are obtained.** The models are written once through
:mod:`optdesign.math`, which dispatches CasADi symbols to CasADi and everything
else to NumPy. cvxpy expressions cannot go through it (NumPy ufuncs such as ``np.abs``
raise on cvxpy objects) and cvxpy never merges like terms, so ``R tan(30) - R tan(-30)``
(a monomial) would stay a non-DGP difference. Instead, :meth:`DesignProblem.expressions`
is evaluated on :class:`Signomial` tracers: exact sums of monomials ``c x^a`` with NumPy
coefficients over the deflection grid, closed under +, -, *, /, ** and ``abs``, merging
like terms as it goes. Whatever a tracer cannot represent (cos of a design variable,
division by a sum, ``max``) becomes a :class:`NotGP` value that carries the reason and
the offending sub-term to the block that uses it. Each row is then classified
(posynomial <= c, monomial >= c, constant) and handed to cvxpy; cvxpy's own
``is_dgp()`` is the final check.

The result (:class:`GPData`) is generic (variables, bounds, rows of exponents and
coefficients); :mod:`optdesign.solvers.cvxpy_gp` solves it without knowing a mechanism.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.problem.design_problem import DesignProblem

#: Exponents are rounded to this many digits to merge like terms (1/3 from 1/3.0 etc.).
_EXP_DIGITS = 12


# --------------------------------------------------------------------------------------
# Tracers
# --------------------------------------------------------------------------------------
class NotGP:
    """A value that is not a signomial of the design variables; carries the reason.

    Every operation on it returns it unchanged, so the first reason reaches the
    objective or constraint block that used the value.
    """

    __array_priority__ = 1000

    def __init__(self, reason: str, term: str = ""):
        self.reason = reason
        self.term = term

    def __repr__(self) -> str:
        return f"NotGP({self.reason!r})"

    def _absorb(self, *_args, **_kw):
        return self

    __add__ = __radd__ = __sub__ = __rsub__ = __mul__ = __rmul__ = _absorb
    __truediv__ = __rtruediv__ = __pow__ = __rpow__ = __neg__ = __abs__ = _absorb
    __pos__ = _absorb

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        return self

    def mean(self, *_a, **_k):
        return self

    max = min = sum = mean

    def __float__(self) -> float:
        # Input checks of the mechanisms call float(); a non-GP value has no sign to check.
        return 1.0


class Signomial:
    """Exact sum of terms ``c(phi) * prod_i x_i^a_i`` over the deflection grid.

    Parameters
    ----------
    names
        Names of the free variables (the exponent vectors follow this order).
    terms
        Exponent tuple -> coefficient (float or NumPy array broadcast against the grid).
    ref
        Values of the free variables at a reference design; ``float()`` of a scalar
        tracer returns its value there (the mechanisms' input checks test the sign of
        their arguments; GP variables are positive by construction).
    """

    __array_priority__ = 1000

    def __init__(self, names: tuple[str, ...], terms: dict, ref: np.ndarray):
        self.names = names
        self.ref = ref
        self.terms: dict[tuple[float, ...], Any] = {}
        for a, c in terms.items():
            if np.all(np.asarray(c) == 0.0):
                continue
            key = tuple(round(float(e), _EXP_DIGITS) + 0.0 for e in a)
            self.terms[key] = self.terms[key] + c if key in self.terms else c
        self.terms = {a: c for a, c in self.terms.items() if not np.all(np.asarray(c) == 0.0)}

    # --- construction -------------------------------------------------------------------
    @classmethod
    def variable(cls, names: tuple[str, ...], k: int, ref: np.ndarray) -> Signomial:
        a = [0.0] * len(names)
        a[k] = 1.0
        return cls(names, {tuple(a): 1.0}, ref)

    def _const(self, value) -> Signomial:
        return Signomial(self.names, {(0.0,) * len(self.names): value}, self.ref)

    def _lift(self, other) -> Signomial | NotGP | None:
        if isinstance(other, Signomial | NotGP):
            return other
        if isinstance(other, int | float | np.floating | np.integer | np.ndarray):
            return self._const(np.asarray(other, dtype=float) if np.ndim(other) else float(other))
        return None

    # --- properties -------------------------------------------------------------------
    @property
    def shape(self) -> tuple[int, ...]:
        return np.broadcast_shapes(*(np.shape(c) for c in self.terms.values()))

    @property
    def is_constant(self) -> bool:
        return all(not any(a) for a in self.terms)

    def constant_value(self):
        """The value of a constant signomial (0 when empty)."""
        return sum(self.terms.values()) if self.terms else 0.0

    def __float__(self) -> float:
        return float(np.max(np.asarray(self.evaluate(self.ref), dtype=float)))

    def evaluate(self, x: np.ndarray):
        """Numeric value at free-variable vector ``x``."""
        total = 0.0
        for a, c in self.terms.items():
            total = total + c * float(np.prod(np.asarray(x, dtype=float) ** np.array(a)))
        return total

    def describe(self, row: int | None = None, digits: int = 4) -> str:
        """Readable form, e.g. ``0.8660*R - 50`` (coefficients at grid ``row``)."""
        if not self.terms:
            return "0"
        parts = []
        for a, c in self.terms.items():
            c = np.asarray(c, dtype=float)
            val = float(c.ravel()[min(row or 0, c.size - 1)]) if c.ndim else float(c)
            if val == 0.0:
                continue
            factors = []
            for name, e in zip(self.names, a, strict=True):
                if e == 1.0:
                    factors.append(name)
                elif e != 0.0:
                    factors.append(f"{name}^{e:.4g}")
            mono = "*".join(factors)
            mag = f"{abs(val):.{digits}g}"
            text = mag if not mono else (mono if mag == "1" else f"{mag}*{mono}")
            parts.append(("- " if val < 0 else "+ ") + text)
        out = " ".join(parts)
        return out[2:] if out.startswith("+ ") else "-" + out[2:]

    # --- arithmetic -------------------------------------------------------------------
    def __neg__(self):
        return Signomial(self.names, {a: -c for a, c in self.terms.items()}, self.ref)

    def __pos__(self):
        return self

    def __add__(self, other):
        o = self._lift(other)
        if o is None:
            return NotImplemented
        if isinstance(o, NotGP):
            return o
        terms = dict(self.terms)
        for a, c in o.terms.items():
            terms[a] = terms[a] + c if a in terms else c
        return Signomial(self.names, terms, self.ref)

    __radd__ = __add__

    def __sub__(self, other):
        o = self._lift(other)
        if o is None:
            return NotImplemented
        return self + (-o)

    def __rsub__(self, other):
        o = self._lift(other)
        if o is None:
            return NotImplemented
        return o + (-self)

    def __mul__(self, other):
        o = self._lift(other)
        if o is None:
            return NotImplemented
        if isinstance(o, NotGP):
            return o
        terms: dict = {}
        for a, c in self.terms.items():
            for b, d in o.terms.items():
                key = tuple(x + y for x, y in zip(a, b, strict=True))
                terms[key] = terms[key] + c * d if key in terms else c * d
        return Signomial(self.names, terms, self.ref)

    __rmul__ = __mul__

    def _inverse(self):
        if len(self.terms) != 1:
            return NotGP(
                f"division by a sum of terms ({self.describe()}) is not a posynomial",
                self.describe(),
            )
        ((a, c),) = self.terms.items()
        if np.any(np.asarray(c) == 0.0):
            return NotGP(f"division by {self.describe()}, which is zero on the grid")
        return Signomial(self.names, {tuple(-e for e in a): 1.0 / c}, self.ref)

    def __truediv__(self, other):
        o = self._lift(other)
        if o is None:
            return NotImplemented
        if isinstance(o, NotGP):
            return o
        return self * o._inverse()

    def __rtruediv__(self, other):
        o = self._lift(other)
        if o is None:
            return NotImplemented
        return o * self._inverse()

    def __pow__(self, e):
        if isinstance(e, Signomial | NotGP):
            return NotGP("a design variable in an exponent is not a monomial")
        e = float(e)
        if not self.terms:
            return self._const(0.0**e)
        if len(self.terms) == 1:
            ((a, c),) = self.terms.items()
            if e != int(e) and np.any(np.asarray(c) < 0):
                return NotGP(f"({self.describe()})^{e:g} of a negative term", self.describe())
            return Signomial(self.names, {tuple(x * e for x in a): c**e}, self.ref)
        if e == int(e) and 1 <= e <= 6:
            out = self
            for _ in range(int(e) - 1):
                out = out * self
            return out
        signs = {float(np.sign(s)) for c in self.terms.values() for s in np.ravel(c) if s}
        if len(signs) > 1:
            return NotGP(
                f"({self.describe()})^{e:g}: power of a signomial (terms of both signs)",
                self.describe(),
            )
        return NotGP(
            f"({self.describe()})^{e:g}: a power of a sum of terms is not a posynomial "
            "(generalised posynomials are not supported by optdesign's GP builder)",
            self.describe(),
        )

    def __abs__(self):
        signs = [np.asarray(c) for c in self.terms.values()]
        if all(np.all(s >= 0) for s in signs):
            return self
        if all(np.all(s <= 0) for s in signs):
            return -self
        return NotGP(f"|{self.describe()}|: absolute value of a signomial", self.describe())

    # --- NumPy protocol ---------------------------------------------------------------
    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        if method != "__call__" or kwargs.get("out") is not None:
            return NotGP(f"numpy {ufunc.__name__}.{method} on a design variable")
        for x in inputs:
            if isinstance(x, NotGP):
                return x
        if all(not isinstance(x, Signomial) or x.is_constant for x in inputs):
            vals = [x.constant_value() if isinstance(x, Signomial) else x for x in inputs]
            return ufunc(*vals)
        binary: dict[Any, Callable] = {
            np.add: lambda a, b: a + b,
            np.subtract: lambda a, b: a - b,
            np.multiply: lambda a, b: a * b,
            np.true_divide: lambda a, b: a / b,
            np.power: lambda a, b: a**b,
        }
        unary: dict[Any, Callable] = {
            np.negative: lambda a: -a,
            np.positive: lambda a: a,
            np.absolute: abs,
            np.fabs: abs,
            np.sqrt: lambda a: a**0.5,
            np.square: lambda a: a**2,
            np.cbrt: lambda a: a ** (1.0 / 3.0),
        }
        if ufunc in binary and len(inputs) == 2:
            a, b = inputs
            a = a if isinstance(a, Signomial) else self._lift(a)
            return binary[ufunc](a, b)
        if ufunc in unary and len(inputs) == 1:
            return unary[ufunc](inputs[0])
        args = ", ".join(x.describe() if isinstance(x, Signomial) else "..." for x in inputs)
        return NotGP(
            f"{ufunc.__name__}({args}) of a design variable is not a monomial",
            f"{ufunc.__name__}({args})",
        )

    def _reduce_last(self, how: str):
        shape = self.shape
        if not shape:
            return self
        if how != "mean":
            return NotGP(f"{how} over the grid of {self.describe()}")
        return Signomial(
            self.names,
            {a: np.broadcast_to(c, shape).mean(axis=-1) for a, c in self.terms.items()},
            self.ref,
        )

    def mean(self, axis=None, dtype=None, out=None, **_kw):
        return self._reduce_last("mean")

    def max(self, axis=None, out=None, **_kw):
        return self._reduce_last("max")

    def min(self, axis=None, out=None, **_kw):
        return self._reduce_last("min")


# --------------------------------------------------------------------------------------
# GP data (generic: no mechanism below this line is known to the solver)
# --------------------------------------------------------------------------------------
@dataclass
class GPRow:
    """One posynomial row ``sum_k c_k prod_i x_i^A[k, i] <= 1`` (c_k > 0).

    ``name`` and ``label`` identify the constraint block and grid row; ``bound`` and
    ``kind`` ("upper"/"lower") tell how the row was normalised, for reports.
    """

    name: str
    label: str
    A: np.ndarray
    c: np.ndarray
    kind: str = "upper"
    bound: float = 1.0
    unit: str = ""


@dataclass
class DGPCheck:
    """Diagnosis of one objective, constraint block or variable."""

    what: str  # "objective", "constraint", "variable"
    name: str
    ok: bool
    reason: str = ""
    term: str = ""
    cvxpy_is_dgp: bool | None = None

    def describe(self) -> str:
        head = f"{self.what} {self.name}: " + ("DGP" if self.ok else "not DGP")
        if self.ok:
            return head + (f" ({self.reason})" if self.reason else "")
        text = f"{head}: {self.reason}"
        if self.term:
            text += f" [offending term: {self.term}]"
        if self.cvxpy_is_dgp is not None:
            text += f" [cvxpy is_dgp(): {self.cvxpy_is_dgp}]"
        return text


@dataclass
class GPData:
    """A GP in the free variables: min t s.t. objective rows <= t, constraint rows <= 1.

    Attributes
    ----------
    names, lower, upper
        Free variables and their (positive) bounds.
    objective, objective_unit
        Name and unit of the objective; ``objective_rows`` are its posynomial rows
        (the objective is their maximum).
    rows
        Constraint rows, normalised to ``posynomial <= 1``.
    checks
        Diagnosis per objective, constraint block and variable.
    infeasible
        Rows that cannot hold for any positive design (constant rows violated).
    """

    names: list[str]
    lower: np.ndarray
    upper: np.ndarray
    objective: str
    objective_unit: str
    objective_rows: list[GPRow]
    rows: list[GPRow]
    checks: list[DGPCheck]
    infeasible: list[str] = field(default_factory=list)
    n_rows_before_pruning: int = 0

    @property
    def is_gp(self) -> bool:
        """Every diagnosed item is DGP."""
        return all(c.ok for c in self.checks)

    def failures(self) -> list[DGPCheck]:
        return [c for c in self.checks if not c.ok]

    def explain(self) -> str:
        """One line per item that breaks DGP form (empty when it is a GP)."""
        return "\n".join(c.describe() for c in self.failures())


# --------------------------------------------------------------------------------------
# Building
# --------------------------------------------------------------------------------------
def trace(problem: DesignProblem):
    """Evaluate the problem's expressions on signomial tracers (first-order Hertz).

    Returns
    -------
    (Expressions | None, str)
        The traced expressions, or None and the reason when the model raised.
    """
    names = tuple(v.name for v in problem.free)
    ref = problem.midpoint()
    x = [Signomial.variable(names, k, ref) for k in range(len(names))]
    design = problem.design_dict(x)
    try:
        with np.errstate(all="ignore"):
            return problem.expressions(design, first_order=True), ""
    except Exception as exc:  # any model failure means "not traceable"
        return None, f"{type(exc).__name__}: {exc}"


def _rows_of(expr, shape_n: int) -> tuple[list[dict], list[float]]:
    """Per grid row: {exponent tuple: coefficient} of the variable terms, constant part."""
    if not isinstance(expr, Signomial):
        vals = np.broadcast_to(np.asarray(expr, dtype=float), (shape_n,))
        return [{} for _ in range(shape_n)], list(vals)
    terms = {
        a: np.broadcast_to(np.asarray(c, dtype=float), (shape_n,)) for a, c in expr.terms.items()
    }
    rows, consts = [], []
    for r in range(shape_n):
        row = {a: float(c[r]) for a, c in terms.items() if any(a) and c[r] != 0.0}
        const = sum(float(c[r]) for a, c in terms.items() if not any(a))
        rows.append(row)
        consts.append(const)
    return rows, consts


def _fmt_row(names, row: dict, const: float = 0.0) -> str:
    n = len(names)
    terms = dict(row)
    if const:
        terms[(0.0,) * n] = const
    return Signomial(tuple(names), terms, np.ones(n)).describe()


def _as_row(name, label, names, terms: dict, scale: float, kind, bound, unit) -> GPRow:
    keys = list(terms)
    A = np.array(keys, dtype=float).reshape(len(keys), len(names))
    c = np.array([terms[k] for k in keys], dtype=float) / scale
    return GPRow(name, label, A, c, kind, bound, unit)


def _prune(rows: list[GPRow]) -> list[GPRow]:
    """Drop rows implied by another row of the block (same monomials, larger coefficients).

    Row j implies row i when i's monomials are a subset of j's and each coefficient of
    i is at most j's: posy_i <= posy_j <= 1. Keeps the GP small (61 grid rows of a pin
    stress are one active row) and its multipliers readable.
    """
    keep: list[GPRow] = []
    dicts = [dict(zip(map(tuple, r.A), r.c, strict=True)) for r in rows]
    for i, di in enumerate(dicts):
        implied = False
        for j, dj in enumerate(dicts):
            if i == j or not set(di) <= set(dj):
                continue
            if all(di[k] <= dj[k] for k in di) and (
                any(di[k] < dj[k] for k in di) or set(di) != set(dj) or j < i
            ):
                implied = True
                break
        if not implied:
            keep.append(rows[i])
    return keep


def _cvxpy_flag(names, row: dict, const: float) -> bool | None:
    """cvxpy's verdict on a (signomial) row as an expression of positive variables."""
    try:
        import cvxpy as cp

        xs = [cp.Variable(pos=True, name=nm) for nm in names]
        expr = 0
        for a, c in row.items():
            mono = c
            for x, e in zip(xs, a, strict=True):
                if e:
                    mono = mono * x**e
            expr = expr + mono
        if const:
            expr = expr + const
        return bool(expr.is_dgp()) if hasattr(expr, "is_dgp") else None
    except Exception:  # the verdict is an extra, never a failure
        return None


def _classify_block(
    name: str,
    expr,
    lower: float | None,
    upper: float | None,
    labels: list[str],
    unit: str,
    names: list[str],
    n_grid: int,
) -> tuple[DGPCheck, list[GPRow], list[str]]:
    """Rows of ``lower <= expr <= upper`` as GP rows, or the reason why not."""
    if isinstance(expr, NotGP):
        return DGPCheck("constraint", name, False, expr.reason, expr.term), [], []
    n = int(np.prod(expr.shape)) if isinstance(expr, Signomial) else int(np.size(expr))
    n = max(n, 1)
    rows, consts = _rows_of(expr, n)
    labels = labels if len(labels) == n else [""] * n
    out: list[GPRow] = []
    infeasible: list[str] = []
    for r, (row, c0) in enumerate(zip(rows, consts, strict=True)):
        lab = labels[r]
        where = f"{name}[{lab}]" if lab else name
        signs = {np.sign(c) for c in row.values()}
        if not row:  # constant row: holds or not, whatever the design
            v = c0
            if (lower is not None and v < lower - 1e-9 * max(1, abs(lower))) or (
                upper is not None and v > upper + 1e-9 * max(1, abs(upper))
            ):
                infeasible.append(f"{where} = {v:.6g} {unit} outside [{lower}, {upper}]".strip())
            continue
        if len(signs) > 1:
            text = _fmt_row(names, row, c0)
            return (
                DGPCheck(
                    "constraint",
                    name,
                    False,
                    f"{where} is a signomial (terms of both signs): {text}",
                    text,
                    _cvxpy_flag(names, row, c0),
                ),
                [],
                [],
            )
        sign = signs.pop()
        pos = {a: abs(c) for a, c in row.items()}
        # sign * posy + c0 within [lower, upper]  ->  posy vs (bound - c0) / sign
        for bound, kind in ((upper, "upper"), (lower, "lower")):
            if bound is None:
                continue
            rhs = (bound - c0) * sign
            posy_le = (kind == "upper") == (sign > 0)  # posy <= rhs, else posy >= rhs
            if posy_le:
                if rhs <= 0:
                    infeasible.append(f"{where}: {_fmt_row(names, row, c0)} cannot meet {bound}")
                    continue
                out.append(_as_row(name, lab, names, pos, rhs, kind, bound, unit))
            else:
                if rhs <= 0:
                    continue  # a positive posynomial is always >= a non-positive number
                if len(pos) > 1:
                    text = _fmt_row(names, row, c0)
                    side = "lower" if kind == "lower" else "upper"
                    return (
                        DGPCheck(
                            "constraint",
                            name,
                            False,
                            f"{where}: a {side} bound {bound:g} on a sum of terms "
                            f"({text}); posynomial >= constant is not DGP",
                            text,
                            False,
                        ),
                        [],
                        [],
                    )
                ((a, c),) = pos.items()
                inv = {tuple(-e for e in a): rhs / c}
                out.append(_as_row(name, lab, names, inv, 1.0, kind, bound, unit))
    ok_text = f"{len(out)} posynomial rows" if out else "no row depends on the design"
    return DGPCheck("constraint", name, True, ok_text), out, infeasible


def build_gp(problem: DesignProblem, objective: str | None = None) -> GPData:
    """The GP of ``problem`` (first-order Hertz, ISO 286 posynomials), with its diagnosis.

    Never raises for a problem that is not a GP: ``GPData.checks`` says, per objective,
    constraint block and variable, whether it is DGP and, if not, why and which term.
    """
    objective = objective or problem.objective_names[0]
    free = problem.free
    names = [v.name for v in free]
    checks: list[DGPCheck] = []
    for v in free:
        if v.lower is None or v.lower <= 0:
            checks.append(
                DGPCheck(
                    "variable",
                    v.name,
                    False,
                    f"lower bound {v.lower:g} {v.unit} is not positive; GP variables live "
                    "in (0, inf) (log change of variables)",
                    v.name,
                )
            )
        if v.discrete:
            checks.append(
                DGPCheck(
                    "variable",
                    v.name,
                    False,
                    f"takes catalogue values {list(v.values)}; a GP is continuous "
                    "(use --formulation catalogue)",
                    v.name,
                )
            )
    gp = GPData(names, problem.lower(), problem.upper(), objective, "", [], [], checks, [])
    ex, error = trace(problem)
    if ex is None:
        checks.append(DGPCheck("problem", problem.name, False, f"model not traceable ({error})"))
        return gp
    n_grid = len(problem.phi)
    if objective not in ex.objectives:
        checks.append(
            DGPCheck("objective", objective, False, "objective not available for this problem")
        )
        return gp
    term = ex.objectives[objective]
    gp.objective_unit = term.unit
    checks.append(_objective_rows(gp, term.name, term.kind, term.expr, problem, names, n_grid))
    for block in ex.constraints:
        if block.lower is None and block.upper is None:
            continue
        check, rows, infeasible = _classify_block(
            block.name,
            block.expr,
            block.lower,
            block.upper,
            block.labels,
            block.unit,
            names,
            n_grid,
        )
        checks.append(check)
        gp.n_rows_before_pruning += len(rows)
        gp.rows += _prune(rows)
        gp.infeasible += infeasible
    for name, limit in problem.objective_limits().items():
        t = ex.objectives[name]
        if t.kind == "spread":
            value = _constant_spread(t.expr)
            if value is None:
                checks.append(
                    DGPCheck(
                        "constraint",
                        f"{name}_max",
                        False,
                        f"{name} = (max - min)/(max + min) over the grid is a ratio of a "
                        "difference of posynomials",
                        f"{name}",
                        False,
                    )
                )
            elif value > limit:
                gp.infeasible.append(f"{name} = {value:.6g} > {name}_max = {limit:g}")
        else:
            check, rows, infeasible = _classify_block(
                f"{name}_max", t.expr, None, limit, [], t.unit, names, n_grid
            )
            checks.append(check)
            gp.rows += _prune(rows)
            gp.infeasible += infeasible
    return gp


def _constant_spread(expr) -> float | None:
    """(max - min)/(max + min) over the grid when it does not depend on the design."""
    if isinstance(expr, NotGP):
        return None
    if not isinstance(expr, Signomial):
        v = np.asarray(expr, dtype=float)
        return float(m.spread(v.min(), v.max()))
    if len(expr.terms) != 1:
        return None
    ((_, c),) = expr.terms.items()
    c = np.asarray(c, dtype=float)
    if np.any(c <= 0):
        return None
    return float(m.spread(c.min(), c.max()))


def _objective_rows(gp: GPData, name, kind, expr, problem, names, n_grid) -> DGPCheck:
    if isinstance(expr, NotGP):
        return DGPCheck("objective", name, False, expr.reason, expr.term)
    if kind == "spread":
        value = _constant_spread(expr)
        if value is None:
            text = expr.describe() if isinstance(expr, Signomial) else ""
            return DGPCheck(
                "objective",
                name,
                False,
                f"{name} = (max - min)/(max + min) over the grid: a difference of posynomials "
                "divided by a sum is not log-log convex",
                text,
                False,
            )
        # design-independent: the GP only checks feasibility
        gp.objective_rows = [GPRow(name, "", np.zeros((1, len(names))), np.array([value]))]
        return DGPCheck("objective", name, True, f"constant {value:.6g} (design-independent)")
    n = int(np.prod(expr.shape)) if isinstance(expr, Signomial) else int(np.size(expr))
    n = max(n, 1) if kind == "max" else 1
    rows, consts = _rows_of(expr, n)
    labels = problem.phi_labels if n == n_grid else [""] * n
    out = []
    for r, (row, c0) in enumerate(zip(rows, consts, strict=True)):
        terms = dict(row)
        if c0:
            terms[(0.0,) * len(names)] = c0
        if any(c < 0 for c in terms.values()):
            text = _fmt_row(names, row, c0)
            return DGPCheck(
                "objective",
                name,
                False,
                f"{name}[{labels[r]}] has a negative term: {text} (a signomial)",
                text,
                _cvxpy_flag(names, row, c0),
            )
        if not terms:
            continue
        out.append(_as_row(name, labels[r], names, terms, 1.0, "objective", 0.0, ""))
    gp.n_rows_before_pruning += len(out)
    gp.objective_rows = _prune(out)
    shape = "max over the grid of posynomials" if kind == "max" else "posynomial"
    return DGPCheck("objective", name, True, f"{shape}, {len(gp.objective_rows)} rows kept")


def diagnose(problem: DesignProblem, objective: str | None = None) -> list[DGPCheck]:
    """Per objective, constraint block and variable: DGP or not, and why not."""
    return build_gp(problem, objective).checks


def is_gp(problem: DesignProblem, objective: str | None = None) -> bool:
    """True when ``problem`` is a GP (the ``--formulation auto`` predicate)."""
    if any(v.discrete for v in problem.free):
        return False
    if any(v.lower is None or v.lower <= 0 for v in problem.free):
        return False  # cheap test first: no tracing needed
    return build_gp(problem, objective).is_gp


def to_cvxpy(gp: GPData):
    """The cvxpy DGP problem of ``gp``.

    Returns
    -------
    (problem, variables, t, constraints)
        ``constraints`` is a list of (GPRow, cvxpy constraint) including the variable
        bounds (named ``bound:NAME``) and the objective rows (``objective``).
    """
    import cvxpy as cp

    xs = [cp.Variable(pos=True, name=n) for n in gp.names]
    t = cp.Variable(pos=True, name="t")

    def posy(row: GPRow):
        expr = 0
        for a, c in zip(row.A, row.c, strict=True):
            mono = float(c)
            for x, e in zip(xs, a, strict=True):
                if e:
                    mono = mono * x ** float(e)
            expr = expr + mono
        return expr

    cons: list[tuple[GPRow, Any]] = []
    for row in gp.objective_rows:
        cons.append((row, posy(row) <= t))
    for row in gp.rows:
        cons.append((row, posy(row) <= 1.0))
    n = len(gp.names)
    for k, x in enumerate(xs):
        e = np.zeros((1, n))
        e[0, k] = 1.0
        up = GPRow(
            f"bound:{gp.names[k]}", "upper", e, np.array([1.0 / gp.upper[k]]), "upper", gp.upper[k]
        )
        lo = GPRow(
            f"bound:{gp.names[k]}", "lower", -e, np.array([gp.lower[k]]), "lower", gp.lower[k]
        )
        cons.append((up, x <= float(gp.upper[k])))
        cons.append((lo, x >= float(gp.lower[k])))
    prob = cp.Problem(cp.Minimize(t), [c for _, c in cons])
    return prob, xs, t, cons
