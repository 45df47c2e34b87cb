"""Planetary roller screw efficiency (seed 003 eq. 14, physics.md 6) and the selector."""

import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.mechanisms import ShiftingFork
from optdesign.models import roller_screw as rs
from optdesign.models import screw

PAPER = dict(r_s=40.0, r_RP=10.0, f_k=0.055, f_r=0.01)  # SI of the paper converted to mm


def test_frictionless_efficiency_is_one():
    a = np.radians(np.linspace(1, 40, 40))[:, None]
    b = np.radians(np.linspace(5, 90, 18))
    eta = rs.efficiency(a, b, 40.0, 10.0, 0.0, 0.0)
    assert np.asarray(eta) == pytest.approx(np.ones((40, 18)), abs=1e-12)


def test_physics_md_values():
    eta = rs.efficiency(np.radians(10.0), np.radians(45.0), **PAPER)
    assert eta == pytest.approx(0.975, abs=1e-3)
    assert eta == pytest.approx(0.974796, abs=1e-6)  # pins the reading of eq. 14
    # Rises with beta and levels off.
    betas = np.radians([15.0, 30.0, 45.0, 60.0, 90.0])
    e_b = np.asarray(rs.efficiency(np.radians(10.0), betas, **PAPER))
    assert np.all(np.diff(e_b) > 0)
    assert e_b[-1] - e_b[2] < 0.015 < e_b[2] - e_b[0]
    # For fixed beta = 45 deg it peaks near alpha_s = 10 deg.
    alphas = np.radians(np.linspace(1, 30, 291))
    peak = np.degrees(alphas[np.argmax(rs.efficiency(alphas, np.radians(45.0), **PAPER))])
    assert 8.0 < peak < 10.5


def test_casadi_matches_numpy():
    a, b = ca.SX.sym("a"), ca.SX.sym("b")
    f = ca.Function("eta", [a, b], [rs.efficiency(a, b, **PAPER)])
    for ad, bd in [(5.0, 30.0), (10.0, 45.0), (20.0, 75.0)]:
        x, y = np.radians(ad), np.radians(bd)
        assert float(f(x, y)) == pytest.approx(float(rs.efficiency(x, y, **PAPER)), rel=1e-13)


@settings(max_examples=80, deadline=None)
@given(a=st.floats(3, 30), b=st.floats(20, 90), f_k=st.floats(0, 0.1), f_r=st.floats(0, 0.05))
def test_efficiency_in_unit_interval(a, b, f_k, f_r):
    eta = rs.efficiency(np.radians(a), np.radians(b), 40.0, 10.0, f_k, f_r)
    assert 0.0 < eta <= 1.0 + 1e-12


def test_selector_ball_and_roller():
    lam = screw.lead_angle(5.0, 20.0)
    ball = rs.ScrewEfficiency.ball(0.003)
    assert ball.forward(lam) == pytest.approx(0.9634, abs=5e-5)
    assert ball.backdrive(lam) == pytest.approx(0.9621, abs=5e-5)
    roller = rs.ScrewEfficiency.roller(r_s=10.0)
    assert roller.forward(lam) == pytest.approx(
        rs.efficiency(lam, np.radians(45.0), 10.0, 10.0, 0.055, 0.01)
    )
    # roller back-driving: friction terms of eq. 11-13 reversed (roller_screw docstring)
    assert roller.backdrive(lam) == pytest.approx(
        rs.efficiency_backdrive(lam, np.radians(45.0), 10.0, 10.0, 0.055, 0.01)
    )
    assert roller.backdrive(lam) < roller.forward(lam)
    with pytest.raises(InputError, match=r"efficiency\.kind"):
        rs.ScrewEfficiency("acme")
    # In the drive: the motor torque scales with 1/eta.
    fork = ShiftingFork(R=90.0, p=5.0, i_a=2.0)
    phi = np.radians([0.0, 20.0])
    T_b = fork.motor_torque(phi, 5e5, eta_screw=ball.forward(lam))
    T_r = fork.motor_torque(phi, 5e5, eta_screw=roller.forward(lam))
    assert T_r / T_b == pytest.approx(ball.forward(lam) / roller.forward(lam))
    # helix angle = lead angle with d_m = 2 r_s
    assert rs.helix_angle(5.0, 10.0) == pytest.approx(lam)


def test_bad_inputs():
    with pytest.raises(InputError, match="r_RP"):
        rs.efficiency(0.1, 0.5, 40.0, -1.0, 0.05, 0.01)
    with pytest.raises(InputError, match="beta"):
        rs.efficiency(0.1, 0.0, 40.0, 10.0, 0.05, 0.01)
    with pytest.raises(InputError, match="f_k"):
        rs.efficiency(0.1, 0.5, 40.0, 10.0, -0.05, 0.01)


# --- screw efficiency: the selector's defaults and wiring ---------------------------------
def test_roller_screw_through_the_selector_is_seed_003s_value():
    # physics.md 6: alpha_s = 10 deg, beta = 45 deg, r_s = 40 mm, r_RP = 10 mm,
    # f_k = 0.055, f_r = 0.01 mm give eta = 0.974796. Lead for a 10 deg helix on
    # d_m = 2 r_s = 80 mm: p = pi * 80 * tan 10 deg = 44.31579 mm.
    from optdesign.models import roller_screw as rs
    from optdesign.models.screw_efficiency import screw_efficiency

    p = math.pi * 80.0 * math.tan(math.radians(10.0))
    assert p == pytest.approx(44.31579, rel=1e-6)
    assert float(screw_efficiency("roller", p, 80.0)) == pytest.approx(0.974796, abs=1e-6)
    back = float(screw_efficiency("roller", p, 80.0, direction="back"))
    lam = math.radians(10.0)
    expected = rs.efficiency_backdrive(lam, math.radians(45.0), 40.0, 10.0, 0.055, 0.01)
    assert back == pytest.approx(float(expected), rel=1e-9)
