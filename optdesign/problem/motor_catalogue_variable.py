"""The motor as a catalogue variable: ``[motor] catalogue = "Yaskawa Sigma-7"`` makes the
design variable ``motor`` (the motor's number in the catalogue, 1 for the smallest rated
torque) one more catalogue variable of the branch and bound, beside the screw and the
pins.

Like the screw's items (:mod:`optdesign.problem.drive`), the motor's data are the
problem's *parameters* on the solver path: a leaf's motor's own values, and at a
relaxation node the most favourable values of the motors in the node's box - the least
rotor inertia where it costs torque or lowers the drive's mode, the largest where it
divides the load's inertia (the inertia ratio), the largest peak torque, rated torque and
top speed, the least mass, the highest and least steep falling line of the speed-torque
envelope - so that the relaxation stays a valid bound. On the NumPy path
they are looked up from the design's number (a number that is no motor's gives NaN and
fails ``motor_catalogue_membership``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from optdesign.errors import ProblemError
from optdesign.models.motor_catalogue import ServoMotor, load_motors, parse_motors

#: The motor catalogues a problem may name, and their files (None: the shipped one).
MOTOR_CATALOGUES: dict[str, str | None] = {"Yaskawa Sigma-7": None}

#: Motor fields that are parameters, with the direction favourable to a relaxation (+1:
#: the largest value of the node's motors, -1: the least) and the record's attribute.
MOTOR_FIELDS: dict[str, tuple[int, str]] = {
    "rotor_inertia": (-1, "rotor_inertia"),
    "rotor_inertia_max": (+1, "rotor_inertia"),
    "peak_torque": (+1, "peak_torque"),
    "rated_torque": (+1, "rated_torque"),
    "max_speed": (+1, "max_speed"),
    "mass": (-1, "mass"),
    # the falling piece of the speed-torque envelope, T + s n <= a: the largest a and the
    # least s over a node's motors give a line above each of theirs at every speed
    "envelope_intercept": (+1, "envelope_intercept"),
    "envelope_slope": (-1, "envelope_slope"),
}

#: Prefix of the motor's parameters (``param:motor_peak_torque``...).
PREFIX = "motor_"


@dataclass(frozen=True)
class MotorCatalogue:
    """A problem's motor catalogue: its name as the file writes it (a shipped catalogue's
    or a CSV file's) and, for a file, the text read when the problem loaded."""

    name: str
    text: str | None = None


def _field(row: ServoMotor, attribute: str) -> float:
    # A motor without a printed mass has none to relax over: 0 (the objective motor_mass
    # is refused for such a catalogue, so the value is never used).
    value = getattr(row, attribute)
    return 0.0 if value is None else float(value)


@cache
def motors(catalogue: MotorCatalogue | str) -> tuple[ServoMotor, ...]:
    """The catalogue's motors, smallest rated torque first (then by designation): motor
    number k is ``motors(catalogue)[k - 1]``. A string is a shipped catalogue's name."""
    if isinstance(catalogue, str):
        catalogue = MotorCatalogue(catalogue)
    if catalogue.text is not None:
        rows = parse_motors(catalogue.text, Path(catalogue.name).name)
    elif catalogue.name in MOTOR_CATALOGUES:
        rows = load_motors(MOTOR_CATALOGUES[catalogue.name])
    else:
        known = ", ".join(MOTOR_CATALOGUES)
        raise ProblemError(
            f"motor.catalogue: unknown catalogue {catalogue.name!r} (known: {known})"
        )
    return tuple(sorted(rows, key=lambda r: (r.rated_torque, r.designation)))


def motor_numbers(catalogue: MotorCatalogue | str) -> list[float]:
    """The values of the variable ``motor``: 1, 2, ... n."""
    return [float(k) for k in range(1, len(motors(catalogue)) + 1)]


def motor_by_number(catalogue: MotorCatalogue | str, number: float) -> ServoMotor:
    """Motor number ``number`` of the catalogue."""
    k = int(np.rint(float(number)))
    rows = motors(catalogue)
    if not (1 <= k <= len(rows)) or abs(number - k) > 1e-9:
        name = catalogue if isinstance(catalogue, str) else catalogue.name
        raise ProblemError(f"variables.motor: {number:g} is no motor of {name!r}")
    return rows[k - 1]


def spec_catalogue(motor) -> MotorCatalogue | None:
    """The catalogue of a ``[motor]`` section (None without one)."""
    if motor is None or motor.catalogue is None:
        return None
    return MotorCatalogue(motor.catalogue, motor.catalogue_text)


def catalogue_of(problem) -> MotorCatalogue | None:
    """The problem's motor catalogue when its motor is a catalogue variable, else None."""
    var = problem.by_name.get("motor")
    if var is None or not var.discrete:
        return None
    return spec_catalogue(problem.spec.motor)


def has_corners(catalogue: MotorCatalogue | None) -> bool:
    """True when a motor of the catalogue has a speed-torque corner (then the problem
    poses the envelope's falling piece; a motor without one has a flat envelope)."""
    return catalogue is not None and any(r.corner_speed is not None for r in motors(catalogue))


def masses_missing(catalogue: MotorCatalogue) -> list[str]:
    """The designations of the catalogue's motors without a mass."""
    return [r.designation for r in motors(catalogue) if r.mass is None]


def parameter_defaults(problem) -> dict[str, float]:
    """Placeholders (1) of the motor's parameters, replaced by every catalogue solve."""
    if catalogue_of(problem) is None:
        return {}
    return {PREFIX + field: 1.0 for field in MOTOR_FIELDS}


def parameter_owners(problem) -> dict[str, tuple[str, ...]]:
    """The motor's parameters, each read from the item of the variable ``motor``."""
    return {name: ("motor",) for name in parameter_defaults(problem)}


def parameter_values(problem, box: dict[str, tuple[float, float]]) -> dict[str, float]:
    """The motor's parameters over the motors whose number lies in ``box["motor"]`` (the
    variable's bounds when the box leaves it out): exact for one motor, favourable over
    several. Empty when the box holds no motor."""
    catalogue = catalogue_of(problem)
    if catalogue is None:
        return {}
    var = problem.by_name["motor"]
    lo, hi = box.get("motor", (var.lower, var.upper))
    rows = [r for k, r in enumerate(motors(catalogue), 1) if lo - 1e-9 <= k <= hi + 1e-9]
    if not rows:
        return {}
    out = {}
    for field, (sign, attribute) in MOTOR_FIELDS.items():
        values = [_field(r, attribute) for r in rows]
        out[PREFIX + field] = max(values) if sign > 0 else min(values)
    return out


def design_values(problem, design: dict[str, Any]) -> tuple[dict[str, Any], Any]:
    """The motor's fields of ``design`` (parameters on the solver path; looked up from its
    number on the NumPy path, element-wise) and where the number is a motor's (1.0) or
    not (0.0; None on the solver path)."""
    catalogue = catalogue_of(problem)
    keys = {f: next(iter(problem.parameter_design({PREFIX + f: 0.0}))) for f in MOTOR_FIELDS}
    if keys["peak_torque"] in design:
        return {f: design[key] for f, key in keys.items()}, None
    number = np.asarray(design["motor"], dtype=float)
    rows = motors(catalogue)
    out = {f: np.full(number.shape, np.nan) for f in MOTOR_FIELDS}
    on = np.zeros(number.shape)
    for idx in np.ndindex(number.shape):
        k = int(np.rint(number[idx])) if np.isfinite(number[idx]) else 0
        if not 1 <= k <= len(rows):
            continue
        on[idx] = float(abs(number[idx] - k) <= 1e-9)
        for field, (_, attribute) in MOTOR_FIELDS.items():
            out[field][idx] = _field(rows[k - 1], attribute)
    if not number.ndim:
        return {f: float(v) for f, v in out.items()}, float(on)
    return out, on


#: Margin on the motor's peak torque before a motor is excluded: the bound below is
#: proved, the margin keeps a motor a solver could still call feasible within its
#: tolerance.
EXCLUSION_MARGIN = 1e-4

#: The requirements (row names) :func:`impossible_motors` rests on: the torque the
#: motion asks within the motor's peak torque, and the motor's speed within its top
#: speed (the cap on the ratio). With either dropped (a diagnosis's search without it),
#: the exclusion proves nothing; with ``mean_ratio`` dropped, it uses the motion alone.
EXCLUSION_ROWS = frozenset({"motor_peak_torque", "motor_speed"})


def torque_floor(problem, row: ServoMotor, ratio_min: float | None = None) -> float | None:
    """A torque (N*mm) every design of ``problem`` whose motor speed stays within
    ``row``'s top speed asks of motor ``row``: at every grid angle the motion's torque is
    at least J0 f' a + M / f' + T_f (the rotor and gear inertia J0 of :func:`~optdesign.
    problem.motor_drive.motor_side_inertia`, without the screw's and the nut's; the
    output's demand M of :func:`~optdesign.problem.motor_drive.output_demand` with an
    efficiency of 1; the ratio's rate dropped), and the speed row caps the ratio f' at the
    top speed over the fin's top rate: the least of the bound over 0 < f' <= the cap, at
    the worst angle. ``ratio_min`` (the least mean ratio a design may have): the ratio at
    the angle where it is largest is at least that mean, so the torque there is at least
    the least of the bound over ``ratio_min <= f' <= the cap`` with the least output
    demand over the stroke; the floor is the larger of the two (infinite when the cap lies below
    ``ratio_min``). None when the motion gives no rate or the demand changes sign."""
    from optdesign.problem.motion import motion_demand

    spec = problem.spec
    demand = motion_demand(spec)
    if demand is None or not demand.rate > 0:
        return None
    load = spec.load
    J_fin, c, k = (
        (0.0, 0.0, 0.0) if load is None else (load.inertia, load.damping, load.hinge_spring)
    )
    a, w = demand.acceleration, demand.rate
    phi = np.asarray(problem.phi, dtype=float)
    M = J_fin * a + c * w + np.abs(k * phi) + spec.requirements.hinge_moment
    if not np.all(M > 0):
        return None
    J0 = row.rotor_inertia + spec.motor.gear_inertia
    cap = row.max_speed / w
    # J0 a f' + M / f' is convex in f' > 0, least at sqrt(M / (J0 a)): clipped to the range
    best = np.minimum(np.sqrt(M / (J0 * a)), cap) if a > 0 else np.full_like(M, cap)
    floor = float(np.max(J0 * best * a + M / best))
    if ratio_min is not None and ratio_min > 0:
        if ratio_min > cap:
            return math.inf
        # the angle of the largest ratio is unknown: the least output demand over the
        # stroke (the spring's share 0 where the stroke passes through 0, whatever the
        # grid), which only lowers the bound
        spring = 0.0 if phi.min() <= 0.0 <= phi.max() else float(np.min(np.abs(k * phi)))
        M_least = float(np.min(M - np.abs(k * phi))) + spring
        top = min(max(math.sqrt(M_least / (J0 * a)), ratio_min), cap) if a > 0 else cap
        floor = max(floor, J0 * top * a + M_least / top)
    return floor + spec.motor.friction_torque


def impossible_motors(problem, dropped: Iterable[str] = ()) -> dict[float, str]:
    """The catalogue motors no design of ``problem`` can use, by their number, with why:
    those whose peak torque lies below :func:`torque_floor` (with the least mean ratio
    when ``mean_ratio`` has a minimum). Empty when the motor is no catalogue variable,
    the motion gives no rate, or ``dropped`` (requirements a search leaves unbounded)
    holds one of :data:`EXCLUSION_ROWS`; ``mean_ratio`` dropped: the floor without it."""
    from optdesign.problem.motion import motion_demand

    dropped = set(dropped)
    catalogue = catalogue_of(problem)
    demand = motion_demand(problem.spec) if catalogue is not None else None
    if demand is None or EXCLUSION_ROWS & dropped:
        return {}
    band = problem.spec.requirements.mean_ratio
    ratio_min = None if band is None or "mean_ratio" in dropped else band.min
    lo, hi = problem.by_name["motor"].lower, problem.by_name["motor"].upper
    out = {}
    for number, row in enumerate(motors(catalogue), 1):
        if not lo <= number <= hi:
            continue
        need = torque_floor(problem, row, ratio_min)
        if need is None or need <= row.peak_torque * (1.0 + EXCLUSION_MARGIN):
            continue
        cap = row.max_speed / demand.rate
        alone = torque_floor(problem, row)
        if alone is not None and alone > row.peak_torque * (1.0 + EXCLUSION_MARGIN):
            # the motion alone proves it: the message names no mean ratio
            out[float(number)] = (
                f"{row.designation}: the motion asks at least {alone * 1e-3:.4g} N*m at any "
                f"design, above its peak torque {row.peak_torque * 1e-3:.4g} N*m (its top "
                f"speed caps the ratio at {cap:.4g})"
            )
        elif math.isinf(need):
            out[float(number)] = (
                f"{row.designation}: its top speed caps the ratio at {cap:.4g}, below "
                f"mean_ratio.min {ratio_min:.4g}"
            )
        else:
            out[float(number)] = (
                f"{row.designation}: the motion asks at least {need * 1e-3:.4g} N*m of any "
                f"design whose mean ratio reaches mean_ratio.min {ratio_min:.4g} (the "
                f"largest ratio at least that, at most its top speed's cap {cap:.4g}), "
                f"above its peak torque {row.peak_torque * 1e-3:.4g} N*m"
            )
    return out
