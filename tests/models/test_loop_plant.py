"""The drive plant and position loop records: each wrong field refused by name."""

from __future__ import annotations

import math

import pytest

from optdesign.errors import InputError
from optdesign.models.loop_plant import DrivePlant, PositionLoop

PLANT = {"motor_inertia": 0.2, "ratio": 150.0, "fin_inertia": 40.0, "stiffness": 3e7}


def test_the_motor_side_is_seen_at_the_fin_through_the_ratio_squared():
    plant = DrivePlant(**PLANT)
    assert plant.motor_inertia_at_fin == pytest.approx(0.2 * 150.0**2)


@pytest.mark.parametrize(
    ("field", "value", "reason"),
    [
        ("motor_inertia", 0.0, "must be positive"),
        ("ratio", -2.0, "must be positive"),
        ("stiffness", math.nan, "must be finite"),
        ("damping", -1.0, "cannot be negative"),
        ("backlash", math.radians(6.0), r"6 deg is outside \[0 deg, 5 deg\]"),
        ("peak_torque", "a lot", "expected a number"),
    ],
)
def test_a_wrong_plant_field_is_refused_by_name(field, value, reason):
    with pytest.raises(InputError, match=rf"^plant\.{field}: .*{reason}"):
        DrivePlant(**{**PLANT, field: value})


def test_limits_may_be_infinite_but_not_other_fields():
    assert DrivePlant(**PLANT, peak_torque=math.inf).max_speed == math.inf
    with pytest.raises(InputError, match=r"plant\.hinge_spring: must be finite"):
        DrivePlant(**PLANT, hinge_spring=math.inf)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"kp": 0.0}, r"loop\.kp: must be positive"),
        ({"kp": 1.0, "kd": -1.0}, r"loop\.kd: cannot be negative"),
        ({"kp": 1.0, "current_lag": math.inf}, r"loop\.current_lag: must be finite"),
        ({"kp": 1.0, "feedback": "rate"}, r"loop\.feedback: expected one of fin, motor"),
    ],
)
def test_a_wrong_loop_field_is_refused_by_name(kwargs, message):
    with pytest.raises(InputError, match=message):
        PositionLoop(**kwargs)
