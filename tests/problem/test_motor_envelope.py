"""The motor's speed-torque corner and thermal time constant in a problem
(optdesign/problem/motor_drive.py): the envelope's row against the envelope read
independently from the datasheet's three points at fine angles of many designs, the
solver's smooth pieces against the NumPy row, the catalogue's relaxation of the envelope
against every motor's, the thermal row against the RMS row it replaces, and every wrong
field refused with its name and reason (file, command line in both output modes, API)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_refusal import command_line_refusal

import optdesign as od
from optdesign.problem import motor_catalogue_variable as mcv
from optdesign.problem.motor_drive import motor_data

ROOT = Path(__file__).resolve().parents[2]
RPM = 2 * math.pi / 60

#: The SGM7J-06A's printed ratings, with a corner and a top-speed torque made up for the
#: test (the shipped manual draws its intermittent zone as a curve and prints no corner).
MOTOR = {"rotor_inertia": "0.8 kg*cm^2", "peak_torque": "6.69 N*m", "rated_torque": "1.91 N*m",
         "max_speed": "6000 rpm", "gear_inertia": "0.1 kg*cm^2", "friction_torque": "0.05 N*m",
         "corner_speed": "5000 rpm", "top_speed_torque": "5.5 N*m"}  # fmt: skip


def _data(motor: dict | None = None, points: int = 61) -> dict:
    data = tomllib.loads((ROOT / "problems" / "fin_actuator_motor.toml").read_text())
    data["motor"] = dict(MOTOR if motor is None else motor)
    data["requirements"]["deflection"]["points"] = points
    return data


def _designs(problem, count: int, seed: int = 1) -> dict:
    rng = np.random.default_rng(seed)
    lo, hi = problem.lower(), problem.upper()
    return problem.design_dict(lo + rng.random((count, len(lo))) * (hi - lo))


def test_the_envelope_row_holds_exactly_where_the_datasheets_envelope_does():
    """At 121 angles of 80 random designs, the peak-torque, speed and envelope rows hold
    together exactly where the torque the motion asks lies under the envelope drawn
    straight between (0, 6.69), (5000 1/min, 6.69) and (6000 1/min, 5.5 N*m); and the row
    is (T + s n) / (T_peak + s n_c) with s = 1.19 N*m per 1000 1/min."""
    problem = od.load(_data(points=121))
    q = problem.quantities(_designs(problem, 80))
    with np.errstate(all="ignore"):
        T = np.asarray(q.motor_peak_torque, dtype=float) / 1e3  # N*m
        n = np.asarray(q.motor_speed, dtype=float) / RPM  # 1/min
        rows = {b.name: np.asarray(b.expr, dtype=float) for b in _blocks(q)}
    ok = np.isfinite(T) & np.isfinite(n)
    T, n = T[ok], n[ok]
    envelope = np.interp(n, [0.0, 5000.0, 6000.0], [6.69, 6.69, 5.5])
    holds = (rows["motor_peak_torque"][ok] <= 1) & (rows["motor_speed"][ok] <= 1)
    holds &= rows["motor_speed_torque"][ok] <= 1
    under = (T <= envelope) & (n <= 6000.0)
    clear = np.abs(T - envelope) > 1e-9
    assert np.array_equal(holds[clear], under[clear])
    s = 1.19 / 1000.0  # N*m per 1/min
    assert rows["motor_speed_torque"][ok] == pytest.approx(
        (T + s * n) / (6.69 + s * 5000), rel=1e-12
    )
    # the grid spans the corner: designs the falling edge alone refuses, and designs it passes
    fall = (n > 5000) & (n <= 6000) & (T <= 6.69)
    assert (fall & ~under).any() and (fall & under).any()


def _blocks(q):
    from optdesign.problem.motor_drive import motor_blocks

    return motor_blocks(q, [""] * len(q.phi))


def test_the_solvers_pieces_are_the_numpy_row():
    """The NLP poses the row as its two smooth pieces (with +f'' and -f''): their max at
    a design equals the NumPy row there, at every angle."""
    import casadi as ca

    problem = od.load(_data())
    z = ca.SX.sym("x", len(problem.free))
    sym = problem.quantities(problem.design_dict([z[k] for k in range(z.shape[0])]))
    block = next(b for b in _blocks(sym) if b.name == "motor_speed_torque")
    assert len(block.pieces) == 2
    pieces = ca.Function("p", [z], list(block.pieces))
    lo, hi = problem.lower(), problem.upper()
    for x in (lo + f * (hi - lo) for f in (0.3, 0.55, 0.7)):
        row = next(
            b
            for b in _blocks(problem.quantities(problem.design_dict(x)))
            if b.name == "motor_speed_torque"
        )
        top = np.maximum(*(np.asarray(p, dtype=float).ravel() for p in pieces(x)))
        assert top == pytest.approx(np.asarray(row.expr, dtype=float).ravel(), rel=1e-12)


def test_a_corner_alone_falls_to_the_rated_torque():
    motor = {k: v for k, v in MOTOR.items() if k != "top_speed_torque"}
    data = motor_data(od.load(_data(motor)).spec)
    assert data.envelope_slope == pytest.approx((6690.0 - 1910.0) / (1000 * RPM))
    assert data.envelope_intercept == pytest.approx(6690.0 + data.envelope_slope * 5000 * RPM)
    plain = motor_data(od.load(_data({k: v for k, v in motor.items() if k != "corner_speed"})).spec)
    assert plain.envelope_slope is None  # no corner: no row
    assert (
        "motor_speed_torque"
        not in od.load(_data({k: v for k, v in motor.items() if k != "corner_speed"}))
        .evaluate(od.load(_data()).lower())
        .constraints
    )


CATALOGUE = """designation,rated_torque_Nm,peak_torque_Nm,rated_speed_rpm,max_speed_rpm,rotor_inertia_1e-4kgm2,corner_speed_rpm,top_speed_torque_Nm
A,1.27,4.46,3000,6000,0.486,4000,2.0
B,1.91,6.69,3000,6000,0.800,5000,
C,2.39,8.36,3000,5000,1.59,,
"""


def test_the_catalogues_relaxed_envelope_lies_above_every_motors():
    """Over any box of motor numbers the relaxation's line (the largest intercept, the least
    slope) is above each motor's falling line at every speed, and a one-motor box is that
    motor's own (B falls to its rated torque: no top-speed torque given; C has no corner)."""
    data = _data({"catalogue": "m.csv", "catalogue_text": CATALOGUE})
    problem = od.load(data)
    rows = mcv.motors(mcv.catalogue_of(problem))
    assert [r.envelope_slope > 0 for r in rows] == [True, True, False]
    assert rows[1].envelope_slope == pytest.approx((6690 - 1910) / (1000 * RPM))
    speeds = np.linspace(0, 6000 * RPM, 61)
    for lo, hi in [(1, 3), (1, 2), (2, 3), (2, 2), (3, 3)]:
        p = mcv.parameter_values(problem, {"motor": (lo, hi)})
        line = p["motor_envelope_intercept"] - p["motor_envelope_slope"] * speeds
        for r in rows[lo - 1 : hi]:
            assert np.all(line >= r.envelope_intercept - r.envelope_slope * speeds - 1e-9)
        if lo == hi:
            r = rows[lo - 1]
            assert (p["motor_envelope_intercept"], p["motor_envelope_slope"]) == (
                r.envelope_intercept,
                r.envelope_slope,
            )
    x = problem.lower()
    assert "motor_speed_torque" in problem.evaluate(x).constraints


def _thermal(tau: str | None, period: str | None = "20 s") -> dict:
    motor = {k: v for k, v in MOTOR.items() if k not in ("corner_speed", "top_speed_torque")}
    if tau is not None:
        motor["thermal_time_constant"] = tau
    data = _data(motor)
    if period is not None:
        data["requirements"]["duty_period"] = period
    return data


def test_the_thermal_row_replaces_the_rms_row_and_tends_to_it_for_a_long_tau():
    """A 20 s cycle against tau = 1e6 s heats as its RMS torque (to 1e-5); against 2 s the
    winding follows each step, and the hottest instant is the 450 N*m step's end, whose
    torque through the ratio there is the largest of the three."""
    x = od.load(_data()).lower() * 0.5 + od.load(_data()).upper() * 0.5
    plain = od.load(_thermal(None)).evaluate(x).constraints
    long = od.load(_thermal("1e6 s")).evaluate(x).constraints
    short = od.load(_thermal("2 s")).evaluate(x).constraints
    assert "motor_thermal_torque" not in plain and "motor_rms_torque" not in long
    rms = float(plain["motor_rms_torque"].values[0])
    assert long["motor_thermal_torque"].values == pytest.approx([rms] * 3, rel=1e-5)
    hot = short["motor_thermal_torque"].values
    assert int(np.argmax(hot)) == 2 and hot.max() > 1.5 * rms


def test_a_thermal_time_constant_without_the_cycles_length_says_what_it_needs():
    with pytest.raises(od.OptDesignError, match=r"requirements\.duty_period"):
        od.load(_thermal("10 min", period=None)).evaluate(od.load(_data()).lower())


# --- refusals ---------------------------------------------------------------------------
REFUSED = [
    ("motor", {**MOTOR, "corner_speed": "-100 rpm"}, "corner_speed: must be positive"),
    ("motor", {**MOTOR, "corner_speed": "7000 rpm"}, "corner_speed: 7000 1/min is not below the top speed"),
    ("motor", {**MOTOR, "thermal_time_constant": "0 s"}, "thermal_time_constant: must be positive"),
    ("motor", {**MOTOR, "top_speed_torque": "8 N*m"}, "top_speed_torque: 8 N*m is outside"),
    ("motor", {k: v for k, v in MOTOR.items() if k != "corner_speed"}, "top_speed_torque: needs corner_speed"),
    ("motor", {"designation": "SGM7J-06A", "corner_speed": "5000 rpm"}, "do not give corner_speed"),
    ("motor", {"catalogue": "m.csv", "catalogue_text": CATALOGUE.replace("6.69,3000,6000,0.800,5000", ",3000,6000,0.800,5000")},
     "column peak_torque_Nm: missing; the corner speed 5000"),
    ("motor", {"catalogue": "m.csv", "catalogue_text": CATALOGUE.replace("4000,2.0", "6000,2.0")},
     "column corner_speed_rpm: 6000 min^-1 is not below the maximum speed"),
    ("motor", {"catalogue": "m.csv", "catalogue_text": CATALOGUE.replace("4000,2.0", "4000,5")},
     "column top_speed_torque_Nm: 5 N*m is outside [0, the peak torque 4.46 N*m]"),
]  # fmt: skip


@pytest.mark.parametrize("section, value, reason", REFUSED)
def test_a_wrong_motor_field_is_refused_naming_it_through_the_api(section, value, reason):
    data = _data()
    data[section] = value
    with pytest.raises(od.OptDesignError) as err:
        od.load(data)
    assert section in str(err.value) and reason in str(err.value)


@pytest.mark.parametrize("json_mode", [False, True], ids=["text", "json"])
@pytest.mark.parametrize("section, value, reason", REFUSED[:4])
def test_a_wrong_motor_field_is_refused_naming_it_on_the_command_line(
    section, value, reason, json_mode, tmp_path
):
    data = _data()
    data[section] = value
    message = command_line_refusal(data, tmp_path, json_mode)
    assert section in message and reason in message


def test_a_duty_period_without_a_duty_cycle_is_refused():
    data = _data()
    del data["requirements"]["duty_cycle"], data["requirements"]["life_min"]
    data["requirements"]["duty_period"] = "20 s"
    with pytest.raises(od.OptDesignError, match="duty_period: the length of a duty cycle"):
        od.load(data)


def test_the_summarys_motor_fact_reads_the_envelope_at_the_top_speed():
    """The motor fact of a design with a corner gives the largest share, over the stroke,
    of the torque the envelope gives at the motor's speed that the motion asks: the
    envelope read from the datasheet's points by interpolation, a separate computation
    from the model's intercept and slope."""
    from optdesign.reports.facts import _motor_fact
    from optdesign.views.facts import design_facts

    problem = od.load(_data())
    design = {**problem.fixed_values, **problem.design_dict(problem.start())}
    facts = design_facts(problem, design)
    q = problem.quantities(design)
    T = np.asarray(q.motor_peak_torque, dtype=float).ravel() / 1e3  # at each grid angle
    n = np.asarray(q.motor_speed, dtype=float).ravel() / RPM
    # the envelope: 6.69 N*m up to the corner, then straight to (6000 1/min, 5.5 N*m)
    line = np.interp(n, [0.0, 5000.0, 6000.0], [6.69, 6.69, 5.5])
    use = float(np.max(T / line))
    assert facts.motor.envelope_use == pytest.approx(use, rel=1e-9)
    assert use >= float(np.max(T)) / 6.69  # never below the peak torque's share
    text = _motor_fact(facts.motor).text()
    assert f"{100 * use:.3g} % of the torque its speed-torque envelope gives" in text
    # without a corner the fact says nothing of an envelope
    plain = od.load(
        _data({k: v for k, v in MOTOR.items() if "corner" not in k and "top_" not in k})
    )
    bare = design_facts(plain, {**plain.fixed_values, **plain.design_dict(plain.start())})
    assert bare.motor.envelope_use is None and "envelope" not in _motor_fact(bare.motor).text()
