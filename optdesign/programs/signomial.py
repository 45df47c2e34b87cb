"""Signomial tracers: the models evaluated on exact sums of monomials, for the GP.

cvxpy expressions cannot go through the models (NumPy ufuncs such as ``np.abs`` raise on
cvxpy objects) and cvxpy never merges like terms, so ``R tan(30) - R tan(-30)`` (a
monomial) would stay a non-DGP difference. :class:`Signomial` tracers are exact sums of
monomials ``c x^a`` with NumPy coefficients over the deflection grid, closed under +, -,
*, /, ** and ``abs``, merging like terms as they go; whatever they cannot represent (cos
of a design variable, division by a sum, ``max``) becomes a :class:`NotGP` value that
carries the reason and the offending sub-term to the block that uses it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

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
        if not parts:  # every coefficient is zero at this grid row
            return "0"
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
            # shown at a grid row where it is not zero: at the others it reads "0"
            shown = self.describe(int(np.flatnonzero(np.ravel(c))[0]))
            return NotGP(f"division by {shown}, which is zero on the grid", shown)
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
