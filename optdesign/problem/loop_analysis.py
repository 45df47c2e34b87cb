"""The position loop of one design, analysed exactly after a solve (docs/loop.md):
the figures the summary and result.json show beside the requirement rows, computed by
:mod:`optdesign.models.loop_linear` and :mod:`optdesign.models.loop_backlash` on the
design's plants (:mod:`optdesign.problem.loop`), not by the rows' smooth forms.

Stability is checked at every grid angle; the bandwidth, the margins and the limit
cycles at the loop's angles (``[loop] angles``: a margin's root search costs about 70 ms
an angle).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from optdesign.models import loop_linear as ll
from optdesign.models.loop_backlash import limit_cycles
from optdesign.problem.loop import drive_plants_of, loop_angles
from optdesign.problem.loop_margins import CYCLE_POINTS


@dataclass(frozen=True)
class LoopFigure:
    """The least (or largest) value of one figure over the angles and where (deg)."""

    value: float
    angle: float


@dataclass(frozen=True)
class LoopFigures:
    """The design's loop: the least -3 dB bandwidth (Hz), phase margin (deg), gain margin
    (a factor), modulus margin min |1 + L| and resonance margin 1 / |L(j w_r)| over the
    loop's angles, the largest stable limit cycle at the fin (deg, 0: none) and its
    frequency (Hz), and the grid angles (deg) where the closed loop is unstable."""

    bandwidth: LoopFigure
    phase_margin: LoopFigure
    gain_margin: LoopFigure
    modulus_margin: LoopFigure
    resonance_margin: LoopFigure
    limit_cycle: LoopFigure
    limit_cycle_frequency: float
    unstable_at: tuple[float, ...]
    angles: int


def _least(values, angles) -> LoopFigure:
    k = int(np.argmin(values))
    return LoopFigure(float(values[k]), float(angles[k]))


def loop_figures(q) -> LoopFigures:
    """The exact loop figures of the design whose NumPy quantities are ``q`` (one design
    with a ``[loop]``)."""
    every, loop = drive_plants_of(q)[0]
    unstable = tuple(math.degrees(p.angle) for p in every if not ll.is_stable(p, loop))
    idx = loop_angles(q.problem)
    plants = [every[i] for i in idx]
    deg = [math.degrees(p.angle) for p in plants]
    w2 = np.asarray(q.two_mass_frequency_squared, dtype=float).reshape(-1)
    bandwidth, phase, gain, modulus, resonance, cycles, cycle_w = [], [], [], [], [], [], []
    for plant, i in zip(plants, idx, strict=True):
        bandwidth.append(ll.bandwidth(plant, loop) / (2.0 * math.pi))
        margins = ll.margins(plant, loop)
        phase.append(margins.phase_margin)
        gain.append(margins.gain_margin)
        modulus.append(margins.stability_margin)
        L, _ = ll.frequency_response(plant, loop, math.sqrt(w2[i] if w2.size > 1 else w2[0]))
        resonance.append(1.0 / abs(complex(np.asarray(L).reshape(-1)[0])))
        stable = [c for c in limit_cycles(plant, loop, CYCLE_POINTS).cycles if c.stable]
        big = max(stable, key=lambda c: c.fin_amplitude, default=None)
        cycles.append(0.0 if big is None else math.degrees(big.fin_amplitude))
        cycle_w.append(math.nan if big is None else big.frequency / (2.0 * math.pi))
    k = int(np.argmax(cycles))
    return LoopFigures(
        bandwidth=_least(bandwidth, deg),
        phase_margin=_least(phase, deg),
        gain_margin=_least(gain, deg),
        modulus_margin=_least(modulus, deg),
        resonance_margin=_least(resonance, deg),
        limit_cycle=LoopFigure(cycles[k], deg[k]),
        limit_cycle_frequency=cycle_w[k],
        unstable_at=unstable,
        angles=len(idx),
    )
