"""The section "Time response" of report.html: on the page exactly when the problem has a
``[loop]``; its numbers those of a direct ``od.simulate`` and ``limit_cycles`` of the same
design, measured here without the view's code.

The design is ``fin_actuator_loop``'s optimum (docs/loop.md), given, so that no test
solves: the page of a solve is built from a result that carries it
(``tests/loop_optimum.py``). ``test_html_page.py`` opens the page in Chromium.
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from loop_optimum import OPTIMUM, loop_report, optimum_report

import optdesign as od
from optdesign.errors import InputError
from optdesign.models import loop_linear as ll
from optdesign.models.loop_backlash import limit_cycles
from optdesign.reports.time_response_html import time_response_json, time_response_section
from optdesign.views import time_response
from optdesign.views.time_response import time_response_view

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"


def _data(page: str) -> dict:
    start = page.index(">", page.index('id="report-data"')) + 1
    return json.loads(page[start : page.index("</script>", start)])


@pytest.fixture(scope="module")
def loop_problem():
    return od.load(PROBLEMS / "fin_actuator_loop.toml")


@pytest.fixture(scope="module")
def loop_page():
    return loop_report()


def test_the_section_is_on_the_page_exactly_when_the_problem_has_a_loop(loop_page):
    assert loop_page.count('<h2 id="time-response">Time response</h2>') == 1
    assert "timeResponse" in loop_page and "time_response" in _data(loop_page)
    # the same design without [loop] (fin_actuator_loop is fin_actuator_motor with one)
    plain = optimum_report(od.load(PROBLEMS / "fin_actuator_motor.toml"))
    assert "Time response" not in plain and "timeResponse" not in plain
    assert "time_response" not in _data(plain)


def test_the_sections_numbers_are_a_direct_simulation_and_harmonic_balance(loop_problem, loop_page):
    """The page's samples, steady state and cycle against od.simulate and limit_cycles of
    the optimum at 0 deg, measured here: the horizon 3 / f_b from the linear loop's
    bandwidth, the tail (the last third) by its extremes and its upward crossings of its
    mean. Published numbers (docs/loop.md): the loop's bandwidth 9.19 Hz, the cycle
    0.0357 deg at 156.1 Hz predicted, 0.0326 deg at 136.2 Hz simulated."""
    shown = _data(loop_page)["time_response"]
    r = od.simulate(loop_problem, design=OPTIMUM, horizon="1 ms", samples=2).response
    f_b = ll.bandwidth(r.plant, r.loop) / (2 * math.pi)
    assert f_b == pytest.approx(9.19, abs=0.01)
    horizon = 3.0 / f_b
    sim = od.simulate(
        loop_problem, design=OPTIMUM, amplitude="1 deg", angle="0 deg", horizon=horizon
    )
    r = sim.response
    assert len(shown["t"]) == r.times.size == 2001
    assert shown["t"][-1] == pytest.approx(horizon, rel=1e-6)
    np.testing.assert_allclose(shown["fin"], np.degrees(r.fin_angle), rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(shown["torque"], r.motor_torque * 1e-3, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(shown["reference"], 1.0)
    # the steady state: the last third
    tail = r.times >= 2.0 * horizon / 3.0
    t, y = r.times[tail], np.degrees(r.fin_angle[tail])
    mean, amplitude = y.mean(), 0.5 * (y.max() - y.min())
    up = np.flatnonzero((y[:-1] <= mean) & (y[1:] > mean))
    frequency = (up.size - 1) / (t[up[-1]] - t[up[0]])
    assert (amplitude, frequency) == pytest.approx((0.0326, 136.2), rel=0.01)
    assert f"fin holds {mean:.5g} deg" in shown["lines"][1]
    # the describing function's cycle at the same angle
    (cycle,) = [c for c in limit_cycles(r.plant, r.loop).cycles if c.stable]
    predicted = math.degrees(cycle.fin_amplitude), cycle.frequency / (2 * math.pi)
    assert predicted[0] == pytest.approx(0.0357, abs=1e-4)
    assert predicted[1] == pytest.approx(156.1, abs=0.1)
    amplitude_row, frequency_row = shown["table"]
    assert amplitude_row[1:3] == [f"{predicted[0]:.4g}", f"{amplitude:.4g}"]
    assert float(frequency_row[1]) == pytest.approx(predicted[1], abs=0.05)
    assert float(frequency_row[2]) == pytest.approx(frequency, rel=2e-3)
    assert amplitude_row[3] == f"{100 * (amplitude / predicted[0] - 1):+.1f} %" == "-8.8 %"
    assert float(frequency_row[3].rstrip(" %")) == pytest.approx(
        100 * (frequency / predicted[1] - 1), abs=0.15
    )
    assert f"{cycle.balance.third_harmonic_gain:.3g}" == "0.115"
    assert "0.115, above the 0.1 its filter hypothesis asks" in shown["lines"][2]


def test_a_design_that_cannot_be_simulated_gets_the_reason_not_a_lost_page(
    loop_problem, monkeypatch
):
    def refused(*args, **kwargs):
        raise InputError("max_events", "more than 20000 events by 0.01 s")

    monkeypatch.setattr(time_response, "simulate_design", refused)
    view = time_response_view(loop_problem, OPTIMUM)
    assert view == "not simulated: max_events: more than 20000 events by 0.01 s"
    html = time_response_section(time_response_json(view))
    assert "Time response" in html and "max_events: more than 20000" in html
    assert "step-response" not in html
    assert time_response_view(od.load(PROBLEMS / "fin_actuator_motor.toml"), OPTIMUM) is None


def test_without_a_predicted_cycle_the_section_says_why_and_what_the_fin_does():
    """The optimum with the encoder on the motor and a stable fin (+500 N*m/rad): L_d never
    crosses -180 deg, so no cycle is predicted, and the simulated fin comes to rest."""
    data = tomllib.loads((PROBLEMS / "fin_actuator_loop.toml").read_text())
    data["loop"]["feedback"] = "motor"
    data["load"]["hinge_spring"] = "500 N*m/rad"
    problem = od.load(data)
    view = time_response_view(problem, OPTIMUM)
    r = view.simulation.response
    cycles = limit_cycles(r.plant, r.loop)
    assert cycles.cycles == () and "never crosses -180 deg" in cycles.reason
    shown = time_response_json(view)
    assert shown["table"] is None and shown["cycle"] is None
    assert (
        f"predicts no stable limit cycle of the clearance at this angle: {cycles.reason}"
        in (shown["lines"][2])
    )
    # what the simulation shows, from a direct run of the same length
    direct = od.simulate(problem, design=OPTIMUM, horizon=view.horizon).response
    tail = np.degrees(direct.fin_angle[direct.times >= 2.0 * view.horizon / 3.0])
    assert 0.5 * (tail.max() - tail.min()) < 0.01 * math.degrees(r.plant.backlash)
    assert f"holds {tail.mean():.5g} deg on average and comes to rest" in shown["lines"][1]
