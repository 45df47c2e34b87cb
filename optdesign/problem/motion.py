"""What the fin must do, from a problem's ``[motion]`` (or its deflection rate alone):
the top rate and acceleration the drive must give (internal units: rad/s, rad/s^2). Pure
functions of the problem's spec, below every drive model that reads them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from optdesign.models import motor as mo

#: The closed-loop step's rise time is the first time it reaches this share of the step.
RISE_LEVEL = 0.95


@dataclass(frozen=True)
class MotionDemand:
    """The fin's top rate (rad/s) and acceleration (rad/s^2), and where they come from."""

    rate: float
    acceleration: float
    source: str


def motion_demand(spec) -> MotionDemand | None:
    """What the fin must do (``[motion]``, else ``requirements.deflection_rate`` alone):
    the top rate is the larger of the given rate and the closed-loop step's peak rate; the
    top acceleration is the step's (its initial value, step x wn^2) or the given one.
    None when the problem gives no rate at all."""
    motion, req = spec.motion, spec.requirements
    given = motion.rate if motion is not None and motion.rate is not None else None
    rate = given if given is not None else req.deflection_rate
    if motion is None:
        return None if rate is None else MotionDemand(rate, 0.0, "requirements.deflection_rate")
    if motion.step is not None:
        zeta, step = motion.damping_ratio, abs(motion.step)
        wn = None if motion.natural_frequency is None else 2.0 * np.pi * motion.natural_frequency
        if wn is None:
            rise = motion.rise_time * 3600.0  # h -> s
            wn = float(mo.natural_frequency_for_rise_time(zeta, rise, RISE_LEVEL))
            how = f"95 % at {rise * 1e3:g} ms, wn = {wn:.4g} rad/s"
        else:
            how = f"wn = {wn:.4g} rad/s"
        peak = float(mo.step_peak_rate(wn, zeta, step))
        acc = float(mo.step_peak_acceleration(wn, zeta, step))
        source = f"a {np.degrees(step):g} deg step, {how}, damping ratio {zeta:g}"
        return MotionDemand(max(peak, rate or 0.0), acc, source)
    if rate is None:
        return None
    return MotionDemand(rate, motion.acceleration or 0.0, "[motion]")
