"""The mechanisms' closed-form bounds of the nut velocity (``Mechanism.
nut_velocity_bounds``) against designs: the nut velocity of every working design, by a
central difference of its nut position (not the mechanism's own velocity), lies inside
the bounds computed from its own values and requirements; and the proofs the problem
draws from them (a ratio band out of reach, a static safety no catalogue screw gives)
refuse the corpus's impossible files before any solve and never a design's own ratio."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import optdesign as od
from optdesign.mechanisms import CrankSlider, ShiftingFork
from optdesign.mechanisms.pivoting_screw import PivotingScrew
from optdesign.problem.necessary import impossibilities

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"
DEG = np.pi / 180
STEP = 1e-6


def _difference(mech, phi):
    """dx/dphi by a central difference of the nut position (rad steps of 1e-6)."""
    with np.errstate(invalid="ignore"):
        ahead = np.asarray(mech.nut_position(phi + STEP), dtype=float)
        behind = np.asarray(mech.nut_position(phi - STEP), dtype=float)
    return (ahead - behind) / (2 * STEP)


def _own(value):
    return (value, value)


@settings(max_examples=300, deadline=None)
@given(
    st.floats(20, 150),
    st.floats(20, 300),
    st.floats(-150, 150),
    st.floats(-1.5, 1.5),
    st.floats(-1.5, 0.5),
    st.floats(0.05, 1.5),
)
def test_a_crank_sliders_nut_velocity_stays_under_its_bound(R, l, n, phi0, start, span):
    """Under its own rod inclination and assembly margin, and with R's upper bound above
    its own, every working crank-slider's nut velocity is at most R / cos(beta)."""
    phi = np.linspace(start, start + span, 121)
    mech = CrankSlider(R=R, l=l, n=n, phi0=phi0, p=5.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.asarray(mech.ratio(phi), dtype=float)
        beta = np.abs(np.asarray(mech.rod_inclination(phi), dtype=float))
    assume(np.all(np.isfinite(ratio)) and np.all(ratio > 0) and beta.max() < 80 * DEG)
    v = _difference(mech, phi)
    margin = float(np.min(np.cos(beta) ** 2))
    for req in ({"rod_inclination_max": beta.max()}, {"assembly_margin_min": margin}):
        bound = CrankSlider.nut_velocity_bounds((phi[0], phi[-1]), req, {"R": (R / 2, R)})
        assert bound.lower == 0.0
        assert np.all(v <= bound.upper * (1 + 1e-6)), (req, v.max(), bound.upper)


def test_a_crank_sliders_bound_is_reached():
    """The bound is tight: with the rod at its 30 deg limit and the arm at -30 deg (R 100,
    l 100, n = 100 cos 30 deg - 50), v = R / cos 30 deg = 115.47 mm/rad."""
    mech = CrankSlider(R=100.0, l=100.0, n=100 * np.cos(30 * DEG) - 50, phi0=-30 * DEG, p=5.0)
    v = float(_difference(mech, np.array(0.0)))
    bound = CrankSlider.nut_velocity_bounds(
        (0.0, 0.1), {"rod_inclination_max": 30 * DEG}, {"R": _own(100.0)}
    )
    assert v == pytest.approx(115.4700538, rel=1e-6) and bound.upper == pytest.approx(v, rel=1e-6)


@settings(max_examples=200, deadline=None)
@given(st.floats(10, 150), st.floats(-1.2, 1.2), st.floats(-0.6, 0.0), st.floats(0.05, 0.6))
def test_a_forks_nut_velocity_lies_between_its_bounds(R, phi0, start, span):
    phi = np.linspace(start, start + span, 121)
    assume(np.all(np.abs(phi0 + phi) < 85 * DEG))
    mech = ShiftingFork(R=R, phi0=phi0, p=5.0)
    v = _difference(mech, phi)
    bound = ShiftingFork.nut_velocity_bounds(
        (phi[0], phi[-1]), {}, {"R": (R * 0.9, R * 1.1), "phi0": (phi0 - 0.01, phi0 + 0.01)}
    )
    assert np.all(v >= bound.lower * (1 - 1e-6)) and np.all(v <= bound.upper * (1 + 1e-6))


@settings(max_examples=300, deadline=None)
@given(
    st.floats(20, 150),
    st.floats(-300, 300),
    st.floats(-300, 300),
    st.floats(-1.5, 1.5),
    st.floats(-1.5, 0.5),
    st.floats(0.05, 1.5),
)
def test_a_pivoting_screws_lever_never_exceeds_its_horn(R, a_T, b_T, phi0, start, span):
    phi = np.linspace(start, start + span, 121)
    mech = PivotingScrew(R=R, a_T=a_T, b_T=b_T, phi0=phi0, p=5.0)
    v = _difference(mech, phi)
    assume(np.all(np.isfinite(v)))
    bound = PivotingScrew.nut_velocity_bounds((phi[0], phi[-1]), {}, {"R": _own(R)})
    assert np.all(np.abs(v) <= bound.upper * (1 + 1e-6))


def _problem(name: str, **requirements):
    data = tomllib.loads((PROBLEMS / f"{name}.toml").read_text())
    data["requirements"].update(requirements)
    return od.load(data)


def test_a_ratio_band_beyond_the_bounds_is_proved_out_of_reach():
    """cs_min_backlash's ratio is at most 2 pi x 2 x (120 / cos 30 deg) / 2 = 870.6 (i_a 2,
    R <= 120 mm, p >= 2 mm): a band from 1500 is refused, and one from 870 is not."""
    (proof,) = impossibilities(_problem("cs_min_backlash", mean_ratio={"min": 1500, "max": 1510}))
    assert proof.requirements[0] == "mean_ratio"
    assert "= 870.6 at every angle" in proof.reason
    assert proof.remedies[0] == "mean_ratio.min of at most 870.6"
    assert impossibilities(_problem("cs_min_backlash", mean_ratio={"min": 870, "max": 900})) == []
    (pivot,) = impossibilities(_problem("pivot_min_backlash", mean_ratio={"min": 1500}))
    assert "= 754 at every angle" in pivot.reason


def test_a_ratio_band_the_fork_cannot_go_below_is_proved():
    """The fork's ratio is at least 2 pi i_a R_min / p_max = 2 pi x 2 x 30 / 10 = 37.7 at
    every angle (fork_min_backlash's bounds): a band below it is refused."""
    (proof,) = impossibilities(_problem("fork_min_backlash", mean_ratio={"min": 10, "max": 30}))
    assert "at least 2 pi x 2 x 30 / 10 = 37.7 at every angle" in proof.reason
    assert proof.remedies[0] == "mean_ratio.max of at least 37.7"
    assert impossibilities(_problem("fork_min_backlash", mean_ratio={"min": 10, "max": 38})) == []


def test_a_static_safety_no_catalogue_screw_gives_is_proved():
    """fin_actuator at 50 kN*m: the nut force is at least 5e7 / 138.6 = 3.608e5 N, and 1.5
    times it exceeds the largest C0a of its HIWIN range (56.6 kN)."""
    (proof,) = impossibilities(_problem("fin_actuator", hinge_moment="50000 N*m"))
    assert proof.requirements[:2] == ("hinge_moment", "static_safety_min")
    assert "= 3.608e+05 N at every angle" in proof.reason and "5.66e+04 N" in proof.reason
    assert impossibilities(_problem("fin_actuator", hinge_moment="5000 N*m")) == []


def test_a_solve_of_a_band_out_of_reach_runs_no_search():
    result = od.solve(_problem("cs_min_ripple", mean_ratio={"min": 1500, "max": 1510}))
    assert result.status == "infeasible" and result.solver == "none"
    assert "mean_ratio" in result.diagnosis.impossible[0].requirements


@pytest.mark.parametrize("name", ["cs_min_backlash", "fork_min_backlash", "pivot_min_backlash"])
def test_a_shipped_optimums_own_ratio_band_is_never_refused(name):
    """A band exactly at a design's own mean ratio, with the bounds of its file: the
    design meets it, so no proof may refuse it (the bounds are an upper and a lower one)."""
    problem = _problem(name)
    x = problem.start()
    with np.errstate(all="ignore"):
        ratio = np.asarray(problem.quantities(problem.design_dict(x)).ratio, dtype=float)
    assume_working = np.all(np.isfinite(ratio)) and np.all(ratio > 0)
    assert assume_working
    mean = float(np.mean(ratio))
    assert impossibilities(_problem(name, mean_ratio={"min": mean, "max": mean})) == []
