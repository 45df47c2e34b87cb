"""Frames and front.csv in the units the summary shows (one source of display units):
ripple in %, a motor torque in N*m, an angle in the unit the file wrote it in, the unit in
each front column's name."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.reports.front_files import read_front_csv, write_front_csv

PROBLEM = Path(__file__).resolve().parents[2] / "problems" / "cs_min_backlash.toml"


def _problem():
    import tomllib

    data = tomllib.loads(PROBLEM.read_text())
    # phi0 written in degrees: shown (and framed) in degrees
    data["variables"]["phi0"] = {"lower": "-30 deg", "upper": "30 deg"}
    return od.load(data)


@pytest.fixture(scope="module")
def solved():
    problem = _problem()
    result = od.solve(problem, starts=2, ranges=False)
    front = od.pareto(problem, ["ripple", "motor_torque"], points=3, workers=1, starts=1)
    return problem, result, front


def _facts(summary: str) -> dict[str, tuple[float, str]]:
    """``name = value unit`` lines of the summary's "at this design" block."""
    out = {}
    block = summary.split("at this design:")[1].split("\n\n")[0]
    for line in block.splitlines():
        m = re.match(r"\s+(\w+) = (\S+)(?: ([^\s(]+))? \(", line)
        if m:
            out[m.group(1)] = (float(m.group(2)), m.group(3) or "")
    return out


def test_result_frame_is_in_the_summarys_units(solved):
    _, result, _ = solved
    frame = result.to_frame()
    facts = _facts(result.summary())
    assert facts["ripple"][1] == "%" and facts["motor_torque"][1] == "N*m"
    objectives = frame.loc["objective"]
    for name in ("ripple", "backlash", "size", "motor_torque"):
        value, unit = facts[name]
        assert objectives.loc[name, "unit"] == unit, name
        assert objectives.loc[name, "value"] == pytest.approx(value, rel=1e-5), name
    # the internal values, converted by hand: ripple a fraction, the torque in N*mm
    assert objectives.loc["ripple", "value"] == pytest.approx(100 * result.objectives["ripple"])
    torque = result.objectives["motor_torque"]
    assert objectives.loc["motor_torque", "value"] == pytest.approx(torque / 1000)


def test_result_frame_variables_as_the_design_table(solved):
    _, result, _ = solved
    frame = result.to_frame().loc["variable"]
    table = result.summary().split("variable ")[1]
    row = next(line for line in table.splitlines() if line.startswith("phi0"))
    cells = row.split()
    assert cells[-3] == "deg" and frame.loc["phi0", "unit"] == "deg"
    assert frame.loc["phi0", "value"] == pytest.approx(float(cells[-4]), rel=1e-5)
    assert frame.loc["phi0", "value"] == pytest.approx(math.degrees(result.design["phi0"]))
    assert frame.loc["phi0", "lower"] == -30 and frame.loc["phi0", "upper"] == 30
    assert frame.loc["R", "unit"] == "mm" and frame.loc["R", "value"] == result.design["R"]


def test_front_frame_names_its_units_and_matches_the_summary(solved):
    _, _, front = solved
    frame = front.to_frame()
    heads = ["ripple [%]", "motor_torque [N*m]", "R [mm]", "phi0 [deg]"]
    assert set(heads) <= set(frame.columns)
    assert frame.attrs["units"]["ripple [%]"] == "%"
    assert frame.attrs["units"]["motor_torque [N*m]"] == "N*m"
    assert "ripple" not in frame.columns  # no column without its unit
    F = front.F
    assert np.allclose(frame["ripple [%]"].to_numpy(), 100 * F[:, 0])
    assert np.allclose(frame["motor_torque [N*m]"].to_numpy(), F[:, 1] / 1000)
    phi0 = [math.degrees(p.design["phi0"]) for p in front.points]
    assert np.allclose(frame["phi0 [deg]"].to_numpy(), phi0)
    # the summary's table shows the same numbers (6 significant digits)
    summary = front.summary()
    table = summary.split("front (")[1].splitlines()
    assert table[1].split()[:2] == ["ripple", "(%)"]
    shown = [[float(x) for x in line.split()[:2]] for line in table[3 : 3 + len(F)]]
    expected = frame[["ripple [%]", "motor_torque [N*m]"]].to_numpy()
    assert np.allclose(shown, expected, rtol=1e-5)


def test_front_csv_has_the_frames_headings_and_reads_back(solved, tmp_path):
    import csv

    problem, _, front = solved
    path = write_front_csv(front, problem, tmp_path / "front.csv")
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    frame = front.to_frame()
    assert list(rows[0]) == list(frame.columns)
    assert float(rows[0]["ripple [%]"]) == pytest.approx(frame["ripple [%]"][0], rel=1e-11)
    # read back: as written, and in internal units with the problem
    as_written = read_front_csv(path, ["ripple", "motor_torque"])
    assert np.allclose(as_written, frame[["ripple [%]", "motor_torque [N*m]"]].to_numpy())
    internal = read_front_csv(path, ["ripple", "motor_torque"], problem)
    assert np.allclose(internal, front.F, rtol=1e-10)


def test_front_csv_without_units_is_read_as_internal(solved, tmp_path):
    """A front.csv written before its headings had units (the benchmarks' reference
    front): read as internal values."""
    problem, _, front = solved
    path = tmp_path / "old.csv"
    lines = ["method,id,ripple,motor_torque,on_front"]
    lines += [f"m,{i},{float(a)!r},{float(b)!r},True" for i, (a, b) in enumerate(front.F)]
    path.write_text("\n".join(lines) + "\n")
    internal = read_front_csv(path, ["ripple", "motor_torque"], problem)
    assert np.array_equal(internal, front.F)


def test_front_csv_without_an_on_front_column_keeps_every_row(solved, tmp_path):
    """A table of points with no ``on_front`` column (written by hand or by another
    tool): every row is a point of the front; with the column, only its True rows."""
    problem, _, front = solved
    path = tmp_path / "plain.csv"
    lines = ["ripple,motor_torque"] + [f"{float(a)!r},{float(b)!r}" for a, b in front.F]
    path.write_text("\n".join(lines) + "\n")
    assert np.array_equal(read_front_csv(path, ["ripple", "motor_torque"], problem), front.F)
    marked = tmp_path / "marked.csv"
    rows = [f"{float(a)!r},{float(b)!r},{k != 0}" for k, (a, b) in enumerate(front.F)]
    marked.write_text("\n".join(["ripple,motor_torque,on_front", *rows]) + "\n")
    assert np.array_equal(read_front_csv(marked, ["ripple", "motor_torque"]), front.F[1:])
    # an objective the table lacks is named (a column "backlash [deg]" would do)
    with pytest.raises(KeyError) as caught:
        read_front_csv(marked, ["ripple", "backlash"])
    assert caught.value.args == ("backlash",)


def test_the_frame_lists_the_rejected_points_only_when_asked(solved):
    """``to_frame(rejected=True)`` adds the points a front rejected (dominated, failed),
    marked off the front; the default lists the front alone."""
    import copy
    from dataclasses import replace

    _, _, front = solved
    front = copy.deepcopy(front)
    front.rejected = [replace(front.points[0], id="r-0", rejected="dominated")]
    plain, full = front.to_frame(), front.to_frame(rejected=True)
    assert list(plain["id"]) == [p.id for p in front.points]
    assert list(full["id"]) == [*plain["id"], "r-0"]
    assert list(full["on_front"]) == [True] * len(plain) + [False]
