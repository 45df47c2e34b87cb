"""The linear position loop of a drive: transfer functions, frequency response,
bandwidth, margins and stability (docs/loop.md).

The plant and controller are :class:`~optdesign.models.loop_plant.DrivePlant` and
:data:`~optdesign.models.loop_plant.Controller` (a PID :class:`~optdesign.models.
loop_plant.PositionLoop` or a :class:`~optdesign.models.loop_plant.CascadeLoop`), here
with the gap closed and without friction or limits. In the fin coordinate (psi = theta / f', J_1 = J_m f'^2, the motor
torque u acting as f' u on psi):

    J_1 psi'' = f' u - tau,      J_2 phi'' = tau - k_h phi - c_f phi',
    tau = k (psi - phi) + c (psi' - phi')

Laplace transformed, with D_1 = J_1 s^2 + c s + k, D_2 = J_2 s^2 + (c + c_f) s + k + k_h
and the determinant Delta = D_1 D_2 - (c s + k)^2,

    phi / u = f' (c s + k) / Delta,     psi / u = f' D_2 / Delta.

The controller u = G(s) [(kp + ki/s)(r - y) - (kd + kv_i/s) s v], G = 1/(tau_i s + 1)
the current loop, y = phi (``feedback="fin"``) or psi (``"motor"``) the measured angle, v
the angle whose speed is measured (``speed_feedback``: y for the PID, whose kv_i = 0; psi
for the cascade, :class:`~optdesign.models.loop_plant.CascadeLoop`, kv_i its
``speed_ki``). Broken at the torque command the open loop is

    L(s) = ((kp s + ki) N_y(s) + (kd s^2 + kv_i s) N_v(s)) / (s (tau_i s + 1) Delta(s))

(N_y, N_v the numerators of y / u and v / u; without integral action the s cancels and is
left out), and the closed loop from the reference to the fin's angle is

    T(s) = (kp s + ki) f' (c s + k) / (s (tau_i s + 1) Delta + C(s))

with C(s) the numerator of L. For the PID (v = y) it reads (kd s^2 + kp s + ki) N_y. The
speed terms act on the measurement: they are in L but not in T's numerator.

Rigid drive (k -> infinity): phi/u -> f' / ((J_1 + J_2) s^2 + c_f s + k_h), so a PD loop
without lag is the second-order loop omega_n^2 = (f' kp + k_h) / (J_1 + J_2),
2 zeta omega_n = (f' kd + c_f) / (J_1 + J_2).

:func:`loop_response` is the one piece that takes CasADi symbols: L(jw) and T(jw) as real
and imaginary parts, from the plant's quantities as separate arguments, for smooth NLP
rows (|T(j w_bw)|^2 >= 1/2, |1 + L(j w_k)|^2 >= 1/Ms^2 on a grid). The rest is NumPy:
polynomials, poles, bandwidth, margins.

Units: mm, t, s, N, rad (:mod:`optdesign.models.loop_plant`); frequencies in rad/s.

Validity
--------
frequency w : w > 0, finite (call)
    The response is taken on the positive imaginary axis; at w = 0 a loop with integral
    action has L infinite, and negative frequencies only mirror the positive ones.
linear loop : the gap closed, no friction, no saturation (documented)
    The figures hold for motions that keep one flank loaded and the torque below the
    peak; the gap's own effect is :mod:`optdesign.models.loop_backlash`'s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models.loop_plant import FEEDBACKS, Controller, DrivePlant
from optdesign.models.validity import Validity

FREQUENCY = Validity(
    "loop_linear.frequency",
    "linear position loop",
    "frequency w of the response",
    0.0,
    None,
    "rad/s",
    "the response is taken on the positive imaginary axis; a loop with integral action "
    "has an infinite gain at w = 0",
    open_lower=True,
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (FREQUENCY,)

#: Grid points per decade used to bracket crossings before a root refines them.
_POINTS_PER_DECADE = 400

#: A sign change of a function is a root when the function there is this small against
#: its values at the bracket's ends; a sign change through a pole leaves it large.
ROOT_RESIDUAL = 1e-6


# --- the CasADi-ready frequency response ------------------------------------------------
class LoopResponse(NamedTuple):
    """L(jw) and T(jw) as real and imaginary parts (NumPy arrays or CasADi expressions).

    Attributes
    ----------
    open_re, open_im
        The open loop L(jw), broken at the torque command.
    closed_re, closed_im
        The closed loop T(jw) from the reference to the fin's angle.
    """

    open_re: Any
    open_im: Any
    closed_re: Any
    closed_im: Any


def _cmul(a, b):
    return a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]


def _cdiv(a, b):
    den = b[0] * b[0] + b[1] * b[1]
    return (a[0] * b[0] + a[1] * b[1]) / den, (a[1] * b[0] - a[0] * b[1]) / den


def loop_response(
    motor_inertia,
    ratio,
    fin_inertia,
    stiffness,
    damping,
    hinge_spring,
    fin_damping,
    kp,
    kd,
    ki,
    current_lag,
    omega,
    feedback: str = "fin",
    speed_ki=0.0,
    speed_feedback: str | None = None,
) -> LoopResponse:
    """L(jw) and T(jw) of the linear loop, real and imaginary parts apart.

    Every argument but ``feedback`` may be a float, a NumPy array (broadcast) or a CasADi
    symbol: a design-dependent inertia, ratio or stiffness gives a smooth expression.
    Only + - * / are used; the one division is by |s (tau_i s + 1) Delta|^2 for L and by
    |s (tau_i s + 1) Delta + C N_y|^2 for T, nonzero at w > 0 unless the loop has a pole
    on the axis there (an undamped plant's resonance with c = c_f = 0 for L, a marginally
    stable loop for T).

    Parameters
    ----------
    motor_inertia, ratio, fin_inertia, stiffness, damping, hinge_spring, fin_damping
        The :class:`~optdesign.models.loop_plant.DrivePlant` quantities (t*mm^2, motor rad
        per fin rad, t*mm^2, N*mm/rad, N*mm*s/rad, N*mm/rad, N*mm*s/rad).
    kp, kd, ki, current_lag
        The controller's gains (:data:`~optdesign.models.loop_plant.Controller`: motor
        torque per fin angle, N*mm/rad, N*mm*s/rad, N*mm/(rad*s)) and the current loop's
        time constant (s).
    omega
        Frequency w > 0 (rad/s).
    feedback
        ``"fin"`` or ``"motor"``: the measured angle.
    speed_ki
        The integral gain on the measured speed kv_i (N*mm/rad; 0 for a PID).
    speed_feedback
        ``"fin"`` or ``"motor"``: the angle whose speed kd and kv_i read; None: the
        measured angle (the PID's).

    Returns
    -------
    LoopResponse
        Re and Im of L(jw) and T(jw).

    Raises
    ------
    InputError
        ``feedback`` or ``speed_feedback`` unknown, or a numeric ``omega`` infinite or not positive (NaN, a
        design that does not assemble, gives NaN).
    """
    if feedback not in FEEDBACKS:
        raise InputError("feedback", f"expected one of {', '.join(FEEDBACKS)}, got {feedback!r}")
    rate_on = feedback if speed_feedback is None else speed_feedback
    if rate_on not in FEEDBACKS:
        raise InputError(
            "speed_feedback", f"expected one of {', '.join(FEEDBACKS)}, got {speed_feedback!r}"
        )
    if not m.is_symbolic(omega):
        # NaN passes through: a design of a population that does not assemble has no
        # frequency, and its rows are NaN (the NumPy path's answer), not an error
        w_arr = np.asarray(omega, dtype=float)
        if np.any(np.isinf(w_arr)) or np.any(w_arr <= 0):
            raise InputError("omega", f"must be finite and positive (rad/s), got {omega!r}")
    w = omega
    J1 = motor_inertia * ratio**2
    k, c = stiffness, damping
    w2 = w * w
    # at s = jw: D_1, D_2, the coupling (c s + k) and Delta = D_1 D_2 - coupling^2
    d1 = (k - J1 * w2, c * w)
    d2 = (k + hinge_spring - fin_inertia * w2, (c + fin_damping) * w)
    cp = (k, c * w)
    prod = _cmul(d1, d2)
    cp2 = _cmul(cp, cp)
    delta = (prod[0] - cp2[0], prod[1] - cp2[1])
    n_phi = (ratio * cp[0], ratio * cp[1])
    n_psi = (ratio * d2[0], ratio * d2[1])
    n_y = n_phi if feedback == "fin" else n_psi
    # s (tau_i s + 1) Delta: the integrator's s is kept in both L and T; it cancels in L's
    # value when ki = 0, and keeps one formula for every gain
    s_lag = _cmul((0.0 * w, w), (1.0 + 0.0 * w, current_lag * w))
    den_open = _cmul(s_lag, delta)
    ref = (ki + 0.0 * w, kp * w)  # kp s + ki
    if rate_on != feedback:  # the cascade's speed on the motor, its angle on the fin
        rate = (-kd * w2, speed_ki * w)  # kd s^2 + kv_i s
        on_y, on_v = _cmul(ref, n_y), _cmul(rate, n_psi if rate_on == "motor" else n_phi)
        num_open = (on_y[0] + on_v[0], on_y[1] + on_v[1])
    else:
        # kd s^2 + (kp + kv_i) s + ki at s = jw; a PID's kv_i = 0 is left out, so that its
        # expressions (and an NLP's graph) are the ones without the speed term
        gain = kp if _is_zero(speed_ki) else kp + speed_ki
        num_open = _cmul((ki - kd * w2, gain * w), n_y)
    L = _cdiv(num_open, den_open)
    char = (den_open[0] + num_open[0], den_open[1] + num_open[1])
    T = _cdiv(_cmul(ref, n_phi), char)
    return LoopResponse(L[0], L[1], T[0], T[1])


def _is_zero(x) -> bool:
    """True for a number (or array) that is 0 everywhere; a CasADi symbol is not."""
    return not m.is_symbolic(x) and bool(np.all(np.asarray(x) == 0.0))


def closed_loop_gain_squared(response: LoopResponse):
    """|T(jw)|^2 of a :func:`loop_response` (smooth; >= 1/2 at the bandwidth's frequency)."""
    return response.closed_re**2 + response.closed_im**2


def return_difference_squared(response: LoopResponse):
    """|1 + L(jw)|^2 of a :func:`loop_response` (smooth; >= 1/Ms^2 on a grid is a modulus
    margin: the Nyquist curve stays outside the circle of radius 1/Ms about -1)."""
    return (1.0 + response.open_re) ** 2 + response.open_im**2


def plant_arguments(plant: DrivePlant, loop: Controller) -> dict[str, float]:
    """The keyword arguments of :func:`loop_response` from the two records (no omega)."""
    return {
        "motor_inertia": plant.motor_inertia,
        "ratio": plant.ratio,
        "fin_inertia": plant.fin_inertia,
        "stiffness": plant.stiffness,
        "damping": plant.damping,
        "hinge_spring": plant.hinge_spring,
        "fin_damping": plant.fin_damping,
        "kp": loop.kp,
        "kd": loop.kd,
        "ki": loop.ki,
        "current_lag": loop.current_lag,
        "feedback": loop.feedback,
        "speed_ki": loop.speed_ki,
        "speed_feedback": loop.speed_feedback,
    }


def frequency_response(plant: DrivePlant, loop: Controller, omega) -> tuple[np.ndarray, np.ndarray]:
    """L(jw) and T(jw) as complex NumPy arrays at ``omega`` (rad/s, > 0)."""
    with np.errstate(divide="ignore", invalid="ignore"):  # an undamped pole on the axis
        r = loop_response(**plant_arguments(plant, loop), omega=np.asarray(omega, dtype=float))
    L = np.asarray(r.open_re) + 1j * np.asarray(r.open_im)
    T = np.asarray(r.closed_re) + 1j * np.asarray(r.closed_im)
    return L, T


# --- polynomials ---------------------------------------------------------------------------
@dataclass(frozen=True)
class LoopPolynomials:
    """The loop's transfer functions as polynomial coefficients, highest power first.

    Attributes
    ----------
    open_numerator, open_denominator
        L(s), broken at the torque command.
    closed_numerator, closed_denominator
        T(s), reference to the fin's angle; ``closed_denominator`` is the characteristic
        polynomial (its roots are the closed loop's poles).
    """

    open_numerator: np.ndarray
    open_denominator: np.ndarray
    closed_numerator: np.ndarray
    closed_denominator: np.ndarray


def _trim(p: np.ndarray) -> np.ndarray:
    nz = np.flatnonzero(p)
    return p[nz[0] :] if nz.size else np.zeros(1)


def _mul(a, b) -> np.ndarray:
    # numpy.polymul's product without its poly1d round trip, which trims leading zeros
    # at three times the cost of the product: a loop analysis builds these polynomials
    # thousands of times (a population's bandwidths), and the zeros are trimmed once, below
    return np.convolve(np.asarray(a, dtype=float), np.asarray(b, dtype=float))


def loop_polynomials(plant: DrivePlant, loop: Controller) -> LoopPolynomials:
    """L(s) and T(s) of the linear loop as polynomial coefficients (module docstring).

    Without integral action (ki = 0) the common factor s is left out of L and T (kv_i, if
    any, is then a gain on v itself).
    """
    J1, J2 = plant.motor_inertia_at_fin, plant.fin_inertia
    k, c, fr = plant.stiffness, plant.damping, plant.ratio
    d1 = np.array([J1, c, k])
    d2 = np.array([J2, c + plant.fin_damping, k + plant.hinge_spring])
    coupling = np.array([c, k])
    delta = np.polysub(_mul(d1, d2), _mul(coupling, coupling))
    n_phi = fr * coupling
    n_psi = fr * d2
    n_y = n_phi if loop.feedback == "fin" else n_psi
    lag = np.array([loop.current_lag, 1.0])
    kp, kd, ki, kv_i = loop.kp, loop.kd, loop.ki, loop.speed_ki
    integral = ki > 0
    ref, s = (np.array([kp, ki]), [1, 0]) if integral else (np.array([kp]), [1])
    rate = np.array([kd, kv_i, 0.0] if integral else [kd, kv_i])  # (kd s + kv_i) s^q
    den_open = _mul(_mul(s, lag), delta)
    if loop.speed_feedback == loop.feedback:
        # one polynomial on y, kd s^2 + (kp + kv_i) s + ki (as the PID's was built)
        ctrl = np.array([kd, kp + kv_i, ki] if integral else [kd, kp + kv_i])
        num_open = _mul(ctrl, n_y)
    else:
        n_v = n_psi if loop.speed_feedback == "motor" else n_phi
        num_open = np.polyadd(_mul(ref, n_y), _mul(rate, n_v))
    char = np.polyadd(den_open, num_open)
    return LoopPolynomials(_trim(num_open), _trim(den_open), _trim(_mul(ref, n_phi)), _trim(char))


def scaled_roots(coefficients) -> np.ndarray:
    """numpy.roots after the substitution s = w0 x, w0 = |a_0 / a_n|^(1/n) (a_n the
    leading coefficient, a_0 the last nonzero one), so that the scaled roots sit near
    |x| = 1: a drive's polynomials span twenty decades in their coefficients."""
    p = _trim(np.asarray(coefficients, dtype=float))
    nz = np.flatnonzero(p)
    zeros_at_origin = len(p) - 1 - nz[-1]
    p = p[: nz[-1] + 1]
    n = len(p) - 1
    if n < 1:
        return np.zeros(zeros_at_origin)
    w0 = abs(p[-1] / p[0]) ** (1.0 / n)
    scaled = p * w0 ** np.arange(n + 1)[::-1]
    return np.concatenate([np.roots(scaled / scaled[0]) * w0, np.zeros(zeros_at_origin)])


def closed_loop_poles(plant: DrivePlant, loop: Controller) -> np.ndarray:
    """The closed loop's poles (rad/s), the roots of its characteristic polynomial."""
    return scaled_roots(loop_polynomials(plant, loop).closed_denominator)


def is_stable(plant: DrivePlant, loop: Controller) -> bool:
    """True when every closed-loop pole lies in the open left half-plane.

    A pole counts as on the axis (not stable) when its real part is above -1e-9 times
    its modulus: the roots' own relative precision.
    """
    p = closed_loop_poles(plant, loop)
    return bool(np.all(p.real < -1e-9 * np.maximum(np.abs(p), 1e-300)))


# --- frequency-domain figures ------------------------------------------------------------
def frequency_range(plant: DrivePlant, loop: Controller) -> tuple[float, float]:
    """Frequencies that hold every crossing (rad/s): two decades beyond the loop's
    corners (the moduli of the poles and zeros of L and T)."""
    pol = loop_polynomials(plant, loop)
    corners = np.abs(
        np.concatenate(
            [
                scaled_roots(pol.open_numerator),
                scaled_roots(pol.open_denominator),
                scaled_roots(pol.closed_denominator),
            ]
        )
    )
    corners = corners[corners > 0]
    return float(corners.min() * 1e-2), float(corners.max() * 1e2)


def _grid(plant: DrivePlant, loop: Controller) -> np.ndarray:
    lo, hi = frequency_range(plant, loop)
    return np.geomspace(lo, hi, int(np.log10(hi / lo) * _POINTS_PER_DECADE) + 2)


def _roots_of(fn, w: np.ndarray) -> list[float]:
    """Sign changes of fn on the grid w, each refined by brentq.

    A sign change through a pole (an undamped plant's resonance on the axis) is no root:
    it is dropped when brentq meets a non-finite value or ends on a value that is not
    small against the bracket's.
    """
    from scipy.optimize import brentq

    v = fn(w)
    out = []
    for i in np.flatnonzero(np.isfinite(v[:-1]) & np.isfinite(v[1:]) & (v[:-1] * v[1:] <= 0)):
        if v[i + 1] == 0.0:
            continue
        if v[i] == 0.0:
            out.append(float(w[i]))
            continue
        try:
            x = brentq(fn, w[i], w[i + 1], xtol=1e-14, rtol=1e-13)
        except ValueError:  # a NaN on the way: the bracket holds a pole
            continue
        fx = fn(x)
        if np.isfinite(fx) and abs(fx) <= ROOT_RESIDUAL * max(abs(v[i]), abs(v[i + 1])):
            out.append(float(x))
    return out


def bandwidth(plant: DrivePlant, loop: Controller) -> float:
    """The closed loop's bandwidth (rad/s): the first frequency where |T(jw)| falls to
    |T(0)| / sqrt(2), half the static gain's power (python-control's ``bandwidth`` with
    ``dbdrop = -3.0103``; its default -3 dB is 0.1 % higher).

    |T(0)| is 1 with integral action and fin feedback, k / (k + k_h) with integral action
    and motor feedback (the hinge load deflects the chain outside the loop); without
    integral action it is f' kp k / (k k_h + f' kp (k + k_h)) for motor feedback and
    f' kp / (f' kp + k_h) for fin feedback. Returns ``inf`` if |T| never falls that low.
    """
    pol = loop_polynomials(plant, loop)
    t0 = abs(np.polyval(pol.closed_numerator, 0.0) / np.polyval(pol.closed_denominator, 0.0))
    level = t0 / np.sqrt(2.0)

    def gap(x):
        return np.abs(frequency_response(plant, loop, x)[1]) - level

    roots = _roots_of(gap, _grid(plant, loop))
    return roots[0] if roots else float("inf")


@dataclass(frozen=True)
class Margins:
    """Stability margins of L and the resonance peak of T.

    Attributes
    ----------
    gain_margin
        1/|L(j w_pc)| at the phase crossover whose margin is nearest 1 in log (python-
        control's choice); ``inf`` if the phase never crosses -180 deg.
    phase_crossover
        w_pc (rad/s); ``nan`` without one.
    phase_margin
        180 deg + arg L(j w_gc) (deg) at the gain crossover of smallest |margin|;
        ``inf`` if |L| never crosses 1.
    gain_crossover
        w_gc (rad/s); ``nan`` without one.
    stability_margin
        min |1 + L(jw)| (1/Ms, the modulus margin), and its frequency.
    resonance_peak
        max |T(jw)| (a plain gain; 1.0 at the static gain of a type-1 loop), and its
        frequency.
    """

    gain_margin: float
    phase_crossover: float
    phase_margin: float
    gain_crossover: float
    stability_margin: float
    stability_margin_frequency: float
    resonance_peak: float
    resonance_frequency: float


def _minimum(fn, w: np.ndarray) -> tuple[float, float]:
    """(min fn, argmin) on the grid, refined on the neighbouring interval."""
    from scipy.optimize import minimize_scalar

    v = fn(w)
    i = int(np.nanargmin(v))
    lo, hi = w[max(i - 1, 0)], w[min(i + 1, len(w) - 1)]
    res = minimize_scalar(
        lambda x: float(fn(np.exp(x))),
        bounds=(np.log(lo), np.log(hi)),
        method="bounded",
        options={"xatol": 1e-12},
    )
    if res.fun < v[i]:
        return float(res.fun), float(np.exp(res.x))
    return float(v[i]), float(w[i])


def margins(plant: DrivePlant, loop: Controller) -> Margins:
    """Gain and phase margins of L, the modulus margin, and T's resonance peak.

    Crossings are bracketed on a log grid over :func:`frequency_range` (400 points per
    decade) and refined by brentq; the extremes by a bounded scalar minimisation.
    """

    def L(x):
        return frequency_response(plant, loop, x)[0]

    def T(x):
        return frequency_response(plant, loop, x)[1]

    w = _grid(plant, loop)
    pcs = [x for x in _roots_of(lambda x: L(x).imag, w) if L(x).real < 0]
    gms = [1.0 / abs(L(x)) for x in pcs]
    if gms:
        i = int(np.argmin(np.abs(np.log(gms))))
        gm, wpc = gms[i], pcs[i]
    else:
        gm, wpc = float("inf"), float("nan")
    gcs = _roots_of(lambda x: np.abs(L(x)) - 1.0, w)
    pms = [float(np.remainder(np.angle(L(x), deg=True), 360.0) - 180.0) for x in gcs]
    if pms:
        i = int(np.argmin(np.abs(pms)))
        pm, wgc = pms[i], gcs[i]
    else:
        pm, wgc = float("inf"), float("nan")
    sm, wsm = _minimum(lambda x: np.abs(1.0 + L(x)), w)
    neg_peak, wr = _minimum(lambda x: -np.abs(T(x)), w)
    return Margins(float(gm), float(wpc), pm, float(wgc), sm, wsm, -neg_peak, wr)


def rigid_natural_frequency(plant: DrivePlant, loop: Controller) -> float:
    """omega_n = sqrt((f' kp + k_h) / (J_1 + J_2)) (rad/s): the closed loop of a rigid
    drive under P control (the module's docstring); ``nan`` when f' kp + k_h <= 0."""
    num = plant.ratio * loop.kp + plant.hinge_spring
    if num <= 0:
        return float("nan")
    return float(np.sqrt(num / (plant.motor_inertia_at_fin + plant.fin_inertia)))
