"""Tests for one-line bugs seeded by hand outside the mutated modules (issue 21, class 11).

Each bug below was planted in the code and went unnoticed by the fast suite; each test
here fails with it. The expected values come from geometry redone in the test (plain
NumPy, bisection, finite differences), from the catalogue's own CSV read with the csv
module, or from numbers written out by hand - never from the function under test.

- the screw/nut joint taking joint A's clearance (any mechanism, A != B);
- the pivoting screw's dead length computed over the first grid step, not the stroke;
- the relaxation's violation measured with min instead of max;
- the catalogue search pruning with a tolerance of 1e-2 instead of 1e-6;
- the catalogue relaxation taking the least favourable item values;
- an upper constraint bound left unscaled.
"""

from __future__ import annotations

import csv
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from test_physics_independent import cs_loop  # the crank-slider loop solved by bisection

import optdesign as od

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"

#: Fixed clearances, all different, so that a joint reading another's value shows.
CLEARANCES = {"A": "0.011 mm", "B": "0.037 mm", "C": "0.023 mm", "O": "0.0013 deg"}


def _problem(stem: str, **sections) -> od.DesignProblem:
    data = tomllib.loads((PROBLEMS / f"{stem}.toml").read_text())
    data.update(sections)
    return od.load(data)


def _fd(f, x: float, h: float = 1e-6) -> float:
    return (f(x + h) - f(x - h)) / (2 * h)


# --- the clearance chain: each fixed clearance reaches its own joint -----------------------
def _crank_slider_nut(d):
    return lambda phi: cs_loop(phi, d["R"], d["l"], d["n"], d["phi0"])[1][0]


def _fork_nut(d):
    # the pin on the line y = R at angle phi0 + phi from the normal: x = R tan(phi0 + phi)
    return lambda phi: d["R"] * math.tan(d["phi0"] + phi)


def _pivot_nut(d):
    def length(phi):
        a = d["phi0"] + phi
        return math.hypot(d["R"] * math.sin(a) - d["a_T"], d["R"] * math.cos(a) - d["b_T"])

    return length


@pytest.mark.parametrize(
    ("stem", "nut", "design"),
    [
        ("cs_min_backlash", _crank_slider_nut, {"R": 90.0, "l": 80.0, "n": 50.0, "phi0": 0.2}),
        ("fork_min_backlash", _fork_nut, {"R": 70.0, "phi0": 0.0}),
        ("pivot_min_backlash", _pivot_nut, {"R": 90.0, "a_T": -220.0, "b_T": 40.0, "phi0": 0.1}),
    ],
)
def test_each_fixed_clearance_reaches_its_own_joint(stem, nut, design):
    problem = _problem(stem)
    keys = set(problem.mechanism.fixed_clearances)
    problem = _problem(stem, clearances={k: CLEARANCES[k] for k in keys})
    x = problem.midpoint()
    values = problem.design_dict(x)
    values.update({k: v for k, v in design.items() if k in values})
    q = problem.quantities(values)
    per_joint = q.backlash.per_joint
    k_grid = [0, 17, len(problem.phi) - 1]
    f = nut({**{"phi0": 0.0}, **design})
    for k in k_grid:
        phi = float(problem.phi[k])
        s_axial = 1.0 / abs(_fd(f, phi))  # rad/mm: output rotation per axial clearance
        for name, key in (("A screw bearings", "A"), ("B screw/nut", "B")):
            mm = float(CLEARANCES[key].split()[0])
            assert float(np.ravel(per_joint[name])[k]) == pytest.approx(
                math.degrees(s_axial * mm), rel=1e-6
            ), (name, phi)
        assert float(np.ravel(per_joint["O output shaft"])[k]) == pytest.approx(0.0013, rel=1e-12)
    if "C" in keys:  # the crank-slider's nut slide: move the screw's line by dn
        d = design

        def phi_at(n_shift, m_target, guess):
            from scipy.optimize import brentq

            def g(phi):
                return cs_loop(phi, d["R"], d["l"], d["n"] + n_shift, d["phi0"])[1][0] - m_target

            return brentq(g, guess - 0.05, guess + 0.05, xtol=1e-14)

        for k in k_grid:
            phi = float(problem.phi[k])
            m0 = f(phi)
            h = 1e-4
            s_lat = abs(phi_at(h, m0, phi) - phi_at(-h, m0, phi)) / (2 * h)
            assert float(np.ravel(per_joint["C nut slide"])[k]) == pytest.approx(
                math.degrees(s_lat * 0.023), rel=1e-5
            )


# --- the pivoting screw's dead length ------------------------------------------------------
def test_pivot_dead_length_is_length_minus_the_whole_stroke():
    problem = _problem("pivot_min_backlash")
    d = {"R": 90.0, "a_T": -220.0, "b_T": 40.0, "phi0": 0.1}
    values = problem.design_dict(problem.midpoint())
    values.update(d)
    ex = problem.expressions(values)
    block = next(b for b in ex.constraints if b.name == "dead_length")
    L = _pivot_nut(d)
    lengths = np.array([L(float(phi)) for phi in problem.phi])
    stroke = L(math.radians(30.0)) - L(math.radians(-30.0))
    assert stroke == pytest.approx(lengths[-1] - lengths[0], rel=1e-12)
    assert stroke > 5.0  # far from one grid step's travel (about stroke / 60)
    np.testing.assert_allclose(np.ravel(block.expr), lengths - stroke, rtol=1e-12)
    assert block.lower == pytest.approx(60.0) and block.upper is None


# --- the relaxation's measure of a violation ----------------------------------------------
def test_relaxation_need_is_the_worst_point_of_the_row():
    from types import SimpleNamespace

    from optdesign.studies.relaxation import _need

    g = np.array([3.0, 7.5, 5.0, 1.0])
    upper = SimpleNamespace(upper=4.0, lower=None)
    lower = SimpleNamespace(upper=None, lower=2.5)
    assert _need(g, upper, hi_side=True) == pytest.approx(3.5)  # 7.5 - 4
    assert _need(g, lower, hi_side=False) == pytest.approx(1.5)  # 2.5 - 1
    assert _need(np.array([1.0, 2.0]), upper, hi_side=True) == 0.0
    assert _need(np.array([3.0, 4.0]), lower, hi_side=False) == 0.0


def test_a_relaxation_site_starts_from_the_design_clipped_into_its_box_only():
    """At a site (catalogue items held in a sub-box) the solves start from the given
    design with the held variables clipped into the box and the others unchanged."""
    from optdesign.formulations.nlp import build_nlp
    from optdesign.studies.relaxation import Site, _Prepared

    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    nlp = build_nlp(problem)
    names = [v.name for v in problem.free]
    x = 0.5 * (problem.lower() + problem.upper())
    held = (problem.upper()[names.index("R")] - 1.0, problem.upper()[names.index("R")])
    site = _Prepared(problem, nlp, Site(box={"R": held}, x_start=x))
    start = nlp.x_from_z(site.starts[-1].z0)
    expected = x.copy()
    expected[names.index("R")] = held[0]
    np.testing.assert_allclose(start, expected, rtol=1e-12)


# --- branch and bound: what may be pruned --------------------------------------------------
def test_prune_tolerance_is_relative_one_in_a_million():
    from optdesign.studies.catalogue import PRUNE_TOL, cannot_improve

    assert PRUNE_TOL == pytest.approx(1e-6)
    incumbent = 2.0
    # a node whose bound is 0.1 % below the incumbent can still hold a better item
    assert not cannot_improve(incumbent * (1 - 1e-3), incumbent)
    assert not cannot_improve(incumbent * (1 - 1e-5), incumbent)
    assert cannot_improve(incumbent * (1 - 1e-7), incumbent)
    assert cannot_improve(incumbent * 1.01, incumbent)
    # negative objectives: the tolerance is relative to the magnitude
    assert not cannot_improve(-2.0 * (1 + 1e-4), -2.0)
    assert cannot_improve(-2.0 * (1 + 1e-7), -2.0)


# --- the catalogue relaxation takes the most favourable items of a box ---------------------
def _strongest_nuts() -> dict[tuple[float, float], dict[str, float]]:
    """(d0, p) -> the strongest nut of the catalogue's CSV (highest Ca, then C0a, then
    rigidity), read with the csv module; rigidity converted from N/um to N/mm."""
    path = ROOT / "optdesign" / "data" / "ball_screws.csv"
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(line for line in fh if not line.startswith("#")))
    best: dict[tuple[float, float], dict[str, float]] = {}
    for r in rows:
        item = {
            "d1": float(r["d1"]),
            "Ca": float(r["Ca"]),
            "C0a": float(r["C0a"]),
            "K_nut": 1000.0 * float(r["rigidity_N_per_um"]),
        }
        key = (float(r["d0"]), float(r["p"]))
        old = best.get(key)
        rank = (item["Ca"], item["C0a"], item["K_nut"])
        if old is None or rank > (old["Ca"], old["C0a"], old["K_nut"]):
            best[key] = item
    return best


def test_catalogue_relaxation_takes_the_most_favourable_items_of_the_box():
    problem = od.load(PROBLEMS / "fin_actuator.toml")
    box = {"d0": (16.0, 20.0), "p": (2.0, 5.0)}
    values = problem.parameter_values(box)
    items = [v for (d0, p), v in _strongest_nuts().items() if 16 <= d0 <= 20 and 2 <= p <= 5]
    assert len(items) >= 3  # several items: the choice of the value matters
    for key in ("d1", "Ca", "C0a", "K_nut"):
        column = [item[key] for item in items]
        assert max(column) > min(column), key
        assert values[f"screw_{key}"] == pytest.approx(max(column), rel=1e-12), key
    # a box holding one item gives that item's own values
    one = problem.parameter_values({"d0": (20.0, 20.0), "p": (5.0, 5.0)})
    item = _strongest_nuts()[(20.0, 5.0)]
    for key in ("d1", "Ca", "C0a", "K_nut"):
        assert one[f"screw_{key}"] == pytest.approx(item[key], rel=1e-12), key
    # the table-fit ratio of the pins: the smallest of the box's items (the smaller
    # clearance is the favourable one for a backlash bound)
    from optdesign.fits import clearance

    box_d = {"d": (5.0, 8.0)}
    pins = [v for v in problem.by_name["d"].values if 5.0 <= v <= 8.0]
    assert len(pins) >= 2
    fit = problem.spec.requirements.fit
    for which in ("max", "min"):
        ratios = [
            float(clearance(fit, D, which, values="table"))
            / float(clearance(fit, D, which, values="smooth"))
            for D in pins
        ]
        assert max(ratios) > min(ratios)
        got = problem.parameter_values(box_d)[f"fit_ratio_{which}"]
        assert got == pytest.approx(min(ratios), rel=1e-12), which


# --- NLP rows: both bounds scaled by the row's divisor -------------------------------------
def test_nlp_rows_are_scaled_on_both_sides():
    from optdesign.studies.nlp_solve import formulation_for

    problem = od.load(PROBLEMS / "cs_min_backlash.toml")
    nlp = formulation_for(problem)
    names = list(nlp.g_names)
    # requirements of the file, in internal units (mm, MPa, dimensionless)
    limits = {
        "nut_travel": (None, 110.0),
        "pin_bearing_pressure": (None, 100.0),
        "pin_shear_stress": (None, 200.0),
        "mean_ratio": (200.0, 260.0),
    }
    seen = set()
    for k, name in enumerate(names):
        base = name.split("[")[0]
        if base not in limits:
            continue
        seen.add(base)
        lo, hi = limits[base]
        scale = float(nlp.g_scale[k])
        assert scale > 1.0, name  # a divisor that is not 1: an unscaled bound would show
        if hi is not None:
            assert float(nlp.ubg[k]) * scale == pytest.approx(hi, rel=1e-12), name
        if lo is not None:
            assert float(nlp.lbg[k]) * scale == pytest.approx(lo, rel=1e-12), name
    assert seen == set(limits)
