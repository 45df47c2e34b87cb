"""The record of a simulated run of the drive in its position loop
(:func:`optdesign.models.loop_simulation.simulate`), and the steady oscillation read off
its tail. Units: mm, t, s, N, rad (angles in rad at the fin, torques in N*mm).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.errors import InputError
from optdesign.models.loop_plant import Controller
from optdesign.models.loop_references import Reference


# --- the record ----------------------------------------------------------------------------
@dataclass(frozen=True)
class LoopSimulation:
    """The time response of the drive in its loop (units in the attribute names' notes).

    Attributes
    ----------
    times
        Sample times (s).
    reference
        r(t), rad at the fin.
    fin_angle, fin_rate
        phi (rad), phi' (rad/s).
    motor_angle, motor_rate
        The motor's angle and rate seen at the fin, theta / f' (rad) and theta' / f'
        (rad/s).
    motor_torque
        The torque the motor applies at its shaft (N*mm): the current loop's output, less
        in the direction of motion near the top speed.
    chain_torque
        The chain's torque on the fin (N*mm).
    hinge_moment
        The air's moment on the fin (N*mm): -k_h phi and the external load.
    contact
        +1 / -1 while the + / - flank transmits torque, 0 in the gap or unloaded.
    event_times, event_kinds
        When the contact closed, opened or unloaded, the motor stuck or slipped, or the
        speed limit began or ended (s; a word each).
    plant, loop, input_reference
        What was simulated (the plant a ``DrivePlant`` or a ``DrivePath``).
    """

    times: np.ndarray
    reference: np.ndarray
    fin_angle: np.ndarray
    fin_rate: np.ndarray
    motor_angle: np.ndarray
    motor_rate: np.ndarray
    motor_torque: np.ndarray
    chain_torque: np.ndarray
    hinge_moment: np.ndarray
    contact: np.ndarray
    event_times: tuple[float, ...]
    event_kinds: tuple[str, ...]
    plant: Any
    loop: Controller
    input_reference: Reference


def steady_oscillation(sim: LoopSimulation, start: float) -> tuple[float, float]:
    """The fin's oscillation after ``start`` (s): (amplitude, frequency).

    The amplitude is half the fin angle's peak-to-peak (rad), the frequency pi times the
    number of crossings of its mid-range, less one, over the time between the first and
    the last (rad/s; each crossing interpolated linearly). ``nan`` for the frequency with
    fewer than three crossings. A measure of a settled limit cycle, for comparing with
    :func:`optdesign.models.loop_backlash.limit_cycles`.
    """
    keep = sim.times >= start
    if np.count_nonzero(keep) < 3:
        raise InputError("start", f"leaves fewer than 3 samples (got {start!r} s)")
    t, y = sim.times[keep], sim.fin_angle[keep]
    mid = 0.5 * (y.max() + y.min())
    above = y > mid
    i = np.flatnonzero(above[:-1] != above[1:])
    tz = t[i] + (mid - y[i]) * (t[i + 1] - t[i]) / (y[i + 1] - y[i])
    w = math.pi * (tz.size - 1) / (tz[-1] - tz[0]) if tz.size >= 3 else float("nan")
    return float(0.5 * (y.max() - y.min())), float(w)
