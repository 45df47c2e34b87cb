"""A catalogue front's points seeded by what the searches before them learnt (first
incumbents, proofs, node bounds and starts: catalogue_knowledge.py, node_bounds.py) give
the front an unseeded run gives, with fewer NLP solves; a front killed on the way resumes
to it in a process that never saw its searches."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

import optdesign as od
from optdesign.formulations.catalogue import bnb as catalogue_bnb
from optdesign.formulations.catalogue import search
from optdesign.formulations.catalogue.bnb import InfeasibleBoxes
from optdesign.formulations.catalogue.discrete import discrete_variables
from optdesign.formulations.catalogue.node_bounds import NodeBounds
from optdesign.problem import problem_from_dict
from optdesign.studies.pareto import catalogue_front

ROOT = Path(__file__).resolve().parents[3]
OBJECTIVES = ["backlash", "motor_torque"]


@pytest.fixture(scope="module")
def small():
    """cs_min_backlash_catalogue cut to 2 leads x 3 pins on a 7-point grid."""
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "6 mm", "8 mm"]}
    data["requirements"]["deflection"]["points"] = 7
    return problem_from_dict(data)


def _branch_and_bound(mp: pytest.MonkeyPatch) -> None:
    """The branch and bound on a catalogue small enough to enumerate, and no memo left
    by another test of this process."""
    mp.setattr(search, "ENUMERATE_MAX", 1)
    mp.setattr(catalogue_bnb, "_MEMOS", {})


def _front(problem, out: Path, **kw):
    return od.pareto(problem, OBJECTIVES, points=3, starts=1, out=out, workers=1, files=False, **kw)


@pytest.fixture(scope="module")
def seeded(small, tmp_path_factory):
    """The front as it runs (one worker: the points chained and seeded)."""
    with pytest.MonkeyPatch.context() as mp:
        _branch_and_bound(mp)
        return _front(small, tmp_path_factory.mktemp("seeded"))


def _points(front):
    frame = front.to_frame()
    cols = [c for c in frame.columns if c.split(" ")[0] in (*OBJECTIVES, "p", "d")]
    return frame[cols].to_dict(orient="records")


def _same_front(a, b) -> None:
    pa, pb = _points(a), _points(b)
    assert len(pa) == len(pb) == 3
    for x, y in zip(pa, pb, strict=True):
        assert x == pytest.approx(y, rel=1e-6)


def test_a_seeded_catalogue_front_equals_an_unseeded_one_with_fewer_solves(
    small, seeded, monkeypatch, tmp_path
):
    _branch_and_bound(monkeypatch)
    # no first incumbents, no memo: every search on its own
    monkeypatch.setattr(
        catalogue_front, "front_knowledge", lambda task, deps: {"incumbents": [], "memo": None}
    )
    bare = _front(small, tmp_path)
    _same_front(seeded, bare)
    assert seeded.n_solves < bare.n_solves


def test_a_killed_catalogue_front_resumes_to_the_whole_front(small, seeded, monkeypatch, tmp_path):
    _branch_and_bound(monkeypatch)
    seen: list[str] = []

    def kill(rec) -> None:
        seen.append(rec["id"] if isinstance(rec, dict) else rec.id)
        if len(seen) == 5:  # the two anchors (two stages each) and the loosest point
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _front(small, tmp_path, on_record=kill)
    catalogue_bnb._MEMOS.clear()  # a new process: none of the killed run's knowledge
    resumed = _front(small, tmp_path, resume=True)
    _same_front(resumed, seeded)


def test_searches_under_tightening_limits_bounded_by_the_nodes_before_them_solve_less(small):
    """The searches of a front's points, loosest limit first, sharing a memo of proofs:
    with the node bounds and starts of the searches before (NodeBounds) each limit's
    optimum is the same combination and value, for fewer NLP solves in all."""
    dvars = discrete_variables(small)
    full = {v.name: (v.lower, v.upper) for v in dvars}
    items = {v.name: v.values for v in dvars}
    found, solves = {}, {}
    for with_nodes in (True, False):
        memo = InfeasibleBoxes(full, items)
        memo.nodes = NodeBounds(full) if with_nodes else None
        found[with_nodes], solves[with_nodes] = [], 0
        for limit in (0.05, 0.04, 0.037, 0.035):  # backlash limits, deg
            r = search.solve_catalogue(
                small,
                method="bnb",
                starts=2,
                seed=1,
                objective="motor_torque",
                eps={"backlash": limit},
                memo=memo,
            )
            assert r.success
            found[with_nodes].append((r.objective, r.details.catalogue.items))
            solves[with_nodes] += r.details.catalogue.nlp_solves
    for (value, chosen), (alone, chosen_alone) in zip(found[True], found[False], strict=True):
        assert chosen == chosen_alone
        assert value == pytest.approx(alone, rel=1e-9)
    assert solves[True] < solves[False]
