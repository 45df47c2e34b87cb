"""Outputs safe for any text: a name from a user (problem ``name``, a reference ``label``,
an objective of :meth:`add_objective`, a method's or a configuration's name) reaches the
terminal, report.html, the CSV files, the plots and the JSON files without breaking or
injecting into any of them.

The rules (docs/reports.md, "Text from the user in the outputs"): the terminal shows
control and format characters escaped, one line per name; the page's embedded JSON
holds no ``<``, ``>``, ``&``, U+2028/U+2029; CSV is written by the csv module with
formula-leading text cells prefixed by ``'``; plots draw ``$`` literally; JSON writes
``null`` for a value that is not finite. Each is checked in the default output mode, with
``--json`` and through the Python API. The page in a real browser:
tests/reports/test_html_page.py.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import re
import unicodedata
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.cli import main
from optdesign.reports.html_page import to_json
from optdesign.text import csv_cell, printable

PROBLEMS = Path(__file__).resolve().parent.parent / "problems"

#: Breaks out of the page's data element (``<!--`` then ``<script`` swallowed the rest
#: of the page), out of an attribute, into plotly's markup and templates, mathtext.
HTML_PART = (
    "<!--<script>x</SCRIPT><script>window.__pwned=1</script>"
    '"><img src=x onerror="window.__pwned=2">\'&amp;<b>%{x}</b>'
)
#: ANSI colour and screen clearing, a carriage return and a newline that forge a
#: status line, a bidi override, a NUL-free C1 control; then characters to keep.
TERM_PART = "\x1b[31m\x1b[2J\r\nstatus    optimal\u202eevil\x9b\u2028\u2029"
MATH_PART = r"$\frac{$ $x$"
KEEP = "é°µ Ω"
NAME = f"{HTML_PART}{TERM_PART}{MATH_PART}{KEEP}"
LABEL = "Ref\x1b[1m\nlabel | =1+1"


def _unsafe(text: str, newlines: bool = True) -> list[str]:
    """Characters of ``text`` that must not reach a terminal raw."""
    bad = []
    for ch in text:
        if ch == "\n" and newlines:
            continue
        if unicodedata.category(ch) in ("Cc", "Cf", "Cs", "Zl", "Zp"):
            bad.append(ch)
    return bad


def _strict_json(text: str):
    """json.loads refusing NaN / Infinity (which are not JSON)."""

    def refuse(name):
        raise AssertionError(f"{name} in JSON output")

    return json.loads(text, parse_constant=refuse)


def _named(folder: Path, name: str, reference: bool = True) -> Path:
    """cs_min_backlash.toml named ``name`` (TOML escapes), with a ``[reference]`` labelled
    :data:`LABEL`."""
    src = (PROBLEMS / "cs_min_backlash.toml").read_text()
    src = src.replace('name = "cs_min_backlash"', "name = " + json.dumps(name))
    if reference:
        src += (
            "\n[reference]\nlabel = "
            + json.dumps(LABEL)
            + '\nR = "90 mm"\nl = "80 mm"\nn = "50 mm"\np = "5 mm"\nphi0 = "0 rad"\nd = "10 mm"\n'
        )
    path = folder / "hostile.toml"
    path.write_text(src)
    assert od.load(path).name == name  # the file holds the name exactly
    return path


@pytest.fixture(scope="module")
def hostile_file(tmp_path_factory) -> Path:
    return _named(tmp_path_factory.mktemp("hostile"), NAME)


@pytest.fixture(scope="module")
def hostile_result(hostile_file):
    problem = od.load(hostile_file)
    return problem, od.solve(problem, starts=1, ranges=False)


# --- the rules themselves -------------------------------------------------------------


def test_printable_escapes_controls_and_keeps_unicode():
    assert printable("a\x1b[31mb\r\n\x00\x7f\x85\u202e\u2066\u200b\u2028") == (
        "a\\x1b[31mb\\r\\n\\x00\\x7f\\x85\\u202e\\u2066\\u200b\\u2028"
    )
    assert printable("line one\nline\ttwo", newlines=True) == "line one\nline\\ttwo"
    assert printable("é ° µ Ω φ 中 \u00a0 ✓") == "é ° µ Ω φ 中 \u00a0 ✓"
    assert printable("lone \ud800 surrogate") == "lone \\ud800 surrogate"
    assert printable(Path("a\nb")) == "a\\nb"


@pytest.mark.parametrize(
    "value, cell",
    [
        ("=HYPERLINK(1)", "'=HYPERLINK(1)"),
        ("+1", "'+1"),
        ("-1+2", "'-1+2"),
        ("-1", "'-1"),  # text that looks like a number is still text
        ("@SUM(A1)", "'@SUM(A1)"),
        ("\tx", "'\tx"),
        ("\rx", "'\rx"),
        ("a=1", "a=1"),
        ("optimal", "optimal"),
        ("", ""),
        (-1.5, -1.5),  # a number stays a number
        (np.float64(-2.0), -2.0),
        (-3, -3),
        (True, True),
        (None, None),
    ],
)
def test_csv_cell_neutralises_formula_text_only(value, cell):
    assert csv_cell(value) == cell


def test_csv_cell_formats_floats_as_numbers():
    assert csv_cell(-0.1234567890123456, digits=12) == "-0.123456789012"
    assert csv_cell(float("nan"), digits=12) == "nan"
    assert csv_cell(2, digits=12) == "2"


def test_embedded_json_cannot_leave_its_script_element():
    data = {"name": NAME, "list": ["</ScRiPt >", "<!--", "a&b"], "bad": [math.nan, -math.inf]}
    text = to_json(data)
    for ch in ("<", ">", "&", "\u2028", "\u2029"):
        assert ch not in text
    back = _strict_json(text)
    assert back["name"] == NAME and back["list"] == data["list"]
    assert back["bad"] == [None, None]


# --- solve: default mode, --json, files ------------------------------------------------


def _data_of(page: str) -> tuple[str, dict]:
    """The content of the page's data element (up to the first ``</script``) and its
    JSON: an HTML parser ends the element there, unless a ``<!--`` in it opened a
    comment-like state (then a ``<script`` in it swallows the rest of the page)."""
    start = page.index('<script type="application/json" id="report-data">')
    start = page.index(">", start) + 1
    content = page[start : page.lower().index("</script", start)]
    return content, _strict_json(content)


def _check_page(page: str, name: str) -> dict:
    """report.html keeps its three script elements whole and its data exact."""
    content, data = _data_of(page)
    assert "<!--" not in page  # plotly's inlined script has none: only a name could
    assert "<" not in content and ">" not in content and "&" not in content
    assert data["problem"] == name
    # the page's own three scripts (plotly, data, drawing) and nothing else
    assert len(re.findall(r"<script", page, re.I)) == 3
    assert len(re.findall(r"</script", page, re.I)) == 3
    # the header shows the name escaped (quotes too), one line
    h1 = re.search(r"<h1>(.*)</h1>", page).group(1)
    assert "&lt;!--&lt;script&gt;" in h1 and "&quot;&gt;&lt;img" in h1 and "&#x27;" in h1
    assert "\\x1b[31m" in h1 and "\\r\\n" in h1 and "\\u2028" in h1 and KEEP in h1
    assert "<img" not in page
    return data


def test_solve_default_mode_shows_the_name_safely(hostile_file, tmp_path, capfd):
    out = tmp_path / "out"
    code = main(["solve", str(hostile_file), "--starts", "1", "--no-ranges", "--out", str(out)])
    stdout, stderr = capfd.readouterr()
    assert code == 0, stderr
    assert _unsafe(stdout) == [] and _unsafe(stderr) == []
    first = stdout.splitlines()[0]
    assert first == f"problem   {printable(NAME)} (crank-slider)"
    assert KEEP in first and "\\x1b[31m\\x1b[2J\\r\\nstatus    optimal\\u202eevil\\x9b" in first
    # the forged status line did not become a line of its own
    assert sum(line.startswith("status") for line in stdout.splitlines()) == 1
    # the reference label: one line, heading its table
    assert f"{printable(LABEL)} vs optimum" in stdout
    assert "Ref\\x1b[1m\\nlabel | =1+1" in stdout
    doc = _strict_json((out / "result.json").read_text())
    assert doc["problem"] == NAME  # JSON carries the name exactly
    assert not any("not written" in n for n in doc["notes"])
    assert (out / "solution.png").stat().st_size > 10_000
    data = _check_page((out / "report.html").read_text(), NAME)
    assert [d["label"] for d in data["designs"]][1] == "optimum"


def test_solve_json_mode_is_exact_json(hostile_file, tmp_path, capfd):
    code = main(["solve", str(hostile_file), "--starts", "1", "--no-ranges", "--json"])
    stdout, _ = capfd.readouterr()
    assert code == 0
    assert _unsafe(stdout) == []  # JSON escapes every control character
    doc = _strict_json(stdout)
    assert doc["problem"] == NAME
    # the reference table (a note) heads with the label as one printable line
    assert any(f"{printable(LABEL)} vs optimum" in note for note in doc["notes"])
    assert not any(LABEL in note for note in doc["notes"])


def test_solve_api_summary_plot_and_frame(hostile_result):
    import matplotlib
    from matplotlib import cbook

    from optdesign.plots import MAX_TITLE_NAME

    matplotlib.use("Agg")
    _, result = hostile_result
    summary = result.summary()
    assert _unsafe(summary) == []
    assert summary.splitlines()[0] == f"problem   {printable(NAME)} (crank-slider)"
    fig = result.plot()
    title = fig.axes[0].get_title()
    assert not cbook.is_math_text(title)  # drawn as written, not as mathtext
    fig.canvas.draw()  # the name's "$\frac{$" failed here
    # the name escaped, cut to MAX_TITLE_NAME characters (its "$\frac{$" is further on)
    assert title.startswith(printable(NAME)[: MAX_TITLE_NAME - 3] + "...: ")
    frame = result.to_frame()
    assert "R" in frame.loc["variable"].index
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_error_that_echoes_a_hostile_key_is_one_safe_line(hostile_file, tmp_path, capfd):
    src = (PROBLEMS / "cs_min_backlash.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(
        src.replace("[requirements]", '[requirements]\n"bo\\u001b[31mgus\\nx\\u202e" = 3')
    )
    for extra in ([], ["--json"]):
        code = main(["solve", str(bad), "--out", str(tmp_path / "o"), *extra])
        stdout, stderr = capfd.readouterr()
        assert code == 2 and stdout == ""
        assert stderr.count("\n") == 1 and _unsafe(stderr) == []
        assert "requirements.bo\\x1b[31mgus\\nx\\u202e: unknown field" in stderr
    code = main(["solve", str(hostile_file), "--objective", "no\x1b[2J\rpe", "--json"])
    _, stderr = capfd.readouterr()
    assert code == 2 and stderr.count("\n") == 1 and _unsafe(stderr) == []
    assert "no\\x1b[2J\\rpe" in stderr


def test_argparse_refusals_are_printable(hostile_file, capfd):
    with pytest.raises(SystemExit) as exc:
        main(["solve", str(hostile_file), "\x1b[2Jx\ny"])
    _, stderr = capfd.readouterr()
    assert exc.value.code == 2 and _unsafe(stderr) == []
    assert stderr.splitlines()[-1] == "optdesign: error: unrecognized arguments: \\x1b[2Jx\\ny"


# --- pareto: front.csv, front.json, front.png, report.html ----------------------------


def test_pareto_files_and_summary_with_a_hostile_name(hostile_file, tmp_path, capfd):
    out = tmp_path / "front"
    args = ["pareto", str(hostile_file), "--objectives", "backlash,size", "--points", "3"]
    code = main([*args, "--workers", "1", "--starts", "1", "--no-progress", "--out", str(out)])
    stdout, stderr = capfd.readouterr()
    assert code == 0, stderr
    assert _unsafe(stdout) == [] and _unsafe(stderr) == []
    assert stdout.splitlines()[0] == f"problem   {printable(NAME)}: objectives backlash, size"
    front = _strict_json((out / "front.json").read_text())
    assert front["problem"] == NAME
    with (out / "front.csv").open(newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][:4] == ["method", "id", "backlash [deg]", "size [mm]"]
    assert len(rows) == 4 and all(len(r) == len(rows[0]) for r in rows)
    assert (out / "front.png").stat().st_size > 10_000
    data = _check_page((out / "report.html").read_text(), NAME)
    assert len(data["front"]["traces"][0]["index"]) == 3


def _hostile_objective_problem():
    """A problem whose own objective has a name a spreadsheet, plotly and mathtext would
    all read as markup, and whose values are negative numbers."""
    from optdesign.problem.objectives import ObjectiveInfo

    problem = od.load(PROBLEMS / "cs_min_backlash.toml")
    # add_objective refuses such a name (names are identifiers: tests/test_user_code.py);
    # the outputs stay safe for any text all the same, so the objective is declared
    # past that check, as a plug-in's own table of objectives could hold it.
    problem._objectives[OBJ] = ObjectiveInfo(OBJ, lambda q: q.size - 1000.0, "max", "mm", OBJ)
    problem._touch()
    return problem


OBJ = '=HYPERLINK("x")|<b>$x$</b>%{y}\x1b[31m'


@pytest.fixture(scope="module")
def hostile_front():
    from optdesign.studies.pareto import EpsilonConstraint

    problem = _hostile_objective_problem()
    # A method's name names its store file, so it must be a plain file name
    # (tests/test_safe_io.py); the CSV test gives the front a hostile one afterwards.
    method = EpsilonConstraint(points=3, starts=1, name="method-1")
    return problem, od.pareto(problem, ["backlash", OBJ], method=method, workers=1)


def test_front_csv_reads_back_with_formulas_neutralised(hostile_front, tmp_path):
    from optdesign.reports.front_files import read_front_csv, write_front_csv

    problem, front = hostile_front
    # a constraint name that a plug-in chose, active at a point; a method's name as a
    # plug-in method could set it (the built-in ones refuse such a name for their store)
    front.points[0].active = ["=1+1", *front.points[0].active]
    front = dataclasses.replace(
        front,
        method="-method=1",
        points=[
            dataclasses.replace(p, method="-method=1", id=p.id.replace("method-1", "-method=1"))
            for p in front.points
        ],
    )
    path = write_front_csv(front, problem, tmp_path / "front.csv")
    with path.open(newline="") as fh:
        rows = list(csv.reader(fh))
    head = rows[0]
    # quoted by csv (it holds a quote), prefixed; the unit after the name
    assert head[2:4] == ["backlash [deg]", "'" + OBJ + " [mm]"]
    assert '"\'=HYPERLINK(""x"")' in path.read_text()  # the csv module's quoting
    first = dict(zip(head, rows[1], strict=True))
    assert first["method"] == "'-method=1" and first["id"].startswith("'-method=1-")
    assert first["active"].startswith("'=1+1;")
    # a negative number is written as a number, not neutralised
    value = front.points[0].objectives[OBJ]
    assert value < 0 and first["'" + OBJ + " [mm]"] == f"{value:.12g}"
    assert float(first["'" + OBJ + " [mm]"]) == pytest.approx(value, rel=1e-11)
    F = read_front_csv(path, ["backlash", OBJ])
    assert F.shape == (3, 2) and np.all(F[:, 1] < 0)


def test_front_api_summary_frame_and_plot(hostile_front):
    import matplotlib
    import matplotlib.pyplot as plt
    from matplotlib import cbook

    matplotlib.use("Agg")
    _, front = hostile_front
    summary = front.summary()
    assert _unsafe(summary) == []
    assert printable(OBJ) in summary and "method-1 front" in summary
    frame = front.to_frame()
    assert OBJ + " [mm]" in frame.columns  # the frame holds the data as it is
    fig = front.plot()
    texts = [fig.axes[0].get_ylabel(), fig.axes[0].get_title()]
    texts += [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    texts += [ax.get_title() for ax in fig.axes[1:]]
    assert not any(cbook.is_math_text(t) for t in texts)
    fig.canvas.draw()
    plt.close(fig)


def test_front_report_carries_every_name_as_data(hostile_front):
    from optdesign.reports.html import front_report

    problem, front = hostile_front
    page = front_report(problem, [front])
    content, data = _data_of(page)
    assert "<" not in content and ">" not in content
    assert data["front"]["axes"][1] == f"{OBJ} (mm)"
    assert data["front"]["traces"][0]["method"] == "method-1"


# --- bench: bench_runs.csv, summary.md, bench_stats.json --------------------------------


def test_bench_outputs_with_hostile_names(tmp_path):
    from optdesign.studies.bench.configs import CONFIGS, Config, nlp_config, register_config

    problem = od.load(_named(tmp_path, "=cmd|x\x1b[31m\nname", reference=False))
    name = "=cfg|$x$<b>"
    register_config(nlp_config(name, "slsqp", {}, description="a|b<img src=x>`c`"))
    try:
        # a configuration that never succeeds: its median time is NaN
        register_config(Config("-fails", "nlp", _fails, "raises"))
        solvers = [name, "-fails"]
        report = od.bench(problems=[problem], solvers=solvers, workers=1, out=tmp_path / "b")
    finally:
        CONFIGS.pop(name, None)
        CONFIGS.pop("-fails", None)
    tmp_path = tmp_path / "b"
    with (tmp_path / "bench_runs.csv").open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 2
    assert rows[0]["config"] == "'" + name
    assert rows[0]["instance"] == "user-000-" + problem.name  # exact: not a formula
    summary = (tmp_path / "summary.md").read_text()
    assert "\\=cfg" not in summary and "=cfg\\|$x$\\<b>" in summary
    assert "a\\|b\\<img src=x>\\`c\\`" in summary
    table = [line for line in summary.splitlines() if "cfg" in line]
    assert table and all(line.count(" | ") == 8 for line in table)  # nine cells
    assert _unsafe(report.summary()) == []
    stats = _strict_json((tmp_path / "bench_stats.json").read_text())["all"]
    assert stats["-fails"]["median_time_s"] is None
    assert rows[1]["config"] == "'-fails" and rows[1]["status"] == "error"
    assert (tmp_path / "bench_profiles.png").stat().st_size > 10_000


def _fails(problem, objective, time_limit):
    raise RuntimeError("deliberate")


def test_bench_refusal_of_a_hostile_configuration_is_one_line(tmp_path, capfd):
    code = main(["bench", "--solvers", "x\x1b[2J\nforged", "--out", str(tmp_path)])
    _, stderr = capfd.readouterr()
    assert code == 2 and stderr.count("\n") == 1 and _unsafe(stderr) == []
    assert "x\\x1b[2J\\nforged" in stderr


# --- progress bars, plot failures, NaN -----------------------------------------------


def test_progress_bar_description_is_printable(tmp_path, monkeypatch):
    import tqdm.auto

    from optdesign.runtime.runner import run_tasks

    seen = []

    class Bar:
        def __init__(self, *args, desc=None, **kw):
            seen.append(desc)

        def update(self, n):
            pass

        def refresh(self):
            pass

        def close(self):
            pass

    monkeypatch.setattr(tqdm.auto, "tqdm", Bar)
    tasks = [{"id": "a"}, {"id": "b"}]
    run_tasks(tasks, _double, tmp_path / "s.jsonl", progress="m\x1b[2J\r\nx: points")
    assert seen == ["m\\x1b[2J\\r\\nx: points"]


def _double(task, deps):
    return {"value": 2}


def test_a_plot_failure_keeps_the_other_outputs(hostile_file, tmp_path, capfd, monkeypatch):
    import optdesign.plots.front
    import optdesign.plots.solution

    def broken(*args, **kw):
        raise RuntimeError("drawing failed\nsecond line")

    monkeypatch.setattr(optdesign.plots.solution, "draw_solution", broken)
    monkeypatch.setattr(optdesign.plots.front, "draw_front", broken)
    out = tmp_path / "solve"
    code = main(["solve", str(hostile_file), "--starts", "1", "--no-ranges", "--out", str(out)])
    stdout, stderr = capfd.readouterr()
    assert code == 0, stderr
    note = "solution.png not written: RuntimeError: drawing failed second line"
    assert f"note      {note}" in stdout
    assert note in _strict_json((out / "result.json").read_text())["notes"]
    assert (out / "report.html").exists() and not (out / "solution.png").exists()
    assert "solution.png" not in stdout.splitlines()[-1]  # not listed as written
    out = tmp_path / "front"
    args = ["pareto", str(hostile_file), "--objectives", "backlash,size", "--points", "2"]
    code = main([*args, "--workers", "1", "--starts", "1", "--no-progress", "--out", str(out)])
    stdout, stderr = capfd.readouterr()
    assert code == 0, stderr
    assert "note: front.png not written: RuntimeError: drawing failed second line" in stdout
    for name in ("front.csv", "front.json", "report.html"):
        assert (out / name).exists()
    assert not (out / "front.png").exists()


def test_result_json_writes_null_for_values_that_are_not_finite(hostile_result):
    import copy

    from optdesign.reports.result_json import result_json

    result = copy.copy(hostile_result[1])
    result.objectives = {k: math.nan for k in result.objectives}
    result.objective = math.inf
    result.wall_time_s = math.nan
    doc = _strict_json(result_json(result))
    assert doc["objective"]["value"] is None and doc["wall_time"]["value"] is None
    assert all(v["value"] is None for v in doc["objectives"].values())
    summary = result.summary()
    assert _unsafe(summary) == [] and "backlash = -" in summary


def test_a_huge_name_is_drawn_shortened_and_quickly(tmp_path):
    """optdesign.plots.plain: a user's text on a figure is cut to MAX_DRAWN characters (a
    problem's name at the head of a title to MAX_TITLE_NAME) and ends with "...": a
    900 kB name took matplotlib's text layout minutes, deaf to Ctrl-C."""
    import time
    import tomllib

    import matplotlib

    from optdesign.plots import MAX_DRAWN, MAX_TITLE_NAME, plain, write_figure
    from optdesign.plots.solution import plot_designs

    matplotlib.use("Agg")
    huge = "N" * 900_000
    assert plain(huge) == "N" * (MAX_DRAWN - 3) + "..."
    escaped = plain("\x1b" * 500)  # an escape counts as the characters drawn
    assert len(escaped) == MAX_DRAWN and escaped.startswith("\\x1b\\x1b")
    assert escaped.endswith("...")
    assert plain("$x$ " * 100).startswith(r"\$x\$ ") and plain("$x$") == r"\$x\$"
    data = tomllib.loads((PROBLEMS / "cs_min_backlash.toml").read_text())
    data["name"] = huge
    problem = od.load(data)
    design = problem.design_dict(problem.start())
    figures = []
    t0 = time.perf_counter()
    note = write_figure(
        lambda: figures.append(plot_designs(problem, {"start": design})) or figures[0],
        tmp_path / "s.png",
    )
    assert note is None and time.perf_counter() - t0 < 30  # minutes before
    title = figures[0].axes[0].get_title()
    assert title == "N" * (MAX_TITLE_NAME - 3) + "...: ratio over the stroke"
