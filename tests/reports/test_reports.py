"""What the engineer reads: units on every number (in the file's units), limits in the
quantity the user wrote, the achieved mean ratio, the requirements echoed, internal rows
hidden, result.json as {value, unit}, and for an infeasible problem the physical
objective and the smallest relaxation of each conflicting requirement."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.display.shown import requirement_echo
from optdesign.problem.load import written_units
from optdesign.reports.result_json import SCHEMA, result_document

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"


def _user_dict(**requirements) -> dict:
    """The issue's new user: crank-slider, +-25 deg, 300 N*m, ratio 150-200, H8/f7,
    angles written in degrees (the problem as a dict; ``requirements`` override)."""
    req = {
        "deflection": {"min": "-25 deg", "max": "25 deg", "points": 51},
        "hinge_moment": "300 N*m",
        "mean_ratio": {"min": 150, "max": 200},
        "nut_travel_max": "90 mm",
        "transmission_angle": {"min": "45 deg", "max": "135 deg"},
        "rod_inclination_max": "25 deg",
        "pin_bearing_pressure_max": "100 MPa",
        "fit": "H8/f7",
    }
    req.update(requirements)
    return {
        "name": "user_cs",
        "mechanism": "crank_slider",
        "variables": {
            "R": {"lower": "30 mm", "upper": "120 mm"},
            "l": {"lower": "40 mm", "upper": "150 mm"},
            "n": {"lower": "0 mm", "upper": "150 mm"},
            "p": {"lower": "2 mm", "upper": "10 mm"},
            "phi0": {"lower": "-30 deg", "upper": "30 deg"},
            "d": {"lower": "4 mm", "upper": "30 mm"},
            "i_a": 2,
            "pin_length_ratio": 1.5,
        },
        "requirements": req,
        "objective": {"minimize": "ripple"},
    }


def _user_problem(**requirements):
    return od.load(_user_dict(**requirements))


@pytest.fixture(scope="module")
def user_result():
    problem = _user_problem()
    return problem, od.solve(problem, starts=2, ranges=False)


def _mean_ratio_by_differences(problem, design) -> float:
    """Mean ratio from central differences of the nut position (not the ratio model):
    i = (2 pi i_a / p) dx/dphi."""
    mech = problem.quantities(design).mechanism
    h = 1e-6
    phi = problem.phi
    dx = (np.asarray(mech.nut_position(phi + h)) - np.asarray(mech.nut_position(phi - h))) / (2 * h)
    return float(np.mean(2 * math.pi * design["i_a"] / design["p"] * np.abs(dx)))


def test_summary_reads_in_the_files_units(user_result):
    problem, result = user_result
    assert result.status == "optimal"
    text = result.summary()
    # phi0 was written in degrees: shown in degrees, bounds too
    row = next(line for line in text.splitlines() if line.startswith("phi0"))
    cells = row.split()
    assert float(cells[3]) == pytest.approx(math.degrees(result.design["phi0"]), rel=1e-5)
    assert cells[4] == "deg" and "[-30, 30]" in row
    # the requirements echoed in the file's units
    assert "hinge_moment = 300 N*m" in text and "rod_inclination_max = 25 deg" in text
    # the achieved mean ratio, checked by finite differences of the nut position
    mean = float(re.search(r"mean_ratio = ([0-9.]+)", text).group(1))
    assert mean == pytest.approx(_mean_ratio_by_differences(problem, result.design), rel=1e-5)
    assert 150 - 1e-3 <= mean <= 200 + 1e-3
    # ripple in %, motor torque in N*m, size explained, efficiency stated
    ripple = float(re.search(r"ripple = ([0-9.]+) %", text).group(1))
    assert ripple == pytest.approx(100 * result.objectives["ripple"], rel=1e-5)
    torque = float(re.search(r"motor_torque = ([0-9.]+) N\*m", text).group(1))
    assert torque == pytest.approx(1e-3 * result.objectives["motor_torque"], rel=1e-5)
    assert "R + l" in text and "drive_efficiency = 100 %" in text
    assert "_envelope" not in text


def test_limits_in_the_quantity_written(user_result):
    _, result = user_result
    text = result.summary()
    limits = text.split("what limits the optimum")[1]
    # the rod inclination binds; it is shown as the angle (25 deg), never its sine
    line = next(x for x in limits.splitlines() if "rod_inclination" in x)
    assert "25 deg" in line and "0.422618" not in line
    assert f"{math.sin(math.radians(25)):.6g}" not in text


def test_result_json_carries_units_and_no_internal_rows(user_result):
    problem, result = user_result
    doc = result_document(result)
    assert doc["schema"] == SCHEMA
    assert all(set(v) >= {"value", "unit"} for v in doc["design"].values())
    assert doc["design"]["phi0"]["unit"] == "deg"
    assert doc["design"]["phi0"]["value"] == pytest.approx(math.degrees(result.design["phi0"]))
    assert doc["objectives"]["ripple"]["unit"] == "%"
    assert doc["objectives"]["motor_torque"]["unit"] == "N*m"
    assert doc["requirements"]["hinge_moment"] == {"value": pytest.approx(300.0), "unit": "N*m"}
    assert doc["achieved"]["mean_ratio"]["value"] == pytest.approx(
        _mean_ratio_by_differences(problem, result.design), rel=1e-5
    )
    assert "_envelope" not in json.dumps(doc)


def test_active_bounds_are_among_the_limits():
    # cs_min_backlash with the nut travel cut to 50 mm: the rod is pressed to its
    # shortest (l = 40 mm, its lower bound), which the old report never listed
    problem = od.load(PROBLEMS / "cs_min_backlash.toml")
    problem.set_requirement("nut_travel_max", "50 mm")
    result = od.solve(problem, starts=2, ranges=False)
    assert result.success
    assert result.design["l"] == pytest.approx(40.0, abs=1e-5)
    text = result.summary().split("what limits the optimum")[1]
    assert "rod length (l) = 40 mm, at its lower bound" in text
    kinds = {(lim["name"], lim["kind"]) for lim in result_document(result)["limits"]}
    assert ("l", "bound") in kinds


def test_a_bare_number_is_echoed_as_what_it_was_taken_as():
    # bare numbers are internal units: 300 is 300 N*mm = 0.3 N*m, and the echo says so
    problem = _user_problem(hinge_moment=300)
    echo = dict(requirement_echo(problem))
    assert echo["hinge_moment"] == "0.3 N*m"


def test_written_units_follow_the_file():
    units = written_units({"variables": {"phi0": {"lower": "-0.5 rad"}, "R": "90 mm", "i_a": 2}})
    assert units == {"variables.phi0.lower": "rad", "variables.R": "mm"}


def test_infeasible_report_shows_physical_objective_and_smallest_relaxation():
    # nut travel <= 25 mm against a mean ratio >= 200 with the lead >= 2 mm, i_a = 2 over
    # +-30 deg: travel = integral of i dphi * p / (2 pi i_a) >= 200 * (pi/3) * 2 / (4 pi)
    # = 33.3 mm, so nut_travel_max must rise to about 33.3 mm (hand derivation).
    spec = _user_dict()
    del spec["requirements"]["transmission_angle"]
    spec["requirements"].update(
        deflection={"min": "-30 deg", "max": "30 deg", "points": 61},
        mean_ratio={"min": 200, "max": 260},
        nut_travel_max="25 mm",
    )
    spec["objective"] = {"minimize": "backlash"}
    problem = od.load(spec)
    result = od.solve(problem, starts=2, ranges=False)  # diagnose=True: the relaxations
    assert not result.success and result.diagnosis.basis == "the NLP"
    text = result.summary()
    shown = float(re.search(r"objective backlash = ([0-9.]+) deg", text).group(1))
    assert shown == pytest.approx(result.objectives["backlash"], rel=1e-6)
    line = next(x for x in text.splitlines() if "(nut_travel): max 25 mm ->" in x)
    needed = float(re.search(r"-> ([0-9.]+) mm", line).group(1))
    hand = 200 * (math.pi / 3) * 2 / (4 * math.pi)
    assert hand * 0.995 <= needed <= hand * 1.02
    # the other way round: a mean ratio of at most 25 mm * 4 pi / (2 mm * pi/3) = 150
    line = next(x for x in text.splitlines() if "(mean_ratio): min 200 ->" in x)
    ratio = float(re.search(r"-> ([0-9.]+)", line).group(1))
    assert 150 * 0.98 <= ratio <= 150 * 1.005
    # and the relaxed problem is feasible
    spec["requirements"]["nut_travel_max"] = f"{needed} mm"
    assert od.solve(od.load(spec), starts=2, ranges=False).success


def _legend_labels(fig) -> list[str]:
    return [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().texts]


def test_solution_plot_draws_the_band_and_the_limits(user_result):
    import matplotlib.pyplot as plt

    _, result = user_result
    fig = result.plot()
    labels = _legend_labels(fig)
    assert "required mean ratio" in labels and "rod_inclination binds" in labels
    assert "initial design" in labels  # the midpoint design meets every requirement
    ratio_ax = fig.axes[0]
    band = next(p for p in ratio_ax.patches if p.get_label() == "required mean ratio")
    xy = band.get_xy()
    ys = [xy[1], xy[1] + band.get_height()] if isinstance(xy, tuple) else np.asarray(xy)[:, 1]
    assert min(ys) == pytest.approx(150) and max(ys) == pytest.approx(200)
    assert "rod inclination" in fig._supxlabel.get_text()
    plt.close(fig)


def test_initial_design_labelled_when_it_violates():
    import matplotlib.pyplot as plt

    problem = od.load(PROBLEMS / "cs_min_backlash.toml")
    # the midpoint design (R 75, l 120, n 75, p 6 mm) travels 75 mm at a mean ratio of 150
    problem.set_requirement("nut_travel_max", "50 mm")
    result = od.solve(problem, starts=1, ranges=False)
    fig = result.plot()
    assert "initial design (violates 2 requirements)" in _legend_labels(fig)
    plt.close(fig)


def test_no_progress_bar_outside_a_terminal(capfd):
    problem = od.load(PROBLEMS / "cs_min_backlash.toml")
    front = od.pareto(problem, ["backlash", "size"], points=3, workers=1, starts=1, progress=True)
    assert len(front.points) >= 2
    err = capfd.readouterr().err
    assert "it/s" not in err and "%|" not in err


def test_cli_flags_skip_the_diagnosis_and_the_report(tmp_path, capsys):
    from optdesign.cli import main

    src = (PROBLEMS / "cs_min_backlash.toml").read_text()
    path = tmp_path / "tight.toml"
    path.write_text(src.replace('nut_travel_max = "110 mm"', 'nut_travel_max = "25 mm"'))
    out = tmp_path / "out"
    args = ["solve", str(path), "--starts", "1", "--no-plot", "--out", str(out)]
    code = main([*args, "--no-diagnosis", "--no-report"])
    text = capsys.readouterr().out
    assert code == 1 and "smallest change" not in text
    assert not (out / "report.html").exists()
    assert "relaxations" not in json.loads((out / "result.json").read_text())


def test_a_band_is_echoed_with_the_sides_the_file_gave():
    problem = _user_problem(mean_ratio={"min": 200, "max": 260})
    assert dict(requirement_echo(problem))["mean_ratio"] == "{min = 200, max = 260}"
    problem = _user_problem(mean_ratio={"min": 200})
    assert dict(requirement_echo(problem))["mean_ratio"] == "{min = 200}"


def test_a_bare_deflection_rate_is_echoed_in_degrees_per_second():
    import math
    import tomllib
    from pathlib import Path

    import optdesign as od

    root = Path(__file__).resolve().parents[2]
    data = tomllib.loads((root / "problems" / "fin_actuator.toml").read_text())
    data["requirements"]["deflection_rate"] = 2.0  # bare: internal rad/s
    echo = dict(requirement_echo(od.load(data)))
    assert echo["deflection_rate"] == f"{math.degrees(2.0):.6g} deg/s"
    data["requirements"]["deflection_rate"] = "120 deg/s"  # as the file wrote it
    assert dict(requirement_echo(od.load(data)))["deflection_rate"] == "120 deg/s"


def test_solve_report_html_stays_under_one_megabyte_and_self_contained(tmp_path):
    """Issue 35: a solve's report.html was 4.8 MB, of which 4.8 MB was plotly's whole
    bundle inlined; the page carries the basic bundle packed (reports/plotly_js.py)."""
    from optdesign.reports import plotly_js

    result = od.solve(od.load(PROBLEMS / "cs_min_backlash.toml"), starts=2, ranges=False)
    page = od.report(result, tmp_path / "report.html")
    assert page.stat().st_size < 1_000_000
    text = page.read_text()
    assert "<script src=" not in text and "<link" not in text  # opens without a network
    assert plotly_js.packed() in text  # the library is in the page, whole
    start = text.index(">", text.index('id="report-data"')) + 1
    data = json.loads(text[start : text.index("</script>", start)])
    optimum = data["designs"][1]
    assert optimum["label"] == "optimum" and optimum["sketch"] and optimum["curves"]["ratio"]
    # the drawn numbers at 7 digits, the design's values whole
    R = next(row for row in optimum["design"] if row["name"] == "R")
    assert R["value"] == result.design["R"]


def test_report_pages_carry_the_shipped_plotly_bundle_unchanged():
    import base64
    import gzip
    import hashlib

    from optdesign.reports import plotly_js

    packed = plotly_js.BUNDLE.read_bytes()
    bundle = gzip.decompress(packed)
    assert hashlib.sha256(bundle).hexdigest() == plotly_js.SHA256
    assert f"plotly.js (basic - minified) v{plotly_js.VERSION}".encode() in bundle[:200]
    assert base64.b64decode(plotly_js.packed()) == packed
    assert "'" not in plotly_js.packed() and "<" not in plotly_js.packed()


def test_an_objective_the_model_cannot_evaluate_is_not_shown_as_a_number(user_result):
    """At a design where the model gives NaN (a linkage that does not assemble), the
    summary says the objective is not defined there instead of showing the solver's
    bound variable as its value."""
    import copy
    import math

    result = copy.copy(user_result[1])
    name = result.objective_name
    result.objectives = {**result.objectives, name: math.nan}
    result.status = "failed"
    line = next(ln for ln in result.summary().splitlines() if ln.startswith("objective "))
    assert line.startswith(f"objective {name} = not defined at this design (the model gives NaN)")
    shown = f"{result.objective:.6g}"
    assert shown not in line
