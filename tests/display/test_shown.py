"""optdesign/display/shown.py as a whole: the angle unit a report shows (per
field, per file, by default), a number's text and JSON, each internal unit as read,
objectives and their statistics, and the requirements echoed in the units the file
wrote them in (pint's conversion as the independent check), with bare numbers, percent,
bands and lists."""

import math
import tomllib
from pathlib import Path
from types import SimpleNamespace

import pytest

import optdesign as od
from optdesign.display.shown import (
    Shown,
    angle_unit,
    json_value,
    objective_shown,
    requirement_echo,
    requirement_values,
    shown,
    variable_shown,
)
from optdesign.problem import problem_from_dict
from optdesign.problem.load import load
from optdesign.units import registry

ROOT = Path(__file__).resolve().parents[2]


def _units(**paths):
    return SimpleNamespace(written_units={k.replace("__", "."): v for k, v in paths.items()})


def test_the_angle_unit_of_a_field_then_of_the_file_then_degrees():
    mixed = _units(
        variables__phi0__lower="rad",
        variables__phi0__upper="radians",
        requirements__deflection__min="deg",
        variables__R__lower="mm",
    )
    assert angle_unit(mixed, "variables.phi0") == "rad"
    assert angle_unit(mixed, "requirements.deflection") == "deg"
    # a field written in both, or not at all: the file's one unit, else degrees
    both = _units(x__a="deg", x__b="rad")
    assert angle_unit(both, "x") == "deg"
    only_rad = _units(a__b="rad", c__d="Radian", e="mm")
    assert angle_unit(only_rad, "nothing") == "rad"
    assert angle_unit(only_rad) == "rad"
    assert angle_unit(_units(a=" Degrees "), None) == "deg"
    assert angle_unit(SimpleNamespace(), "x") == "deg"
    assert angle_unit(SimpleNamespace(written_units=None)) == "deg"
    # a path prefix matches whole components only
    prefix = _units(variables__phi00="rad", other="deg")
    assert angle_unit(prefix, "variables.phi0") == "deg"
    assert angle_unit(_units(variables__phi0="°"), "variables.phi0") == "deg"


def test_a_numbers_text_and_json():
    assert Shown(12.5, "deg").text() == "12.5 deg"
    assert Shown(1 / 3, "mm").text(3) == "0.333 mm"
    assert Shown(0.5, "%").text() == "0.5 %"
    assert Shown(7.0).text() == "7"
    assert Shown(math.nan, "mm").text() == "-" and Shown(None, "mm").text() == "-"
    assert Shown(2.0, "N*m").to_json() == {"value": 2.0, "unit": "N*m"}
    assert Shown(math.inf, "mm").to_json() == {"value": None, "unit": "mm"}
    assert Shown(None, "").to_json() == {"value": None, "unit": ""}
    assert Shown(3, "mm").to_json()["value"] == 3.0


def test_each_internal_unit_as_the_user_reads_it():
    assert shown(math.pi / 6, "rad") == Shown(pytest.approx(30.0), "deg")
    assert shown(0.5, "rad", angle="rad") == Shown(0.5, "rad")
    assert shown(2500.0, "N*mm") == Shown(2.5, "N*m")
    assert shown(3.0, "mm") == Shown(3.0, "mm")
    assert shown(3.0, "") == Shown(3.0, "")


def test_a_variable_in_the_unit_its_field_was_written_in():
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")  # phi0 bounds in rad
    by_name = {v.name: v for v in problem.variables}
    assert variable_shown(problem, by_name["phi0"], 0.25) == Shown(0.25, "rad")
    assert variable_shown(problem, by_name["R"], 40.0) == Shown(40.0, "mm")


def test_objectives_and_their_statistics_as_read():
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    assert objective_shown(problem, "ripple", 0.02) == Shown(pytest.approx(2.0), "%")
    assert objective_shown(problem, "motor_torque", 2500.0) == Shown(pytest.approx(2.5), "N*m")
    assert objective_shown(problem, "CVaR_0.9(motor_torque)", 2500.0) == Shown(
        pytest.approx(2.5), "N*m"
    )
    assert objective_shown(problem, "mean(ripple)", 0.5) == Shown(pytest.approx(50.0), "%")
    assert objective_shown(problem, "unknown", 3.0) == Shown(3.0, "")
    assert objective_shown(None, "ripple", 3.0) == Shown(3.0, "")


def _problem(**requirements):
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash.toml").read_text())
    data["requirements"].update(requirements)
    return od.load(data)


def test_requirements_are_echoed_in_the_units_the_file_wrote():
    problem = _problem(
        hinge_moment="0.5 kN*m",
        nut_travel_max="4.3 in",
        rod_inclination_max="0.5 rad",
        transmission_angle={"min": "40 deg", "max": "2.4 rad"},
    )
    values = requirement_values(problem)
    ureg = registry()
    assert values["hinge_moment"] == Shown(0.5, "kN*m")
    inch = float(ureg.Quantity(problem.spec.requirements.nut_travel_max, "mm").to("in").magnitude)
    assert values["nut_travel_max"] == Shown(pytest.approx(inch, rel=1e-14), "in")
    assert values["nut_travel_max"].value == 4.3  # tidied back to what was written
    assert values["rod_inclination_max"] == Shown(0.5, "rad")
    assert values["transmission_angle"] == {"min": Shown(40.0, "deg"), "max": Shown(2.4, "rad")}
    assert values["deflection"] == {
        "min": Shown(-30.0, "deg"),
        "max": Shown(30.0, "deg"),
        "points": 61,
    }
    assert values["mean_ratio"] == {"min": 200.0, "max": 260.0}
    assert values["pin_shear_planes"] == 2
    # defaults are not echoed (the hinge moment always is)
    assert "efficiency_min" not in values
    echo = dict(requirement_echo(problem))
    assert echo["hinge_moment"] == "0.5 kN*m"
    assert echo["transmission_angle"] == "{min = 40 deg, max = 2.4 rad}"
    assert echo["mean_ratio"] == "{min = 200, max = 260}"
    assert echo["pin_shear_planes"] == "2"


def test_bare_numbers_show_what_they_were_taken_as():
    problem = _problem(hinge_moment=5.0e5, rod_inclination_max=0.5, nut_travel_max=110)
    values = requirement_values(problem)
    # a bare number is internal: N*mm shown as N*m, rad as degrees, mm as mm
    assert values["hinge_moment"] == Shown(pytest.approx(500.0), "N*m")
    assert values["rod_inclination_max"] == Shown(pytest.approx(math.degrees(0.5)), "deg")
    assert values["nut_travel_max"] == Shown(110.0, "mm")


def test_json_of_requirement_values():
    assert json_value(Shown(2.0, "mm")) == {"value": 2.0, "unit": "mm"}
    assert json_value({"min": Shown(1.0, "deg"), "n": 3}) == {
        "min": {"value": 1.0, "unit": "deg"},
        "n": {"value": 3, "unit": ""},
    }
    assert json_value(0.5) == {"value": 0.5, "unit": ""}
    assert json_value(True) is True
    assert json_value("H7/g6") == "H7/g6"


def test_a_plain_number_written_in_percent_is_shown_in_percent():
    assert requirement_values(_problem(ripple_max="5 %"))["ripple_max"] == Shown(5.0, "%")
    assert requirement_values(_problem(ripple_max="7 percent"))["ripple_max"] == Shown(7.0, "%")
    assert requirement_values(_problem(ripple_max=0.05))["ripple_max"] == 0.05
    assert dict(requirement_echo(_problem(ripple_max=0.05)))["ripple_max"] == "0.05"


# --- the input echo of a report -------------------------------------------------------
def test_a_bare_zero_angle_is_echoed_in_the_one_angle_unit_the_file_wrote():
    """A bare 0 has no unit of its own: a file that wrote every angle in rad sees it in
    rad too, one that wrote them in degrees in deg."""
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash.toml").read_text())
    req = data["requirements"]
    req["deflection"] = {"min": 0, "max": "0.5 rad", "points": 11}
    req["transmission_angle"] = {"min": "0.7 rad", "max": "2.4 rad"}
    req["rod_inclination_max"] = "0.5 rad"
    echo = dict(requirement_echo(problem_from_dict(data)))
    assert echo["deflection"] == "{min = 0 rad, max = 0.5 rad, points = 11}"
    req["deflection"] = {"min": 0, "max": "30 deg", "points": 11}
    req["transmission_angle"] = {"min": "40 deg", "max": "140 deg"}
    req["rod_inclination_max"] = "30 deg"
    data["variables"]["phi0"] = {"lower": "-30 deg", "upper": "30 deg"}
    echo = dict(requirement_echo(problem_from_dict(data)))
    assert echo["deflection"] == "{min = 0 deg, max = 30 deg, points = 11}"


def test_an_objective_without_a_problem_or_a_declaration_is_shown_bare():
    """An objective value shown with no problem (a record read alone) or under a name the
    problem does not declare: the number as it is, with no unit."""
    from optdesign.display.shown import Shown, objective_shown

    assert objective_shown(None, "backlash", 0.5) == Shown(0.5, "")
    assert objective_shown(None, "backlash", 0.5).text() == "0.5"
    problem = load(Path(__file__).resolve().parents[2] / "problems" / "cs_min_backlash.toml")
    assert objective_shown(problem, "not_an_objective", 2.0) == Shown(2.0, "")
    shown = objective_shown(problem, "CVaR_0.9(backlash)", 0.03)  # a statistic of it
    assert shown.unit == "deg" and shown.value == pytest.approx(0.03)


def test_an_angle_is_shown_in_the_unit_the_file_wrote_it_in():
    from optdesign.display.shown import shown

    as_rad = shown(0.5, "rad", "rad")
    assert (as_rad.value, as_rad.unit) == (0.5, "rad")
    as_deg = shown(0.5, "rad")
    assert as_deg.unit == "deg" and as_deg.value == pytest.approx(math.degrees(0.5), rel=1e-15)
