"""The spread of a design's backlash over the pin contact models ([D17]'s eq. 11, the
conforming pin in its bore, Palmgren's empirical approach, Huth's pin in its lug):
``od.solve(..., contact_models=True)`` and ``optdesign solve --contact-models``."""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

from optdesign.display.shown import objective_shown
from optdesign.errors import OptDesignError
from optdesign.mechanisms.joints import CONTACT_MODELS


def contact_model_spread(problem: Any, design: dict[str, float]) -> str | None:
    """The worst-case backlash of ``design`` under each pin contact model (eq. 11 of
    [D17], the conforming pin in its bore, Palmgren's empirical approach, Huth's pin in
    its lug), as one line; None when the problem has no backlash objective or no sized
    pin. A model the problem cannot evaluate (Huth's without ``[materials.lug]``) shows
    ``n/a`` and the reason. The models differ most in what they leave out (the bulk
    compression, the pin's bending, the conformity), so the spread is what a designer
    should read beside the one model the file chose."""
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
