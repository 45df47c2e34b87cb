"""Sinusoidal-input describing functions of the drive's nonlinearities: backlash and
saturation (docs/loop.md).

A nonlinearity driven by x(t) = A sin(w t) puts out a periodic y(t); its describing
function is the complex gain of the fundamental,

    N(A) = (b1 + j a1) / A,   b1 = (1/pi) int y sin(wt) d(wt),  a1 = (1/pi) int y cos(wt) d(wt)

(Gelb and Vander Velde 1968 [GVV68], the sinusoidal-input describing function). For the
two nonlinearities here N depends on the amplitude A only, not on the frequency: the
backlash is friction-controlled (the output holds still while the input crosses the gap)
and the saturation is static.

Conventions
-----------
Backlash, half-width ``b``: the input moves 2b (the total width, the gap end to end)
between the two contacts. The output follows the input at a distance b while it pushes
and holds still while the gap is crossed. With r = b / A and A > b,

    Re N = 1/2 + (1/pi) [asin(1 - 2r) + 2 (1 - 2r) sqrt(r (1 - r))]
    Im N = -(4/pi) r (1 - r)

the output lags: Im N < 0. python-control's ``friction_backlash_nonlinearity(b_pc)``
writes the same function with the *total* width b_pc = 2b (its deadband is +-b_pc/2):
python-control's "N(b_pc) = 0.5 - j/pi" is N(A = 2b) here (r = 1/2).
For A <= b the input never closes the gap after the first contact, the output stands
still and its fundamental is zero: N(A) = 0, the limit of the formula (continuous at
A = b, where Re N and Im N both vanish). N -> 1 as A -> infinity (the gap is lost in the
stroke).

Saturation, unit slope, limit ``c`` (y = x for |x| <= c, c sign(x) beyond): with u = c/A,

    N(A) = 1                                                   A <= c
    N(A) = (2/pi) [asin(u) + u sqrt(1 - u^2)]                  A > c

real, falling from 1 to 4c/(pi A) at large A.

Dead zone, unit slope, half-width ``b`` (y = 0 for |x| <= b, x - b sign(x) beyond): the
input less a unit saturation at b, so N is one less the saturation's,

    N(A) = 0                                                   A <= b
    N(A) = 1 - (2/pi) [asin(r) + r sqrt(1 - r^2)],  r = b/A     A > b

real, rising from 0 to 1. It is the elastic backlash of a chain with compliance (the
chain's spring k acts on the deflection less the gap, k dz(x)): unlike the
friction-controlled backlash above, the output side has its own inertia and moves in
the gap, and the chain's torque is a single-valued function of the deflection. Gating a
damping c x' to the contact (c x' where |x| > b) gives the same fundamental, N(A) c x',
so the whole contact torque k dz(x) + c x' 1{|x| > b} has the describing function
N(A) (k + j w c) (docs/loop.md).

Units: the amplitude A is in the unit of the nonlinearity's input, the one ``b`` and
``c`` are given in (rad for an angular backlash at the fin: the project's internal
unit); N is a plain number. Frequencies do not enter (see
:mod:`optdesign.models.harmonic_balance` for the loop, in rad/s).

The filter hypothesis. N keeps the fundamental and drops the harmonics: it describes the
loop only where the linear part filters them out, |L(3jw)| << |L(jw)| at the cycle's
frequency w. It is weak (a) near A = b for backlash, where the output is a train of short
pushes, rich in harmonics, and the fundamental is small; (b) at large A for saturation,
where the output approaches a square wave, whose third harmonic is 1/3 of the
fundamental; (c) when the loop has a resonance near 3w or 5w (a drive's elastic mode
above the loop's bandwidth can amplify exactly the harmonics the hypothesis drops),
and (d) for a loop with little roll-off (a PD loop with a fast derivative). There the
predicted amplitude and frequency are estimates, and a cycle predicted near a tangency
of the two curves may not exist (or one may exist that is not predicted).
:mod:`optdesign.models.harmonic_balance` reports |L(3jw)| / |L(jw)| with each cycle.

Validity
--------
amplitude A : A >= 0, finite (call)
    A sinusoid's amplitude; the functions refuse a negative or non-finite one.
backlash amplitude : A / b > 1 (documented)
    Below, the gap is never crossed after the first contact: N = 0 is the limit the
    functions return, not a describing function of a moving output.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from optdesign.errors import InputError
from optdesign.models._checks import require_nonnegative, require_positive
from optdesign.models.validity import Validity

AMPLITUDE = Validity(
    "describing_function.amplitude",
    "describing function",
    "input amplitude A",
    0.0,
    None,
    "",
    "a sinusoid's amplitude is a non-negative, finite number",
    checked=("call",),
)
BACKLASH_AMPLITUDE = Validity(
    "describing_function.backlash_amplitude",
    "backlash describing function",
    "amplitude over half-width A / b",
    1.0,
    None,
    "",
    "below, the output never moves after the first contact: N = 0 is a limit, not the "
    "fundamental of a moving output",
    open_lower=True,
    checked=("documented",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (AMPLITUDE, BACKLASH_AMPLITUDE)


def _amplitude(A) -> np.ndarray:
    require_nonnegative("A", A)
    return np.asarray(A, dtype=float)


# --- backlash ----------------------------------------------------------------------------
def backlash_df(A, b):
    """Describing function N(A) of a friction-controlled backlash of half-width ``b``.

    Parameters
    ----------
    A : float or array_like
        Input amplitude (>= 0, in the unit of ``b``).
    b : float
        Half-width of the gap (>= 0): the input travels 2b between the contacts.
        python-control's ``friction_backlash_nonlinearity`` takes the total, 2b.

    Returns
    -------
    complex or numpy.ndarray of complex
        N(A), shaped as ``A``; 0 where A <= b (the output never moves).

    Raises
    ------
    InputError
        ``A`` negative or not finite, ``b`` negative or not finite.
    """
    A = _amplitude(A)
    require_nonnegative("b", b)
    b = float(b)
    moving = A > b
    # r in (0, 1) where the output moves; elsewhere a harmless placeholder
    r = np.where(moving, b / np.where(moving, A, 1.0), 0.5)
    x = 1.0 - 2.0 * r
    real = 0.5 + (np.arcsin(x) + 2.0 * x * np.sqrt(r * (1.0 - r))) / np.pi
    imag = -4.0 / np.pi * r * (1.0 - r)
    out = np.where(moving, real + 1j * imag, 0.0 + 0.0j)
    return out[()] if out.ndim == 0 else out


def backlash_df_derivative(A, b):
    """dN/dA of :func:`backlash_df` (per unit of A): 0 where A <= b.

    With r = b/A: d Re N/dA = (8 r / (pi A)) sqrt(r (1 - r)), d Im N/dA =
    (4 r / (pi A)) (1 - 2 r). Same arguments and errors as :func:`backlash_df`.
    """
    A = _amplitude(A)
    require_nonnegative("b", b)
    b = float(b)
    moving = A > b
    Am = np.where(moving, A, 1.0)
    r = np.where(moving, b / Am, 0.5)
    d_real = 8.0 * r / (np.pi * Am) * np.sqrt(r * (1.0 - r))
    d_imag = 4.0 * r / (np.pi * Am) * (1.0 - 2.0 * r)
    out = np.where(moving, d_real + 1j * d_imag, 0.0 + 0.0j)
    return out[()] if out.ndim == 0 else out


# --- saturation --------------------------------------------------------------------------
def saturation_df(A, c):
    """Describing function N(A) of a unit-slope saturation at +-``c`` (real).

    Parameters
    ----------
    A : float or array_like
        Input amplitude (>= 0, in the unit of ``c``).
    c : float
        Output limit (> 0).

    Returns
    -------
    float or numpy.ndarray
        N(A) in (0, 1], shaped as ``A``; 1 where A <= c (the input never reaches the limit).

    Raises
    ------
    InputError
        ``A`` negative or not finite, ``c`` not positive or not finite.
    """
    A = _amplitude(A)
    require_positive("c", c)
    c = float(c)
    limited = A > c
    u = np.where(limited, c / np.where(limited, A, 1.0), 1.0)
    out = np.where(limited, 2.0 / np.pi * (np.arcsin(u) + u * np.sqrt(1.0 - u * u)), 1.0)
    return out[()] if out.ndim == 0 else out


def saturation_df_derivative(A, c):
    """dN/dA of :func:`saturation_df`: -(4/pi)(u/A) sqrt(1 - u^2) with u = c/A, 0 where
    A <= c (the left derivative at A = c is 0 as well: N is C^1 there)."""
    A = _amplitude(A)
    require_positive("c", c)
    c = float(c)
    limited = A > c
    Al = np.where(limited, A, 1.0)
    u = np.where(limited, c / Al, 1.0)
    out = np.where(limited, -4.0 / np.pi * u / Al * np.sqrt(1.0 - u * u), 0.0)
    return out[()] if out.ndim == 0 else out


def saturation_amplitude(N, c) -> float:
    """The amplitude A > c at which :func:`saturation_df` equals ``N`` (0 < N < 1).

    N falls strictly from 1 at A = c, and N(A) < (1 + 2/pi) c / A, so the root lies in
    (c, 2c/N): a bracketed root (brentq). Raises InputError naming ``N`` outside (0, 1).
    """
    from scipy.optimize import brentq

    require_positive("c", c)
    if not (np.isfinite(N) and 0.0 < N < 1.0):
        raise InputError("N", f"a saturation's describing function lies in (0, 1), got {N!r}")
    c, N = float(c), float(N)
    x = brentq(lambda s: float(saturation_df(s, 1.0)) - N, 1.0, 2.0 / N, xtol=1e-15, rtol=1e-15)
    return c * x


# --- dead zone --------------------------------------------------------------------------
def dead_zone_df(A, b):
    """Describing function N(A) of a unit-slope dead zone of half-width ``b`` (real).

    Parameters
    ----------
    A : float or array_like
        Input amplitude (>= 0, in the unit of ``b``).
    b : float
        Half-width (> 0): the output is zero while |x| <= b.

    Returns
    -------
    float or numpy.ndarray
        N(A) = 1 - :func:`saturation_df` (A, b), in [0, 1), shaped as ``A``.

    Raises
    ------
    InputError
        ``A`` negative or not finite, ``b`` not positive or not finite.
    """
    return 1.0 - saturation_df(A, b)


def dead_zone_df_derivative(A, b):
    """dN/dA of :func:`dead_zone_df`: (4/pi)(r/A) sqrt(1 - r^2), r = b/A; 0 where A <= b."""
    return -saturation_df_derivative(A, b)


def dead_zone_amplitude(N, b) -> float:
    """The amplitude A > b at which :func:`dead_zone_df` equals ``N`` (0 < N < 1)."""
    if not (np.isfinite(N) and 0.0 < N < 1.0):
        raise InputError("N", f"a dead zone's describing function lies in (0, 1), got {N!r}")
    return saturation_amplitude(1.0 - float(N), b)


# --- the nonlinearities as records -------------------------------------------------------
@dataclass(frozen=True)
class Backlash:
    """A friction-controlled backlash of half-width ``half_width`` (total 2 x half_width).

    Parameters
    ----------
    half_width
        b > 0, in the unit of the loop signal it acts on (rad at the fin).
    """

    half_width: float

    def __post_init__(self):
        require_positive("half_width", self.half_width)

    #: N is complex: the harmonic balance solves for A and w together.
    real = False

    @property
    def threshold(self) -> float:
        """The amplitude below which N is constant (0: the gap is never crossed)."""
        return float(self.half_width)

    def describing_function(self, A):
        """N(A), :func:`backlash_df`."""
        return backlash_df(A, self.half_width)

    def derivative(self, A):
        """dN/dA, :func:`backlash_df_derivative`."""
        return backlash_df_derivative(A, self.half_width)


@dataclass(frozen=True)
class Saturation:
    """A unit-slope saturation at +-``limit``.

    Parameters
    ----------
    limit
        c > 0, in the unit of the loop signal it acts on (a torque, a current, ...).
    """

    limit: float

    def __post_init__(self):
        require_positive("limit", self.limit)

    #: N is real: the harmonic balance goes through the phase crossovers.
    real = True

    @property
    def threshold(self) -> float:
        """The amplitude below which N is constant (1: the limit is never reached)."""
        return float(self.limit)

    def describing_function(self, A):
        """N(A), :func:`saturation_df`."""
        return saturation_df(A, self.limit)

    def derivative(self, A):
        """dN/dA, :func:`saturation_df_derivative`."""
        return saturation_df_derivative(A, self.limit)

    def amplitude(self, N) -> float:
        """The amplitude where N(A) = ``N``, :func:`saturation_amplitude`."""
        return saturation_amplitude(N, self.limit)


@dataclass(frozen=True)
class DeadZone:
    """A unit-slope dead zone of half-width ``half_width``: the elastic backlash of a
    compliant chain, on the chain's deflection.

    Parameters
    ----------
    half_width
        b > 0, in the unit of the loop signal it acts on (rad at the fin).
    """

    half_width: float

    def __post_init__(self):
        require_positive("half_width", self.half_width)

    #: N is real: the harmonic balance goes through the phase crossovers.
    real = True

    @property
    def threshold(self) -> float:
        """The amplitude below which N is constant (0: the gap is never closed)."""
        return float(self.half_width)

    def describing_function(self, A):
        """N(A), :func:`dead_zone_df`."""
        return dead_zone_df(A, self.half_width)

    def derivative(self, A):
        """dN/dA, :func:`dead_zone_df_derivative`."""
        return dead_zone_df_derivative(A, self.half_width)

    def amplitude(self, N) -> float:
        """The amplitude where N(A) = ``N``, :func:`dead_zone_amplitude`."""
        return dead_zone_amplitude(N, self.half_width)
