"""A design's time response in its position loop, as the report shows it: a step of the
fin at mid-stroke, simulated with the chain's gap, friction and the motor's limits
(:func:`optdesign.problem.loop_time.simulate_design`), and the steady oscillation it
settles in beside the describing function's limit cycle at the same angle
(:func:`optdesign.models.loop_backlash.limit_cycles`). docs/loop.md and
docs/reports.md say what the page shows.

The run is chosen to stay short: a 1 deg step, simulated for three times 1/f_b (f_b
the linear loop's bandwidth at that angle, in Hz; 0.33 s for ``fin_actuator_loop``),
between 0.1 s and 1 s. A hunting loop costs about a millisecond per contact event (a
150 Hz cycle makes 600 events a second: benchmarks/loop/README.md), so the horizon is
what the section costs. A 9 Hz loop's step settles within about 1/f_b; the last third of
the run, after 2/f_b, is measured as the steady state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign.models import loop_linear as ll
from optdesign.models.harmonic_balance import FILTER_HYPOTHESIS
from optdesign.models.loop_backlash import limit_cycles
from optdesign.models.loop_run import steady_oscillation
from optdesign.problem.loop_time import DesignSimulation, design_plant, simulate_design

#: The step of the fin the report simulates (rad).
STEP = math.radians(1.0)
#: The horizon in units of 1 / f_b (the linear loop's bandwidth in Hz) ...
HORIZON_PER_BANDWIDTH = 3.0
#: ... between these (s); without a bandwidth (a loop that never falls to half power,
#: or an unstable one), the longest.
HORIZON_RANGE = (0.1, 1.0)
#: The share of the run, at its end, measured as the steady state.
TAIL = 1.0 / 3.0
#: Output samples of the run: about 40 a period of a 150 Hz cycle over 0.33 s.
SAMPLES = 2001
#: Periods of the cycle the close-up shows, at the run's end.
PERIODS_SHOWN = 5
#: A fin that moves less than this share of the gap's half-width over the tail has
#: settled: what is left is the integration's own ripple (1e-5 b in a loop that stops).
SETTLED = 0.01


@dataclass(frozen=True)
class PredictedCycle:
    """The describing function's stable limit cycle of the chain's clearance at the
    simulated angle (the largest, when there are several).

    Attributes
    ----------
    amplitude
        The fin's amplitude (rad).
    frequency
        Its frequency (rad/s).
    third_harmonic_gain
        |L_d(3jw)| / |L_d(jw)|, the filter hypothesis' measure.
    filter_bound
        The gain up to which the hypothesis is taken to hold (0.1).
    times, angle
        The predicted sinusoid over the close-up (s, rad at the fin): about the
        simulated tail's mean, rising through it where the simulated fin first does.
    """

    amplitude: float
    frequency: float
    third_harmonic_gain: float
    filter_bound: float
    times: np.ndarray
    angle: np.ndarray

    @property
    def filter_hypothesis_holds(self) -> bool:
        return self.third_harmonic_gain <= self.filter_bound


@dataclass(frozen=True)
class TimeResponseView:
    """What the report shows of a design's time response in its loop.

    Attributes
    ----------
    simulation
        The run: the grid angle, its index and the model's record (internal units).
    step
        The reference's step (rad).
    horizon
        The time simulated (s).
    bandwidth
        The linear loop's bandwidth at the angle (Hz) that set the horizon; nan: none.
    tail_start
        Where the measured steady state begins (s).
    settled
        The fin's mean angle over the tail (rad).
    oscillation
        Half the fin's peak-to-peak over the tail (rad).
    oscillation_frequency
        The frequency of the fin's crossings of its mid-range over the tail (rad/s);
        nan with fewer than three.
    cycle
        The predicted stable cycle, or None.
    no_cycle
        Why none is predicted ("" with one): the harmonic balance's reason, or the
        unstable cycles it found (thresholds, not states the loop settles in).
    close_up
        The first time (s) of the close-up on the cycle: the last
        :data:`PERIODS_SHOWN` periods (of the predicted cycle, else of the measured
        oscillation, else the whole tail).
    """

    simulation: DesignSimulation
    step: float
    horizon: float
    bandwidth: float
    tail_start: float
    settled: float
    oscillation: float
    oscillation_frequency: float
    cycle: PredictedCycle | None
    no_cycle: str
    close_up: float

    @property
    def gap(self) -> float:
        """The chain's gap at the angle, its half-width b at the fin (rad)."""
        return float(self.simulation.response.plant.backlash)

    @property
    def settles(self) -> bool:
        """Whether the fin comes to rest: it moves less than :data:`SETTLED` b over the
        tail."""
        return self.oscillation < SETTLED * self.gap

    @property
    def amplitude_error(self) -> float:
        """Simulated over predicted amplitude, less one (nan without a cycle)."""
        return self.oscillation / self.cycle.amplitude - 1.0 if self.cycle else math.nan

    @property
    def frequency_error(self) -> float:
        """Simulated over predicted frequency, less one (nan without a cycle)."""
        if self.cycle is None:
            return math.nan
        return self.oscillation_frequency / self.cycle.frequency - 1.0


def time_response_view(problem: Any, design: dict[str, float]) -> TimeResponseView | str | None:
    """The :class:`TimeResponseView` of ``design`` at mid-stroke; None without a
    ``[loop]``; or why it could not be simulated (a page says it, and is still written).
    """
    if problem.spec.loop is None:
        return None
    try:
        return _view(problem, design)
    except Exception as exc:  # the page is one output among several: say it, do not fail
        return f"not simulated: {exc}"


def _horizon(bandwidth_hz: float) -> float:
    lo, hi = HORIZON_RANGE
    if not (math.isfinite(bandwidth_hz) and bandwidth_hz > 0.0):
        return hi
    return min(hi, max(lo, HORIZON_PER_BANDWIDTH / bandwidth_hz))


def _view(problem: Any, design: dict[str, float]) -> TimeResponseView:
    at = design_plant(problem, design)
    with np.errstate(all="ignore"):
        bandwidth = ll.bandwidth(at.plant, at.loop) / (2.0 * math.pi)
    horizon = _horizon(bandwidth)
    sim = simulate_design(problem, design, "step", STEP, horizon=horizon, samples=SAMPLES)
    r = sim.response
    tail_start = horizon * (1.0 - TAIL)
    settled = float(np.mean(r.fin_angle[r.times >= tail_start]))
    amplitude, frequency = steady_oscillation(r, tail_start)
    cycles = limit_cycles(r.plant, r.loop)
    big = max((c for c in cycles.cycles if c.stable), key=lambda c: c.fin_amplitude, default=None)
    shown = big.frequency if big is not None else frequency
    period = 2.0 * math.pi / shown if math.isfinite(shown) and shown > 0.0 else math.inf
    close_up = max(tail_start, horizon - PERIODS_SHOWN * period)
    cycle = None
    if big is not None:
        times, angle = _predicted(r, big.fin_amplitude, big.frequency, settled, close_up, horizon)
        cycle = PredictedCycle(
            amplitude=big.fin_amplitude,
            frequency=big.frequency,
            third_harmonic_gain=big.balance.third_harmonic_gain,
            filter_bound=float(FILTER_HYPOTHESIS.upper),
            times=times,
            angle=angle,
        )
    return TimeResponseView(
        simulation=sim,
        step=STEP,
        horizon=horizon,
        bandwidth=float(bandwidth),
        tail_start=tail_start,
        settled=settled,
        oscillation=amplitude,
        oscillation_frequency=frequency,
        cycle=cycle,
        no_cycle="" if cycle else _why_none(cycles),
        close_up=close_up,
    )


def _why_none(cycles: Any) -> str:
    unstable = [c for c in cycles.cycles if not c.stable]
    if unstable:
        where = ", ".join(
            f"{math.degrees(c.fin_amplitude):.3g} deg at {c.frequency / (2 * math.pi):.4g} Hz"
            for c in unstable
        )
        return f"only unstable cycles ({where}): thresholds, not states the loop settles in"
    return cycles.reason or "no cycle"


def _predicted(r, amplitude, omega, mean, start, end) -> tuple[np.ndarray, np.ndarray]:
    """The predicted sinusoid over [start, end], in phase with the simulated fin's first
    upward crossing of ``mean`` there (the start when it never crosses)."""
    keep = (r.times >= start) & (r.times <= end)
    t, y = r.times[keep], r.fin_angle[keep]
    up = np.flatnonzero((y[:-1] <= mean) & (y[1:] > mean))
    t0 = float(t[0])
    if up.size:
        i = int(up[0])
        t0 = float(t[i] + (mean - y[i]) * (t[i + 1] - t[i]) / (y[i + 1] - y[i]))
    times = np.linspace(start, end, max(2, int(40 * (end - start) * omega / (2 * math.pi)) + 1))
    return times, mean + amplitude * np.sin(omega * (times - t0))
