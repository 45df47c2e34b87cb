"""optdesign.models.motor_catalogue: the shipped servomotors (Yaskawa Sigma-7 SGM7J and
SGM7A, ratings tables of the Rotary Servomotor Product Manual) and a user's CSV."""

from __future__ import annotations

import dataclasses
import math
from importlib import resources

import pytest

from optdesign.errors import InputError
from optdesign.models import motor as mo
from optdesign.models import motor_catalogue as cat

HEADER = (
    "designation,rated_torque_Nm,peak_torque_Nm,rated_speed_rpm,max_speed_rpm,"
    "rotor_inertia_1e-4kgm2,mass_kg"
)


def test_the_shipped_catalogue_reads_into_typed_frozen_records():
    motors = cat.load_motors()
    assert len(motors) == 14
    assert [m.designation for m in motors][:2] == ["SGM7J-A5A", "SGM7J-01A"]
    assert len({m.designation for m in motors}) == 14
    assert {m.series for m in motors} == {"SGM7J", "SGM7A"}
    r = cat.by_designation("SGM7J-01A")
    # printed 0.318 / 1.11 N*m, 3000 / 6000 min^-1, 0.0659 (0.0739 with brake) x 1e-4 kg*m^2
    assert (r.rated_torque, r.peak_torque) == (318.0, 1110.0)
    assert r.rated_speed == pytest.approx(100.0 * math.pi, rel=1e-15)
    assert r.max_speed == pytest.approx(200.0 * math.pi, rel=1e-15)
    assert r.rotor_inertia == pytest.approx(0.00659, rel=1e-12)  # t*mm^2
    assert r.rotor_inertia_brake == pytest.approx(0.00739, rel=1e-12)
    assert r.rated_output == 100e3 and r.mass is None
    assert r.source == "servo_motors.csv, line 27, section 4.2.2, p. 4-4, SGM7J-01A"
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.rated_torque = 1.0  # type: ignore[misc]
    big = cat.by_designation("SGM7A-70A")
    assert (big.peak_torque, big.rotor_inertia_brake, big.page) == (54000.0, None, "5-7")
    assert "footnote *9" in big.note
    with pytest.raises(InputError, match=r"^designation: 'SGM7J-99A' is not in the catalogue"):
        cat.by_designation("SGM7J-99A")


@pytest.mark.parametrize(
    ("designation", "printed"),
    [
        # rated, peak torque (N*m), motor moment of inertia (1e-4 kg*m^2), as printed
        ("SGM7J-A5A", (0.159, 0.557, 0.0395)),
        ("SGM7J-02A", (0.637, 2.23, 0.263)),
        ("SGM7J-08A", (2.39, 8.36, 1.59)),
        ("SGM7A-15A", (4.90, 14.7, 2.00)),
        ("SGM7A-30A", (9.80, 29.4, 7.00)),
        ("SGM7A-70A", (22.3, 54.0, 12.3)),
    ],
)
def test_rows_against_the_printed_ratings(designation, printed):
    r = cat.by_designation(designation)
    got = (r.rated_torque / mo.N_M, r.peak_torque / mo.N_M, r.rotor_inertia / mo.KG_CM2)
    assert got == pytest.approx(printed, rel=1e-12)


@pytest.mark.parametrize("motor", cat.load_motors(), ids=lambda m: m.designation)
def test_each_row_agrees_with_the_manuals_own_derived_columns(motor):
    """The manual prints, beside torque and inertia, the rated power rate T^2 / J, the
    rated angular acceleration T / J and the rated output T n: three-figure values that
    catch a mistyped torque or inertia (a slipped digit moves them by 10 % or more)."""
    T = motor.rated_torque / mo.N_M  # N*m
    J = motor.rotor_inertia / mo.KG_M2  # kg*m^2
    assert T**2 / J / 1e3 == pytest.approx(motor.power_rate, rel=6e-3)
    assert T / J == pytest.approx(motor.angular_acceleration, rel=6e-3)
    # SGM7J prints the output in W (three figures), SGM7A in kW (two): 3.0 kW is 3.08 kW
    tolerance = 3e-3 if motor.series == "SGM7J" else 3e-2
    assert motor.rated_torque * motor.rated_speed == pytest.approx(
        motor.rated_output, rel=tolerance
    )
    assert motor.peak_torque >= motor.rated_torque
    assert motor.max_speed >= motor.rated_speed > 0
    assert motor.rotor_inertia_brake is None or motor.rotor_inertia_brake > motor.rotor_inertia


def test_the_header_cites_the_manual_and_ships_as_package_data():
    text = resources.files("optdesign").joinpath("data/servo_motors.csv").read_text()
    head = "\n".join(line for line in text.splitlines() if line.startswith("#"))
    for needle in (
        "YASKAWA",
        "Rotary Servomotor Product Manual",
        '4.2.2 "Ratings of Servomotors without Gears"',
        "p. 4-4",
        "p. 5-7",
        "https://manualshive.com/",
        "Values transcribed as printed",
        "mass_kg is empty on every row",
    ):
        assert needle in head, needle
    assert all(m.mass is None for m in cat.load_motors())


def test_thk_selection_picks_the_first_motor_that_meets_all_four_checks():
    """THK's transfer example asks Trms <= rated (1305 N*mm), Tmax <= peak (4730 N*mm),
    1500 min^-1 and a rotor of at least 3.39e-4 kg*m^2. The SGM7J-06A has the torque but
    a rotor of 0.8e-4 kg*m^2; the inertia rule governs and the first motor in this
    catalogue that meets all four is the SGM7A-30A (7.00e-4 kg*m^2)."""
    torque_only = cat.find(1305.0, 4730.0, 1500.0 * mo.RPM)
    assert torque_only[0].designation == "SGM7J-06A"
    hits = cat.find(1305.0, 4730.0, 1500.0 * mo.RPM, 3.39e-4 * mo.KG_M2)
    assert [m.designation for m in hits] == ["SGM7A-30A", "SGM7A-40A", "SGM7A-50A", "SGM7A-70A"]
    assert cat.find(rated_torque_min=1e9) == ()


def test_a_users_csv_loads_with_its_own_masses(tmp_path):
    path = tmp_path / "my_motors.csv"
    path.write_text(f"# my motors\n{HEADER}\nM1,1.0,3.0,3000,5000,0.5,1.2\nM2,2,6,2000,4000,1,\n")
    motors = cat.load_motors(path)
    assert [m.designation for m in motors] == ["M1", "M2"]
    m1 = motors[0]
    assert (m1.rated_torque, m1.peak_torque, m1.rotor_inertia) == (1000.0, 3000.0, 0.05)
    assert m1.mass == pytest.approx(1.2e-3) and motors[1].mass is None
    assert m1.source == "my_motors.csv, line 3, M1"
    assert cat.by_designation("M2", motors).max_speed == pytest.approx(4000.0 * mo.RPM)


@pytest.mark.parametrize(
    ("row", "field", "reason"),
    [
        ("M1,1.0,,3000,5000,0.5,", "peak_torque_Nm", "missing"),
        ("M1,1.0,0.5,3000,5000,0.5,", "peak_torque_Nm", "below the rated torque"),
        ("M1,1.0,3.0,3000,5000,-0.5,", "rotor_inertia_1e-4kgm2", "negative rotor inertia"),
        ("M1,1.0,3.0,3000,5000,0,", "rotor_inertia_1e-4kgm2", "zero rotor inertia"),
        ("M1,1.0,3.0,0,0,0.5,", "max_speed_rpm", "cannot turn"),
        ("M1,1.0,3.0,3000,-1,0.5,", "max_speed_rpm", "cannot turn"),
        ("M1,1.0,3.0,6000,5000,0.5,", "rated_speed_rpm", "outside (0, max speed"),
        ("M1,-1.0,3.0,3000,5000,0.5,", "rated_torque_Nm", "must be positive"),
        ("M1,one,3.0,3000,5000,0.5,", "rated_torque_Nm", "'one' is not a number"),
        ("M1,1.0,3.0,3000,5000,nan,", "rotor_inertia_1e-4kgm2", "not a finite number"),
        ("M1,1.0,3.0,3000,5000,0.5,-2", "mass_kg", "a mass must be positive"),
        (",1.0,3.0,3000,5000,0.5,", "designation", "missing"),
    ],
)
def test_a_bad_row_is_refused_naming_the_file_line_and_column(tmp_path, row, field, reason):
    path = tmp_path / "bad.csv"
    path.write_text(f"{HEADER}\nOK,1,2,1000,2000,0.1,\n{row}\n")
    with pytest.raises(InputError) as err:
        cat.load_motors(path)
    message = str(err.value)
    assert err.value.field.startswith("bad.csv, line 3")
    assert err.value.field.endswith(f"column {field}")
    assert reason in message and "\n" not in message


def test_a_bad_file_is_refused_naming_what_is_wrong(tmp_path):
    missing = tmp_path / "short.csv"
    missing.write_text("designation,rated_torque_Nm,max_speed_rpm\nM1,1,3000\n")
    with pytest.raises(InputError, match=r"^short\.csv, line 1: missing column\(s\) peak_torque"):
        cat.load_motors(missing)
    twice = tmp_path / "twice.csv"
    twice.write_text(f"{HEADER}\nM1,1,2,1000,2000,0.1,\nM1,1,2,1000,2000,0.1,\n")
    with pytest.raises(InputError, match=r"'M1' already on line 2"):
        cat.load_motors(twice)
    with pytest.raises(InputError, match="no motor rows"):
        cat.parse_motors(f"{HEADER}\n", "empty.csv")
    with pytest.raises(InputError, match="cannot read the motor file"):
        cat.load_motors(tmp_path / "nowhere.csv")
