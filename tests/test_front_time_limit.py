"""A time limit for a Pareto study (``od.pareto(..., time_limit=)``, ``optdesign pareto
--time-limit``): no point begins after it, the points running finish and are stored, the
front says how many were left out, and a resume computes them - to the front an
uninterrupted run gives. The deadline is replaced by a counter of stored records here,
so that no test depends on timing."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
import optdesign.solvers.casadi_nlp
import optdesign.solvers.multistart
from optdesign.cli import main
from optdesign.solvers import deadline

# The patch below replaces deadline.passed for the front's own check; the modules that
# bind `passed` by name are imported first, so that none binds the patch for good (a
# later test in the same run would find every start "out of time").

ROOT = Path(__file__).resolve().parents[1]
FILE = ROOT / "problems" / "cs_min_backlash.toml"
OBJECTIVES = ["ripple", "backlash"]


def passes_after(monkeypatch, n_records: int) -> list:
    """The deadline passes once ``n_records`` records are stored (the on_record list)."""
    seen: list = []
    monkeypatch.setattr(deadline, "passed", lambda: len(seen) >= n_records)
    return seen


def test_a_front_stopped_by_its_time_limit_says_so_and_a_resume_completes_it(tmp_path, monkeypatch):
    problem = od.load(FILE)
    seen = passes_after(monkeypatch, 8)  # the anchors (4 records) and a few points
    front = od.pareto(
        problem, OBJECTIVES, points=12, out=tmp_path, time_limit=60, on_record=seen.append
    )
    n = len(front.points) + len(front.rejected)
    assert 0 < n < 12
    note = f"time limit of 60 s reached: {12 - n} of 12 points not computed"
    assert front.notes and front.notes[0].startswith(note)
    assert f"note      epsilon: {note}" in front.summary()
    assert front.to_dict()["notes"] == front.notes
    monkeypatch.undo()
    resumed = od.pareto(problem, OBJECTIVES, points=12, out=tmp_path, resume=True)
    whole = od.pareto(problem, OBJECTIVES, points=12)
    assert resumed.notes == [] and len(resumed.points) == 12
    # no optimum lost: the same front as an uninterrupted run (one worker)
    assert np.array_equal(resumed.F, whole.F)


def test_a_time_limit_before_the_anchors_is_refused_naming_it(monkeypatch):
    passes_after(monkeypatch, 0)
    with pytest.raises(od.InputError) as caught:
        od.pareto(od.load(FILE), OBJECTIVES, points=6, time_limit=5)
    assert caught.value.field == "time_limit"
    text = str(caught.value)
    assert "5 s passed before the anchors (ripple, backlash) were computed" in text
    assert text.endswith("give more time, or a run with an out folder continues")


def test_time_limit_is_refused_where_no_point_would_watch_it(tmp_path, capsys):
    # the command line's refusal, word for word (below)
    with pytest.raises(od.InputError, match="time_limit: not applied by the nsga2 method"):
        od.pareto(FILE, OBJECTIVES, points=6, method="nsga2", time_limit=5)
    with pytest.raises(od.InputError, match=r"time_limit: 0 is outside \(0, 86400\]"):
        od.pareto(FILE, OBJECTIVES, points=6, time_limit=0)
    argv = ["pareto", str(FILE), "--objectives", "ripple,backlash", "--points", "4"]
    code = main([*argv, "--method", "weighted_sum", "--time-limit", "5", "--out", str(tmp_path)])
    assert code == 2
    err = capsys.readouterr().err
    assert "--time-limit: not applied by the weighted_sum method" in err
    assert not (tmp_path / "front.csv").exists()


def test_pareto_time_limit_on_the_command_line(tmp_path, monkeypatch, capsys):
    # the command line's own runs: the deadline passes once 6 records are stored (counted
    # by the store's lines, as a user's folder shows them)
    out = tmp_path / "front"
    store = out / "epsilon.jsonl"

    def stored() -> int:
        return len(store.read_text().splitlines()) - 1 if store.exists() else 0

    monkeypatch.setattr(deadline, "passed", lambda: stored() >= 6)
    argv = ["pareto", str(FILE), "--objectives", "ripple,backlash", "--points", "10"]
    code = main([*argv, "--time-limit", "30", "--out", str(out), "--no-plot", "--no-progress"])
    text = capsys.readouterr().out
    assert code == 0
    assert "note      epsilon: time limit of 30 s reached:" in text
    assert "of 10 points not computed" in text
    data = json.loads((out / "front.json").read_text())
    assert any("time limit of 30 s reached" in n for f in data["fronts"] for n in f["notes"])
