"""The motor, the load and the motion of a problem file (:mod:`optdesign.problem.spec`):
``[motor]``, ``[load]`` and ``[motion]``. Values in internal units once parsed (mm, N, s,
rad; a mass in t, an inertia in t*mm^2 = N*mm*s^2; README "Units")."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from pydantic import Field, ValidationInfo, model_validator

from optdesign.errors import InputError
from optdesign.problem.spec_types import (
    Angle,
    AngularAcceleration,
    AngularSpeed,
    Dimensionless,
    Frequency,
    Inertia,
    Mass,
    Moment,
    RotationalDamping,
    RotationalStiffness,
    Speed,
    Time,
    _Model,
    _shown,
)

#: Largest motor CSV a problem may name (the shipped one is 4 kB).
MAX_CATALOGUE_BYTES = 1 << 20


def is_catalogue_file(catalogue: str) -> bool:
    """True when ``[motor] catalogue`` names a CSV file rather than a shipped catalogue."""
    return catalogue.lower().endswith(".csv")


def read_catalogue_file(catalogue: str, folder: str | None) -> str:
    """The text of a user's motor CSV: ``catalogue`` relative to ``folder`` (the problem
    file's folder; the working folder for a problem given as a dict), checked by parsing
    it, so that a wrong row is refused when the problem loads (ValueError naming the
    file, the line and the column)."""
    from optdesign.safe_io import UnsafeFileError, read_file

    path = Path(catalogue)
    if not path.is_absolute() and folder is not None:
        path = Path(folder) / path
    try:
        raw = read_file(path, what="the motor catalogue", limit=MAX_CATALOGUE_BYTES, follow=True)
    except UnsafeFileError as exc:  # its reason alone: the message words an output's
        raise ValueError(f"catalogue: cannot read {path}: it {exc.reason}") from None
    except OSError as exc:
        raise ValueError(f"catalogue: cannot read {path} ({exc.strerror})") from None
    if raw is None:
        raise ValueError(f"catalogue: no file {path}")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ValueError(f"catalogue: {path} is not a UTF-8 text file") from None
    return checked_catalogue(text, path.name)


def checked_catalogue(text: str, file: str) -> str:
    """``text`` when it parses as a motor CSV; else ValueError naming the file, the line
    and the column."""
    from optdesign.models.motor_catalogue import parse_motors

    try:
        parse_motors(text, file)
    except InputError as exc:
        raise ValueError(f"catalogue: {exc}") from None
    return text


#: The motor's data a problem needs, with what each is for.
MOTOR_DATA = {
    "rotor_inertia": "the rotor's inertia (the torque to accelerate it, the inertia ratio)",
    "peak_torque": "the instantaneous maximum torque (the peak demand's limit)",
    "max_speed": "the top speed (the speed limit)",
}


#: The motor's optional data (a motor of the catalogue or a catalogue variable carries its
#: own: they are refused beside a designation or a catalogue).
OPTIONAL_DATA = (
    "rated_torque",
    "mass",
    "corner_speed",
    "top_speed_torque",
    "thermal_time_constant",
)


class Motor(_Model):
    """The drive's motor (``max_speed`` in 1/min, turns per minute, as ISO's n): one motor
    of the shipped catalogue (``designation``), one given by its data, or a catalogue
    whose motors the search chooses from (``catalogue``: the variable ``motor``,
    :mod:`optdesign.problem.motor_catalogue_variable`). ``rated_torque`` (the continuous
    torque) limits the RMS torque of the duty cycle; ``mass`` is reported and is the
    objective ``motor_mass``. ``catalogue`` is a shipped catalogue's name or a CSV file
    with the shipped one's columns (relative to the problem file's folder); the file's
    text is read once, when the problem loads, into ``catalogue_text`` (so a problem
    carries its motors to every worker, and a changed file is a changed problem).
    ``gear_inertia`` is what else turns with the motor (gear, coupling), at the motor
    shaft; ``friction_torque`` the drive's own friction at the motor shaft.

    Optional data of a motor given by its data: ``corner_speed`` (1/min), above which the
    intermittent torque falls linearly from the peak torque to ``top_speed_torque`` at
    the top speed (to the rated torque without it), and ``thermal_time_constant``, the
    winding's: with it the duty cycle's heating is the first-order thermal model's, not
    its plain RMS (:mod:`optdesign.models.motor_limits`)."""

    designation: str | None = None
    catalogue: str | None = None
    catalogue_text: str | None = Field(None, repr=False)
    rotor_inertia: Inertia | None = None
    peak_torque: Moment | None = None
    rated_torque: Moment | None = None
    max_speed: Speed | None = None
    mass: Mass | None = None
    corner_speed: Speed | None = None
    top_speed_torque: Moment | None = None
    thermal_time_constant: Time | None = None
    gear_inertia: Inertia = 0.0
    friction_torque: Moment = 0.0

    @model_validator(mode="before")
    @classmethod
    def _read_file(cls, data: Any, info: ValidationInfo) -> Any:
        # A CSV named by the file is read here, once: a dump of the spec re-validated
        # elsewhere (a worker, a changed copy) carries the text and reads no file.
        if not isinstance(data, dict):
            return data
        catalogue = data.get("catalogue")
        if isinstance(catalogue, str) and is_catalogue_file(catalogue):
            text = data.get("catalogue_text")
            if text is None:
                folder = (info.context or {}).get("folder")
                text = read_catalogue_file(catalogue, folder)
            elif isinstance(text, str):
                text = checked_catalogue(text, Path(catalogue).name)
            data = {**data, "catalogue_text": text}
        elif data.get("catalogue_text") is not None:
            raise ValueError("catalogue_text: only with a catalogue CSV file (catalogue = FILE)")
        return data

    @model_validator(mode="after")
    def _data(self):
        given = [k for k in (*MOTOR_DATA, *OPTIONAL_DATA) if getattr(self, k) is not None]
        if self.catalogue is not None:
            from optdesign.problem.motor_catalogue_variable import MOTOR_CATALOGUES

            if self.catalogue not in MOTOR_CATALOGUES and self.catalogue_text is None:
                known = ", ".join(repr(k) for k in MOTOR_CATALOGUES)
                raise ValueError(
                    f"catalogue: unknown {self.catalogue!r} (known: {known}, or a CSV file "
                    'with the shipped catalogue\'s columns, e.g. catalogue = "motors.csv")'
                )
            mine = given + (["designation"] if self.designation is not None else [])
            if mine:
                raise ValueError(
                    f"catalogue: the search picks the motor; do not give {', '.join(mine)} too"
                )
            return self
        if self.designation is not None:
            if given:
                raise ValueError(
                    f"designation: gives the motor's data; do not give {', '.join(given)} too"
                )
            from optdesign.models.motor_catalogue import by_designation

            try:
                by_designation(self.designation)
            except InputError as exc:
                raise ValueError(f"designation: {exc.reason}") from None
            return self
        missing = [k for k in MOTOR_DATA if getattr(self, k) is None]
        if missing:
            raise ValueError(
                f"{missing[0]}: needed ({MOTOR_DATA[missing[0]]}); give the motor's data, a "
                'designation of the shipped catalogue (e.g. designation = "SGM7J-04A") or a '
                'catalogue to choose from (catalogue = "Yaskawa Sigma-7")'
            )
        for name in ("rotor_inertia", "peak_torque", "rated_torque", "max_speed", "mass"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise ValueError(f"{name}: must be positive, got {value:g} (internal units)")
        if self.thermal_time_constant is not None and not self.thermal_time_constant > 0:
            raise ValueError(
                f"thermal_time_constant: must be positive, got "
                f"{self.thermal_time_constant * 3600.0:g} s"
            )
        self._check_envelope()
        for name in ("gear_inertia", "friction_torque"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name}: cannot be negative, got {getattr(self, name):g}")
        if self.rated_torque is not None and self.rated_torque > self.peak_torque:
            raise ValueError(
                f"rated_torque: {_shown('motor_torque_max', self.rated_torque)} is above the "
                f"peak torque {_shown('motor_torque_max', self.peak_torque)}"
            )
        return self

    def _check_envelope(self) -> None:
        # The envelope falls from the peak torque at the corner to the top-speed torque
        # at the top speed: a corner outside (0, top speed) or a torque that rises is a
        # typing error, not a motor.
        if self.corner_speed is None:
            if self.top_speed_torque is not None:
                raise ValueError(
                    "top_speed_torque: needs corner_speed (the speed above which the peak "
                    "torque falls to it)"
                )
            return
        if not self.corner_speed > 0:
            raise ValueError(f"corner_speed: must be positive, got {self.corner_speed:g} 1/min")
        if self.corner_speed >= self.max_speed:
            raise ValueError(
                f"corner_speed: {self.corner_speed:g} 1/min is not below the top speed "
                f"max_speed = {self.max_speed:g} 1/min (a motor whose peak torque holds up to "
                "its top speed has no corner: leave corner_speed out)"
            )
        top = self.top_speed_torque
        if top is None and self.rated_torque is None:
            raise ValueError(
                "corner_speed: needs top_speed_torque or rated_torque (the torque the "
                "intermittent zone falls to at the top speed)"
            )
        if top is not None and not 0 <= top <= self.peak_torque:
            raise ValueError(
                f"top_speed_torque: {_shown('motor_torque_max', top)} is outside [0, the peak "
                f"torque {_shown('motor_torque_max', self.peak_torque)}]: the intermittent "
                "torque falls from the peak above the corner"
            )


class Load(_Model):
    """The control surface as the drive sees it: its inertia about the hinge, its
    aerodynamic hinge spring dM/d(deflection) (either sign: negative for a statically
    unstable fin) and a structural damping."""

    inertia: Inertia
    hinge_spring: RotationalStiffness = 0.0
    damping: RotationalDamping = 0.0
    nut_mass: Mass = 0.0

    @model_validator(mode="after")
    def _physical(self):
        if not self.inertia > 0:
            raise ValueError(f"inertia: must be positive, got {self.inertia:g} t*mm^2")
        if self.damping < 0:
            raise ValueError(f"damping: cannot be negative, got {self.damping:g} N*mm*s/rad")
        if self.nut_mass < 0:
            raise ValueError(f"nut_mass: cannot be negative, got {self.nut_mass:g} t")
        return self


class Motion(_Model):
    """What the fin must do (internal units: a frequency in Hz, a time in h, as every
    file's): its top rate, and a step of the closed loop (a second-order
    response of natural frequency ``natural_frequency``, or reaching 95 % of the step at
    ``rise_time``, with ``damping_ratio``), whose peak rate and acceleration
    (:func:`optdesign.models.motor.step_peak_rate`, ``step_peak_acceleration``) the
    motor must give. Without a step, ``acceleration`` is the fin's top acceleration."""

    rate: AngularSpeed | None = None
    acceleration: AngularAcceleration | None = None
    step: Angle | None = None
    natural_frequency: Frequency | None = None
    rise_time: Time | None = None
    damping_ratio: Dimensionless = Field(0.7, gt=0.0, lt=1.0)

    @model_validator(mode="after")
    def _one_response(self):
        if self.natural_frequency is not None and self.rise_time is not None:
            raise ValueError("give natural_frequency or rise_time, not both")
        response = self.natural_frequency is not None or self.rise_time is not None
        if response and self.step is None:
            raise ValueError("step: a closed-loop response needs the step it answers")
        if self.step is not None and not response:
            raise ValueError("step: give natural_frequency or rise_time with it")
        if self.step is not None and self.acceleration is not None:
            raise ValueError("acceleration: the step's response gives it; give one of the two")
        if self.step is not None and not 0 < abs(self.step) <= math.pi:
            raise ValueError(f"step: must lie in (0, 180] deg, got {math.degrees(self.step):g}")
        for name in ("rate", "acceleration", "natural_frequency", "rise_time"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise ValueError(f"{name}: must be positive, got {value:g}")
        return self
