"""Small variants of the shipped problem fin_actuator_loop, shared by the tests of the
loop's objectives (one free variable, so that an NLP can be checked against a scan)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import optdesign as od

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"

#: The design where the shipped problem with its items fixed has its largest bandwidth
#: (found by maximising it; the offset n is the scans' free variable).
FAST = {"R": 101.591698, "l": 146.677980, "phi0": 0.4952934, "d0": 25.0, "p": 5.0, "d": 16.0}


def small_loop_problem(objective: str, angles: int = 2, **sections) -> od.DesignProblem:
    """fin_actuator_loop with its items and R, l, phi0 fixed at :data:`FAST`, the offset n
    free, the loop's rows at ``angles`` angles, and only the requirements a bandwidth
    needs: the stroke and its loads, the transmission angle, the motor and the loop's
    bandwidth of 8 Hz; minimising ``objective``, with ``sections`` added or replaced."""
    data = tomllib.loads((PROBLEMS / "fin_actuator_loop.toml").read_text())
    variables = data["variables"]
    for name in ("R", "l", "d0", "p", "d"):
        variables[name] = f"{FAST[name]} mm"
    variables["phi0"] = f"{FAST['phi0']} rad"
    keep = ("deflection", "hinge_moment", "deflection_rate", "transmission_angle", "fit")
    keep += ("fit_clearance", "pin_shear_planes")
    data["requirements"] = {k: v for k, v in data["requirements"].items() if k in keep}
    data["requirements"]["bandwidth_min"] = "8 Hz"
    data["loop"]["angles"] = angles
    data["objective"] = {"minimize": objective}
    return od.load({**data, **sections})


def assert_no_scan_point_beats(problem: od.DesignProblem, result, objective: str) -> None:
    """No design of a 200-point scan of ``problem``'s one free variable, evaluated on the
    NumPy path, that meets every requirement has a smaller ``objective`` than the NLP's
    ``result``, and the scan's best is the grid point next to the NLP's optimum."""
    import numpy as np

    x = problem.free[0]
    scan = np.linspace(x.lower, x.upper, 200)[:, None]
    ev = problem.evaluate(scan)
    values = np.where(ev.violation <= 1e-6, ev.objectives[objective], np.inf)
    best = int(np.argmin(values))
    assert np.isfinite(values[best])
    assert result.objective <= values[best] * (1 + 1e-9)
    assert abs(scan[best, 0] - result.design[x.name]) < (x.upper - x.lower) / 199
