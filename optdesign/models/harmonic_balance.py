"""Limit cycles of a linear loop closed through a nonlinearity, by harmonic balance
(docs/loop.md).

The loop: a nonlinearity N (:mod:`optdesign.models.describing_function`) in series with
a linear open loop L(s), under negative feedback. A sinusoid of amplitude A and frequency
w at the nonlinearity's input comes back unchanged when

    1 + N(A) L(jw) = 0,   i.e.   L(jw) = -1/N(A)

the crossing of the Nyquist curve of L with the curve -1/N(A) (Gelb and Vander Velde
1968, [GVV68] in docs/references.md). Two routes:

* N real (saturation, dead zone): -1/N(A) runs along the negative real axis, from -1 to
  -inf (N in (0, 1]). The cycles sit at the phase crossovers w180 (Im L(jw180) = 0,
  Re L < 0), each where N(A) = -1/L(jw180) can be met (|L(jw180)| > 1): one bracketed
  root in w, then one in A.
* N complex (backlash): a 2-D root of 1 + N(A) L(jw) in (A, w). Starts from the
  crossings of the two curves sampled on grids (A/b from 1 + 1e-8 to 1e6, w over the
  loop's range), each refined by ``scipy.optimize.root``; the residual 1 + N L, not
  L + 1/N, stays bounded as A -> b, where N -> 0.

Stability of a cycle: Loeb's criterion (as [GVV68] give it). Write
P(A, w) = 1 + N(A) L(jw) = U + jV. A cycle at P = 0 is stable (a slightly larger
amplitude decays, a smaller one grows) when

    dU/dA dV/dw - dU/dw dV/dA > 0

(perturb s = jw to sigma + jw, the amplitude growing as exp(sigma t); L analytic in s
makes dP/ds = -j dP/dw, and d sigma / dA = -det / |dP/dw|^2: a stable cycle has
d sigma / dA < 0). Multiplying P
by a function of A alone (P/N = L + 1/N) scales the determinant by |1/N|^2 > 0: the
verdict does not depend on the form. It is the graphical rule: the cycle is stable when
the -1/N curve, followed towards larger A, leaves the region the Nyquist curve encircles.
A determinant within 1e-9 of the product of the derivatives' moduli is reported as
undecided (a tangency: the prediction itself is doubtful there).

Units: w in rad/s, A in the unit of the nonlinearity's input (rad for a backlash at the
fin), L a plain gain from the nonlinearity's output back to its input.

What is found: cycles whose frequency lies in the loop's range (``omega_range``) and,
for backlash, whose amplitude lies in the grid above; crossings nearer than the grids
resolve (a near-tangency) can be missed. A loop that is unstable as a linear system at
N = 1 (the gain the nonlinearity has at large amplitude) is not diagnosed here: a cycle
is a balance of the first harmonic, not a proof that trajectories reach it.

Validity
--------
filter hypothesis : |L(3jw)| / |L(jw)| <= 0.1 at the cycle (documented)
    The describing function keeps the fundamental only. A saturation's output at large
    amplitude is a square wave, whose third harmonic is 1/3 of the fundamental; a loop
    that passes 1/10 of the third harmonic's gain puts at most about 3 % of the
    fundamental back into the input, the order of the describing function's error. Above
    it the amplitude and frequency are estimates only (docs/loop.md); each
    :class:`LimitCycle` carries the ratio.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from optdesign.errors import InputError
from optdesign.models.describing_function import Backlash, DeadZone, Saturation
from optdesign.models.validity import Validity

FILTER_HYPOTHESIS = Validity(
    "harmonic_balance.filter_hypothesis",
    "describing-function harmonic balance",
    "third-harmonic gain |L(3jw)| / |L(jw)| at the cycle",
    0.0,
    0.1,
    "",
    "the describing function keeps the fundamental only: a loop passing 1/10 of the third "
    "harmonic's gain puts back at most about 3 % of the fundamental (a square wave's third "
    "harmonic is 1/3 of it)",
    checked=("documented",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (FILTER_HYPOTHESIS,)

#: Backlash amplitudes searched, A/b - 1 (log-spaced): from just outside the gap, where
#: -1/N runs to -j inf, to where N is within 1e-6 of 1.
_BACKLASH_EXCESS = (1e-8, 1e6)
#: Relative size of a determinant below which Loeb's criterion does not decide.
_UNDECIDED = 1e-9


# --- the linear loop ---------------------------------------------------------------------
@dataclass(frozen=True)
class Loop:
    """A linear open loop L, evaluated on the imaginary axis.

    Build it with :func:`polynomial_loop` or :func:`callable_loop`.

    Parameters
    ----------
    response
        w (rad/s, an array) -> L(jw) (complex array of the same shape).
    omega_range
        (w_min, w_max), rad/s: where cycles are sought.
    numerator, denominator
        The polynomials (highest power first) of a :func:`polynomial_loop`, else None.
    """

    response: Callable[[np.ndarray], np.ndarray]
    omega_range: tuple[float, float]
    numerator: tuple[float, ...] | None = None
    denominator: tuple[float, ...] | None = None

    def __call__(self, omega) -> np.ndarray:
        """L(jw) at ``omega`` (rad/s)."""
        return np.asarray(self.response(np.asarray(omega, dtype=float)), dtype=complex)

    def derivative(self, omega) -> np.ndarray:
        """dL(jw)/dw: exact for polynomials (j dL/ds), else a central difference."""
        w = np.asarray(omega, dtype=float)
        if self.numerator is not None and self.denominator is not None:
            n, d = np.poly1d(self.numerator), np.poly1d(self.denominator)
            s = 1j * w
            return 1j * (n.deriv()(s) * d(s) - n(s) * d.deriv()(s)) / d(s) ** 2
        h = 1e-6 * np.maximum(np.abs(w), 1e-12)
        return (self(w + h) - self(w - h)) / (2.0 * h)


def _omega_range(omega_range) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in omega_range)
    except (TypeError, ValueError):
        raise InputError(
            "omega_range", f"must be two numbers (rad/s), got {omega_range!r}"
        ) from None
    if not (np.isfinite(lo) and np.isfinite(hi) and 0.0 < lo < hi):
        raise InputError("omega_range", f"must be 0 < w_min < w_max, finite, got {omega_range!r}")
    return lo, hi


def _coefficients(field: str, values) -> tuple[float, ...]:
    try:
        arr = np.atleast_1d(np.asarray(values, dtype=float))
    except (TypeError, ValueError):
        raise InputError(field, f"must be real polynomial coefficients, got {values!r}") from None
    if arr.ndim != 1 or arr.size == 0 or not np.all(np.isfinite(arr)):
        raise InputError(field, f"must be finite coefficients, highest power first, got {values!r}")
    nonzero = np.flatnonzero(arr)
    if nonzero.size == 0:
        raise InputError(field, "is the zero polynomial")
    return tuple(arr[nonzero[0] :])


def polynomial_loop(
    numerator: Sequence[float], denominator: Sequence[float], omega_range=None
) -> Loop:
    """L(s) = numerator(s) / denominator(s), coefficients highest power first.

    ``omega_range`` defaults to two decades beyond the loop's corner frequencies (the
    moduli of its nonzero poles and zeros), (1e-2, 1e2) rad/s if it has none. The loop
    must be proper (deg numerator <= deg denominator): the describing function needs a
    loop that filters the harmonics. Raises InputError naming the argument.
    """
    num = _coefficients("numerator", numerator)
    den = _coefficients("denominator", denominator)
    if len(num) > len(den):
        raise InputError(
            "numerator",
            f"degree {len(num) - 1} above the denominator's {len(den) - 1}: an improper "
            "loop amplifies the harmonics the describing function drops",
        )
    if omega_range is None:
        corners = np.abs(np.concatenate([np.roots(num), np.roots(den)]))
        corners = corners[corners > 1e-12 * max(1.0, corners.max(initial=0.0))]
        omega_range = (1e-2 * corners.min(), 1e2 * corners.max()) if corners.size else (1e-2, 1e2)
    n, d = np.poly1d(num), np.poly1d(den)
    return Loop(lambda w: n(1j * w) / d(1j * w), _omega_range(omega_range), num, den)


def callable_loop(response: Callable[[np.ndarray], np.ndarray], omega_range) -> Loop:
    """A loop given as a function w (rad/s, array) -> L(jw), sought over ``omega_range``."""
    if not callable(response):
        raise InputError("response", f"must be a function w -> L(jw), got {response!r}")
    lo, hi = _omega_range(omega_range)
    probe = np.asarray(response(np.array([lo, hi])))
    if probe.shape != (2,):
        raise InputError("response", f"must map an array of w to one of L(jw), got {probe!r}")
    return Loop(response, (lo, hi))


# --- the answer --------------------------------------------------------------------------
@dataclass(frozen=True)
class LimitCycle:
    """One solution of 1 + N(A) L(jw) = 0.

    Attributes
    ----------
    amplitude
        A at the nonlinearity's input (its unit).
    frequency
        w, rad/s.
    describing_function
        N(A).
    loop_response
        L(jw) (= -1/N(A) to the solver's precision).
    loeb
        dU/dA dV/dw - dU/dw dV/dA of P = 1 + N L (module docstring).
    stability
        "stable", "unstable" or "undecided" (Loeb's criterion; undecided at a tangency).
    third_harmonic_gain
        |L(3jw)| / |L(jw)|: the filter hypothesis, FILTER_HYPOTHESIS (<= 0.1).
    """

    amplitude: float
    frequency: float
    describing_function: complex
    loop_response: complex
    loeb: float
    stability: str
    third_harmonic_gain: float

    @property
    def stable(self) -> bool:
        return self.stability == "stable"

    @property
    def filter_hypothesis_holds(self) -> bool:
        return bool(FILTER_HYPOTHESIS.contains(self.third_harmonic_gain))


@dataclass(frozen=True)
class HarmonicBalance:
    """Every limit cycle found, by increasing frequency, or none and why.

    Attributes
    ----------
    cycles
        The solutions (may be empty).
    reason
        Why there is none ("" when there are cycles).
    omega_range
        The frequencies searched, rad/s.
    """

    cycles: tuple[LimitCycle, ...]
    reason: str
    omega_range: tuple[float, float]

    @property
    def none(self) -> bool:
        return not self.cycles


def _cycle(loop: Loop, nl, A: float, w: float) -> LimitCycle:
    N = complex(nl.describing_function(A))
    Lw = complex(loop(w))
    P_A = complex(nl.derivative(A)) * Lw
    P_w = N * complex(loop.derivative(w))
    det = (np.conj(P_A) * P_w).imag  # = Re(P_A) Im(P_w) - Re(P_w) Im(P_A)
    if abs(det) <= _UNDECIDED * abs(P_A) * abs(P_w):
        verdict = "undecided"
    else:
        verdict = "stable" if det > 0 else "unstable"
    third = abs(complex(loop(3.0 * w))) / abs(Lw)
    return LimitCycle(float(A), float(w), N, Lw, float(det), verdict, float(third))


def _grid(loop: Loop, points: int) -> tuple[np.ndarray, np.ndarray]:
    w = np.geomspace(*loop.omega_range, points)
    with np.errstate(all="ignore"):
        L = loop(w)
    if L.shape != w.shape:
        raise InputError("loop", f"L(jw) has shape {L.shape} for {w.shape} frequencies")
    return w, L


# --- real N: the phase crossovers --------------------------------------------------------
def _real_route(loop: Loop, nl: Saturation | DeadZone, points: int) -> HarmonicBalance:
    from scipy.optimize import brentq

    w, L = _grid(loop, points)
    im = L.imag
    ok = np.isfinite(L)
    crossing = np.flatnonzero(ok[:-1] & ok[1:] & (np.sign(im[:-1]) * np.sign(im[1:]) <= 0))
    roots: list[float] = []
    for k in crossing:
        if im[k] == 0.0:
            wk = float(w[k])
        elif im[k + 1] == 0.0:
            continue  # the next interval starts on it
        else:
            wk = brentq(lambda x: float(loop(x).imag), w[k], w[k + 1], xtol=1e-15, rtol=1e-14)
        Lk = complex(loop(wk))
        # a sign change through a pole on the axis is no crossing
        if np.isfinite(Lk) and abs(Lk.imag) <= 1e-8 * abs(Lk) + 1e-300:
            roots.append(wk)
    if not roots:
        return HarmonicBalance(
            (),
            "the loop's phase never crosses -180 deg in the range: the Nyquist curve "
            "never meets -1/N(A), which lies on the negative real axis",
            loop.omega_range,
        )
    cycles, seen = [], []
    for wk in roots:
        Lk = complex(loop(wk)).real
        seen.append(f"L(j{wk:.6g}) = {Lk:.6g}")
        if Lk < -1.0:  # N = -1/L in (0, 1): a saturation or a dead zone reaches it
            cycles.append(_cycle(loop, nl, nl.amplitude(-1.0 / Lk), wk))
    if not cycles:
        return HarmonicBalance(
            (),
            "at every phase crossover the loop gain is below 1 or the curve crosses the "
            f"positive axis ({'; '.join(seen)}): -1/N(A) <= -1 is never reached",
            loop.omega_range,
        )
    return HarmonicBalance(tuple(cycles), "", loop.omega_range)


# --- complex N: a 2-D root from the curves' crossings ------------------------------------
def _crossings(P: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices (i, k) and fractions where segment P[i]P[i+1] meets Q[k]Q[k+1]."""
    p0, dp = P[:-1, None], np.diff(P)[:, None]
    q0, dq = Q[None, :-1], np.diff(Q)[None, :]
    det = dp.real * dq.imag - dp.imag * dq.real
    r = q0 - p0
    with np.errstate(all="ignore"):
        s = (r.real * dq.imag - r.imag * dq.real) / det
        t = (r.real * dp.imag - r.imag * dp.real) / det
    hit = (det != 0) & np.isfinite(s) & np.isfinite(t) & (s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)
    i, k = np.nonzero(hit)
    return np.stack([i, k]), np.stack([s[i, k], t[i, k]])


def _complex_route(loop: Loop, nl: Backlash, points: int) -> HarmonicBalance:
    from scipy.optimize import root

    b = nl.threshold
    excess = np.geomspace(*_BACKLASH_EXCESS, max(points // 8, 200))
    A = b * (1.0 + excess)
    minus_inv = -1.0 / nl.describing_function(A)
    w, L = _grid(loop, points)
    ok = np.isfinite(L)
    (i, k), (s, t) = _crossings(minus_inv, np.where(ok, L, np.nan))
    lo_x, hi_x = np.log(_BACKLASH_EXCESS)
    lo_w, hi_w = np.log(loop.omega_range)

    def residual(z):
        A_, w_ = b * (1.0 + np.exp(z[0])), np.exp(z[1])
        r = 1.0 + complex(nl.describing_function(A_)) * complex(loop(w_))
        return [r.real, r.imag]

    found: list[tuple[float, float]] = []
    for ii, kk, ss, tt in zip(i, k, s, t, strict=True):
        z0 = [
            np.log(excess[ii]) + ss * np.log(excess[ii + 1] / excess[ii]),
            np.log(w[kk]) + tt * np.log(w[kk + 1] / w[kk]),
        ]
        sol = root(residual, z0, method="hybr", options={"xtol": 1e-14})
        z = sol.x
        # judged by the residual: hybr's own flag reports a tight xtol it could not
        # improve on at a root it has already reached
        if not (np.all(np.isfinite(z)) and np.hypot(*residual(z)) < 1e-10):
            continue
        if not (lo_x - 1.0 <= z[0] <= hi_x and lo_w - 1e-9 <= z[1] <= hi_w + 1e-9):
            continue
        A_, w_ = b * (1.0 + np.exp(z[0])), float(np.exp(z[1]))
        if any(abs(A_ - a) <= 1e-7 * a and abs(w_ - v) <= 1e-7 * v for a, v in found):
            continue
        found.append((A_, w_))
    if not found:
        return HarmonicBalance(
            (),
            "the Nyquist curve does not meet -1/N(A) for A/b in (1 + 1e-8, 1e6) and w in "
            f"({loop.omega_range[0]:.6g}, {loop.omega_range[1]:.6g}) rad/s: no amplitude "
            "balances the loop's gain and phase together",
            loop.omega_range,
        )
    found.sort(key=lambda aw: aw[1])
    return HarmonicBalance(tuple(_cycle(loop, nl, a, v) for a, v in found), "", loop.omega_range)


def harmonic_balance(
    loop: Loop, nonlinearity: Saturation | DeadZone | Backlash, points: int = 4000
):
    """The limit cycles of ``loop`` closed through ``nonlinearity`` (negative feedback).

    Parameters
    ----------
    loop
        The linear open loop, :func:`polynomial_loop` or :func:`callable_loop`.
    nonlinearity
        :class:`~optdesign.models.describing_function.Saturation` or
        :class:`~optdesign.models.describing_function.DeadZone` (real N: the phase
        crossovers) or :class:`~optdesign.models.describing_function.Backlash` (complex
        N: a 2-D root solve).
    points
        Frequencies sampled over ``loop.omega_range`` (log-spaced) to bracket the
        crossings, 100 to 10^6.

    Returns
    -------
    HarmonicBalance
        Every cycle found with its Loeb verdict and filter check, or none and why.
    """
    if not isinstance(loop, Loop):
        raise InputError("loop", f"must be a Loop (polynomial_loop, callable_loop), got {loop!r}")
    if not isinstance(points, int | np.integer) or not 100 <= points <= 1_000_000:
        raise InputError("points", f"must be an integer in [100, 1e6], got {points!r}")
    if isinstance(nonlinearity, Saturation | DeadZone):
        return _real_route(loop, nonlinearity, int(points))
    if isinstance(nonlinearity, Backlash):
        return _complex_route(loop, nonlinearity, int(points))
    raise InputError(
        "nonlinearity", f"must be a Saturation, a DeadZone or a Backlash, got {nonlinearity!r}"
    )
