"""The time response of a design in its position loop (docs/loop.md): the
plant of one grid angle (:mod:`optdesign.problem.loop`), or the plant following the fin
along the stroke (:class:`~optdesign.models.loop_path.DrivePath`), simulated by
:func:`optdesign.models.loop_simulation.simulate` for a step, a sine or the duty cycle's
deflection history, and its samples as a CSV with units.

Angles are given as quantities (``"3 deg"``) and read at the boundary; the record holds
internal units (rad, s, N*mm), the CSV the units a user reads (deg, deg/s, N*m).
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.errors import InputError, ProblemError
from optdesign.models.loop_path import DrivePath, DutyHistory, duty_history
from optdesign.models.loop_plant import DrivePlant, PositionLoop
from optdesign.models.loop_simulation import (
    MAX_EVENTS,
    MAX_HORIZON,
    LoopSimulation,
    SineReference,
    StepReference,
    simulate,
)
from optdesign.problem.loop import drive_plants_of
from optdesign.units import to_internal

#: The references :func:`simulate_design` takes.
REFERENCES = ("step", "sine", "duty")
#: The plants: fixed at one grid angle, or following the fin along the stroke.
PLANTS = ("angle", "path")
#: The default horizon of a step or a sine (s).
HORIZON = 0.5


@dataclass(frozen=True)
class DesignSimulation:
    """A design's time response: the grid angle (rad) and its index, the model's record
    (:class:`~optdesign.models.loop_simulation.LoopSimulation`, internal units), the
    plant (``"angle"``: fixed at that angle; ``"path"``: following the fin, its angles
    the fin's own) and, for the duty cycle, its history (None otherwise; the angle is
    then its first step's grid angle)."""

    angle: float
    index: int
    response: LoopSimulation
    plant: str = "angle"
    duty: DutyHistory | None = None


def _nearest(phi: np.ndarray, angle: float) -> int:
    return int(np.argmin(np.abs(phi - angle)))


def simulate_design(
    problem: Any,
    design: dict[str, float],
    reference: str = "step",
    amplitude: Any = "1 deg",
    angle: Any = None,
    horizon: Any = None,
    frequency: Any = "5 Hz",
    samples: int = 2001,
    plant: str | None = None,
    periods: int = 1,
    period: Any = None,
) -> DesignSimulation:
    """The response of ``design`` (every variable, internal units) of ``problem`` (with a
    ``[loop]``) from rest at the gap's centre: a step or a sine about the grid angle
    nearest ``angle`` (default: the middle of the stroke), or the duty cycle.

    Parameters
    ----------
    reference
        ``"step"`` (of ``amplitude`` at t = 0), ``"sine"`` (``amplitude`` at
        ``frequency``) or ``"duty"`` (``requirements.duty_cycle`` over ``periods``
        periods: :func:`duty_simulation_history`).
    amplitude, angle
        Angles (``"1 deg"``, or a number in rad).
    horizon
        The simulated time of a step or a sine (``"0.5 s"``, the default, or a number in
        s), at most 600 s; a duty run lasts its periods.
    frequency
        The sine's frequency (``"5 Hz"``, or a number in Hz).
    samples
        Output samples, 2 to 10^6.
    plant
        ``"angle"`` (the plant of the grid angle, held: the default of a step and a sine)
        or ``"path"`` (following the fin along the stroke: the duty cycle's, and its
        only one). With ``"path"`` the angles are the fin's own: a step or a sine is
        about the grid angle, from rest there.
    periods, period
        The duty cycle's periods simulated (1 or more) and its length (a time, or a
        number in s; default ``requirements.duty_period``).
    """
    if problem.spec.loop is None:
        raise ProblemError("simulate: needs a [loop] section (the controller)")
    args = simulation_arguments(reference, amplitude, horizon, frequency, plant, periods, period)
    if args.duty:
        if angle is not None:
            raise InputError("angle", "a duty run follows its steps' deflections: give none")
        duty = duty_simulation_history(problem, args)
        at = design_plant(problem, design, duty.reference.angles[0])
        path = design_path(problem, design)
        response = simulate(
            path,
            at.loop,
            duty.reference,
            duty.horizon,
            samples,
            initial_motor_angle=duty.reference.angles[0],
            initial_fin_angle=duty.reference.angles[0],
            max_events=MAX_EVENTS,
            load=duty.load,
        )
        return DesignSimulation(at.angle, at.index, response, "path", duty)
    at = design_plant(problem, design, angle)
    if args.plant == "angle":
        response = simulate(at.plant, at.loop, args.reference, args.horizon, samples)
        return DesignSimulation(at.angle, at.index, response)
    # the path's angles are the fin's: the reference moved to the grid angle
    ref = args.reference
    if isinstance(ref, StepReference):
        ref = StepReference(at.angle + ref.amplitude, ref.time)
    else:
        ref = SineReference(ref.amplitude, ref.frequency, at.angle)
    path = design_path(problem, design)
    response = simulate(
        path,
        at.loop,
        ref,
        args.horizon,
        samples,
        initial_motor_angle=at.angle,
        initial_fin_angle=at.angle,
    )
    return DesignSimulation(at.angle, at.index, response, "path")


def design_path(problem: Any, design: dict[str, float]) -> DrivePath:
    """The :class:`~optdesign.models.loop_path.DrivePath` of ``design`` through the
    plants of every grid angle."""
    with np.errstate(all="ignore"):
        q = problem.quantities(design)
        plants, _ = drive_plants_of(q)[0]
    return DrivePath.from_plants(plants)


def duty_simulation_history(problem: Any, args: SimulationArguments) -> DutyHistory:
    """``requirements.duty_cycle`` as a deflection history and a hinge load
    (:func:`optdesign.models.loop_path.duty_history`) over ``args.periods`` periods of
    ``args.period`` (else ``requirements.duty_period``), at ``requirements.
    deflection_rate``; each missing requirement refused naming it."""
    req = problem.spec.requirements
    if not req.duty_cycle:
        raise InputError(
            "requirements.duty_cycle",
            "the duty reference needs the duty cycle's steps (deflection, hinge_moment, time)",
        )
    if req.deflection_rate is None:
        raise InputError(
            "requirements.deflection_rate", "the duty reference moves between steps at it"
        )
    period = args.period
    if period is None:
        if req.duty_period is None:
            raise InputError(
                "period",
                "give the duty cycle's length (period, --period) or requirements.duty_period",
            )
        period = req.duty_period * 3600.0  # h -> s
    spring = problem.spec.load.hinge_spring if problem.spec.load is not None else 0.0
    steps = req.duty_cycle
    return duty_history(
        [s.deflection for s in steps],
        [s.hinge_moment for s in steps],
        [s.time for s in steps],
        period,
        req.deflection_rate,
        args.periods,
        spring,
    )


@dataclass(frozen=True)
class DesignPlant:
    """The drive of a design at one grid angle (rad; its index in the grid) and its
    position loop (:mod:`optdesign.models.loop_plant` records)."""

    angle: float
    index: int
    plant: DrivePlant
    loop: PositionLoop


def design_plant(problem: Any, design: dict[str, float], angle: Any = None) -> DesignPlant:
    """The :class:`DesignPlant` of ``design`` at the grid angle nearest ``angle`` (a
    quantity, or a number in rad; default: the middle of the stroke), which must lie on
    the stroke."""
    phi = np.asarray(problem.phi, dtype=float)
    where = float(np.mean(phi[[0, -1]])) if angle is None else to_internal(angle, "angle", "angle")
    if not phi[0] - 1e-9 <= where <= phi[-1] + 1e-9:
        raise InputError(
            "angle",
            f"{math.degrees(where):g} deg lies outside the stroke "
            f"({math.degrees(phi[0]):g} to {math.degrees(phi[-1]):g} deg)",
        )
    k = _nearest(phi, where)
    with np.errstate(all="ignore"):
        q = problem.quantities(design)
        plants, loop = drive_plants_of(q, [k])[0]
    return DesignPlant(float(phi[k]), k, plants[0], loop)


@dataclass(frozen=True)
class SimulationArguments:
    """A run's arguments in internal units: the reference (a model's record, rad and
    rad/s; None for the duty cycle, built from the problem), the horizon (s; None for the
    duty cycle), the plant (``"angle"`` or ``"path"``), and the duty cycle's periods and
    length (s, or None: the problem's)."""

    reference: Any
    horizon: float | None
    plant: str = "angle"
    periods: int = 1
    period: float | None = None

    @property
    def duty(self) -> bool:
        return self.reference is None


def _seconds(value: Any, field: str) -> float:
    if isinstance(value, int | float) and not isinstance(value, bool):
        T = float(value)  # a number is seconds here (a file's bare time would be hours)
    else:
        T = to_internal(value, "time", field) * 3600.0  # h -> s
    if not (math.isfinite(T) and 0.0 < T <= MAX_HORIZON):
        raise InputError(field, f"must be in (0, {MAX_HORIZON:g}] s, got {T:g} s")
    return T


def simulation_arguments(
    reference: str,
    amplitude: Any,
    horizon: Any,
    frequency: Any,
    plant: str | None = None,
    periods: Any = 1,
    period: Any = None,
) -> SimulationArguments:
    """:class:`SimulationArguments` read from quantities, each refused naming its argument
    (before any solve: the command line checks them first; what the duty cycle needs of
    the problem is checked by :func:`duty_simulation_history`)."""
    if reference not in REFERENCES:
        raise InputError("reference", f"expected one of {', '.join(REFERENCES)}, got {reference!r}")
    if plant is not None and plant not in PLANTS:
        raise InputError("plant", f"expected one of {', '.join(PLANTS)}, got {plant!r}")
    if reference == "duty":
        if plant == "angle":
            raise InputError(
                "plant",
                "a duty cycle sweeps the stroke: the plant of one angle would be wrong "
                "there; the duty reference takes the path plant",
            )
        if horizon is not None:
            raise InputError("horizon", "a duty run lasts its periods: give periods instead")
        if not isinstance(periods, int | np.integer) or isinstance(periods, bool) or periods < 1:
            raise InputError("periods", f"must be a whole number >= 1, got {periods!r}")
        length = None if period is None else _seconds(period, "period")
        if length is not None and periods * length > MAX_HORIZON:
            raise InputError(
                "periods",
                f"{periods} periods of {length:g} s exceed the {MAX_HORIZON:g} s a run may last",
            )
        return SimulationArguments(None, None, "path", int(periods), length)
    amp = to_internal(amplitude, "angle", "amplitude")
    T = HORIZON if horizon is None else _seconds(horizon, "horizon")
    plant = plant or "angle"
    if reference == "step":
        return SimulationArguments(StepReference(amp), T, plant)
    f = to_internal(frequency, "frequency", "frequency")
    return SimulationArguments(SineReference(amp, 2.0 * math.pi * f), T, plant)


#: The CSV's columns: header (with its unit), the record's field, the factor to it.
_COLUMNS = (
    ("time [s]", "times", 1.0),
    ("reference [deg]", "reference", 180.0 / math.pi),
    ("fin_angle [deg]", "fin_angle", 180.0 / math.pi),
    ("fin_rate [deg/s]", "fin_rate", 180.0 / math.pi),
    ("motor_angle_at_fin [deg]", "motor_angle", 180.0 / math.pi),
    ("motor_rate_at_fin [deg/s]", "motor_rate", 180.0 / math.pi),
    ("motor_torque [N*m]", "motor_torque", 1e-3),
    ("chain_torque [N*m]", "chain_torque", 1e-3),
    ("contact [-1/0/+1]", "contact", 1.0),
)


#: The column a run with a hinge load (the duty cycle) adds.
_LOAD_COLUMN = ("hinge_moment [N*m]", "hinge_moment", 1e-3)


def simulation_csv(sim: DesignSimulation) -> str:
    """The samples as CSV text, one column per quantity, its unit in the header (angles
    in deg at the fin, the motor's seen at the fin; torques in N*m, the motor's at its
    shaft, the chain's at the fin; a duty run adds the air's moment on the fin)."""
    columns = _COLUMNS + ((_LOAD_COLUMN,) if sim.duty is not None else ())
    out = io.StringIO()
    out.write(",".join(name for name, _, _ in columns) + "\n")
    data = np.column_stack(
        [np.asarray(getattr(sim.response, field), dtype=float) * f for _, field, f in columns]
    )
    np.savetxt(out, data, delimiter=",", fmt="%.9g")
    return out.getvalue()
