"""What a design achieves, as a user reads it: the mean ratio and its range over the
stroke, the drive efficiency used (evaluated by :mod:`optdesign.views.facts`), every
objective with its unit (and what "size" measures for this mechanism)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from optdesign.display.shown import Shown, objective_shown
from optdesign.text import printable
from optdesign.views.facts import DesignFacts, MotorFacts

if TYPE_CHECKING:
    from optdesign.problem.loop_analysis import LoopFigures


@dataclass(frozen=True)
class Fact:
    """One number of a design: name, value with unit, and what it is."""

    name: str
    value: Shown
    description: str = ""

    def text(self) -> str:
        """One line (a user's objective name and description shown printable)."""
        extra = f" ({printable(self.description)})" if self.description else ""
        return f"{printable(self.name)} = {self.value.text()}{extra}"

    def to_json(self) -> dict[str, Any]:
        return {**self.value.to_json(), "description": self.description}


def shown_facts(problem: Any, facts: DesignFacts | None) -> list[Fact]:
    """The mean ratio, ratio range, drive efficiency (and motor) of a design's evaluated
    ``facts`` (:func:`optdesign.views.facts.design_facts`), worded; [] for None."""
    if problem is None or facts is None:
        return []
    out = [
        Fact("mean_ratio", Shown(facts.mean_ratio, ""), "mean reduction ratio over the stroke"),
        Fact("ratio_min", Shown(facts.ratio_min, ""), "smallest ratio over the stroke"),
        Fact("ratio_max", Shown(facts.ratio_max, ""), "largest ratio over the stroke"),
    ]
    req = problem.spec.requirements
    screw = problem.spec.screw
    if screw is None:
        source = "screw x gear, from the file"
    elif screw.efficiency_design == "HIWIN":
        source = "screw x gear, screw at HIWIN's design value 0.85 for sizing"
    else:
        source = "screw x gear, screw from its lead and friction"
    if req.eta_screw == 1.0 and req.eta_gear == 1.0 and problem.spec.screw is None:
        source = "lossless: the file gives no eta_screw, eta_gear or [screw]"
    out.append(Fact("drive_efficiency", Shown(100.0 * facts.drive_efficiency, "%"), source))
    if facts.motor is not None:
        out.append(_motor_fact(facts.motor))
    out += _loop_facts(facts.loop)
    return out


def _loop_facts(loop: LoopFigures | str | None) -> list[Fact]:
    """The design's position loop, analysed exactly (optdesign.problem.loop_analysis):
    the least bandwidth and margins over the loop's angles, the largest limit cycle."""
    if loop is None:
        return []
    if isinstance(loop, str):  # a report, not the result: say why the figures are missing
        return [Fact("loop", Shown(float("nan"), ""), f"not analysed: {loop}")]
    f = loop
    where = f"over the loop's {f.angles} angles"
    stable = (
        "stable at every grid angle"
        if not f.unstable_at
        else f"UNSTABLE at {len(f.unstable_at)} grid angles from {f.unstable_at[0]:+.1f} deg"
    )
    cycle = (
        f"largest stable backlash limit cycle at the fin (harmonic balance), at "
        f"{f.limit_cycle.angle:+.0f} deg, {f.limit_cycle_frequency:.4g} Hz"
        if f.limit_cycle.value > 0
        else "no stable backlash limit cycle (harmonic balance)"
    )
    rows = (
        ("loop_bandwidth", f.bandwidth, "Hz", f"least -3 dB bandwidth {where}", f"; {stable}"),
        ("loop_phase_margin", f.phase_margin, "deg", f"least phase margin {where}", ""),
        ("loop_gain_margin", f.gain_margin, "", f"least gain margin {where}", ""),
        ("loop_modulus_margin", f.modulus_margin, "", f"least min |1 + L(jw)| {where}", ""),
        (
            "loop_resonance_margin",
            f.resonance_margin,
            "",
            f"least 1 / |L| at the drive's own mode {where}",
            "",
        ),
    )
    out = [
        Fact(name, Shown(fig.value, unit), f"{text}, at {fig.angle:+.0f} deg{tail}")
        for name, fig, unit, text, tail in rows
    ]
    return [*out, Fact("limit_cycle_amplitude", Shown(f.limit_cycle.value, "deg"), cycle)]


def _motor_fact(motor: MotorFacts) -> Fact:
    """The motor of the design, named, with its data and how much of each it uses."""
    name, peak, demand = motor.name, motor.peak_torque, motor.demand
    used = f", {100.0 * demand / peak:.3g} % of it used by the motion" if demand else ""
    if motor.envelope_use is not None:
        used += (
            f", {100.0 * motor.envelope_use:.3g} % of the torque its speed-torque envelope "
            "gives at the motion's speed"
        )
    text = (
        f"peak torque of the motor{' ' + name if name else ''}{used}; rotor "
        f"{motor.rotor_inertia * 10:.4g} kg*cm^2, top speed "
        f"{motor.max_speed * 60 / (2 * np.pi):.5g} 1/min"
    )
    if motor.mass is not None and motor.mass > 0:
        text += f", mass {motor.mass * 1e3:.4g} kg"
    return Fact("motor", Shown(peak * 1e-3, "N*m"), text)


def objective_facts(problem: Any, objectives: dict[str, float]) -> list[Fact]:
    """Every objective's value with its unit and description; ``size`` says what it
    measures for this mechanism."""
    out = []
    for name, value in objectives.items():
        info = problem.objectives.get(name) if problem is not None else None
        desc = info.description if info is not None else ""
        if name == "size" and problem is not None:
            desc = f"{desc}: {problem.mechanism.size_description}"
        out.append(Fact(name, objective_shown(problem, name, value), desc))
    return out
