"""AC servomotor catalogue: rated and peak torque, rated and maximum speed, rotor inertia
(and mass where printed), from one public manufacturer manual (package data), or from a
user's CSV with the same columns.

Source (the CSV's header repeats it): YASKAWA Electric, *Sigma-7-Series AC Servo Drive,
Rotary Servomotor Product Manual*, section 4.2.2 (SGM7J-A5A to -08A, p. 4-4) and section
5.2.4 (SGM7A-15A to -70A, p. 5-7), 200 V motors without gears, read through the
manualshive.com mirror of the manual (the manual number and edition are not on the pages
read). Values are transcribed as printed; the masses are not (they are in the manual's
dimension tables), so ``mass`` is None for every shipped motor.

Units in the records: the internal ones (README "Units"; conversions in
:mod:`optdesign.models.motor`): torques N*mm (printed N*m x 1e3), speeds rad/s (printed
min^-1 x 2 pi / 60), inertias t*mm^2 (printed 1e-4 kg*m^2 x 0.1), mass t (kg x 1e-3),
rated output N*mm/s (W x 1e3).

Validity
--------
items : the rows of the CSV (rated torque 0.159-22.3 N*m)
    Catalogue data hold for the motors printed; a designation the catalogue does not
    list is no motor (refused by :func:`by_designation`).
"""

from __future__ import annotations

import csv
import functools
import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from optdesign.errors import InputError
from optdesign.models.motor import KG, KG_CM2, N_M, RPM
from optdesign.models.motor_limits import envelope_intercept, envelope_slope
from optdesign.models.validity import Validity

CATALOGUE_ITEMS = Validity(
    "motor_catalogue.rated_torque",
    "servomotor catalogue",
    "rated torque",
    159.0,
    22300.0,
    "N*mm",
    "the catalogue's data hold for the motors it prints (SGM7J-A5A 0.159 N*m to SGM7A-70A "
    "22.3 N*m)",
    shown_unit="N*m",
    scale=1e-3,
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (CATALOGUE_ITEMS,)

#: The manual every shipped record comes from.
CATALOGUE_SOURCE = (
    "YASKAWA, Sigma-7-Series AC Servo Drive Rotary Servomotor Product Manual, "
    "section 4.2.2 (p. 4-4) and section 5.2.4 (p. 5-7)"
)

_RESOURCE = "data/servo_motors.csv"

#: Columns a motor CSV must have (``rotor_inertia_brake_1e-4kgm2``, ``mass_kg``,
#: ``rated_output_W``, ``power_rate_kW_per_s``, ``angular_accel_rad_per_s2``,
#: ``corner_speed_rpm``, ``top_speed_torque_Nm``, ``series``, ``section``, ``page`` and
#: ``note`` are optional and may be empty).
REQUIRED_COLUMNS = (
    "designation",
    "rated_torque_Nm",
    "peak_torque_Nm",
    "rated_speed_rpm",
    "max_speed_rpm",
    "rotor_inertia_1e-4kgm2",
)
_OPTIONAL_NUMBERS = (
    "rotor_inertia_brake_1e-4kgm2",
    "mass_kg",
    "rated_output_W",
    "power_rate_kW_per_s",
    "angular_accel_rad_per_s2",
    "corner_speed_rpm",
    "top_speed_torque_Nm",
)


@dataclass(frozen=True)
class ServoMotor:
    """One motor of the catalogue (internal units: N*mm, rad/s, t*mm^2, t).

    Attributes
    ----------
    designation
        The maker's model (``"SGM7J-01A"``), unique in a file.
    series
        The motor family (``"SGM7J"``), or ``""``.
    rated_torque, peak_torque
        Continuous rated torque and instantaneous maximum torque (N*mm).
    rated_speed, max_speed
        Rated and maximum speed (rad/s).
    rotor_inertia
        Rotor moment of inertia of the standard motor (t*mm^2).
    rotor_inertia_brake
        With a holding brake (t*mm^2), or None where not printed.
    mass
        Motor mass (t), or None where not printed or not transcribed.
    rated_output
        Rated output (N*mm/s; W x 1e3), or None.
    power_rate, angular_acceleration
        Printed rated power rate (kW/s) and rated angular acceleration (rad/s^2), kept in
        the printed units as checks of the transcription (T_rated^2 / J and T_rated / J),
        or None.
    section, page
        Where in the manual; ``""`` for a user's file without them.
    file, line
        The CSV and its line the row was read from.
    note
        Remark on the printed values, if any.
    corner_speed, top_speed_torque
        The intermittent zone's corner (rad/s), above which the peak torque falls
        linearly to ``top_speed_torque`` (N*mm) at the top speed
        (:mod:`optdesign.models.motor_limits`); None where not given (no fall). Without
        a top-speed torque the fall ends at the rated torque.
    """

    designation: str
    series: str
    rated_torque: float
    peak_torque: float
    rated_speed: float
    max_speed: float
    rotor_inertia: float
    rotor_inertia_brake: float | None
    mass: float | None
    rated_output: float | None
    power_rate: float | None
    angular_acceleration: float | None
    section: str
    page: str
    file: str
    line: int
    note: str = ""
    corner_speed: float | None = None
    top_speed_torque: float | None = None

    @property
    def envelope_slope(self) -> float:
        """How fast the intermittent torque falls above the corner (N*mm per rad/s); 0
        without a corner."""
        if self.corner_speed is None:
            return 0.0
        top = self.rated_torque if self.top_speed_torque is None else self.top_speed_torque
        return envelope_slope(self.peak_torque, self.corner_speed, self.max_speed, top)

    @property
    def envelope_intercept(self) -> float:
        """The falling line's torque at standstill, T_peak + s n_c (N*mm); the peak
        torque without a corner."""
        corner = 0.0 if self.corner_speed is None else self.corner_speed
        return envelope_intercept(self.peak_torque, corner, self.envelope_slope)

    @property
    def source(self) -> str:
        """Citation of this row."""
        where = f", section {self.section}, p. {self.page}" if self.page else ""
        return f"{self.file}, line {self.line}{where}, {self.designation}"


class _Row:
    """One CSV row being read, for errors that name the file, the line and the column."""

    def __init__(self, file: str, line: int, values: dict[str, str]):
        self.file, self.line, self.values = file, line, values
        self.name = values.get("designation", "").strip()

    def error(self, column: str, reason: str) -> InputError:
        who = f" ({self.name})" if self.name else ""
        return InputError(f"{self.file}, line {self.line}{who}, column {column}", reason)

    def text(self, column: str) -> str:
        return (self.values.get(column) or "").strip()

    def number(self, column: str) -> float | None:
        """The column's number, or None where the cell is empty."""
        raw = self.text(column)
        if not raw:
            return None
        try:
            value = float(raw)
        except ValueError:
            raise self.error(column, f"{raw!r} is not a number") from None
        if not math.isfinite(value):
            raise self.error(column, f"{raw!r} is not a finite number")
        return value

    def required(self, column: str) -> float:
        value = self.number(column)
        if value is None:
            raise self.error(column, "missing; every motor needs it")
        return value

    def positive(self, column: str, what: str, required: bool = True) -> float | None:
        value = self.required(column) if required else self.number(column)
        if value is not None and value <= 0:
            raise self.error(column, f"{value:g}: {what}")
        return value


def _motor(row: _Row) -> ServoMotor:
    if not row.name:
        raise row.error("designation", "missing; every motor needs a name")
    rated = row.required("rated_torque_Nm")
    if rated <= 0:
        raise row.error("rated_torque_Nm", f"{rated:g}: a rated torque must be positive")
    corner = row.number("corner_speed_rpm")
    if corner is not None and row.number("peak_torque_Nm") is None:
        raise row.error(
            "peak_torque_Nm",
            f"missing; the corner speed {corner:g} min^-1 is where the peak torque starts to "
            "fall, so the motor needs it",
        )
    peak = row.required("peak_torque_Nm")
    if peak < rated:
        raise row.error("peak_torque_Nm", f"{peak:g} N*m is below the rated torque {rated:g} N*m")
    n_max = row.required("max_speed_rpm")
    if n_max <= 0:
        raise row.error("max_speed_rpm", f"{n_max:g}: a motor that cannot turn (max speed <= 0)")
    n_rated = row.required("rated_speed_rpm")
    if not 0 < n_rated <= n_max:
        raise row.error(
            "rated_speed_rpm", f"{n_rated:g} min^-1 is outside (0, max speed {n_max:g} min^-1]"
        )
    inertia = row.required("rotor_inertia_1e-4kgm2")
    if inertia <= 0:
        kind = "negative" if inertia < 0 else "zero"
        raise row.error("rotor_inertia_1e-4kgm2", f"{inertia:g}: a {kind} rotor inertia")
    brake = row.positive("rotor_inertia_brake_1e-4kgm2", "an inertia must be positive", False)
    if brake is not None and brake < inertia:
        raise row.error(
            "rotor_inertia_brake_1e-4kgm2",
            f"{brake:g} is below the motor's own {inertia:g}: a brake adds inertia",
        )
    mass = row.positive("mass_kg", "a mass must be positive", False)
    top = _envelope(row, corner, peak, n_max)
    output = row.positive("rated_output_W", "a rated output must be positive", False)
    return ServoMotor(
        designation=row.name,
        series=row.text("series"),
        rated_torque=N_M * rated,
        peak_torque=N_M * peak,
        rated_speed=RPM * n_rated,
        max_speed=RPM * n_max,
        rotor_inertia=KG_CM2 * inertia,
        rotor_inertia_brake=None if brake is None else KG_CM2 * brake,
        mass=None if mass is None else KG * mass,
        rated_output=None if output is None else 1e3 * output,
        power_rate=row.positive("power_rate_kW_per_s", "must be positive", False),
        angular_acceleration=row.positive("angular_accel_rad_per_s2", "must be positive", False),
        section=row.text("section"),
        page=row.text("page"),
        file=row.file,
        line=row.line,
        note=row.text("note"),
        corner_speed=None if corner is None else RPM * corner,
        top_speed_torque=None if top is None else N_M * top,
    )


def _envelope(row: _Row, corner: float | None, peak: float, n_max: float) -> float | None:
    """The row's top-speed torque (N*m, None when not given), after checking the corner
    and the torque against the peak torque and the top speed."""
    top = row.number("top_speed_torque_Nm")
    if corner is None:
        if top is not None:
            raise row.error(
                "top_speed_torque_Nm",
                f"{top:g} N*m without a corner speed (corner_speed_rpm): give the speed above "
                "which the peak torque falls",
            )
        return None
    if corner <= 0:
        raise row.error("corner_speed_rpm", f"{corner:g}: a corner speed must be positive")
    if corner >= n_max:
        raise row.error(
            "corner_speed_rpm",
            f"{corner:g} min^-1 is not below the maximum speed {n_max:g} min^-1 (a motor whose "
            "peak torque holds up to its top speed has no corner: leave the cell empty)",
        )
    if top is not None and not 0 <= top <= peak:
        raise row.error(
            "top_speed_torque_Nm",
            f"{top:g} N*m is outside [0, the peak torque {peak:g} N*m]: the intermittent "
            "torque falls from the peak above the corner",
        )
    return top


def parse_motors(text: str, file: str = "<text>") -> tuple[ServoMotor, ...]:
    """Motors of a CSV text (``#`` lines are comments); errors name ``file``, the line
    and the column (:class:`optdesign.errors.InputError`)."""
    lines = [
        (k, line)
        for k, line in enumerate(text.splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not lines:
        raise InputError(file, "no header line (designation, rated_torque_Nm, ...)")
    header_line, header_text = lines[0]
    header = [h.strip() for h in next(csv.reader([header_text]))]
    missing = [c for c in REQUIRED_COLUMNS if c not in header]
    if missing:
        raise InputError(
            f"{file}, line {header_line}",
            f"missing column(s) {', '.join(missing)} (required: {', '.join(REQUIRED_COLUMNS)})",
        )
    out: list[ServoMotor] = []
    seen: dict[str, int] = {}
    for k, line in lines[1:]:
        cells = next(csv.reader([line]))
        row = _Row(file, k, dict(zip(header, cells, strict=False)))
        if len(cells) > len(header):
            raise row.error("-", f"{len(cells)} cells for {len(header)} columns")
        motor = _motor(row)
        if motor.designation in seen:
            raise row.error(
                "designation", f"{motor.designation!r} already on line {seen[motor.designation]}"
            )
        seen[motor.designation] = k
        out.append(motor)
    if not out:
        raise InputError(file, "no motor rows")
    return tuple(out)


def load_motors(path: str | Path | None = None) -> tuple[ServoMotor, ...]:
    """The motors of a CSV file (default: the shipped catalogue, read once)."""
    if path is None:
        return _shipped()
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise InputError(str(path), f"cannot read the motor file ({err.strerror})") from None
    return parse_motors(text, path.name)


@functools.cache
def _shipped() -> tuple[ServoMotor, ...]:
    text = resources.files("optdesign").joinpath(_RESOURCE).read_text(encoding="utf-8")
    return parse_motors(text, Path(_RESOURCE).name)


def by_designation(designation: str, motors: tuple[ServoMotor, ...] | None = None) -> ServoMotor:
    """The motor of this designation; InputError naming ``designation`` if none."""
    for motor in _shipped() if motors is None else motors:
        if motor.designation == designation:
            return motor
    raise InputError("designation", f"{designation!r} is not in the catalogue ({CATALOGUE_SOURCE})")


def find(
    rated_torque_min: float = 0.0,
    peak_torque_min: float = 0.0,
    max_speed_min: float = 0.0,
    rotor_inertia_min: float = 0.0,
    motors: tuple[ServoMotor, ...] | None = None,
) -> tuple[ServoMotor, ...]:
    """Motors meeting the selection check (internal units): rated torque >= an RMS
    torque, peak torque >= a peak torque, top speed >= a motor speed, rotor inertia >=
    the load's over the allowed inertia ratio. Smallest rated torque first."""
    pool = _shipped() if motors is None else motors
    hits = [
        mo
        for mo in pool
        if mo.rated_torque >= rated_torque_min
        and mo.peak_torque >= peak_torque_min
        and mo.max_speed >= max_speed_min
        and mo.rotor_inertia >= rotor_inertia_min
    ]
    return tuple(sorted(hits, key=lambda mo: (mo.rated_torque, mo.designation)))
