"""The loads of optdesign/models/loads.py (motor torque, the fork pin's normal force,
backdriven torque, pin stresses) against hand derivations with their numbers written out."""

from __future__ import annotations

import math

import pytest

from optdesign.models.loads import (
    backdriven_motor_torque,
    fork_pin_normal_force,
    motor_torque,
    pin_bearing_pressure,
    pin_shear_stress,
)


# --- loads ----------------------------------------------------------------------------------
def test_motor_torque_by_hand():
    # T = F p / (2 pi i_a eta): 1000 N * 5 mm / (2 * 3.14159265 * 2 * 0.9) = 442.0970641 N*mm
    assert motor_torque(1000.0, 5.0, 2.0, 0.9) == pytest.approx(442.0970641, rel=1e-9)
    # gear efficiency multiplies the screw's: eta = 0.9 * 0.8
    assert motor_torque(1000.0, 5.0, 2.0, 0.9, 0.8) == pytest.approx(552.6213301, rel=1e-9)
    # back-driven: F p eta' / (2 pi i_a) = 1000 * 5 * 0.5 / (4 pi) = 198.9436789 N*mm
    assert backdriven_motor_torque(1000.0, 5.0, 2.0, 0.5) == pytest.approx(198.9436789, rel=1e-9)


def test_pin_stresses_by_hand():
    # single shear 4F/(pi d^2): 4 * 1000 / (3.14159265 * 100) = 12.7323954 MPa
    assert pin_shear_stress(1000.0, 10.0, 1) == pytest.approx(12.73239545, rel=1e-9)
    # double shear halves it: 6.3661977 MPa (also the default)
    assert pin_shear_stress(1000.0, 10.0, 2) == pytest.approx(6.366197724, rel=1e-9)
    assert pin_shear_stress(1000.0, 10.0) == pytest.approx(6.366197724, rel=1e-9)
    # projected bearing pressure F/(d L): 1000 / (10 * 15) = 6.6667 MPa
    assert pin_bearing_pressure(1000.0, 10.0, 15.0) == pytest.approx(6.6666667, rel=1e-8)


def test_load_defaults_are_lossless_and_the_paper_neutral_angle():
    # eta = 1 by default: 1000 N * 5 mm / (2 pi * 2) = 397.8873577 N*mm
    assert motor_torque(1000.0, 5.0, 2.0) == pytest.approx(397.8873577, rel=1e-9)
    assert backdriven_motor_torque(1000.0, 5.0, 2.0) == pytest.approx(397.8873577, rel=1e-9)
    # phi0 = 0 by default: 5e5 N*mm * cos(0.3) / 50 mm = 9553.3648 N
    assert fork_pin_normal_force(5e5, 50.0, 0.3) == pytest.approx(9553.364891, rel=1e-9)


def test_backdriven_torque_multiplies_both_efficiencies():
    # F p eta_s eta_g / (2 pi i_a) = 1000 * 5 * 0.5 * 0.8 / (4 pi) = 159.1549431 N*mm
    assert backdriven_motor_torque(1000.0, 5.0, 2.0, 0.5, 0.8) == pytest.approx(
        2000.0 / (4 * math.pi), rel=1e-12
    )
    assert 2000.0 / (4 * math.pi) == pytest.approx(159.1549431, rel=1e-9)
