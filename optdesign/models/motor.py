"""The motor in the drive: inertia seen through the linkage, torque along a motion, RMS
and peak torque over a duty cycle, speed, drive-train frequencies, and what a closed
loop's step response asks of the motor (docs/motor.md).

Pure functions through :mod:`optdesign.math`: each takes floats, NumPy arrays (the
deflection grid on the last axis) or CasADi symbols, except
:func:`natural_frequency_for_rise_time` (a root of the step response: numbers only, a
requirement's value, not a design quantity).

The chain and its one ratio. The motor turns theta, the gear divides by i_gear, the
screw moves the nut lead/(2 pi) per screw radian, the linkage turns the fin phi. The
motor's angle is a function of the fin's, theta = f(phi), and its derivatives along the
stroke are the chain's ratio and the ratio's rate:

    f'(phi)  = dtheta/dphi    = i_gear (2 pi / lead) dx/dphi       (:func:`motor_ratio`)
    f''(phi) = d2theta/dphi2  = i_gear (2 pi / lead) d2x/dphi2     (the same function)

(f' is the project's reduction ratio, :func:`optdesign.models.ratio.ratio_from_nut_velocity`.)
Along a fin motion phi(t) the motor moves with

    theta_dot  = f' phi_dot
    theta_ddot = f' phi_ddot + f'' phi_dot^2

and the second term is the ratio's own: with a stroke-varying ratio the motor
accelerates even while the fin turns at a constant rate.

Torque at the motor. The drive is one rigid degree of freedom; its kinetic energy is
1/2 J_m theta_dot^2 + 1/2 J_out phi_dot^2, with J_m everything that turns with the motor
or moves with the nut (rotor, gears, screw, the nut's mass through the lead: a fixed
ratio) and J_out what turns with the fin (the fin about its hinge). Lagrange's equation
in phi, divided by f', gives the torque the motor must apply

    T_m = J_m theta_ddot + M_out / (f' eta) + T_f,
    M_out = J_out phi_ddot + c phi_dot + k phi + M_h        (:func:`output_torque`)

M_out is the torque the drive applies to the fin: its inertia, a damping c, the hinge's
aerodynamic spring k (negative for a statically unstable fin) and the hinge moment M_h
the air load puts on it, positive when it opposes +phi. The output-side inertia is
carried through the efficiency eta with the load (conservative; THK's selection method
[THK-EX] adds the whole reflected inertia without efficiency, which the motor-side term
J_m theta_ddot does here). The linkage's own links (a rod, a fork) are not in the
model; their inertia would add a term 1/2 dJ(phi)/dphi phi_dot^2 with a
position-dependent J: lump a small part into J_out or J_m.

Signs: phi, theta, torques and rates are positive in the same sense (f' > 0 over the
stroke, the row ``ratio_positive`` of a problem). Efficiency: by default the motor
drives (``M_out / (f' eta)`` for either sign of M_out), which gives the largest
magnitude for both signs and is the conservative choice for peak and RMS torque. With
``back_efficiency`` given, where the output returns power to the drive (M_out phi_dot
< 0: the air load or the fin's inertia pushes the fin the way it is moving) the torque
is ``M_out eta' / f'`` instead (back-driving); at rest (phi_dot = 0) the driving form
holds. T_f is the drive's own friction at the motor (bearings, seals, a preloaded
nut): give it the sign of theta_dot (THK: +120 N*mm moving forward, 0 at rest).

Units: mm, N, s, rad (README "Units"). Hence mass in tonnes (1 t = 1000 kg = 1 N*s^2/mm)
and inertia in t*mm^2 (= N*mm*s^2); the conversions (:data:`KG`, :data:`KG_M2`,
:data:`KG_CM2`, :data:`KG_MM2`, :data:`N_M`, :data:`RPM`):

    1 kg        = 1e-3 t
    1 kg*m^2    = 1e3 t*mm^2     (1 t*mm^2 = 1e-3 kg*m^2)
    1 kg*cm^2   = 0.1 t*mm^2     (catalogues print 1e-4 kg*m^2 = 1 kg*cm^2)
    1 kg*mm^2   = 1e-3 t*mm^2    (optdesign.models.screw_sizing's inertia unit)
    1 N*m       = 1e3 N*mm
    1 min^-1    = 2 pi / 60 rad/s

Stiffnesses in N*mm/rad, speeds in rad/s, frequencies in rad/s unless a name says Hz.

Validity
--------
damping ratio zeta : 0 < zeta < 1 (call)
    The step-response formulas (rise time, peak rate) are those of an underdamped
    second-order loop; zeta >= 1 has no overshoot and other closed forms.
rise level : 0 < level < 1 (call)
    A rise time is the first time the response reaches a fraction of the step.
efficiency eta : 0 < eta <= 1 (call)
    A passive drive loses power; eta = 0 transmits nothing.
rigid drive : closed-loop natural frequency <= 0.3 x the drive's anti-resonance (documented)
    The torque model takes the chain as rigid. Driven at omega below an anti-resonance
    omega_a, the load of a two-mass drive moves 1/(1 - (omega/omega_a)^2) times as far as
    a rigid one: 10 % more at omega/omega_a = 0.3, where the rigid torques stop being a
    bound. Documented here; the problem integration checks it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models._checks import require_finite, require_nonnegative, require_positive
from optdesign.models.ratio import ratio_from_nut_velocity
from optdesign.models.validity import Validity

DAMPING_RATIO = Validity(
    "motor.damping_ratio",
    "second-order step response",
    "damping ratio zeta",
    0.0,
    1.0,
    "",
    "the rise-time and peak-rate formulas are those of an underdamped loop (0 < zeta < 1)",
    open_lower=True,
    open_upper=True,
    checked=("call",),
)
RISE_LEVEL = Validity(
    "motor.rise_level",
    "second-order step response",
    "rise level (fraction of the step)",
    0.0,
    1.0,
    "",
    "a rise time is the first time the response reaches a fraction of the step",
    open_lower=True,
    open_upper=True,
    checked=("call",),
)
EFFICIENCY = Validity(
    "motor.efficiency",
    "torque through the drive",
    "efficiency eta",
    0.0,
    1.0,
    "",
    "a passive drive loses power; eta = 0 transmits nothing",
    open_lower=True,
    checked=("call",),
)
RIGID_DRIVE = Validity(
    "motor.rigid_drive",
    "rigid-drive torque model",
    "closed-loop natural frequency / drive anti-resonance sqrt(k / J_load)",
    0.0,
    0.3,
    "",
    "below 0.3 a two-mass drive's load moves at most 10 % further than a rigid one's "
    "(1 / (1 - 0.3^2)); above it the rigid torques are no bound",
    checked=("documented",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (DAMPING_RATIO, RISE_LEVEL, EFFICIENCY, RIGID_DRIVE)

#: Tonnes per kilogram (mass in t).
KG = 1e-3
#: t*mm^2 per kg*m^2.
KG_M2 = 1e3
#: t*mm^2 per kg*cm^2 (= 1e-4 kg*m^2, the catalogues' unit).
KG_CM2 = 0.1
#: t*mm^2 per kg*mm^2 (the unit of optdesign.models.screw_sizing's inertias).
KG_MM2 = 1e-3
#: N*mm per N*m.
N_M = 1e3
#: rad/s per min^-1 (rev/min).
RPM = 2.0 * np.pi / 60.0


def _check_efficiency(field: str, value) -> None:
    require_positive(field, value)
    if not m.is_symbolic(value) and np.any(np.asarray(value, dtype=float) > 1.0):
        raise InputError(
            field, f"{value!r} is outside {EFFICIENCY.range_text()} ({EFFICIENCY.why})"
        )


# --- inertia through the chain ----------------------------------------------------------
def reflected_inertia(J, ratio):
    """Inertia seen at a drive's input of a body of inertia ``J`` on its output.

    ``ratio`` is input angle per output angle (a gear's i_gear; the whole chain's f'),
    so the body turns 1/ratio as fast and keeps its kinetic energy:
    J_in = J / ratio^2 (t*mm^2 for J in t*mm^2).
    """
    return J / ratio**2


def inertia_at_output(J_input, ratio):
    """The inverse of :func:`reflected_inertia`: an input-side inertia seen at the
    output, J_input * ratio^2."""
    return J_input * ratio**2


def translating_mass_inertia(mass, lead):
    """Inertia at the screw of a mass moving with the nut, mass (lead / 2 pi)^2.

    ``mass`` in t, ``lead`` in mm per screw turn: t*mm^2. (80 kg on a 40 mm lead,
    THK's transfer example: 3.24e-3 kg*m^2 = 3.24 t*mm^2.)
    """
    return mass * (lead / (2.0 * m.pi)) ** 2


def motor_side_inertia(
    J_rotor,
    J_screw=0.0,
    nut_mass=0.0,
    lead=1.0,
    gear_ratio=1.0,
    J_gear_motor=0.0,
    J_gear_screw=0.0,
):
    """Everything that turns with the motor or moves with the nut, at the motor shaft.

    J_m = J_rotor + J_gear_motor + (J_gear_screw + J_screw + nut_mass (lead/2 pi)^2) /
    gear_ratio^2 (t*mm^2), ``gear_ratio`` motor turns per screw turn. The same sum as
    HIWIN's F 3.19 (optdesign.models.screw_sizing.reflected_inertia, there in kg*mm^2),
    built from :func:`translating_mass_inertia` and :func:`reflected_inertia`.
    """
    screw_side = J_gear_screw + J_screw + translating_mass_inertia(nut_mass, lead)
    return J_rotor + J_gear_motor + reflected_inertia(screw_side, gear_ratio)


def motor_ratio(nut_rate, lead, gear_ratio=1.0):
    """The chain's ratio f' = dtheta/dphi = gear_ratio (2 pi / lead) dx/dphi.

    The map is linear in the nut's rate, so ``motor_ratio(d2x/dphi2, lead, gear_ratio)``
    is the ratio's rate f'' = d2theta/dphi2. One definition:
    :func:`optdesign.models.ratio.ratio_from_nut_velocity`.
    """
    return ratio_from_nut_velocity(nut_rate, lead, gear_ratio)


def inertia_at_motor(J_motor_side, J_out, ratio):
    """Total inertia at the motor, J_m + J_out / f'^2 (t*mm^2); varies along the stroke
    with the ratio f' (a grid of values)."""
    return J_motor_side + reflected_inertia(J_out, ratio)


def inertia_at_fin(J_at_motor, ratio):
    """Total inertia at the fin, J_at_motor f'^2 (t*mm^2): what a fin-side controller
    accelerates."""
    return inertia_at_output(J_at_motor, ratio)


def inertia_ratio(J_load, J_rotor):
    """Load inertia at the motor over the rotor's (the makers' inertia ratio)."""
    return J_load / J_rotor


def min_rotor_inertia(J_load, max_ratio=10.0):
    """The smallest rotor inertia a load allows, J_load / max_ratio.

    THK's selection rule keeps the load at most ``max_ratio`` times the rotor ("normally
    3 to 10"; its transfer example asks J_M >= 3.39e-3 / 10 = 3.39e-4 kg*m^2); servo
    makers print their own allowable ratio per motor.
    """
    require_positive("max_ratio", max_ratio)
    return J_load / max_ratio


# --- motion -------------------------------------------------------------------------------
def motor_rate(ratio, phi_dot):
    """Motor speed theta_dot = f' phi_dot (rad/s)."""
    return ratio * phi_dot


def motor_acceleration(ratio, ratio_rate, phi_dot, phi_ddot):
    """Motor acceleration theta_ddot = f' phi_ddot + f'' phi_dot^2 (rad/s^2)."""
    return ratio * phi_ddot + ratio_rate * phi_dot**2


# --- torque -------------------------------------------------------------------------------
def output_torque(J_out=0.0, phi_ddot=0.0, damping=0.0, phi_dot=0.0, spring=0.0, phi=0.0, load=0.0):
    """Torque the drive applies to the fin: J_out phi_ddot + c phi_dot + k phi + M_h (N*mm).

    ``J_out`` t*mm^2, ``damping`` c in N*mm*s/rad, ``spring`` the hinge's aerodynamic
    stiffness k in N*mm/rad (negative for an unstable fin), ``load`` the hinge moment
    M_h (N*mm, positive against +phi).
    """
    return J_out * phi_ddot + damping * phi_dot + spring * phi + load


def torque_at_motor(M_out, ratio, efficiency=1.0, back_efficiency=None, phi_dot=None):
    """Motor torque that balances an output torque ``M_out`` through the chain (N*mm).

    Driving: M_out / (f' eta), for either sign of M_out (the default; the larger
    magnitude). With ``back_efficiency`` eta' (and ``phi_dot``), where the output
    returns power (M_out phi_dot < 0) the load back-drives: M_out eta' / f'. At
    phi_dot = 0 the driving form holds. Smooth except at that switch (an ``if_else`` on
    the CasADi path).
    """
    _check_efficiency("efficiency", efficiency)
    driving = M_out / (ratio * efficiency)
    if back_efficiency is None:
        return driving
    _check_efficiency("back_efficiency", back_efficiency)
    if phi_dot is None:
        raise InputError("phi_dot", "back-driving needs the fin's rate (the power's sign)")
    back = M_out * back_efficiency / ratio
    return m.where(M_out * phi_dot < 0, back, driving)


def motor_torque(
    J_motor_side,
    ratio,
    ratio_rate,
    phi_dot,
    phi_ddot,
    M_out=0.0,
    efficiency=1.0,
    back_efficiency=None,
    friction=0.0,
):
    """Torque at the motor along a fin motion (N*mm).

    T_m = J_m (f' phi_ddot + f'' phi_dot^2) + M_out / (f' eta) + T_f

    Parameters
    ----------
    J_motor_side
        J_m, inertia at the motor of what turns with it or moves with the nut
        (:func:`motor_side_inertia`), t*mm^2.
    ratio, ratio_rate
        f' = dtheta/dphi and f'' = d2theta/dphi2 at the fin angle (:func:`motor_ratio`).
    phi_dot, phi_ddot
        The fin's rate (rad/s) and acceleration (rad/s^2).
    M_out
        Torque the drive applies to the fin (:func:`output_torque`), N*mm.
    efficiency, back_efficiency
        See :func:`torque_at_motor`.
    friction
        T_f, the drive's own friction at the motor, signed with theta_dot (N*mm).
    """
    theta_ddot = motor_acceleration(ratio, ratio_rate, phi_dot, phi_ddot)
    through = torque_at_motor(M_out, ratio, efficiency, back_efficiency, phi_dot)
    return J_motor_side * theta_ddot + through + friction


# --- duty cycle ---------------------------------------------------------------------------
def _phases(values) -> list:
    """The phases of a duty cycle as a list: a list/tuple as it is, a CasADi column
    element by element, a NumPy array along its last axis."""
    if isinstance(values, list | tuple):
        return list(values)
    if m.is_symbolic(values):
        return [values[i] for i in range(values.shape[0])]
    arr = np.asarray(values, dtype=float)
    return [arr[..., i] for i in range(arr.shape[-1])]


def rms_torque(torques, durations):
    """Effective (RMS) torque of a duty cycle, sqrt(sum T_i^2 t_i / sum t_i) (N*mm).

    ``torques`` one value per phase (a phase's value may itself be an array over
    designs, or a CasADi expression); ``durations`` the phases' times (s, numbers >= 0,
    their sum > 0). THK's equation (54); the motor's rated torque must be at least this.
    """
    T, t = _phases(torques), _phases(durations)
    if len(T) != len(t):
        raise InputError("durations", f"{len(t)} durations for {len(T)} torques")
    for k, dt in enumerate(t):
        require_nonnegative(f"durations[{k}]", dt)
    total = sum(t)
    require_positive("durations", total)
    return m.sqrt(sum(Ti**2 * ti for Ti, ti in zip(T, t, strict=True)) / total)


def peak_torque(torques):
    """Largest torque magnitude over the phases, max |T_i| (N*mm); the motor's peak
    (instantaneous maximum) torque must be at least this. Non-smooth: an NLP bounds each
    phase, -T_peak <= T_i <= T_peak, instead."""
    T = _phases(torques)
    if not T:
        raise InputError("torques", "no phase")
    out = m.fabs(T[0])
    for Ti in T[1:]:
        out = m.fmax(out, m.fabs(Ti))
    return out


def torque_margin(demand, capacity):
    """1 - demand / capacity (>= 0 when the motor suffices), the screw models' form."""
    return 1.0 - demand / capacity


def speed_margin(motor_speed, max_speed):
    """1 - |theta_dot| / max_speed (>= 0 when the motor can turn that fast)."""
    return 1.0 - m.fabs(motor_speed) / max_speed


# --- frequencies --------------------------------------------------------------------------
def anti_resonance(J_load, k):
    """Anti-resonance of a two-mass drive, sqrt(k / J_load) (rad/s): the load alone on
    the shaft's stiffness k (N*mm/rad; J in t*mm^2). Seen at the motor as a notch."""
    return m.sqrt(k / J_load)


def resonance(J_motor, J_load, k):
    """Resonance of a free two-mass drive, sqrt(k (J_m + J_l) / (J_m J_l)) (rad/s):
    motor and load swinging against each other on the stiffness k."""
    return m.sqrt(k * (J_motor + J_load) / (J_motor * J_load))


def hertz(omega):
    """rad/s to Hz, omega / 2 pi."""
    return omega / (2.0 * m.pi)


def locked_frequency_squared(k_chain, J_out, hinge_spring=0.0):
    """omega^2 = (k_chain + k_hinge) / J_out (rad^2/s^2): the fin oscillating on the
    chain's stiffness at the fin (N*mm/rad) with the motor held.

    A negative hinge spring (a statically unstable fin) lowers it; at k_chain + k_hinge
    <= 0 there is no oscillation: omega^2 <= 0, the fin diverges. Returned squared so
    that a requirement omega >= omega_min is the smooth constraint omega^2 >= omega_min^2
    through both cases. ``J_out``: what moves when the chain deflects with the motor held
    (the fin, and the output-side parts of the chain reflected to it).
    """
    return (k_chain + hinge_spring) / J_out


def frequency_from_squared(omega_squared):
    """sqrt(max(omega^2, 0)) (rad/s): 0 where there is no oscillation (reports; an NLP
    constrains omega^2 itself)."""
    return m.sqrt(m.fmax(omega_squared, 0.0))


# --- a closed loop's step -----------------------------------------------------------------
def _check_zeta(zeta) -> None:
    require_finite("zeta", zeta)
    if not m.is_symbolic(zeta) and not np.all(DAMPING_RATIO.contains(zeta)):
        raise InputError("zeta", DAMPING_RATIO.refusal(float(np.max(zeta))))


def step_response(t, wn, zeta):
    """Unit-step response of wn^2 / (s^2 + 2 zeta wn s + wn^2), 0 < zeta < 1:
    y(t) = 1 - exp(-zeta wn t) sin(wd t + acos zeta) / sqrt(1 - zeta^2), wd = wn
    sqrt(1 - zeta^2)."""
    _check_zeta(zeta)
    root = m.sqrt(1.0 - zeta**2)
    return 1.0 - m.exp(-zeta * wn * t) * m.sin(wn * root * t + m.arccos(zeta)) / root


def natural_frequency_for_rise_time(zeta, t_rise, level=0.95):
    """Natural frequency wn (rad/s) whose step response first reaches ``level`` of the
    step at ``t_rise`` (s).

    wn = tau / t_rise with tau the first root of y(tau) = level at wn = 1 (a bracketed
    root on [0, pi / sqrt(1 - zeta^2)], before the first peak). ``level = 0.95`` is the
    "5 % rise time", the first entry into a 5 % band (for zeta >= 0.69 the overshoot
    stays inside it, so it is also the 5 % settling time): zeta = 0.7, 72 ms give
    wn = 40.28 rad/s. Numbers only.
    """
    from scipy.optimize import brentq

    _check_zeta(zeta)
    require_positive("t_rise", t_rise)
    if not RISE_LEVEL.contains(level):
        raise InputError("level", RISE_LEVEL.refusal(level))
    zeta, level = float(zeta), float(level)
    peak = np.pi / np.sqrt(1.0 - zeta**2)
    tau = brentq(lambda s: float(step_response(s, 1.0, zeta)) - level, 0.0, peak, xtol=1e-14)
    return tau / float(t_rise)


def step_peak_rate_time(wn, zeta):
    """Time of the step response's largest rate, acos(zeta) / wd (s): where
    tan(wd t) = sqrt(1 - zeta^2) / zeta."""
    _check_zeta(zeta)
    return m.arccos(zeta) / (wn * m.sqrt(1.0 - zeta**2))


def step_peak_rate(wn, zeta, step):
    """Largest rate of the response to a step of ``step`` (its unit per s):
    step wn exp(-zeta acos(zeta) / sqrt(1 - zeta^2)).

    dy/dt = wn exp(-zeta wn t) sin(wd t) / sqrt(1 - zeta^2) peaks at
    :func:`step_peak_rate_time`, where sin(wd t) = sqrt(1 - zeta^2).
    """
    _check_zeta(zeta)
    return step * wn * m.exp(-zeta * m.arccos(zeta) / m.sqrt(1.0 - zeta**2))


def step_peak_acceleration(wn, zeta, step):
    """Largest acceleration magnitude of the step response, step wn^2, at t = 0+.

    d2y/dt2 = wn^2 exp(-zeta wn t) cos(wd t + asin zeta) / sqrt(1 - zeta^2) is wn^2 at
    t = 0; its later extremes are smaller (the first, negative one is wn^2
    exp(-zeta (pi - 2 asin zeta) / sqrt(1 - zeta^2))). ``zeta`` is checked, not used.
    """
    _check_zeta(zeta)
    return step * wn**2


def phase_torques(
    J_total, acceleration, running_torque, phases: Sequence[str] = ("accel", "run", "decel")
):
    """The torques of a trapezoidal move at the motor, as THK's selection lists them:
    accelerating J alpha + T_run, running T_run, decelerating -J alpha + T_run, stopped 0
    (N*mm; ``phases`` any of ``"accel"``, ``"run"``, ``"decel"``, ``"stop"``)."""
    table = {
        "accel": J_total * acceleration + running_torque,
        "run": running_torque,
        "decel": -J_total * acceleration + running_torque,
        "stop": 0.0 * running_torque,
    }
    unknown = [p for p in phases if p not in table]
    if unknown:
        raise InputError("phases", f"unknown phase(s) {unknown}; known: {sorted(table)}")
    return [table[p] for p in phases]
