"""Time of a 2 s step simulation of a representative drive in its position loop.

The drive: 0.02 t*mm^2 at the motor (2e-5 kg*m^2), ratio 60, a 10 t*mm^2 fin
(0.01 kg*m^2) on a chain of 1e7 N*mm/rad at the fin (anti-resonance 1000 rad/s), a hinge
spring of 2e4 N*mm/rad, a gap of +-0.05 deg at the fin, 30 N*mm of motor friction, a peak
torque of 250 N*mm and a top speed of 150 rad/s; PID on the motor's angle with a 0.2 ms
current loop. A 10 deg step saturates the torque, reaches the speed limit, closes and
unloads the contact and sticks the motor: every event kind but "opens" occurs.

A second case times the worst kind of run: the same drive without friction and limits,
PD on the fin's angle (kd = 45 N*mm*s/rad), 0.1 deg gap, which settles in a limit cycle
near 870 rad/s: about 1100 contact events in 2 s.

Usage: python benchmarks/loop/simulation_time.py [repeats]   (default 5; prints the
median and the spread, and the run's event counts).
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from collections import Counter

from optdesign.models import loop_simulation as ls
from optdesign.models.loop_plant import DrivePlant, PositionLoop

PLANT = DrivePlant(
    motor_inertia=0.02,
    ratio=60.0,
    fin_inertia=10.0,
    stiffness=1e7,
    damping=400.0,
    hinge_spring=2e4,
    fin_damping=20.0,
    backlash=math.radians(0.05),
    friction_torque=30.0,
    peak_torque=250.0,
    max_speed=150.0,
)
LOOP = PositionLoop(kp=2000.0, kd=60.0, ki=8000.0, current_lag=2e-4, feedback="motor")
CYCLING = DrivePlant(
    motor_inertia=0.02,
    ratio=60.0,
    fin_inertia=10.0,
    stiffness=1e7,
    damping=400.0,
    hinge_spring=2e4,
    fin_damping=20.0,
    backlash=math.radians(0.1),
)
CYCLING_LOOP = PositionLoop(kp=1500.0, kd=45.0, current_lag=1e-4, feedback="fin")


def _time(plant, loop, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        sim = ls.simulate(plant, loop, ls.StepReference(math.radians(10.0)), 2.0, samples=4001)
        times.append(time.perf_counter() - t0)
    return sim, times


def main(repeats: int = 5) -> None:
    sim, times = _time(PLANT, LOOP, repeats)
    print(
        f"2 s step, {repeats} runs: median {statistics.median(times):.3f} s "
        f"(min {min(times):.3f}, max {max(times):.3f})"
    )
    print(f"events: {len(sim.event_times)} {dict(Counter(sim.event_kinds))}")
    print(
        f"final fin angle {math.degrees(sim.fin_angle[-1]):.4f} deg, "
        f"peak torque {max(abs(sim.motor_torque)):.1f} N*mm, "
        f"peak motor speed {max(abs(sim.motor_rate)) * PLANT.ratio:.1f} rad/s"
    )
    sim, times = _time(CYCLING, CYCLING_LOOP, repeats)
    print(
        f"2 s step in a limit cycle, {repeats} runs: median {statistics.median(times):.3f} s "
        f"(min {min(times):.3f}, max {max(times):.3f}); {len(sim.event_times)} events"
    )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
