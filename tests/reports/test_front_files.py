"""optdesign/reports/front_files.py's files, on a front made up of known points (no
solve): front.csv's rows, headings, digits and units, written and read back through the
csv module, several fronts in one file, the unit checks on reading, front.json."""

import copy
import csv
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.display.frames import front_table
from optdesign.reports.front_files import read_front_csv, write_front_csv, write_front_json
from optdesign.studies.pareto.front import FrontPoint, make_front

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"
OBJ = ["ripple", "backlash"]


@pytest.fixture(scope="module")
def problem():
    return od.load(PROBLEMS / "cs_min_backlash.toml")


def _front(problem, method="made", points=((0.01, 0.30), (0.02, 0.20), (0.03, 0.25))):
    mid = problem.design_dict(problem.midpoint())
    pts = []
    for i, (a, b) in enumerate(points):
        design = {**mid, "R": mid["R"] + i}
        pts.append(
            FrontPoint(
                id=f"{method}-{i}",
                kind="eps",
                target="ripple",
                status="optimal",
                verified=True,
                objectives={"ripple": a, "backlash": b},
                design=design,
                active=["stroke", "ripple_max"] if i == 0 else [],
                method=method,
            )
        )
    return make_front(pts, OBJ, method, problem=problem)


def _read(path):
    with Path(path).open(newline="") as fh:
        return list(csv.reader(fh))


def test_the_rows_are_the_points_then_the_rejected_ones_on_request(problem):
    front = _front(problem)
    rows = front_table(front, problem)
    assert [r["id"] for r in rows] == ["made-0", "made-1"]
    with_rejected = front_table(front, problem, rejected=True)
    assert [(r["id"], r["on_front"]) for r in with_rejected] == [
        ("made-0", True),
        ("made-1", True),
        ("made-2", False),
    ]
    assert with_rejected[0]["active"] == "stroke;ripple_max"


def test_front_csv_writes_headings_with_units_and_twelve_digits(problem, tmp_path):
    front = _front(problem, points=((1 / 3, 0.10), (0.02, 0.20)))
    path = write_front_csv(front, problem, tmp_path / "front.csv")
    assert path == tmp_path / "front.csv"
    table = _read(path)
    heads = table[0]
    assert heads[:2] == ["method", "id"]
    assert heads[2:5] == ["ripple [%]", "backlash [deg]", "R [mm]"]
    assert heads[-4:] == ["status", "verified", "on_front", "active"]
    second = dict(zip(heads, table[2], strict=True))  # sorted by ripple: 1/3 comes second
    assert second["ripple [%]"] == format(100 / 3, ".12g")
    assert second["id"] == "made-0" and second["status"] == "optimal"
    assert second["on_front"] == "True" and second["verified"] == "True"
    assert second["active"] == "stroke;ripple_max"
    mid = problem.design_dict(problem.midpoint())
    assert float(second["R [mm]"]) == pytest.approx(mid["R"], rel=1e-11)
    assert dict(zip(heads, table[1], strict=True))["id"] == "made-1"
    assert len(table) == 3


def test_several_fronts_share_one_file_with_their_rejected_points(problem, tmp_path):
    fronts = [_front(problem, "a"), _front(problem, "b", points=((0.05, 0.1),))]
    table = _read(write_front_csv(fronts, problem, tmp_path / "front.csv"))
    assert [(r[0], r[1]) for r in table[1:]] == [
        ("a", "a-0"),
        ("a", "a-1"),
        ("a", "a-2"),
        ("b", "b-0"),
    ]


def test_an_empty_front_writes_the_method_heading_alone(problem, tmp_path):
    empty = make_front([], OBJ, "none", problem=problem)
    assert _read(write_front_csv(empty, problem, tmp_path / "e.csv")) == [["method"]]
    assert _read(write_front_csv([], problem, tmp_path / "n.csv")) == [["method"]]


def test_reading_back_as_written_and_in_internal_units(problem, tmp_path):
    front = _front(problem)
    path = write_front_csv(front, problem, tmp_path / "front.csv")
    internal = read_front_csv(path, OBJ, problem)
    assert np.allclose(internal, [[0.01, 0.30], [0.02, 0.20]], rtol=1e-11)
    shown = read_front_csv(path, OBJ)
    assert np.allclose(shown[:, 0], [1.0, 2.0], rtol=1e-11)  # percent
    # one objective alone, in the other order
    assert np.allclose(read_front_csv(path, ["backlash"], problem), [[0.30], [0.20]])
    assert read_front_csv(path, OBJ, problem).shape == (2, 2)


def test_a_file_without_front_rows_reads_as_an_empty_matrix(problem, tmp_path):
    path = tmp_path / "off.csv"
    path.write_text("ripple,backlash,on_front\n0.1,0.2,False\n")
    F = read_front_csv(path, OBJ, problem)
    assert F.shape == (0, 2)


def test_a_heading_in_another_unit_is_refused_naming_the_column(problem, tmp_path):
    path = tmp_path / "other.csv"
    path.write_text("ripple [ppm],backlash [deg]\n10,0.2\n")
    with pytest.raises(ValueError) as err:
        read_front_csv(path, OBJ, problem)
    assert f"{path}: column 'ripple [ppm]' is not in %" in str(err.value)
    # Without the problem the values are taken as written.
    assert np.allclose(read_front_csv(path, OBJ), [[10.0, 0.2]])


def test_a_heading_is_the_name_or_the_name_with_a_bracketed_unit_only(problem, tmp_path):
    path = tmp_path / "near.csv"
    path.write_text("ripple_max [%],ripplex,ripple [%,backlash\n1,2,3,4\n")
    with pytest.raises(KeyError) as err:
        read_front_csv(path, ["ripple"])
    assert err.value.args == ("ripple",)
    ok = tmp_path / "ok.csv"
    ok.write_text("ripple_max [%],ripple [%],backlash\n1,2,0.5\n")
    assert np.allclose(read_front_csv(ok, OBJ, problem), [[0.02, 0.5]])


def test_a_spreadsheet_neutralised_heading_is_found(problem, tmp_path):
    path = tmp_path / "neutral.csv"
    path.write_text("'=f [N],backlash\n3,0.5\n")
    assert np.allclose(read_front_csv(path, ["=f", "backlash"]), [[3.0, 0.5]])


def test_front_json_holds_every_front_with_meta_and_null_for_non_finite(problem, tmp_path):
    front = _front(problem)
    front.metrics["hv"] = math.inf
    path = write_front_json([front], tmp_path / "front.json", problem="cs", seed=3)
    data = json.loads(path.read_text())
    assert data["problem"] == "cs" and data["seed"] == 3
    assert len(data["fronts"]) == 1
    assert data["fronts"][0]["method"] == "made"
    assert data["fronts"][0]["metrics"]["hv"] is None
    assert [p["id"] for p in data["fronts"][0]["points"]] == ["made-0", "made-1"]
    assert "Infinity" not in path.read_text() and "NaN" not in path.read_text()


ROOT = Path(__file__).resolve().parents[2]


# --- resuming a stored front ------------------------------------------------------------
@pytest.fixture(scope="module")
def weighted_run(tmp_path_factory):
    """A finished 3-point weighted-sum front of cs_min_backlash (its output folder)."""
    out = tmp_path_factory.mktemp("weighted")
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    front = od.pareto(problem, ["backlash", "size"], 3, method="weighted_sum", starts=1, out=out)
    assert len(front.points) >= 2
    return problem, out, front


def test_front_csv_lists_the_rejected_points_off_the_front(weighted_run, tmp_path):
    """front.csv holds every point, the rejected ones (dominated, failed) marked off it."""
    problem, _, front = weighted_run
    front = copy.deepcopy(front)
    front.rejected = [replace(front.points[0], id="r-0", rejected="dominated")]
    path = write_front_csv(front, problem, tmp_path / "front.csv")
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["id"] for r in rows] == [*(p.id for p in front.points), "r-0"]
    assert [r["on_front"] for r in rows] == ["True"] * len(front.points) + ["False"]


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


def _front_of_midpoints(problem, objectives=("backlash", "size")):
    """A two-point front over the problem's mid-box design (no solve): enough to draw."""
    design = problem.design_dict(problem.midpoint())
    points = [
        FrontPoint(
            id=f"eps-{k}",
            kind="eps",
            target="backlash",
            objectives=dict(zip(objectives, values, strict=True)),
            design=dict(design),
            status="optimal",
            verified=True,
            method="epsilon",
        )
        for k, values in enumerate([(0.1, 30.0), (0.2, 20.0)])
    ]
    return make_front(points, list(objectives), "epsilon", problem=problem)


# --- files of a front ---------------------------------------------------------------------
def test_an_empty_fronts_csv_has_the_heading_every_front_csv_starts_with(cs_min_backlash, tmp_path):
    """A front with no point still writes front.csv: the one heading ``method``, the
    first heading of a front with points."""
    empty = make_front([], ["backlash", "size"], "epsilon", problem=cs_min_backlash)
    path = write_front_csv(empty, cs_min_backlash, tmp_path / "empty.csv")
    assert path.read_text() == "method\n"
    full = _front_of_midpoints(cs_min_backlash)
    text = write_front_csv(full, cs_min_backlash, tmp_path / "full.csv").read_text()
    assert text.split(",")[0] == "method"
