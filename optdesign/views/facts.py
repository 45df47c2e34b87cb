"""What a design achieves, evaluated: the mean ratio and its range over the stroke, the
drive efficiency used, and the motor chosen with its data and the torque the motion
asks of it. :mod:`optdesign.reports.facts` words them in the user's units."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from optdesign import math as m

if TYPE_CHECKING:
    from optdesign.problem.loop_analysis import LoopFigures


@dataclass(frozen=True)
class MotorFacts:
    """The motor of a design, in the models' units (mm, N, s, t).

    Attributes
    ----------
    name
        Its designation ("" when the file names none).
    peak_torque
        Its peak torque (N*mm).
    rotor_inertia
        Its rotor's inertia (t*mm^2).
    max_speed
        Its top speed (rad/s).
    mass
        Its mass (t), or None when its data give none.
    demand
        The largest torque the motion asks of it (N*mm), or None without a motion.
    envelope_use
        With a speed-torque corner, the largest share over the stroke of the torque the
        envelope gives at the motor's speed that the motion asks (1: it binds), or None.
    """

    name: str
    peak_torque: float
    rotor_inertia: float
    max_speed: float
    mass: float | None
    demand: float | None
    envelope_use: float | None = None


@dataclass(frozen=True)
class DesignFacts:
    """What a design achieves over the stroke.

    Attributes
    ----------
    mean_ratio
        The mean reduction ratio over the stroke (the grid's mean).
    ratio_min, ratio_max
        The smallest and largest ratio over the stroke.
    drive_efficiency
        The smallest drive efficiency (screw x gear) over the stroke, a fraction.
    motor
        The design's motor, or None: the problem has none, or the design's motor number
        is no catalogue item's (its membership row says so).
    loop
        The design's position loop analysed exactly
        (:func:`optdesign.problem.loop_analysis.loop_figures`), None without a
        ``[loop]``, or why it could not be analysed.
    """

    mean_ratio: float
    ratio_min: float
    ratio_max: float
    drive_efficiency: float
    motor: MotorFacts | None = None
    loop: LoopFigures | str | None = None


def design_facts(
    problem: Any, design: dict[str, float], quantities: Any = None
) -> DesignFacts | None:
    """The :class:`DesignFacts` of ``design`` (NumPy path of the models); None without a
    problem or a design.

    Parameters
    ----------
    problem
        The design problem, or None.
    design
        The design: variable name -> value.
    quantities
        ``problem.quantities(design)`` when the caller has it already.
    """
    if problem is None or not design:
        return None
    with np.errstate(all="ignore"):
        q = problem.quantities(design) if quantities is None else quantities
        ratio = np.asarray(q.ratio, dtype=float).ravel()
        eta = np.asarray(q.drive_efficiency, dtype=float).ravel()
    return DesignFacts(
        float(m.grid_mean(ratio)),
        float(np.min(ratio)),
        float(np.max(ratio)),
        float(np.min(eta)),
        _motor_facts(problem, q),
        _loop_figures(problem, q),
    )


def _loop_figures(problem: Any, q: Any) -> LoopFigures | str | None:
    """The loop's exact figures at the design, or why they are missing (a page, not the
    result: a failure is said, not raised)."""
    if problem.spec.loop is None:
        return None
    from optdesign.problem.loop_analysis import loop_figures

    try:
        with np.errstate(all="ignore"):
            return loop_figures(q)
    except Exception as exc:
        return str(exc)


def _motor_facts(problem: Any, q: Any) -> MotorFacts | None:
    """The motor of the design, named, with its data and the motion's demand on it."""
    from optdesign.problem.motor_catalogue_variable import catalogue_of, motor_by_number

    if problem.spec.motor is None:
        return None
    catalogue = catalogue_of(problem)
    name = problem.spec.motor.designation or ""
    if catalogue is not None:
        try:
            name = motor_by_number(catalogue, float(q.design["motor"])).designation
        except Exception:  # a number that is no motor's: the membership row says so
            return None
    motor = q.motor_data
    with np.errstate(all="ignore"):
        demand = float(np.max(np.asarray(q.motor_peak_torque, dtype=float))) if q.motion else None
        envelope = None
        if demand is not None and motor.envelope_slope is not None:
            # the torque the envelope gives at each angle's speed: the peak up to the
            # corner, falling linearly above it
            speed = np.asarray(q.motor_speed, dtype=float)
            available = np.minimum(
                motor.peak_torque, motor.envelope_intercept - motor.envelope_slope * speed
            )
            envelope = float(np.max(np.asarray(q.motor_peak_torque, dtype=float) / available))
    return MotorFacts(
        name,
        float(motor.peak_torque),
        float(motor.rotor_inertia),
        float(motor.max_speed),
        None if motor.mass is None else float(motor.mass),
        demand,
        envelope,
    )
