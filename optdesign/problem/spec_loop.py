"""The position loop of a problem file (:mod:`optdesign.problem.spec`): ``[loop]``.

Values in internal units once parsed (README "Units"): gains are motor torque per fin
angle (kp in N*mm/rad, kd in N*mm*s/rad, ki in N*mm/(rad*s); the cascade's speed_gain in
N*mm*s/rad, its position_gain in 1/s), the current loop's time constant and the speed
loop's integral time in h (every file's time; :func:`optdesign.problem.loop.loop_gains`
turns them into seconds), a frequency in Hz. The equations are those of
:mod:`optdesign.models.loop_plant`; docs/loop.md says how the gains are placed.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from optdesign.problem.spec_types import (
    Dimensionless,
    Frequency,
    IntegralGain,
    Rate,
    RotationalDamping,
    RotationalStiffness,
    Time,
    _Model,
)

#: The controller's forms: a PID on the measured angle, or a position P loop around a
#: speed PI loop on the motor's measured speed (docs/loop.md).
STRUCTURES = ("pid", "cascade")
PID_GAINS = ("kp", "kd", "ki")
CASCADE_GAINS = ("position_gain", "speed_gain", "speed_integral_time")

#: The longest current-loop lag a file may give (1 s, in h): a current loop is
#: milliseconds; a lag of seconds is a unit slip (ms written as s), not a motor.
MAX_CURRENT_LAG = 1.0 / 3600.0


class Loop(_Model):
    """The position loop around the drive: ``structure`` "pid" (the default) with fixed
    gains (``kp``, ``kd``, ``ki``), or "cascade" with fixed ``position_gain`` (Kpos,
    1/s), ``speed_gain`` (Kv) and ``speed_integral_time`` (Ti, absent or 0 for a P speed
    loop); or ``bandwidth`` and ``damping_ratio``, from which kp and kd (Kpos and Kv) are
    placed on the rigid drive at the design's mean ratio (one controller for the whole
    stroke: its loop gain then follows i(phi) / mean i). ``current_lag``: the current loop's time constant;
    ``feedback``: the angle measured ("fin", or "motor": the encoder on the motor).
    ``chain_damping`` (at the fin, across the chain) or ``chain_damping_ratio`` (of the
    chain's own mode, c = 2 zeta sqrt(k J1 J2 / (J1 + J2)) at each angle): the chain's
    viscous damping, 2 % of critical when neither is given. ``angles``: how many of the
    stroke's grid angles, evenly spread and both ends included, carry the loop's
    requirement rows (each costs the solver a frequency response per frequency checked;
    at most the grid's points)."""

    structure: Literal["pid", "cascade"] = "pid"
    kp: RotationalStiffness | None = None
    kd: RotationalDamping | None = None
    ki: IntegralGain = 0.0
    position_gain: Rate | None = None
    speed_gain: RotationalDamping | None = None
    speed_integral_time: Time | None = None
    bandwidth: Frequency | None = None
    damping_ratio: Dimensionless | None = None
    current_lag: Time = 0.0
    feedback: Literal["fin", "motor"] = "fin"
    chain_damping: RotationalDamping | None = None
    chain_damping_ratio: Dimensionless | None = Field(None, ge=0.0, lt=1.0)
    angles: int = Field(7, ge=2, le=2001)

    @model_validator(mode="after")
    def _one_tuning(self):
        self._one_structure()
        if self.structure == "cascade":
            self._cascade_gains()
        elif self.bandwidth is None and self.kp is None:
            raise ValueError(
                'kp: needed (motor torque per fin angle, e.g. kp = "2 N*m/rad"), or give '
                'bandwidth (and damping_ratio) to place the gains, e.g. bandwidth = "15 Hz"'
            )
        if self.bandwidth is not None:
            placed = ("kp", "kd") if self.structure == "pid" else CASCADE_GAINS[:2]
            given = [k for k in placed if getattr(self, k) is not None]
            if given:
                raise ValueError(
                    f"bandwidth: places {' and '.join(placed)} on the drive; do not give "
                    f"{', '.join(given)} too"
                )
            if not self.bandwidth > 0:
                raise ValueError(f"bandwidth: must be positive, got {self.bandwidth:g} Hz")
            zeta = 0.7 if self.damping_ratio is None else self.damping_ratio
            if not 0.0 < zeta <= 2.0:
                raise ValueError(f"damping_ratio: must lie in (0, 2], got {zeta:g}")
        elif self.damping_ratio is not None:
            raise ValueError("damping_ratio: only with bandwidth (the gains it places)")
        if self.kp is not None and not self.kp > 0:
            raise ValueError(f"kp: must be positive, got {self.kp:g} N*mm/rad")
        for name, unit, scale in (
            ("kd", "N*m*s/rad", 1e-3),
            ("ki", "N*m/(rad*s)", 1e-3),
            ("current_lag", "s", 3600.0),
            ("chain_damping", "N*m*s/rad", 1e-3),
        ):
            value = getattr(self, name)
            if value is not None and value < 0:
                raise ValueError(f"{name}: cannot be negative, got {value * scale:g} {unit}")
        if self.current_lag > MAX_CURRENT_LAG:
            raise ValueError(
                f"current_lag: {self.current_lag * 3600.0:g} s is longer than 1 s; a current "
                'loop answers in milliseconds (e.g. current_lag = "0.5 ms")'
            )
        if self.chain_damping is not None and self.chain_damping_ratio is not None:
            raise ValueError("chain_damping: give it or chain_damping_ratio, not both")
        return self

    def _one_structure(self) -> None:
        """Refuse the other structure's gains: a file mixing them says two controllers."""
        if self.structure == "pid":
            given = [k for k in CASCADE_GAINS if getattr(self, k) is not None]
            if given:
                raise ValueError(
                    f'{given[0]}: a gain of structure = "cascade"; this loop is a PID '
                    '(structure = "pid", the default): give structure = "cascade" with '
                    "position_gain and speed_gain, or the PID's kp, kd, ki"
                )
        else:
            # ki defaults to 0.0 (a spec's own dump carries it): only a nonzero one mixes
            given = [k for k in PID_GAINS if getattr(self, k)]
            if given:
                raise ValueError(
                    f'{given[0]}: a PID gain; structure = "cascade" takes position_gain, '
                    "speed_gain and speed_integral_time instead (kp = speed_gain x "
                    "position_gain, kd = speed_gain)"
                )

    def _cascade_gains(self) -> None:
        """The cascade's gains: both given (or placed from bandwidth), positive; Ti >= 0."""
        if self.bandwidth is None:
            for name, example in (("position_gain", '"60 1/s"'), ("speed_gain", '"0.2 N*m*s/rad"')):
                if getattr(self, name) is None:
                    raise ValueError(
                        f'{name}: needed for structure = "cascade" (e.g. {name} = {example}), '
                        'or give bandwidth (and damping_ratio) to place it, e.g. bandwidth = "15 Hz"'
                    )
        for name, unit, scale in (("position_gain", "1/s", 1.0), ("speed_gain", "N*m*s/rad", 1e-3)):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise ValueError(f"{name}: must be positive, got {value * scale:g} {unit}")
        ti = self.speed_integral_time
        if ti is not None and ti < 0:
            raise ValueError(
                f"speed_integral_time: cannot be negative, got {ti * 3600.0:g} s (0 or absent: "
                "a P speed loop)"
            )

    @property
    def zeta(self) -> float:
        """The damping ratio the placed gains aim at (0.7 unless given)."""
        return 0.7 if self.damping_ratio is None else self.damping_ratio
