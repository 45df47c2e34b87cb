"""The motor's limits beyond one peak and one rated torque (docs/motor.md): the intermittent
speed-torque envelope above a corner speed, and the first-order thermal model of the
winding over a periodic duty cycle.

Speed-torque envelope. A servomotor's datasheet draws two zones in the speed-torque plane:
the continuous one (under the rated torque) and the intermittent one, whose upper edge is
the peak torque up to a corner speed n_c and then falls - the drive's voltage no longer
pushes the peak current against the back-EMF - to a torque T_top at the top speed n_max.
Taken as straight between the corner and the top speed (the usual way of reading such a
curve into a sizing tool), the torque available at speed n (0 <= n <= n_max) is

    T_av(n) = min(T_peak, T_peak - s (n - n_c)),     s = (T_peak - T_top) / (n_max - n_c)

(:func:`available_torque`). With only the corner given, T_top is the rated torque: the
two zones meet at the top speed. The envelope is the minimum of two straight lines, so a
demand (n, T) lies under it exactly when it lies under both: T <= T_peak and
T + s n <= T_peak + s n_c (:func:`envelope_intercept`), each a linear inequality - a
smooth NLP row, exact, without the kink at the corner.

Thermal model. A winding of thermal time constant tau heats as a first-order lag of the
loss, proportional to the torque squared: tau dx/dt = T(t)^2 - x, x the torque whose
square gives the current temperature rise at steady state (the maker's tau is the time a
cold motor takes to reach 63 % of its final rise under a constant load). The motor holds
when x <= T_rated^2 at every instant. For a cycle of steps of torque T_i held for t_i,
repeated, the periodic steady state has a closed form (:func:`thermal_weights`): x at
the end of each step is a weighted mean of the T_i^2, with weights that sum to 1 and
tend to t_i / sum t_j (the plain RMS) when the cycle is short against tau and to 1 on the
step itself (the step's own torque) when it is long. Within a step x moves monotonically
towards T_i^2, so its peak over the cycle is at the end of a step.

Pure functions through :mod:`optdesign.math` (numbers, NumPy arrays or CasADi symbols)
except :func:`thermal_weights`, whose inputs are the problem's numbers.

Validity
--------
envelope speed : 0 <= n <= n_max
    The envelope is drawn up to the top speed only; the problem's speed row keeps the
    motor below it (:func:`available_torque` gives NaN above).
thermal time constant : tau > 0
    A lag needs a positive time constant (checked by :func:`thermal_weights`). One lump:
    the motor's tau describes the whole motor; a winding loaded far above its rated
    current heats faster than it (its own, shorter constant), so a cycle of short steps
    far above the rated torque is better checked with the winding's constant.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models._checks import require_positive
from optdesign.models.validity import Validity

ENVELOPE_SPEED = Validity(
    "motor_limits.envelope_speed",
    "speed-torque envelope",
    "motor speed / top speed",
    0.0,
    1.0,
    "",
    "the datasheet's envelope ends at the top speed; the speed row keeps the motor below it",
    checked=("documented",),
)
THERMAL_TIME_CONSTANT = Validity(
    "motor_limits.thermal_time_constant",
    "first-order thermal model",
    "thermal time constant tau",
    0.0,
    None,
    "s",
    "a lag needs a positive time constant",
    open_lower=True,
    checked=("file", "call"),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (ENVELOPE_SPEED, THERMAL_TIME_CONSTANT)


def envelope_slope(peak_torque, corner_speed, max_speed, top_torque):
    """s = (T_peak - T_top) / (n_max - n_c): how fast the intermittent torque falls above
    the corner (N*mm per rad/s); 0 for a motor whose envelope does not fall."""
    return (peak_torque - top_torque) / (max_speed - corner_speed)


def envelope_intercept(peak_torque, corner_speed, slope):
    """T_peak + s n_c: the falling line's torque extended back to standstill (N*mm). A
    demand (n, T) lies under the falling piece when T + s n <= this."""
    return peak_torque + slope * corner_speed


def available_torque(speed, peak_torque, corner_speed, max_speed, top_torque):
    """The intermittent torque the motor gives at ``speed`` (rad/s, its magnitude), N*mm:
    the peak torque up to the corner speed, then falling linearly to ``top_torque`` at
    ``max_speed``. Not defined above the top speed (NaN there, NumPy)."""
    s = envelope_slope(peak_torque, corner_speed, max_speed, top_torque)
    n = m.fabs(speed)
    out = m.fmin(peak_torque, envelope_intercept(peak_torque, corner_speed, s) - s * n)
    if m.is_symbolic(out):
        return out
    return np.where(np.asarray(n) <= max_speed * (1.0 + 1e-12), out, np.nan)


def thermal_weights(durations, tau: float) -> np.ndarray:
    """W with x_k = sum_i W[k, i] T_i^2, x_k the filtered squared torque at the end of step
    k in the periodic steady state of tau dx/dt = T(t)^2 - x over steps of ``durations``
    (s, each > 0) repeated (``tau`` in s, > 0).

    Stepping through step i, x goes from x_start to a_i x_start + (1 - a_i) T_i^2 with
    a_i = exp(-t_i / tau); around the cycle, x_k = sum_i (1 - a_i) P_ki T_i^2 / (1 - A),
    with P_ki the product of a_j over the steps after i up to k (cyclically; 1 for i = k)
    and A the product of all a_j. The 1 - a are written with expm1, so that a cycle many
    orders shorter than tau keeps its digits (the weights then tend to t_i / sum t_j).
    Each row of W sums to 1."""
    t = np.asarray(durations, dtype=float).ravel()
    if t.size == 0:
        raise InputError("durations", "no step")
    if not np.all(np.isfinite(t)) or np.any(t <= 0):
        raise InputError("durations", f"every step must last a positive time, got {t.tolist()}")
    require_positive("tau", tau)
    n = t.size
    r = t / tau
    one_minus_a = -np.expm1(-r)
    one_minus_A = -np.expm1(-r.sum())
    W = np.empty((n, n))
    for k in range(n):
        for i in range(n):
            # the steps after i up to k, going forward around the cycle
            after = [(i + j) % n for j in range(1, (k - i) % n + 1)]
            W[k, i] = one_minus_a[i] * np.exp(-r[after].sum()) / one_minus_A
    return W


def thermal_torque_squares(torques: Any, durations, tau: float) -> list[Any]:
    """x_k = sum_i W[k, i] T_i^2 at the end of each step (N^2*mm^2): the torque squared
    whose steady heating equals the winding's at that instant (:func:`thermal_weights`).
    ``torques`` one value per step (numbers, arrays over designs or CasADi expressions)."""
    T = list(torques)
    W = thermal_weights(durations, tau)
    if len(T) != W.shape[0]:
        raise InputError("durations", f"{W.shape[0]} durations for {len(T)} torques")
    squares = [Ti**2 for Ti in T]
    return [sum(float(W[k, i]) * squares[i] for i in range(len(T))) for k in range(len(T))]


def thermal_torque(torques: Any, durations, tau: float):
    """The duty cycle's thermal equivalent torque (N*mm, NumPy): sqrt of the largest x_k
    of :func:`thermal_torque_squares`, the torque a constant load would need to heat the
    winding as much as the cycle's hottest instant. It lies between the plain RMS torque
    (tau much longer than the cycle) and the largest step torque (much shorter); the
    motor holds when it is at most the rated torque."""
    squares = [np.asarray(x, dtype=float) for x in thermal_torque_squares(torques, durations, tau)]
    return np.sqrt(np.max(np.stack(squares), axis=0))
