"""Issue 24: the sweep in an interactive page (``sweep.html``, ``od.report(sweep, ...)``):
the design chart and the table, each point's design on its own problem, every name
embedded as text (a problem named with ``<!--``, ``"`` and ``</script>`` cannot end the
data's ``<script>`` element or re-open one)."""

import json
from pathlib import Path

import pytest

import optdesign as od
from optdesign.cli import main
from optdesign.display.shown import objective_shown
from optdesign.errors import InputError
from optdesign.reports.sweep_html import NOT_COMPUTED
from optdesign.reports.sweep_text import _cell, sweep_rows

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"
NASTY = '<!--<script>x</script>"><b>%{x}</b>'


def _data(page: str) -> dict:
    start = page.index(">", page.index('id="report-data"')) + 1
    return json.loads(page[start : page.index("</script>", start)])


@pytest.fixture(scope="module")
def nasty(tmp_path_factory):
    folder = tmp_path_factory.mktemp("nasty")
    src = (PROBLEMS / "cs_min_backlash.toml").read_text()
    path = folder / "nasty.toml"
    path.write_text(src.replace('name = "cs_min_backlash"', "name = " + json.dumps(NASTY)))
    vary = {"requirements.hinge_moment": ("300 N*m", "700 N*m", 3)}
    return folder, path, od.sweep(path, vary, starts=2)


def test_the_page_carries_the_chart_the_table_and_each_points_design(nasty):
    folder, _path, sweep = nasty
    page = od.report(sweep, folder / "sweep.html").read_text()
    data = _data(page)  # parsed back whole: nothing in the names ended the element
    assert data["problem"] == NASTY and data["kind"] == "sweep"
    assert f"<title>optdesign sweep: {NASTY}" not in page and "&lt;!--&lt;script&gt;" in page
    assert page.count("<script") == 3  # plotly, the data, the page's own script
    headers, rows = sweep_rows(sweep)
    assert data["table"]["headers"] == headers
    assert data["table"]["rows"] == [[_cell(v) for v in row] for row in rows]
    (trace,) = data["front"]["traces"]
    assert trace["coords"][0] == [300.0, 500.0, 700.0]
    assert trace["coords"][1] == pytest.approx(
        [objective_shown(sweep.problem, "backlash", p.objective).value for p in sweep.points]
    )
    assert data["front"]["axes"] == ["hinge_moment [N*m]", "backlash (deg)"]
    for k, p in enumerate(sweep.points):
        view = data["designs"][trace["index"][k]]
        assert view["label"] == f"point {p.index}: hinge_moment [N*m] = {300 + 200 * k:g}"
        R = next(row for row in view["design"] if row["name"] == "R")
        assert R["value"] == pytest.approx(p.design["R"])
        # the point's design checked on the point's problem: it meets its requirements
        assert view["violated"] == []
        assert view["sensitivities"] == [NOT_COMPUTED]  # not "none": nothing was asked


def test_od_report_refuses_a_sweep_without_a_design(nasty, tmp_path):
    _folder, _path, sweep = nasty
    empty = type(sweep)(sweep.problem, sweep.objective, sweep.axes, [], 0.0, True)
    with pytest.raises(InputError, match="the sweep has no point with a design"):
        od.report(empty, tmp_path / "s.html")


def test_the_command_writes_sweep_html(nasty, capsys):
    folder, path, _sweep = nasty
    out = folder / "cli"
    args = ["sweep", str(path), "--vary", "requirements.hinge_moment=300..700N*m:2"]
    assert main([*args, "--starts", "1", "--out", str(out), "--no-progress"]) == 0
    assert "sweep.html" in capsys.readouterr().out
    data = _data((out / "sweep.html").read_text())
    assert [row[1] for row in data["table"]["rows"]] == ["300", "700"]


def test_a_points_costs_say_which_way_each_limit_moves(tmp_path):
    """Issue 35: a point's line read "requirements.deflection.min: +1 % -> backlash
    +0.7 %", not saying that 1 % of -30 deg moves it down; it says so, with the value
    on the point's own problem (the swept hinge moment at the point's)."""
    vary = {"requirements.hinge_moment": ("400 N*m", "600 N*m", 2)}
    sweep = od.sweep(PROBLEMS / "cs_min_backlash.toml", vary, starts=1, sensitivities=True)
    data = _data(od.report(sweep, tmp_path / "sweep.html").read_text())
    for view, moment in zip(data["designs"], ("400", "600"), strict=True):
        lines = view["sensitivities"]
        assert any(
            line.startswith("deflection.min -30 deg: lowering it by 1 % to -30.3 deg -> backlash ")
            for line in lines
        ), lines
        assert any(
            line.startswith(f"hinge_moment {moment} N*m: raising it by 1 % to ") for line in lines
        ), lines
