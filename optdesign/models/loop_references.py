"""The references a simulated position loop follows (:mod:`optdesign.models.
loop_simulation`): a step, a sine and a sampled deflection history, each a frozen record
called with a time and naming the times where it jumps.

Units: rad at the fin, s, rad/s.

Validity
--------
reference angle : |r| <= pi rad (call)
    A fin turns less than half a turn; a non-finite angle is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from optdesign.errors import InputError
from optdesign.models.validity import Validity

#: The largest horizon simulated (s): a fin's manoeuvre lasts seconds.
MAX_HORIZON = 600.0
#: The most output samples returned.
MAX_SAMPLES = 1_000_000
#: The largest reference angle (rad): a fin turns less than half a turn.
MAX_ANGLE = math.pi

REFERENCE_ANGLE = Validity(
    "loop_references.angle",
    "loop simulation",
    "reference angle |r| at the fin",
    0.0,
    MAX_ANGLE,
    "rad",
    "a fin turns less than half a turn",
    shown_unit="deg",
    scale=180.0 / math.pi,
    checked=("call",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (REFERENCE_ANGLE,)


def angle_value(field: str, value) -> float:
    """``value`` as a reference angle (rad), refused naming ``field`` unless finite and
    within :data:`MAX_ANGLE`."""
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(field, f"expected a number (rad), got {value!r}") from None
    if not (math.isfinite(value) and abs(value) <= MAX_ANGLE):
        raise InputError(field, f"must be finite with |value| <= pi rad, got {value!r}")
    return value


@dataclass(frozen=True)
class StepReference:
    """A step of ``amplitude`` (rad at the fin) at ``time`` (s, >= 0)."""

    amplitude: float
    time: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "amplitude", angle_value("reference.amplitude", self.amplitude))
        t = float(self.time)
        if not (math.isfinite(t) and 0.0 <= t <= MAX_HORIZON):
            raise InputError("reference.time", f"must be in [0, {MAX_HORIZON:g}] s, got {t!r}")
        object.__setattr__(self, "time", t)

    def __call__(self, t: float) -> float:
        return self.amplitude if t >= self.time else 0.0

    @property
    def span(self) -> tuple[float, float]:
        """The least and the largest angle the reference takes (rad)."""
        before = self.amplitude if self.time == 0 else 0.0
        return min(self.amplitude, before), max(self.amplitude, before)

    @property
    def breaks(self) -> tuple[float, ...]:
        """Times where the reference jumps (the integration restarts there)."""
        return (self.time,) if self.time > 0 else ()


@dataclass(frozen=True)
class SineReference:
    """r(t) = offset + amplitude sin(frequency t) (rad at the fin; frequency in rad/s)."""

    amplitude: float
    frequency: float
    offset: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "amplitude", angle_value("reference.amplitude", self.amplitude))
        object.__setattr__(self, "offset", angle_value("reference.offset", self.offset))
        w = float(self.frequency)
        if not (math.isfinite(w) and 0.0 < w <= 1e6):
            raise InputError("reference.frequency", f"must be in (0, 1e6] rad/s, got {w!r}")
        object.__setattr__(self, "frequency", w)

    def __call__(self, t: float) -> float:
        return self.offset + self.amplitude * math.sin(self.frequency * t)

    @property
    def span(self) -> tuple[float, float]:
        """The least and the largest angle the reference takes (rad)."""
        return self.offset - abs(self.amplitude), self.offset + abs(self.amplitude)

    @property
    def breaks(self) -> tuple[float, ...]:
        """Times where the reference jumps: none."""
        return ()


@dataclass(frozen=True)
class SampledReference:
    """A deflection history: piecewise linear through (``times``, ``angles``), held
    before the first and after the last sample (s, rad at the fin)."""

    times: tuple[float, ...]
    angles: tuple[float, ...]

    def __post_init__(self):
        try:
            t = np.asarray(self.times, dtype=float).ravel()
            a = np.asarray(self.angles, dtype=float).ravel()
        except (TypeError, ValueError):
            raise InputError("reference.times", "times and angles must be numbers") from None
        if t.size < 2 or t.size != a.size or t.size > MAX_SAMPLES:
            raise InputError(
                "reference.times",
                f"needs 2 to {MAX_SAMPLES} times, as many as angles (got {t.size}, {a.size})",
            )
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
            raise InputError("reference.times", "must be finite and strictly increasing")
        if not (np.all(np.isfinite(a)) and np.max(np.abs(a)) <= MAX_ANGLE):
            raise InputError("reference.angles", "must be finite with |angle| <= pi rad")
        object.__setattr__(self, "times", tuple(t.tolist()))
        object.__setattr__(self, "angles", tuple(a.tolist()))
        object.__setattr__(self, "_t", t)
        object.__setattr__(self, "_a", a)

    def __call__(self, t: float) -> float:
        return float(np.interp(t, self._t, self._a))

    @property
    def span(self) -> tuple[float, float]:
        """The least and the largest angle the reference takes (rad)."""
        return float(np.min(self._a)), float(np.max(self._a))

    @property
    def breaks(self) -> tuple[float, ...]:
        """Times where the reference jumps: none."""
        return ()


Reference = StepReference | SineReference | SampledReference
