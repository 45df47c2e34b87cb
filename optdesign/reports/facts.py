"""What a design achieves, as a user reads it: the mean ratio and its range over the
stroke, the drive efficiency used, every objective with its unit (and what "size"
measures for this mechanism)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from optdesign import math as m
from optdesign.errors import OptDesignError
from optdesign.reports.units import Shown, objective_shown
from optdesign.text import printable


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


def design_facts(problem: Any, design: dict[str, float]) -> list[Fact]:
    """Mean ratio, ratio range, drive efficiency of ``design`` (NumPy path)."""
    if problem is None or not design:
        return []
    with np.errstate(all="ignore"):
        q = problem.quantities(design)
        ratio = np.asarray(q.ratio, dtype=float).ravel()
        eta = np.asarray(q.drive_efficiency, dtype=float).ravel()
    out = [
        Fact(
            "mean_ratio",
            Shown(float(m.grid_mean(ratio)), ""),
            "mean reduction ratio over the stroke",
        ),
        Fact("ratio_min", Shown(float(np.min(ratio)), ""), "smallest ratio over the stroke"),
        Fact("ratio_max", Shown(float(np.max(ratio)), ""), "largest ratio over the stroke"),
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
    out.append(Fact("drive_efficiency", Shown(100.0 * float(np.min(eta)), "%"), source))
    return out


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


def contact_model_spread(problem: Any, design: dict[str, float]) -> str | None:
    """The worst-case backlash of ``design`` under each pin contact model (eq. 11 of
    [D17], the conforming pin in its bore, Palmgren's empirical approach), as one line;
    None when the problem has no backlash objective or no sized pin. The models differ
    most in what they leave out (the bulk compression, the conformity), so the spread is
    what a designer should read beside the one model the file chose."""
    import copy

    from optdesign.mechanisms.joints import CONTACT_MODELS

    if problem is None or not design or "backlash" not in problem.objectives:
        return None
    if "d" not in problem.by_name:
        return None
    x = np.array([design[v.name] for v in problem.free], dtype=float)
    chosen = problem.spec.requirements.pin_contact
    parts = []
    for model in CONTACT_MODELS:
        other = problem if model == chosen else copy.copy(problem)
        try:
            if other is not problem:
                other.set_requirement("pin_contact", model)
            with np.errstate(all="ignore"):
                value = float(np.ravel(other.evaluate(x).objectives["backlash"])[0])
        except OptDesignError as exc:
            parts.append(f"{model} n/a ({exc})")
            continue
        mark = " (the file's)" if model == chosen else ""
        parts.append(f"{model} {objective_shown(problem, 'backlash', value).text(6)}{mark}")
    return "backlash by pin contact model: " + ", ".join(parts)
