"""Geometric-programming (GP) formulation of a design problem, and its DGP diagnosis.

A design problem is a GP when, after the change of variables ``y = log x``, every
objective and constraint row is a posynomial bounded above (or a monomial bounded on
either side). Two things make that true for some of optdesign's problems: Hertz
flattening taken to first order (b^2/D, a monomial) and the ISO 286 fit formulas
(posynomials in D, :mod:`optdesign.models.fit_formulas`).

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

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.objective_refusals import smooth_form_refusal
from optdesign.programs.signomial import NotGP, Signomial

__all__ = ["DGPCheck", "GPData", "GPRow", "NotGP", "Signomial", "build_gp", "is_gp"]


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
        # a number of the NumPy path (a row no free variable enters, e.g. the loop's
        # post-solve checks) may come as one design's row, (1, n)
        vals = np.broadcast_to(np.asarray(expr, dtype=float).reshape(-1), (shape_n,))
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
                    side = "a lower" if kind == "lower" else "an upper"
                    return (
                        DGPCheck(
                            "constraint",
                            name,
                            False,
                            f"{where}: {side} bound {bound:g} on a sum of terms "
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
                    "(use formulation='catalogue')",
                    v.name,
                )
            )
    gp = GPData(names, problem.lower(), problem.upper(), objective, "", [], [], checks, [])
    info = problem.objectives.get(objective)
    refusal = smooth_form_refusal(problem, objective, "a GP")
    if not refusal and info is not None and info.not_posynomial:
        refusal = f"{objective} is {info.not_posynomial}"
    if refusal:
        checks.append(DGPCheck("objective", objective, False, refusal))
        return gp
    if info is not None and info.bound_rows is not None:
        # a root of the model (the closed loop's bandwidth): no expression of the design,
        # let alone a posynomial; only an NLP can pose its implicit epigraph rows
        checks.append(
            DGPCheck(
                "objective",
                objective,
                False,
                f"{objective} is a root of the model (bounded by implicit rows), not a "
                "posynomial of the design; use formulation='nlp' or 'catalogue'",
            )
        )
        return gp
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
    if not out:  # 0 at every design: cvxpy's min t would be "unbounded", not an optimum
        return DGPCheck(
            "objective",
            name,
            False,
            f"{name} is 0 whatever the design: a GP minimises a positive posynomial",
            name,
        )
    gp.n_rows_before_pruning += len(out)
    gp.objective_rows = _prune(out)
    shape = "max over the grid of posynomials" if kind == "max" else "posynomial"
    return DGPCheck("objective", name, True, f"{shape}, {len(gp.objective_rows)} rows kept")


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
