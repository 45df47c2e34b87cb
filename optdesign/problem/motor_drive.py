"""The motor in the design: inertia reflected through the stroke, the torque, speed and
RMS torque the motion asks of the motor, and the fin's natural frequencies, over the
deflection grid, for any mechanism (built from its ``nut_velocity`` and
``nut_acceleration``); and the requirements they make.

Mechanism-free: everything here reads the design's quantities (the ratio f'(phi) and
its rate f''(phi), the drive's efficiency and stiffness) and the problem's ``[motor]``,
``[load]`` and ``[motion]`` sections (:mod:`optdesign.problem.spec_motor`); the
physics is :mod:`optdesign.models.motor`'s. Internal units: mm, N, s, rad; inertia in
t*mm^2 (= N*mm*s^2), mass in t (docs/motor.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import ProblemError
from optdesign.models import motor as mo
from optdesign.models import motor_limits as ml
from optdesign.problem import drive
from optdesign.problem import motor_catalogue_variable as mcv
from optdesign.problem.motion import MotionDemand as MotionDemand
from optdesign.problem.motion import motion_demand
from optdesign.problem.objectives import ConstraintBlock


@dataclass(frozen=True)
class MotorData:
    """The motor of a design (internal units: t*mm^2, N*mm, rad/s, t): numbers for a
    motor the problem names, the catalogue's parameters (solver path) or looked-up values
    (NumPy path) for a motor the search chooses. ``rotor_inertia`` is the one that costs
    torque, ``rotor_inertia_max`` the one that divides the load's inertia: equal for one
    motor, the least and the largest of a relaxation node's motors otherwise.
    ``envelope_intercept`` and ``envelope_slope`` are the falling piece of its
    speed-torque envelope, T + s n <= T_peak + s n_c (None when no motor of the problem
    has a corner; :mod:`optdesign.models.motor_limits`); ``thermal_time_constant`` the
    winding's (s), or None."""

    designation: str
    rotor_inertia: Any
    peak_torque: Any
    rated_torque: Any
    max_speed: Any
    mass: Any
    gear_inertia: float
    friction_torque: float
    rotor_inertia_max: Any = None
    on_catalogue: Any = None
    envelope_intercept: Any = None
    envelope_slope: Any = None
    thermal_time_constant: float | None = None

    @property
    def inertia_for_ratio(self) -> Any:
        return self.rotor_inertia if self.rotor_inertia_max is None else self.rotor_inertia_max


def motor_data(spec) -> MotorData | None:
    """The motor the ``[motor]`` section names: a catalogue row (``designation``) or its
    data; None without a section, or when the search chooses the motor (:func:`motor_of`)."""
    motor = spec.motor
    if motor is None or motor.catalogue is not None:
        return None
    if motor.designation is not None:
        from optdesign.models.motor_catalogue import by_designation

        row = by_designation(motor.designation)
        corner = row.corner_speed is not None
        return MotorData(
            row.designation,
            row.rotor_inertia,
            row.peak_torque,
            row.rated_torque,
            row.max_speed,  # rad/s
            row.mass,
            motor.gear_inertia,
            motor.friction_torque,
            envelope_intercept=row.envelope_intercept if corner else None,
            envelope_slope=row.envelope_slope if corner else None,
        )
    max_speed = motor.max_speed * 2.0 * np.pi / 60.0  # 1/min -> rad/s
    intercept = slope = None
    if motor.corner_speed is not None:
        top = motor.rated_torque if motor.top_speed_torque is None else motor.top_speed_torque
        corner = motor.corner_speed * mo.RPM
        slope = ml.envelope_slope(motor.peak_torque, corner, max_speed, top)
        intercept = ml.envelope_intercept(motor.peak_torque, corner, slope)
    tau = motor.thermal_time_constant
    return MotorData(
        "",
        motor.rotor_inertia,
        motor.peak_torque,
        motor.rated_torque,
        max_speed,
        motor.mass,
        motor.gear_inertia,
        motor.friction_torque,
        envelope_intercept=intercept,
        envelope_slope=slope,
        thermal_time_constant=None if tau is None else tau * 3600.0,  # h -> s
    )


def motor_of(q) -> MotorData | None:
    """The motor of design ``q``: :func:`motor_data`, or the catalogue motor its variable
    ``motor`` numbers (:mod:`optdesign.problem.motor_catalogue_variable`)."""
    spec = q.problem.spec
    fixed = motor_data(spec)
    if fixed is not None or spec.motor is None:
        return fixed
    values, on = mcv.design_values(q.problem, q.design)
    corner = mcv.has_corners(mcv.catalogue_of(q.problem))
    return MotorData(
        "",
        values["rotor_inertia"],
        values["peak_torque"],
        values["rated_torque"],
        values["max_speed"],
        values["mass"],
        spec.motor.gear_inertia,
        spec.motor.friction_torque,
        values["rotor_inertia_max"],
        on,
        envelope_intercept=values["envelope_intercept"] if corner else None,
        envelope_slope=values["envelope_slope"] if corner else None,
    )


def _need(value, what: str, field: str):
    if value is None:
        raise ProblemError(f"{field}: needs {what}")
    return value


# --- quantities of a design (functions of its Quantities q) -------------------------------
def ratio_rate(q):
    """f''(phi) = d2theta/dphi2 over the grid: the ratio's rate along the stroke,
    f' x (d2x/dphi2) / (dx/dphi) (the map from the nut's rate to the motor's is linear)."""
    acc = q.call_mechanism("nut_acceleration", q.phi)
    return q.ratio * acc / q.mechanism._divisor(q.nut_velocity)


def motor_side_inertia(q):
    """J_m at the motor shaft: the rotor, the gear's ``gear_inertia``, the screw shaft
    (a solid steel shaft of d0 over the support length, when ``[screw]`` gives them)
    through the gear, and the nut's mass through the lead (t*mm^2; over the grid, since
    the nut's share is m (dx/dphi / f')^2)."""
    motor = _need(q.motor_data, "a [motor] section", "the motor's inertia")
    J = motor.rotor_inertia + motor.gear_inertia
    J_screw = drive.screw_shaft_inertia(q)
    if J_screw is not None:
        i_a = q.design.get("i_a", 1.0)
        J = J + J_screw * mo.KG_MM2 / i_a**2
    load = q.problem.spec.load
    if load is not None and load.nut_mass:
        # m (lead / 2 pi i_a)^2 = m (dx/dphi / f')^2
        J = J + load.nut_mass * (q.nut_velocity / q.ratio) ** 2
    return J


def fin_inertia(q) -> float:
    """The fin's inertia about its hinge (t*mm^2)."""
    load = _need(q.problem.spec.load, "a [load] section (the fin's inertia)", "[load]")
    return load.inertia


def inertia_at_motor(q):
    """J_m + J_fin / f'^2 over the grid (t*mm^2)."""
    return mo.inertia_at_motor(q.motor_side_inertia, fin_inertia(q), q.ratio)


def inertia_ratio(q):
    """The load's inertia at the motor over the rotor's, over the grid."""
    motor = q.motor_data
    return mo.inertia_ratio(q.inertia_at_motor - motor.rotor_inertia, motor.inertia_for_ratio)


def motor_speed(q):
    """The motor's speed at the fin's top rate, f' x rate (rad/s), over the grid."""
    demand = _need(
        motion_demand(q.problem.spec),
        "the fin's rate: [motion] rate or a step, or requirements.deflection_rate",
        "the motor's speed",
    )
    return mo.motor_rate(q.ratio, demand.rate)


def output_demand(q, rate, acceleration):
    """The torque the drive applies to the fin (N*mm) at the top rate and acceleration,
    over the grid: J_fin alpha + c omega + |k phi| + M_h, every term against the drive (an
    upper bound: the step's peak acceleration and peak rate come at different times)."""
    load = q.problem.spec.load
    J = 0.0 if load is None else load.inertia
    c = 0.0 if load is None else load.damping
    k = 0.0 if load is None else load.hinge_spring
    spring = np.abs(k * np.asarray(q.phi, dtype=float))
    return mo.output_torque(J, acceleration, c, rate, 0.0, 0.0, q.hinge_moment) + _column(q, spring)


def motor_peak_torque(q):
    """The torque the motor must give at each grid angle (N*mm): J_m (f' alpha + |f''|
    omega^2) + M_out / (f' eta) + T_f, at the top rate omega and acceleration alpha of the
    fin (:func:`motion_demand`), M_out by :func:`output_demand`; an upper bound of the
    torque along the motion (docs/motor.md)."""
    steady, swing = _peak_torque_terms(q)
    return steady + m.fabs(swing)


def motor_peak_torque_pieces(q) -> tuple[Any, Any]:
    """The two smooth pieces of :func:`motor_peak_torque`, with +f'' and with -f'': their
    element-wise max is the peak torque (|f''| = max(f'', -f'')). An NLP bounds each: the
    kink of |f''| where the ratio turns (inside the stroke of every linkage here) stalls
    Ipopt at its iteration limit from every start."""
    steady, swing = _peak_torque_terms(q)
    return steady + swing, steady - swing


def _peak_torque_terms(q) -> tuple[Any, Any]:
    """J_m f' alpha + M_out / (f' eta) + T_f, and J_m f'' omega^2 (its sign kept)."""
    motor = q.motor_data
    demand = _need(
        motion_demand(q.problem.spec),
        "the fin's rate: [motion] rate or a step, or requirements.deflection_rate",
        "the motor's torque",
    )
    w, a = demand.rate, demand.acceleration
    J = q.motor_side_inertia
    through = mo.torque_at_motor(output_demand(q, w, a), q.ratio, q.drive_efficiency)
    return J * q.ratio * a + through + motor.friction_torque, J * q.ratio_rate * w**2


def duty_torques(q) -> list[Any]:
    """The motor's torque in each step of the duty cycle (N*mm): the step's hinge moment
    held at its deflection, through the ratio there and the forward efficiency, plus the
    drive's friction."""
    spec = q.problem.spec
    steps = _need(spec.requirements.duty_cycle, "requirements.duty_cycle", "the RMS torque")
    motor = q.motor_data
    friction = 0.0 if motor is None else motor.friction_torque
    phis = np.array([s.deflection for s in steps])
    ratio = q.call_mechanism("ratio", phis)
    return [
        mo.torque_at_motor(s.hinge_moment, drive.at_angle(ratio, k), q.drive_efficiency) + friction
        for k, s in enumerate(steps)
    ]


def motor_rms_torque(q):
    """The RMS torque of the duty cycle (N*mm): :func:`duty_torques` weighted by each
    step's share of the time (THK's equation (54))."""
    steps = q.problem.spec.requirements.duty_cycle
    return mo.rms_torque(duty_torques(q), [s.time for s in steps])


def motor_thermal_torques(q) -> list[Any]:
    """sqrt(x_k) at the end of each duty step (N*mm): the torque whose steady heating
    equals the winding's then, in the periodic steady state of the first-order thermal
    model of time constant tau over the cycle of ``requirements.duty_period``
    (:func:`optdesign.models.motor_limits.thermal_torque_squares`)."""
    req = q.problem.spec.requirements
    tau = q.motor_data.thermal_time_constant
    period = _need(
        req.duty_period,
        "requirements.duty_period (the duty cycle's length, its steps' times being shares "
        "of it), to compare with the winding's time constant",
        "motor.thermal_time_constant",
    )
    total = sum(s.time for s in req.duty_cycle)
    seconds = [s.time / total * period * 3600.0 for s in req.duty_cycle]  # h -> s
    squares = ml.thermal_torque_squares(duty_torques(q), seconds, tau)
    return [m.sqrt(x) for x in squares]


def chain_stiffness(q):
    """The chain's stiffness at the fin with the motor held (N*mm/rad), over the grid."""
    if q.problem.spec.screw is None:
        raise ProblemError(
            "the natural frequency: needs a [screw] section (the chain's stiffness: its "
            "bearings, nut and shaft)"
        )
    return q.output_stiffness


def locked_frequency_squared(q):
    """omega^2 of the fin on the chain with the motor held, (k_chain + k_hinge) / J_fin
    (rad^2/s^2), over the grid; <= 0 where the fin diverges."""
    load = q.problem.spec.load
    spring = 0.0 if load is None else load.hinge_spring
    return mo.locked_frequency_squared(chain_stiffness(q), fin_inertia(q), spring)


def two_mass_frequency_squared(q):
    """omega^2 of the drive's own mode with the motor free (rad^2/s^2), over the grid:
    the motor side J_1 = J_m f'^2 at the fin and the fin J_2 on the chain's stiffness k,
    the fin on its hinge spring k_h: the larger root of J_1 J_2 w^4 - (k (J_1 + J_2) +
    k_h J_1) w^2 + k k_h = 0 (with k_h = 0, k (J_1 + J_2) / (J_1 J_2))."""
    load = q.problem.spec.load
    kh = 0.0 if load is None else load.hinge_spring
    k = chain_stiffness(q)
    J1 = q.motor_side_inertia * q.ratio**2
    J2 = fin_inertia(q)
    A = J1 * J2
    B = k * (J1 + J2) + kh * J1
    C = k * kh
    return (B + m.sqrt(m.fmax(B**2 - 4.0 * A * C, 0.0))) / (2.0 * A)


def _column(q, values):
    """A grid of numbers shaped like the design's grid quantities (a CasADi column, or the
    last axis of NumPy arrays)."""
    if m.is_symbolic(q.ratio):
        import casadi as ca

        return ca.DM(np.asarray(values, dtype=float))
    return np.asarray(values, dtype=float)


def _hz(omega_squared):
    return np.sqrt(np.maximum(np.asarray(omega_squared, dtype=float), 0.0)) / (2.0 * np.pi)


# --- requirements ---------------------------------------------------------------------------
def motor_blocks(q, labels: list[str]) -> list[ConstraintBlock]:
    """The motor's and the fin's requirements: peak torque, speed and (with a duty cycle
    and a rated torque) RMS torque within the motor's, as ratios to the motor's limits
    (which are parameters when the search chooses the motor), the inertia ratio, the
    natural frequencies. None without ``[motor]`` and without those requirements."""
    spec = q.problem.spec
    req = spec.requirements
    motor = q.motor_data
    out: list[ConstraintBlock] = []
    if motor is not None:
        _need(
            motion_demand(spec),
            "the fin's rate: [motion] rate or a step, or requirements.deflection_rate",
            "[motor]",
        )
        name = f" {motor.designation}" if motor.designation else ""
        if motor.on_catalogue is not None:
            out.append(
                ConstraintBlock(
                    "motor_catalogue_membership",
                    motor.on_catalogue,
                    1.0,
                    None,
                    [""],
                    "",
                    "motor is a motor of the catalogue",
                )
            )
        pieces = ()
        if m.is_symbolic(q.ratio):  # the solver's rows: the smooth pieces (see there)
            pieces = tuple(p / motor.peak_torque for p in motor_peak_torque_pieces(q))
        out.append(
            ConstraintBlock(
                "motor_peak_torque",
                q.motor_peak_torque / motor.peak_torque,
                None,
                1.0,
                labels,
                "",
                f"torque the motion asks of the motor{name} / its peak torque",
                pieces=pieces,
            )
        )
        out.append(
            ConstraintBlock(
                "motor_speed",
                q.motor_speed / motor.max_speed,
                None,
                1.0,
                labels,
                "",
                f"speed of the motor{name} at the fin's top rate / its top speed",
            )
        )
        if motor.envelope_slope is not None:
            out.append(_envelope_block(q, motor, labels, name))
        if motor.rated_torque is not None and req.duty_cycle:
            out.append(_duty_block(q, motor, name))
    if req.inertia_ratio_max is not None:
        _need(motor, "a [motor] section (the rotor's inertia)", "requirements.inertia_ratio_max")
        out.append(
            ConstraintBlock(
                "inertia_ratio",
                q.inertia_ratio,
                None,
                req.inertia_ratio_max,
                labels,
                "",
                "load inertia at the motor / rotor inertia",
            )
        )
    if req.natural_frequency_min is not None:
        low = (2.0 * np.pi * req.natural_frequency_min) ** 2
        out.append(
            ConstraintBlock(
                "natural_frequency",
                q.locked_frequency_squared,
                low,
                None,
                labels,
                "rad^2/s^2",
                "natural frequency of the fin on the chain, motor held (the row holds its square)",
                display=_hz,
                display_unit="Hz",
            )
        )
        if motor is not None:
            out.append(
                ConstraintBlock(
                    "drive_mode_frequency",
                    q.two_mass_frequency_squared,
                    low,
                    None,
                    labels,
                    "rad^2/s^2",
                    "frequency of the drive's own mode, motor free (the row holds its square)",
                    display=_hz,
                    display_unit="Hz",
                )
            )
    return out


def _envelope_block(q, motor: MotorData, labels: list[str], name: str) -> ConstraintBlock:
    """The falling piece of the speed-torque envelope at every grid angle: (T + s n) /
    (T_peak + s n_c) <= 1 at the motor's speed n and the torque T the motion asks there,
    linear in (n, T); with the peak-torque row (T <= T_peak) it is exact for the
    envelope min(T_peak, T_peak - s (n - n_c)). Every phase of the motion asks at most T
    at at most n, and the envelope falls with speed, so the one point covers them all."""
    s, a = motor.envelope_slope, motor.envelope_intercept
    speed = q.motor_speed
    pieces = ()
    if m.is_symbolic(q.ratio):  # the solver's rows: the smooth pieces of the peak torque
        pieces = tuple((p + s * speed) / a for p in motor_peak_torque_pieces(q))
    return ConstraintBlock(
        "motor_speed_torque",
        (q.motor_peak_torque + s * speed) / a,
        None,
        1.0,
        labels,
        "",
        f"torque the motion asks of the motor{name} at its speed, against its speed-torque "
        "envelope above the corner, (T + s n) / (T_peak + s n_c)",
        pieces=pieces,
    )


def _duty_block(q, motor: MotorData, name: str) -> ConstraintBlock:
    """The duty cycle's heating against the rated torque: the plain RMS torque, or with
    the winding's thermal time constant the first-order thermal model's torque at the end
    of every step (it is never below the RMS torque, so it replaces that row)."""
    if motor.thermal_time_constant is None:
        return ConstraintBlock(
            "motor_rms_torque",
            q.motor_rms_torque / motor.rated_torque,
            None,
            1.0,
            [""],
            "",
            f"RMS torque of the duty cycle / the motor{name}'s rated torque",
        )
    rows = [x / motor.rated_torque for x in motor_thermal_torques(q)]
    if m.is_symbolic(*rows):
        import casadi as ca

        expr = ca.vertcat(*rows)
    else:
        expr = np.stack(np.broadcast_arrays(*rows), axis=-1)
    return ConstraintBlock(
        "motor_thermal_torque",
        expr,
        None,
        1.0,
        [f"after step {k}" for k in range(1, len(rows) + 1)],
        "",
        f"thermal torque of the duty cycle (first-order winding, tau = "
        f"{motor.thermal_time_constant:g} s) / the motor{name}'s rated torque",
    )


def natural_period(q) -> Any:
    """2 pi / omega of the fin on the chain, motor held (s), over the grid: minimised, it
    raises the lowest natural frequency (NaN where the fin diverges)."""
    w2 = q.locked_frequency_squared
    return 2.0 * m.pi / m.sqrt(w2)
