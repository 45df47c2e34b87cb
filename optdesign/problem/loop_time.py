"""The time response of a design in its position loop (docs/loop.md): the
plant of one grid angle (:mod:`optdesign.problem.loop`) simulated by
:func:`optdesign.models.loop_simulation.simulate`, and its samples as a CSV with units.

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
from optdesign.models.loop_plant import DrivePlant, PositionLoop
from optdesign.models.loop_simulation import (
    MAX_HORIZON,
    LoopSimulation,
    SineReference,
    StepReference,
    simulate,
)
from optdesign.problem.loop import drive_plants_of
from optdesign.units import to_internal

#: The references :func:`simulate_design` takes.
REFERENCES = ("step", "sine")


@dataclass(frozen=True)
class DesignSimulation:
    """A design's time response at one grid angle: the angle (rad), the index in the
    grid, and the model's record (:class:`~optdesign.models.loop_simulation.
    LoopSimulation`, internal units)."""

    angle: float
    index: int
    response: LoopSimulation


def _nearest(phi: np.ndarray, angle: float) -> int:
    return int(np.argmin(np.abs(phi - angle)))


def simulate_design(
    problem: Any,
    design: dict[str, float],
    reference: str = "step",
    amplitude: Any = "1 deg",
    angle: Any = None,
    horizon: Any = "0.5 s",
    frequency: Any = "5 Hz",
    samples: int = 2001,
) -> DesignSimulation:
    """The response of ``design`` (every variable, internal units) of ``problem`` (with a
    ``[loop]``) about the grid angle nearest ``angle`` (default: the middle of the
    stroke), from rest at the gap's centre.

    Parameters
    ----------
    reference
        ``"step"`` (of ``amplitude`` at t = 0) or ``"sine"`` (``amplitude`` at
        ``frequency``).
    amplitude, angle
        Angles (``"1 deg"``, or a number in rad).
    horizon
        The simulated time (``"0.5 s"``, or a number in s), at most 600 s.
    frequency
        The sine's frequency (``"5 Hz"``, or a number in Hz).
    samples
        Output samples, 2 to 10^6.
    """
    if problem.spec.loop is None:
        raise ProblemError("simulate: needs a [loop] section (the controller)")
    args = simulation_arguments(reference, amplitude, horizon, frequency)
    at = design_plant(problem, design, angle)
    response = simulate(at.plant, at.loop, args.reference, args.horizon, samples)
    return DesignSimulation(at.angle, at.index, response)


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
    """The reference (a model's record, rad and rad/s) and the horizon (s) of a run."""

    reference: Any
    horizon: float


def simulation_arguments(reference: str, amplitude: Any, horizon: Any, frequency: Any):
    """:class:`SimulationArguments` read from quantities, each refused naming its argument
    (before any solve: the command line checks them first)."""
    if reference not in REFERENCES:
        raise InputError("reference", f"expected one of {', '.join(REFERENCES)}, got {reference!r}")
    amp = to_internal(amplitude, "angle", "amplitude")
    if isinstance(horizon, int | float) and not isinstance(horizon, bool):
        T = float(horizon)  # a number is seconds here (a file's bare time would be hours)
    else:
        T = to_internal(horizon, "time", "horizon") * 3600.0  # h -> s
    if not (math.isfinite(T) and 0.0 < T <= MAX_HORIZON):
        raise InputError("horizon", f"must be in (0, {MAX_HORIZON:g}] s, got {T:g} s")
    if reference == "step":
        return SimulationArguments(StepReference(amp), T)
    f = to_internal(frequency, "frequency", "frequency")
    return SimulationArguments(SineReference(amp, 2.0 * math.pi * f), T)


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


def simulation_csv(sim: DesignSimulation) -> str:
    """The samples as CSV text, one column per quantity, its unit in the header (angles
    in deg at the fin, the motor's seen at the fin; torques in N*m, the motor's at its
    shaft, the chain's at the fin)."""
    out = io.StringIO()
    out.write(",".join(name for name, _, _ in _COLUMNS) + "\n")
    data = np.column_stack(
        [np.asarray(getattr(sim.response, field), dtype=float) * f for _, field, f in _COLUMNS]
    )
    np.savetxt(out, data, delimiter=",", fmt="%.9g")
    return out.getvalue()
