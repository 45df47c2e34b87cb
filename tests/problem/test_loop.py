"""optdesign/problem/loop.py and the [loop] section: the plant of fin_actuator_motor's
design at every grid angle against its quantities computed here from the catalogue, the
screw's geometry and differences of the nut position; the gains placed from a bandwidth
against the rigid drive's closed loop; every wrong field refused with its name and
reason (API, command line in both output modes)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_refusal import command_line_refusal

import optdesign as od
from optdesign.models.motor_catalogue import by_designation
from optdesign.problem.loop import (
    bandwidth_factor,
    drive_plants,
    loop_gains,
    position_loop,
)

ROOT = Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "problems"

#: fin_actuator_motor's optimum (tests/problem/test_motor_drive.py): R, l, n, phi0 and
#: the catalogue's d0, p, d.
OPTIMUM = {"R": 105.0, "l": 60.0, "n": 102.0, "phi0": 0.23, "d0": 25.0, "p": 5.0, "d": 10.0}


def _with_loop(**loop) -> dict:
    data = tomllib.loads((PROBLEMS / "fin_actuator_motor.toml").read_text())
    data["loop"] = loop or {"bandwidth": "9 Hz", "current_lag": "0.5 ms"}
    return data


def _quantities(problem, values=OPTIMUM):
    x = np.array([values[v.name] for v in problem.free])
    return problem.quantities(problem.design_dict(x))


def test_the_plant_of_each_angle_is_the_designs_drive_computed_independently():
    """J_m: the SGM7J-06A's rotor and the gear's inertia, the 300 mm steel shaft of 25 mm
    (m d0^2 / 8) through the 2:1 gear, the 0.6 kg nut through lead / (2 pi i_a); f' from
    central differences of the nut position; b half the worst-case backlash in rad; the
    chain's damping 2 % of critical for its own mode."""
    problem = od.load(_with_loop())
    q = _quantities(problem)
    plants = drive_plants(q)
    assert len(plants) == 61
    row = by_designation("SGM7J-06A")
    rho, d0, length, i_a, lead = 7.85e-9, 25.0, 300.0, 2.0, 5.0  # t/mm^3, mm
    shaft = rho * math.pi * d0**2 / 4 * length * d0**2 / 8  # t*mm^2
    nut = 0.6e-3 * (lead / (2 * math.pi * i_a)) ** 2
    J_m = row.rotor_inertia + 0.1 * 0.1 + shaft / i_a**2 + nut  # 0.1 kg*cm^2 = 0.01 t*mm^2
    h = 1e-5
    compliance = np.asarray(q.output_compliance).reshape(-1)
    for j in range(0, 61, 15):
        plant = plants[j]
        phi = plant.angle
        x = q.mechanism.nut_position(np.array([phi - h, phi + h]))
        ratio = 2 * math.pi * i_a / lead * float(x[1] - x[0]) / (2 * h)
        assert plant.ratio == pytest.approx(ratio, rel=1e-7)
        assert plant.motor_inertia == pytest.approx(J_m, rel=1e-9)
        assert plant.fin_inertia == pytest.approx(500.0)  # 0.5 kg*m^2
        assert plant.hinge_spring == pytest.approx(-5e5) and plant.fin_damping == 5e3
        assert plant.friction_torque == 50.0 and plant.peak_torque == row.peak_torque
        assert plant.max_speed == pytest.approx(row.max_speed)
        k = 1.0 / float(compliance[j])
        assert plant.stiffness == pytest.approx(k, rel=1e-9)
        J1 = J_m * ratio**2
        critical = 2 * math.sqrt(k * J1 * 500.0 / (J1 + 500.0))
        assert plant.damping == pytest.approx(0.02 * critical, rel=1e-6)
    worst = np.asarray(q.backlash.worst_case).reshape(-1)
    assert [p.backlash for p in plants] == pytest.approx(np.radians(worst) / 2, rel=1e-12)
    # the chain's stiffness sets the locked frequency the motor problem requires
    w2 = np.asarray(q.locked_frequency_squared).reshape(-1)
    assert [(p.stiffness + p.hinge_spring) / p.fin_inertia for p in plants] == pytest.approx(w2)


def test_gains_placed_from_a_bandwidth_give_the_rigid_drive_that_bandwidth_at_the_mean_ratio():
    """kp, kd placed at the mean ratio: the rigid loop J s^2 + (c + f kd) s + k_h + f kp
    with f the mean ratio has w_n = 2 pi 9 Hz / bandwidth_factor(0.7) and zeta 0.7, and
    |T(j 2 pi 9 Hz)| = 1/sqrt(2) for its kp f / (J s^2 + ...) once the hinge spring's
    static share is taken out."""
    problem = od.load(_with_loop(bandwidth="9 Hz", current_lag="0.5 ms"))
    q = _quantities(problem)
    loop = position_loop(q)
    f = float(np.mean(np.asarray(q.ratio)))
    J = float(np.mean(np.asarray(q.motor_side_inertia))) * f**2 + 500.0
    wn = 2 * math.pi * 9.0 / bandwidth_factor(0.7)
    assert (-5e5 + f * loop.kp) / J == pytest.approx(wn**2, rel=1e-12)
    assert (5e3 + f * loop.kd) / J == pytest.approx(2 * 0.7 * wn, rel=1e-12)
    assert bandwidth_factor(1 / math.sqrt(2)) == pytest.approx(1.0)
    assert bandwidth_factor(1.0) == pytest.approx(0.643594, rel=1e-5)
    assert loop.current_lag == pytest.approx(5e-4) and loop.feedback == "fin"
    # fixed gains pass through in internal units
    fixed = od.load(_with_loop(kp="100 N*m/rad", kd="1 N*m*s/rad", ki="10 N*m/(rad*s)"))
    gains = loop_gains(_quantities(fixed))
    assert (gains.kp, gains.kd, gains.ki) == pytest.approx((1e5, 1e3, 1e4))


# --- refusals ---------------------------------------------------------------------------
KP = "150 N*m/rad"
REFUSED = [
    ({}, "kp: needed"),
    ({"kp": "-2 N*m/rad"}, "kp: must be positive"),
    ({"kp": "2 N*m"}, "expected a rotational stiffness"),
    ({"kp": KP, "ki": "3 N*m/rad"}, "expected an integral gain"),
    ({"bandwidth": "15 Hz", "kp": KP}, "do not give kp too"),
    ({"kp": KP, "damping_ratio": 0.7}, "damping_ratio: only with bandwidth"),
    ({"bandwidth": "15 Hz", "damping_ratio": 0}, "damping_ratio: must lie in (0, 2]"),
    ({"kp": KP, "current_lag": "2 s"}, "current_lag: 2 s is longer than 1 s"),
    ({"kp": KP, "feedback": "encoder"}, "feedback"),
    ({"kp": KP, "kd": "-1 N*m*s/rad"}, "kd: cannot be negative, got -1 N*m*s/rad"),
    ({"kp": KP, "chain_damping": "-1 N*m*s/rad"}, "chain_damping: cannot be negative"),
    ({"kp": KP, "chain_damping": "1 N*m*s/rad", "chain_damping_ratio": 0.02}, "not both"),
    ({"kp": KP, "gain": 1}, "gain: unknown field"),
]


def _refused_data(value: dict) -> dict:
    data = _with_loop()
    data["loop"] = value
    return data


@pytest.mark.parametrize("value, reason", REFUSED)
def test_a_wrong_loop_field_is_refused_naming_it_through_the_api(value, reason):
    with pytest.raises(od.OptDesignError) as err:
        od.load(_refused_data(value))
    assert "loop." in str(err.value) and reason in str(err.value)


@pytest.mark.parametrize("json_mode", [False, True], ids=["text", "json"])
@pytest.mark.parametrize("value, reason", [REFUSED[1], REFUSED[3], REFUSED[4], REFUSED[7]])
def test_a_wrong_loop_field_is_refused_naming_it_on_the_command_line(
    value, reason, json_mode, tmp_path
):
    message = command_line_refusal(_refused_data(value), tmp_path, json_mode)
    assert "loop" in message and reason in message


def test_a_loop_without_the_drive_it_closes_around_is_refused_saying_what_it_needs():
    for section in ("load", "motor"):
        data = _with_loop()
        del data[section]
        with pytest.raises(od.OptDesignError, match=rf"\[loop\]: needs a \[{section}\] section"):
            od.load(data)
