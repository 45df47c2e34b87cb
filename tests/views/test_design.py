"""optdesign.views.design: what a page shows of a design, evaluated into one record."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.mechanisms.base import Sketch
from optdesign.solvers.constraint_rows import constraint_rows
from optdesign.views.design import DesignView, design_rows, design_view
from optdesign.views.sketches import stroke_angles

PROBLEM = Path(__file__).resolve().parents[2] / "problems" / "cs_min_ripple.toml"


@pytest.fixture(scope="module")
def problem():
    return od.load(PROBLEM)


def _counted(monkeypatch, problem, name):
    calls = []
    method = getattr(problem, name)

    def counting(*args, **kw):
        calls.append(name)
        return method(*args, **kw)

    monkeypatch.setattr(problem, name, counting)
    return calls


def test_a_design_view_evaluates_the_problem_once_and_its_quantities_once(problem, monkeypatch):
    start = problem.design_dict(problem.start())
    ev = problem.evaluate(np.array([start[v.name] for v in problem.free]))
    evaluations = []
    # the evaluation's own quantities are not the view's: it is answered from ``ev``
    monkeypatch.setattr(problem, "evaluate", lambda x: evaluations.append(x) or ev)
    quantities = _counted(monkeypatch, problem, "quantities")
    view = design_view(problem, start)
    assert isinstance(view, DesignView)
    assert (len(evaluations), len(quantities)) == (1, 1)


def test_a_design_view_holds_the_designs_objectives_rows_curves_frames_and_facts(problem):
    start = problem.design_dict(problem.start())
    view = design_view(problem, start)
    ev = problem.evaluate(np.array([start[v.name] for v in problem.free]))
    assert dict(view.objectives) == {k: float(v) for k, v in ev.objectives.items()}
    active, violated = constraint_rows(problem, start)
    assert view.rows == design_rows(problem, start)
    assert (list(view.rows.active), list(view.rows.violated)) == (active, violated)
    assert view.curves.ratio.shape == np.shape(problem.phi)
    assert (view.curves.backlash is None) == (not problem.has("d"))
    # sketched at the stroke's ends and middle
    assert tuple(f.phi for f in view.frames) == stroke_angles(problem)
    assert stroke_angles(problem)[0] == pytest.approx(float(problem.phi[0]))
    assert all(isinstance(f.sketch, Sketch) for f in view.frames)
    facts = view.facts
    assert facts.ratio_min <= facts.mean_ratio <= facts.ratio_max
    assert facts.ratio_min == pytest.approx(float(np.min(view.curves.ratio)))
    assert 0.0 < facts.drive_efficiency <= 1.0


def test_a_design_view_is_a_frozen_record(problem):
    view = design_view(problem, problem.design_dict(problem.start()))
    with pytest.raises(AttributeError):
        view.facts = None
