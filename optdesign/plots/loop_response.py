"""The figure of a design's time response in its loop (:func:`optdesign.api.simulate`):
the reference and the fin's angle over time, with the motor's angle seen at the fin, and
below them the motor's and the chain's torques."""

from __future__ import annotations

import math

import numpy as np

from optdesign.plots import new_figure


def plot_loop_response(sim):
    """A matplotlib Figure (outside pyplot) of a :class:`~optdesign.problem.loop_time.
    DesignSimulation`: angles in deg, torques in N*m, time in s."""
    r = sim.response
    fig = new_figure(figsize=(8.0, 6.0))
    top, bottom = fig.subplots(2, 1, sharex=True)
    t = np.asarray(r.times)
    top.plot(t, np.degrees(r.reference), "k--", lw=1.0, label="reference")
    top.plot(t, np.degrees(r.motor_angle), lw=0.8, label="motor (at the fin)")
    top.plot(t, np.degrees(r.fin_angle), lw=1.2, label="fin")
    top.set_ylabel("angle [deg]")
    if sim.duty is not None:
        title = "response in the loop over the duty cycle (the plant following the fin)"
    elif sim.plant == "path":
        title = f"response in the loop about {math.degrees(sim.angle):+.1f} deg (plant following the fin)"
    else:
        title = f"response in the loop at {math.degrees(sim.angle):+.1f} deg of the stroke"
    top.set_title(title)
    top.legend(loc="best" if sim.duty is not None else "lower right")
    # the motor's torque is the chain's over the ratio (hundreds): an axis of its own
    bottom.plot(t, np.asarray(r.chain_torque) * 1e-3, "C1", lw=0.8)
    bottom.set_ylabel("chain torque at the fin [N*m]", color="C1")
    motor = bottom.twinx()
    motor.plot(t, np.asarray(r.motor_torque) * 1e-3, "C0", lw=0.8)
    motor.set_ylabel("motor torque at its shaft [N*m]", color="C0")
    bottom.set_xlabel("time [s]")
    return fig
