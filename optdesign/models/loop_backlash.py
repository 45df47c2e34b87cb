"""Limit cycles the chain's clearance sustains in the position loop, by harmonic balance
(docs/loop.md).

The model of the clearance. The chain of a :class:`~optdesign.models.loop_plant.DrivePlant`
is elastic: its torque at the fin is k (|d| - b) + c d' in contact (d = psi - phi the
deflection, b the half-gap), zero in the gap, and the fin has its own inertia, so it moves
in the gap. That is a dead zone on the spring's deflection, not the friction-controlled
backlash of :class:`~optdesign.models.describing_function.Backlash` (a rigid chain
whose output holds still while the gap is crossed). A sinusoidal deflection d = A sin wt
through the dead zone gives the torque's fundamental N(A) (k + j w c) d, N the dead zone's
real describing function (:func:`~optdesign.models.describing_function.dead_zone_df`):
the damping gated to the contact has the same N as the spring.

Lur'e form. Cut the loop at the dead zone: its input is d, its output v, and the chain's
torque is (k + c s) v. With the reference at zero, D_2 = J_2 s^2 + c_f s + k_h (the fin
on its air spring, without the chain), J_1 = J_m f'^2 and the controller and current loop
(:mod:`optdesign.models.loop_linear`'s rational form) split by the angle each term reads,
u = -K_phi phi - K_psi psi: for the PID K(s) = G(s)(kd s^2 + kp s + ki)/s on the measured
angle; for the cascade G(s)(kp s + ki)/s on the measured angle and G(s)(kd s^2 + kv_i s)/s
on psi (the motor's speed),

    phi = (k + c s) v / D_2,
    J_1 s^2 psi = -f' (K_phi phi + K_psi psi) - (k + c s) v,

so d = psi - phi = -L_d(s) v with

    L_d = (k + c s) (J_1 s^2 + D_2 + f' (K_phi + K_psi)) / ((J_1 s^2 + f' K_psi) D_2)

(fin feedback: K_psi = 0; motor feedback: K_phi = 0).

At N = 1 (the gap closed), 1 + L_d = 0 is the linear loop's characteristic equation of
:mod:`optdesign.models.loop_linear`. A cycle is 1 + N(A) L_d(jw) = 0: N is real in [0, 1),
so w is a phase crossover of L_d with L_d(jw) < -1, and A the amplitude of the
deflection where N(A) = -1/L_d(jw). The fin swings with N A |k + j w c| / |D_2(jw)|.

Not in the model: friction and the motor's limits (the linear loop's), the contact's
"never pulling" clip (a damped contact pulls briefly when it opens fast; small for a
lightly damped chain), a bias that keeps one flank in contact (a hinge load: the cycle
is then about an offset; here it is symmetric about the gap's centre).

Units: mm, t, s, N, rad; amplitudes in rad at the fin, frequencies in rad/s.

Validity
--------
loop gain at the cycle : |L_d(j w)| >= 1.3 at the cycle's phase crossover (documented)
    The cycle's deflection is A ~ (4/pi) b / (1 - 1/|L_d|): near |L_d| = 1 a small error
    of the describing function in the loop's gain becomes a large one in A (10 times at
    |L_d| = 1.1). Against the simulation (docs/loop.md) the fin's amplitude came within
    6 % where |L_d| >= 1.3 and 10.5 % off at 1.12; the frequency within 5 % throughout.
    Each cycle's |L_d| is 1 / N, N its ``balance.describing_function``.
filter hypothesis : :mod:`optdesign.models.harmonic_balance`'s (documented)
    Every cycle carries its third-harmonic gain; near the chain's resonance it is about
    0.11, at the edge of that range.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models.describing_function import DeadZone
from optdesign.models.harmonic_balance import (
    HarmonicBalance,
    LimitCycle,
    harmonic_balance,
    polynomial_loop,
)
from optdesign.models.loop_linear import frequency_range
from optdesign.models.loop_plant import CONTROLLERS, Controller, DrivePlant
from optdesign.models.validity import Validity

LOOP_GAIN = Validity(
    "loop_backlash.loop_gain",
    "chain clearance limit cycle",
    "|L_d(jw)| at the cycle's phase crossover",
    1.3,
    None,
    "",
    "the cycle's amplitude goes as b / (1 - 1/|L_d|): near 1 an error in the loop's gain "
    "becomes a large one in the amplitude (within 6 % of the simulation above 1.3, 10.5 % "
    "off at 1.12)",
    checked=("documented",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (LOOP_GAIN,)


def _parts(plant: DrivePlant, loop: Controller):
    """The plant's pieces and f' K_phi, f' K_psi's numerators over s_lag = s^q (tau_i s + 1)
    (None for an angle no term reads)."""
    J1 = plant.motor_inertia_at_fin
    d2 = np.array([plant.fin_inertia, plant.fin_damping, plant.hinge_spring])
    motor = np.array([J1, 0.0, 0.0])
    lag = np.array([loop.current_lag, 1.0])
    kp, kd, ki, kv_i = loop.kp, loop.kd, loop.ki, loop.speed_ki
    integral = ki > 0
    s = np.array([1.0, 0.0]) if integral else np.array([1.0])
    s_lag = np.polymul(s, lag)
    terms: dict[str, np.ndarray | None] = {"fin": None, "motor": None}
    if loop.speed_feedback == loop.feedback:
        # the PID's kd s^2 + kp s + ki (kv_i = 0 adds nothing), all on the measured angle
        ctrl = np.array([kd, kp + kv_i, ki] if integral else [kd, kp + kv_i])
        terms[loop.feedback] = plant.ratio * ctrl
    else:
        ref = np.array([kp, ki] if integral else [kp])
        rate = np.array([kd, kv_i, 0.0] if integral else [kd, kv_i])
        terms[loop.feedback] = plant.ratio * ref
        terms[loop.speed_feedback] = plant.ratio * rate
    return J1, d2, motor, s_lag, terms["fin"], terms["motor"]


def deflection_loop(plant: DrivePlant, loop: Controller) -> tuple[np.ndarray, np.ndarray]:
    """L_d(s), the linear part seen by the chain's dead zone (module docstring), as
    (numerator, denominator) coefficients, highest power first."""
    _, d2, motor, s_lag, f_phi, f_psi = _parts(plant, loop)
    chain = np.array([plant.damping, plant.stiffness])
    inner = np.polymul(s_lag, np.polyadd(motor, d2))
    for term in (f_phi, f_psi):
        if term is not None:
            inner = np.polyadd(inner, term)
    num = np.polymul(chain, inner)
    motor_side = np.polymul(s_lag, motor)
    if f_psi is not None:
        motor_side = np.polyadd(motor_side, f_psi)
    den = np.polymul(motor_side, d2)
    return np.trim_zeros(num, "f"), np.trim_zeros(den, "f")


def _fin_per_deflection(plant: DrivePlant, w: float, N: float) -> complex:
    """phi / d at a cycle: N (k + j w c) / D_2(jw)."""
    d2 = plant.hinge_spring - plant.fin_inertia * w * w + 1j * plant.fin_damping * w
    return N * (plant.stiffness + 1j * w * plant.damping) / d2


@dataclass(frozen=True)
class BacklashCycle:
    """One limit cycle of the chain's clearance in the loop.

    Attributes
    ----------
    fin_amplitude
        Amplitude of the fin's angle (rad).
    motor_amplitude
        Amplitude of the motor's angle seen at the fin, theta / f' (rad).
    deflection_amplitude
        Amplitude A of the chain's deflection psi - phi (rad), > b.
    frequency
        w (rad/s).
    stable
        Loeb's verdict: a stable cycle is the one a loop settles in (an unstable one is
        a threshold: a larger disturbance grows to the next stable cycle or diverges).
    balance
        The harmonic balance's record (N, L_d(jw), Loeb's determinant, third-harmonic
        gain |L_d(3jw)| / |L_d(jw)|).
    """

    fin_amplitude: float
    motor_amplitude: float
    deflection_amplitude: float
    frequency: float
    stable: bool
    balance: LimitCycle


@dataclass(frozen=True)
class BacklashCycles:
    """The limit cycles the chain's clearance can sustain, or none and why.

    Attributes
    ----------
    cycles
        By increasing frequency (may be empty).
    reason
        Why there is none ("" when there are cycles).
    backlash
        The half-gap b at the fin (rad).
    harmonic_balance
        The underlying :class:`~optdesign.models.harmonic_balance.HarmonicBalance` (None
        without backlash).
    """

    cycles: tuple[BacklashCycle, ...]
    reason: str
    backlash: float
    harmonic_balance: HarmonicBalance | None

    @property
    def none(self) -> bool:
        return not self.cycles

    @property
    def largest_stable_fin_amplitude(self) -> float:
        """The largest stable cycle's fin amplitude (rad), 0 without one."""
        return max((c.fin_amplitude for c in self.cycles if c.stable), default=0.0)


def limit_cycles(plant: DrivePlant, loop: Controller, points: int = 8000) -> BacklashCycles:
    """The limit cycles of the chain's clearance in the position loop (harmonic balance
    of the dead zone on the chain's deflection; module docstring).

    Parameters
    ----------
    plant, loop
        The drive at one fin angle and its controller; ``plant.backlash`` is b.
    points
        Frequencies sampled to bracket the phase crossovers (log-spaced over two decades
        beyond the loop's corners).

    Returns
    -------
    BacklashCycles
        Each cycle's fin, motor and deflection amplitudes (rad) and frequency (rad/s),
        with Loeb's verdict; or none and the reason.
    """
    if not isinstance(plant, DrivePlant):
        raise InputError("plant", f"must be a DrivePlant, got {plant!r}")
    if not isinstance(loop, CONTROLLERS):
        raise InputError("loop", f"must be a PositionLoop or a CascadeLoop, got {loop!r}")
    b = plant.backlash
    if b == 0.0:
        return BacklashCycles((), "the chain has no clearance (backlash = 0)", 0.0, None)
    num, den = deflection_loop(plant, loop)
    hb = harmonic_balance(
        polynomial_loop(num, den, frequency_range(plant, loop)), DeadZone(b), points=points
    )
    cycles = []
    for c in hb.cycles:
        N = float(np.real(c.describing_function))
        phi_per_d = _fin_per_deflection(plant, c.frequency, N)
        cycles.append(
            BacklashCycle(
                fin_amplitude=float(abs(phi_per_d) * c.amplitude),
                motor_amplitude=float(abs(1.0 + phi_per_d) * c.amplitude),
                deflection_amplitude=c.amplitude,
                frequency=c.frequency,
                stable=c.stable,
                balance=c,
            )
        )
    reason = hb.reason
    if not cycles and not reason:
        reason = "no cycle"
    return BacklashCycles(tuple(cycles), reason, b, hb)


def cycle_amplitude_margin(
    loop_at_crossover,
    frequency,
    amplitude_max,
    backlash,
    stiffness,
    damping,
    fin_inertia,
    fin_damping,
    hinge_spring,
):
    """A smooth indicator that the phase crossover of L_d at ``frequency`` sustains no
    cycle whose fin amplitude exceeds ``amplitude_max``: >= 0 when it does not.

    At a phase crossover w (Im L_d(jw) = 0, L_d(jw) = ``loop_at_crossover`` < -1) the
    cycle's deflection A solves N(A) = N* = -1/L_d, and the fin swings with
    N* A g, g = |k + j w c| / |D_2(jw)|, increasing in A. So the fin amplitude is at most
    ``amplitude_max`` exactly when N* <= N(A_max), A_max = ``amplitude_max`` / (N* g) the
    deflection that would give it: the indicator is N(A_max) - N*, with N the dead zone's
    describing function (:func:`~optdesign.models.describing_function.dead_zone_df`)
    written through :mod:`optdesign.math` (0 for A_max <= b).

    Works on CasADi symbols. Its limits (docs/loop.md): it holds at one phase crossover,
    which an NLP must track (w a variable bracketed between the crossovers of the
    design's family, with Im L_d(jw) = 0 a constraint); where L_d(jw) >= -1 there is no
    cycle at all but the indicator is negative (N* >= 1 > N); and it is a statement of the
    describing function, as good as its filter hypothesis at that crossover.

    Parameters
    ----------
    loop_at_crossover
        L_d(jw), real (< -1 where a cycle exists).
    frequency
        The phase crossover w (rad/s).
    amplitude_max
        The fin amplitude allowed (rad).
    backlash, stiffness, damping, fin_inertia, fin_damping, hinge_spring
        The :class:`~optdesign.models.loop_plant.DrivePlant` quantities (rad, N*mm/rad,
        N*mm*s/rad, t*mm^2, N*mm*s/rad, N*mm/rad).
    """
    w = frequency
    n_star = -1.0 / loop_at_crossover
    d2_re = hinge_spring - fin_inertia * w * w
    d2_im = fin_damping * w
    gain = m.sqrt((stiffness**2 + (w * damping) ** 2) / (d2_re**2 + d2_im**2))
    a_max = amplitude_max / (n_star * gain)
    # r = b / A_max clipped at 1: N = 0 inside the gap; N is C^1 through r = 1
    r = m.fmin(backlash / a_max, 1.0)
    root = m.sqrt(m.fmax(1.0 - r * r, 0.0))
    n_max = 1.0 - 2.0 / m.pi * (m.arcsin(r) + r * root)
    return n_max - n_star
