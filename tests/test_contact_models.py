"""The pin contact models side by side (issue 26): Palmgren's empirical approach as a
selectable model, and the backlash of an optimum under each model (``--contact-models``,
``od.solve(..., contact_models=True)``)."""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.errors import InputError, OptDesignError
from optdesign.mechanisms.joints import PinJoint
from optdesign.problem import problem_from_dict

ROOT = Path(__file__).resolve().parents[1]
FIN = ROOT / "problems" / "fin_actuator.toml"


def test_palmgren_joint_against_the_printed_approach():
    """[D17]'s pin (d 10, L 20, 20 kN): Palmgren 3.84e-5 x 20 000^0.9 / 20^0.8 = 25.97 um
    ([P59]), added to the fit's clearance; the stiffness is its tangent F / (0.9 delta)."""
    pin = PinJoint(10.0, 20.0, contact="palmgren")
    added = float(pin.clearance(20000.0) - pin.fit_clearance())
    assert added == pytest.approx(3.84e-5 * 20000.0**0.9 / 20.0**0.8, rel=1e-12)
    assert added * 1e3 == pytest.approx(25.97, abs=0.01)
    h = 1.0
    slope = float(pin.clearance(20000.0 + h) - pin.clearance(20000.0 - h)) / (2 * h)
    assert float(pin.contact_stiffness(20000.0)) == pytest.approx(1 / slope, rel=1e-6)
    # 2.35 times eq. 11's flattening of pin and bore (11.04 um): the bulk compression
    duan = float(PinJoint(10.0, 20.0).clearance(20000.0) - pin.fit_clearance())
    assert added / duan == pytest.approx(2.352, abs=1e-3)
    with pytest.raises(InputError, match=r"materials\.pin\.E"):
        PinJoint(10.0, 20.0, E=7.0e4, contact="palmgren")
    with pytest.raises(InputError, match=r"pin\.contact"):
        PinJoint(10.0, 20.0, contact="tate")


def _at_optimum(model: str) -> float:
    data = tomllib.loads(FIN.read_text())
    data["requirements"]["pin_contact"] = model
    problem = problem_from_dict(data)
    design = dict(R=105.571, l=59.7942, n=102.087, phi0=math.radians(13.132), d0=25, p=5, d=6)
    x = np.array([design[v.name] for v in problem.free], dtype=float)
    return float(np.ravel(problem.evaluate(x).objectives["backlash"])[0])


def test_backlash_spread_over_the_contact_models_at_the_fin_optimum(fin_lug_optimum):
    problem, result = fin_lug_optimum
    line = next(n for n in result.notes if n.startswith("backlash by pin contact model"))
    values = {
        name: float(v)
        for name, v in re.findall(r"(duan2017|conforming|palmgren) ([0-9.]+) deg", line)
    }
    assert set(values) == {"duan2017", "conforming", "palmgren"}
    assert "duan2017 0.0348393 deg (the file's)" in line
    # each model's value equals the problem written with that model, evaluated at the
    # optimum the summary states (a file, not the spread's copy)
    for model, value in values.items():
        assert value == pytest.approx(_at_optimum(model), rel=2e-5)
    # the conforming contact is the stiffest reading, Palmgren's (bulk compression) the softest
    assert values["conforming"] < values["duan2017"] < values["palmgren"]
    assert problem.spec.requirements.pin_contact == "duan2017"  # the problem is unchanged
    assert line in result.summary()
    with pytest.raises(OptDesignError, match="contact_models"):
        od.solve(problem, contact_models="yes")
