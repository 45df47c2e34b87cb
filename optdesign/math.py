"""One public math namespace for two back-ends: CasADi symbols and NumPy arrays.

Every model formula in :mod:`optdesign.models` - and every mechanism, objective or
constraint a user writes - is written once with these functions (``from optdesign import
math as m``).
Called with CasADi ``SX``/``MX``/``DM`` arguments they build CasADi expressions (exact
derivatives for the solvers); called with floats or NumPy arrays they evaluate
numerically with NumPy broadcasting (plots, sweeps, Monte Carlo, NSGA-II).

Conventions for grids: in NumPy mode the deflection grid runs along the *last* axis and
design parameters broadcast against it (e.g. shape ``(pop, 1)`` against ``(n_phi,)``);
in CasADi mode the grid is a column vector and designs are scalars. The aggregations
(:func:`grid_max`, :func:`grid_min`, :func:`grid_mean`) reduce over the grid in both.
"""

from __future__ import annotations

import contextvars
import functools
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

import casadi as ca
import numpy as np

_CASADI_TYPES = (ca.SX, ca.MX, ca.DM)

pi = np.pi

#: Smallest argument of a guarded square root on the CasADi path.
SQRT_GUARD = 1e-12
#: Smallest magnitude of a rate that the solver path divides by (mm/rad): a linkage at a
#: dead point (the nut standing still, dx/dphi = 0) gives huge but finite forces and
#: sensitivities there instead of inf and NaN. No design a requirement admits moves that
#: slowly (the ratio band alone keeps |dx/dphi| above a few mm/rad).
RATE_GUARD = 1e-9


_F = TypeVar("_F", bound=Callable[..., Any])

#: The memo of the innermost :func:`shared_subexpressions` block (None outside one).
_SHARED: contextvars.ContextVar[dict | None] = contextvars.ContextVar(
    "optdesign_shared_subexpressions", default=None
)


@contextmanager
def shared_subexpressions() -> Iterator[None]:
    """Share the results of :func:`shareable` model functions within this block.

    A design problem asks its mechanism for the same quantities many times (the nut
    velocity for the ratio, the nut force and the motor torque; the rod force for the
    pin pressure, the shear and every joint's clearance; ...), and each model function
    rebuilds its own subexpressions. Inside this block a call with the very same argument
    objects returns the first call's result object: on the CasADi path one node of the
    expression graph instead of a copy per use (cs_min_backlash: formulation build
    0.098 -> 0.048 s, the same constraints and, after CSE, the same 4182 instructions),
    on the NumPy path one evaluation. Results are keyed by the identity of the arguments,
    which the memo keeps alive; arrays must not be modified in place inside the block.
    Per thread and per context (``contextvars``); blocks nest.
    """
    token = _SHARED.set({})
    try:
        yield
    finally:
        _SHARED.reset(token)


def shareable(fn: _F) -> _F:
    """Mark a pure model function whose results :func:`shared_subexpressions` may share."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        memo = _SHARED.get()
        if memo is None:
            return fn(*args, **kwargs)
        key = (fn, *map(id, args), *((k, id(v)) for k, v in sorted(kwargs.items())))
        hit = memo.get(key)
        if hit is None:
            hit = memo[key] = ((args, kwargs), fn(*args, **kwargs))
        return hit[1]

    return wrapper  # type: ignore[return-value]


def is_symbolic(*xs: Any) -> bool:
    """True if any argument is a CasADi object (the expression must stay in CasADi)."""
    return any(isinstance(x, _CASADI_TYPES) for x in xs)


def _unary(ca_fn, np_fn):
    def fn(x):
        return ca_fn(x) if isinstance(x, _CASADI_TYPES) else np_fn(x)

    fn.__doc__ = f"Element-wise {np_fn.__name__} on CasADi or NumPy input."
    return fn


sin = _unary(ca.sin, np.sin)
cos = _unary(ca.cos, np.cos)
tan = _unary(ca.tan, np.tan)
sqrt = _unary(ca.sqrt, np.sqrt)
arcsin = _unary(ca.asin, np.arcsin)
arccos = _unary(ca.acos, np.arccos)
arctan = _unary(ca.atan, np.arctan)
exp = _unary(ca.exp, np.exp)
log = _unary(ca.log, np.log)
fabs = _unary(ca.fabs, np.abs)


def sqrt_domain(x):
    """Square root for a quantity that is non-negative wherever the model is valid.

    NumPy path: plain ``sqrt``, NaN outside the domain, so invalid designs show up (a
    linkage that does not assemble there); the NaN is the answer, so NumPy's "invalid
    value" RuntimeWarning is not printed. CasADi path: ``sqrt(fmax(x, 1e-12))`` so that
    a solver's iterate outside the domain never produces NaN, in the value or in its
    derivatives (sqrt'(0) is infinite, and infinity times the zero derivative of fmax is
    NaN); a constraint of the problem keeps the solution inside, where the guard is
    inactive.
    """
    if isinstance(x, _CASADI_TYPES):
        return ca.sqrt(ca.fmax(x, SQRT_GUARD))
    with np.errstate(invalid="ignore"):
        return np.sqrt(x)


def divide_domain(a, b, tiny: float = RATE_GUARD):
    """``a / b`` for a divisor that is non-zero wherever the model is valid (a rate, the
    sine of a transmission angle, a loop's Jacobian determinant): the division's
    counterpart of :func:`sqrt_domain`.

    NumPy path: ``a / b``, NaN where ``b == 0`` (the design is found invalid there, as a
    root of a negative is), without NumPy's "divide by zero" RuntimeWarning. CasADi
    path: ``a / away_from_zero(b, tiny)``, so that a solver's iterate where the divisor
    passes through zero gets a huge, finite value and derivatives instead of inf and NaN;
    ``tiny`` is in the divisor's own unit (default :data:`RATE_GUARD`, 1e-9). Other
    values (the GP diagnosis's tracers) are divided as they are.
    """
    if is_symbolic(a, b):
        return a / away_from_zero(b, tiny)
    if not (_is_numeric(a) and _is_numeric(b)):
        return a / b
    b = np.asarray(b, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(b == 0.0, np.nan, np.divide(a, b))
    return out[()]  # a NumPy scalar for scalar arguments, as the other functions


def _is_numeric(x) -> bool:
    """A number or a NumPy array of numbers (not a CasADi symbol nor a tracer)."""
    return (
        isinstance(x, int | float | np.number | np.ndarray) and np.asarray(x).dtype.kind in "fiub"
    )


def away_from_zero(x, tiny: float = RATE_GUARD):
    """``x`` where ``|x| >= tiny``, else ``tiny`` with the sign of ``x`` (``+tiny`` at 0):
    a divisor that is never zero, for the solver path (guarded mechanisms)."""
    if is_symbolic(x):
        return ca.if_else(ca.fabs(x) < tiny, ca.if_else(x < 0, -tiny, tiny), x)
    x = np.asarray(x, dtype=float)
    return np.where(np.abs(x) < tiny, np.where(x < 0, -tiny, tiny), x)


def arctan2(y, x):
    """Element-wise two-argument arctangent."""
    return ca.atan2(y, x) if is_symbolic(y, x) else np.arctan2(y, x)


def fmax(a, b):
    """Element-wise maximum."""
    return ca.fmax(a, b) if is_symbolic(a, b) else np.maximum(a, b)


def fmin(a, b):
    """Element-wise minimum."""
    return ca.fmin(a, b) if is_symbolic(a, b) else np.minimum(a, b)


def power(x, e):
    """Element-wise power ``x**e``."""
    return x**e


def where(cond, a, b):
    """Element-wise choice: ``a`` where ``cond`` holds, else ``b``."""
    if is_symbolic(cond, a, b):
        return ca.if_else(cond, a, b)
    return np.where(cond, a, b)


def grid_max(x):
    """Maximum over the deflection grid (last axis in NumPy, the column in CasADi)."""
    return ca.mmax(x) if is_symbolic(x) else np.max(x, axis=-1)


def grid_min(x):
    """Minimum over the deflection grid."""
    return ca.mmin(x) if is_symbolic(x) else np.min(x, axis=-1)


def grid_mean(x):
    """Mean over the deflection grid."""
    if is_symbolic(x):
        return ca.sum1(x) / x.shape[0]
    return np.mean(x, axis=-1)


def grid_sum(x):
    """Sum over the deflection grid."""
    return ca.sum1(x) if is_symbolic(x) else np.sum(x, axis=-1)


def spread(lo, hi):
    """Relative spread (hi - lo)/(hi + lo) of a band [lo, hi]: half its width over its
    mid-value (the papers' ratio ripple, [D17]). The one definition of the formula.

    On the CasADi path the divisor is kept away from zero (:func:`away_from_zero`): a
    band centred on zero (a linkage at a dead point, or an iterate of the envelope's
    bounds) gives a huge value instead of inf or NaN; the NumPy path shows it as it is."""
    if is_symbolic(lo, hi):
        return (hi - lo) / away_from_zero(hi + lo)
    return (hi - lo) / (hi + lo)


def grid_spread(x):
    """Spread of ``x`` over the deflection grid, :func:`spread` of its min and max."""
    return spread(grid_min(x), grid_max(x))
