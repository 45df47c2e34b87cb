"""Tests written from the fifth mutation sample's survivors (issue 21, mutmut, SEED=24)
in studies/pareto, storage, units and reports.

Each test names the behaviour it pins, not the mutant it was written from (the mutants
and their verdicts go to the fifth sample's table in docs/testing.md). Every test was
checked to fail on its mutant (``MUTANT_UNDER_TEST=<name> pytest`` in a copy of the
run's ``mutants/``) and to pass on the code.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import optdesign as od
from optdesign.studies.pareto.front import FrontPoint, make_front

ROOT = Path(__file__).resolve().parents[1]


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


# --- the front's plot ---------------------------------------------------------------------
def test_a_fronts_plot_on_a_given_axes_draws_there_without_sketches(cs_min_backlash):
    """``front.plot(ax=...)`` draws the objective space on the caller's axes and returns
    the caller's figure, with no sketch axes added."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    front = _front_of_midpoints(cs_min_backlash)
    fig, ax = plt.subplots()
    try:
        assert front.plot(ax=ax) is fig
        assert fig.axes == [ax]
        x, y = ax.lines[0].get_data()
        assert list(y) == pytest.approx([30.0, 20.0])
        assert len(x) == 2
    finally:
        plt.close("all")


# --- the front's back-ends ----------------------------------------------------------------
def test_an_ipopt_front_warm_starts_its_sweep_solves(cs_min_backlash):
    """With Ipopt throughout (``solver="ipopt"``) the sweep's solves are warm-started
    (primal and dual, a small barrier); the plain fallback is not."""
    from optdesign.studies.pareto.eps_solver import EpsSolver

    eps = EpsSolver(cs_min_backlash, ["backlash", "size"], "ipopt")
    assert not eps.has_fallback
    for use in ("primary", "warm"):
        options = eps.backend(use).options["ipopt"]
        assert options["warm_start_init_point"] == "yes"
        assert options["mu_init"] == 1e-6
    assert "warm_start_init_point" not in eps.backend("fallback").options["ipopt"]


# --- the front's objectives ---------------------------------------------------------------
def test_a_library_front_of_a_repeated_objective_is_refused_naming_the_field(cs_min_backlash):
    """``compute_front`` (below the API's own check) refuses an objective given twice,
    naming the field and the list, before any solve."""
    from optdesign.errors import InputError
    from optdesign.studies.pareto import compute_front

    with pytest.raises(InputError) as caught:
        compute_front(cs_min_backlash, ["backlash", "backlash"], 3)
    assert caught.value.field == "objectives"
    assert str(caught.value) == "objectives: repeated objective in ['backlash', 'backlash']"
