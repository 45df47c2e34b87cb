"""od.report(result_or_front, path): the command line's report.html for a result or a
front made in Python, written as safely as the command line writes it."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import optdesign as od
from optdesign.cli import main
from optdesign.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
PROBLEM = ROOT / "problems" / "cs_min_backlash.toml"


def test_report_of_a_result_is_the_commands_page(tmp_path, capsys):
    out = tmp_path / "cli"
    code = main(["solve", str(PROBLEM), "--starts", "2", "--no-ranges", "--out", str(out)])
    assert code == 0
    capsys.readouterr()
    result = od.solve(PROBLEM, starts=2, ranges=False)
    written = od.report(result, tmp_path / "mine.html")
    assert written == tmp_path / "mine.html"
    assert written.read_bytes() == (out / "report.html").read_bytes()
    # a folder: report.html in it, as the command line's --out
    folder = tmp_path / "folder"
    folder.mkdir()
    assert od.report(result, folder) == folder / "report.html"
    assert (folder / "report.html").read_bytes() == written.read_bytes()


def test_report_of_a_front_is_the_commands_page(tmp_path, capsys):
    out = tmp_path / "cli"
    args = ["pareto", str(PROBLEM), "--objectives", "backlash,size", "--points", "3"]
    args += ["--workers", "1", "--starts", "1", "--deterministic", "--no-progress"]
    assert main([*args, "--no-plot", "--out", str(out)]) == 0
    capsys.readouterr()
    front = od.pareto(
        PROBLEM, ["backlash", "size"], points=3, workers=1, starts=1, deterministic=True
    )
    page = od.report(front, tmp_path / "front.html").read_text()
    cli = (out / "report.html").read_text()
    assert page == cli
    assert '"kind":"front"' in page.replace(" ", "")


def test_report_replaces_a_planted_link_without_following_it(tmp_path):
    result = od.solve(PROBLEM, starts=1, ranges=False)
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me")
    link = tmp_path / "report.html"
    os.symlink(victim, link)
    od.report(result, tmp_path)
    assert victim.read_text() == "keep me"
    assert not link.is_symlink() and "<html" in link.read_text().lower()


@pytest.mark.parametrize(
    ("subject", "path", "expected"),
    [
        (
            "text",
            "r.html",
            "result: expected a Result (od.solve), a Front (od.pareto) or a Sweep (od.sweep)",
        ),
        (
            [],
            "r.html",
            "result: expected a Result (od.solve), a Front (od.pareto) or a Sweep (od.sweep)",
        ),
        (None, 42, "path: expected a folder or file path, got 42"),
        (None, "", "path: '' is not a usable path"),
        (None, "file.txt/r.html", "path: "),
    ],
)
def test_report_refuses_naming_the_argument(tmp_path, subject, path, expected):
    (tmp_path / "file.txt").write_text("a file")
    if subject is None:
        subject = od.solve(PROBLEM, starts=1, ranges=False)
    if isinstance(path, str) and path:
        path = tmp_path / path
    with pytest.raises(InputError) as caught:
        od.report(subject, path)
    assert str(caught.value).startswith(expected)
    if "file.txt" in str(path):
        assert str(caught.value).endswith("is a file, not a folder")  # the page's folder


def test_report_refuses_a_result_without_a_design(tmp_path):
    import dataclasses

    result = od.solve(PROBLEM, starts=1, ranges=False)
    empty = dataclasses.replace(result, design={})
    with pytest.raises(InputError, match=r"^result: has no design to report \(status optimal\)"):
        od.report(empty, tmp_path / "r.html")
    assert not (tmp_path / "r.html").exists()


def test_the_page_of_a_design_reads_its_view_and_evaluates_no_model(monkeypatch):
    """What the page shows of a design comes from its evaluated view
    (:func:`optdesign.views.design.design_view`): formatting it neither evaluates the
    design nor sketches its mechanism (the limits' wording reads the problem's
    declarations only)."""
    import dataclasses

    from optdesign.reports.html import design_json
    from optdesign.views.design import design_view

    problem = od.load(ROOT / "problems" / "cs_min_ripple.toml")
    view = design_view(problem, problem.design_dict(problem.start()))

    def evaluates(*args, **kw):
        raise AssertionError("the page evaluated the model")

    monkeypatch.setattr(problem, "evaluate", evaluates)
    monkeypatch.setattr(problem.mechanism, "sketch", evaluates)
    data = design_json(problem, view, "initial design")
    assert data["label"] == "initial design"
    assert len(data["sketch"]) == 3
    assert len(data["curves"]["ratio"]) == len(view.curves.ratio)
    # a mechanism that draws no sketch at one angle: the page shows none
    frames = (dataclasses.replace(view.frames[0], sketch=None), *view.frames[1:])
    assert design_json(problem, dataclasses.replace(view, frames=frames), "x")["sketch"] == []
