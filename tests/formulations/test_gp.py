"""Geometric-programming formulation (issue 4): tracer algebra, GP vs exact NLP, diagnosis."""

from __future__ import annotations

import copy
import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from optdesign.errors import ProblemError
from optdesign.formulations.gp import NotGP, Signomial, build_gp, is_gp, to_cvxpy
from optdesign.models.fit_formulas import fit_clearance
from optdesign.problem import load_problem, problem_from_dict
from optdesign.studies.gp import require_gp, solve_gp_problem

ROOT = Path(__file__).resolve().parents[2]
FORK = ROOT / "problems" / "fork_min_backlash.toml"
#: Known exact optimum of fork_min_backlash (Ipopt multistart, confirmed by DE).
FORK_NLP_OPTIMUM = 0.0194989

#: The paper's crank-slider with its linkage fixed: only the lead and the pins are sized.
CS_FIXED = {
    "name": "cs_fixed_linkage",
    "mechanism": "crank_slider",
    "variables": {
        "R": 90,
        "l": 80,
        "n": 50,
        "phi0": 0.0,
        "p": {"lower": 2, "upper": 10},
        "d": {"lower": 4, "upper": 30},
        "i_a": 2,
        "pin_length_ratio": 1.5,
    },
    "requirements": {
        "deflection": {"min": "-30 deg", "max": "30 deg", "points": 61},
        "hinge_moment": "500 N*m",
        "mean_ratio": {"min": 200, "max": 260},
        "nut_travel_max": "110 mm",
        "pin_bearing_pressure_max": "100 MPa",
        "pin_shear_stress_max": "200 MPa",
        "pin_shear_planes": 2,
    },
    "objective": {"minimize": "backlash"},
}


def test_tracer_merges_like_terms_into_a_monomial():
    names = ("R", "d")
    R = Signomial.variable(names, 0, np.array([90.0, 10.0]))
    t = np.tan(np.radians(30.0))
    travel = R * np.tan(np.radians(30.0)) - R * np.tan(np.radians(-30.0))
    assert list(travel.terms) == [(1.0, 0.0)]
    assert travel.terms[(1.0, 0.0)] == pytest.approx(2 * t, rel=1e-14)
    # a difference that does not cancel stays a signomial; abs of it is not DGP
    assert isinstance(abs(R - 50.0), NotGP)
    assert isinstance(np.cos(R), NotGP)
    # abs of a sum of negative terms is its negation (a posynomial), of positive ones itself
    flipped = abs(-2.0 * R - 3.0)
    assert isinstance(flipped, Signomial) and flipped.terms[(1.0, 0.0)] == pytest.approx(2.0)
    assert flipped.terms[(0.0, 0.0)] == pytest.approx(3.0)
    assert abs(2.0 * R) is not None and abs(2.0 * R).terms[(1.0, 0.0)] == pytest.approx(2.0)
    # numpy's roots and powers of a monomial: the exponents and coefficients they give
    d = Signomial.variable(names, 1, np.array([90.0, 10.0]))
    root = np.sqrt(4.0 * R * d**3)
    assert {k: float(v) for k, v in root.terms.items()} == {(0.5, 1.5): 2.0}
    assert float(np.sqrt(4.0 * R).evaluate(np.array([9.0, 1.0]))) == pytest.approx(6.0)
    assert {k: float(v) for k, v in np.negative(2.0 * R).terms.items()} == {(1.0, 0.0): -2.0}
    assert {k: float(v) for k, v in np.square(3.0 * d).terms.items()} == {(0.0, 2.0): 9.0}
    cube_root = np.cbrt(8.0 * d**3)
    assert list(cube_root.terms) == [(0.0, 1.0)]
    assert float(cube_root.terms[(0.0, 1.0)]) == pytest.approx(2.0, rel=1e-15)
    # over the grid: a mean stays a signomial; a max or min is not DGP, and says which
    grid = R * np.array([1.0, 3.0])
    assert {k: float(v) for k, v in grid.mean().terms.items()} == {(1.0, 0.0): 2.0}
    for how in ("max", "min"):
        reduced = getattr(grid, how)()
        assert isinstance(reduced, NotGP) and reduced.reason.startswith(f"{how} over the grid of")
    # terms whose exponents round alike (to 12 digits) are one term, their coefficients
    # summed: x^0.1 x^0.2 (exponent 0.30000000000000004) and x^0.3
    alike = Signomial(names, {(0.1 + 0.2, 0.0): 2.0, (0.3, 0.0): 3.0}, np.array([90.0, 10.0]))
    assert {k: float(v) for k, v in alike.terms.items()} == {(0.3, 0.0): 5.0}
    # a monomial written as the reports show it
    assert (2.0 * R * d**2).describe() == "2*R*d^2"
    # dividing by a sum of terms is not a GP, and says so
    over_sum = 1.0 / (R + 1.0)
    assert isinstance(over_sum, NotGP)
    assert over_sum.reason == f"division by a sum of terms ({over_sum.term}) is not a posynomial"
    # dividing by a term whose coefficient is zero at some grid angle is refused, saying so
    over_zero = 1.0 / (R * np.array([0.0, 1.0]))
    assert isinstance(over_zero, NotGP) and "zero on the grid" in over_zero.reason
    assert isinstance(1.0 / (R * np.array([0.5, 1.0])), Signomial)
    # a product merges the like terms it makes: (R + 1)(R + 1) = R^2 + 2 R + 1
    square = (R + 1.0) * (R + 1.0)
    assert {k: float(v) for k, v in square.terms.items()} == {
        (2.0, 0.0): 1.0,
        (1.0, 0.0): 2.0,
        (0.0, 0.0): 1.0,
    }


def test_integer_powers_of_a_sum_of_terms_are_expanded_from_the_first():
    """(R + 1)^1 is R + 1 and (R + 1)^3 its expansion; a fractional power of a sum is no
    posynomial and says so."""
    names = ("R", "d")
    R = Signomial.variable(names, 0, np.array([90.0, 10.0]))
    first = (R + 1.0) ** 1
    assert isinstance(first, Signomial)
    assert {k: float(v) for k, v in first.terms.items()} == {(1.0, 0.0): 1.0, (0.0, 0.0): 1.0}
    cube = (R + 1.0) ** 3
    assert {k: float(v) for k, v in cube.terms.items()} == {
        (3.0, 0.0): 1.0,
        (2.0, 0.0): 3.0,
        (1.0, 0.0): 3.0,
        (0.0, 0.0): 1.0,
    }
    half = (R + 1.0) ** 0.5
    assert isinstance(half, NotGP) and "not a posynomial" in half.reason


def test_an_objective_the_model_does_not_give_is_named_in_the_gp_diagnosis():
    fork = load_problem(ROOT / "problems" / "fork_min_backlash.toml")
    checks = [c for c in build_gp(fork, "no_such").checks if c.what == "objective"]
    assert [(c.name, c.ok, c.reason) for c in checks] == [
        ("no_such", False, "objective not available for this problem")
    ]
    # a variable whose lower bound is not positive is named as the offending term
    cs = load_problem(ROOT / "problems" / "cs_min_backlash.toml")
    n = next(c for c in build_gp(cs).checks if c.what == "variable" and c.name == "n")
    assert (n.ok, n.term) == (False, "n") and "lower bound 0 mm is not positive" in n.reason


def test_iso286_fit_is_a_posynomial_that_matches_the_numbers():
    names = ("d",)
    D = Signomial.variable(names, 0, np.array([10.0]))
    c = fit_clearance(D, "H7/g6", "max")
    assert all(np.all(np.asarray(v) > 0) for v in c.terms.values())  # posynomial
    for d in (4.0, 10.0, 25.0):
        assert c.evaluate(np.array([d])) == pytest.approx(fit_clearance(d, "H7/g6", "max"))
    assert 1e3 * c.evaluate(np.array([10.0])) == pytest.approx(30.9, abs=0.05)


def test_fork_gp_agrees_with_exact_nlp_and_is_certified():
    problem = load_problem(FORK)
    assert is_gp(problem)
    r = solve_gp_problem(problem, nlp_starts=2)
    assert r.status == "optimal" and r.verified
    # GP (first-order Hertz) vs exact NLP: within 0.1 % (acceptance), here ~0.01 %
    assert abs(r.details.gp.gap_gp_nlp_rel) < 1e-3
    assert r.details.gp.nlp_exact.objective == pytest.approx(FORK_NLP_OPTIMUM, rel=1e-5)
    assert r.objective == pytest.approx(FORK_NLP_OPTIMUM, rel=1e-3)
    # the exact model at the GP design is the exact optimum too (same active set)
    assert r.objectives["backlash"] == pytest.approx(FORK_NLP_OPTIMUM, rel=1e-5)
    cert = r.certificate
    assert cert.lower_bound <= r.objective * (1 + 1e-9)
    assert r.bound == cert.lower_bound
    assert cert.gap_rel < 1e-6
    # nut travel 2 R tan 30 <= 110 is what fixes R
    assert r.design["R"] == pytest.approx(110 / (2 * np.tan(np.radians(30))), rel=1e-6)


def test_the_objectives_gp_rows_keep_the_angle_of_each_grid_row():
    """The fork's worst-case backlash is a max over the grid: one posynomial row per
    angle, pruned to the row that dominates the others, labelled with its angle."""
    gp = build_gp(load_problem(FORK))
    assert [(r.name, r.label) for r in gp.objective_rows] == [("backlash", "phi=+0.0deg")]
    assert gp.n_rows_before_pruning > len(gp.objective_rows)


def test_a_posynomial_constraints_check_counts_its_rows():
    checks = {c.name: c for c in build_gp(load_problem(FORK)).checks if c.what == "constraint"}
    shear = checks["pin_shear_stress"]
    assert shear.ok and re.fullmatch(r"[1-9][0-9]* posynomial rows", shear.reason)


def test_a_catalogue_variable_is_no_gp_variable_and_the_check_says_what_to_use():
    problem = load_problem(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
    check = next(c for c in build_gp(problem).checks if c.what == "variable" and c.name == "p")
    assert not check.ok
    assert check.reason == (
        "takes catalogue values [2, 2.5, 3, 4, 5, 6, 8, 10]; a GP is "
        "continuous (use formulation='catalogue')"
    )


def test_a_requirement_a_fixed_linkage_cannot_meet_is_named_at_its_angles():
    """With the linkage fixed the transmission angle's rows are constants: outside their
    band they are infeasible whatever the lead and pins, each named at its angle."""
    data = copy.deepcopy(CS_FIXED)
    data["requirements"]["transmission_angle"] = {"min": "89 deg", "max": "140 deg"}
    gp = build_gp(problem_from_dict(data))
    assert gp.is_gp  # constants are no obstacle to the form, only to feasibility
    rows = [r for r in gp.infeasible if r.startswith("transmission_angle[")]
    assert rows and rows[0].startswith("transmission_angle[phi=-23.0deg] = 0.0216494")
    assert all("outside [" in r for r in rows)


def test_fixed_linkage_crank_slider_is_a_gp():
    problem = problem_from_dict(copy.deepcopy(CS_FIXED))
    gp = build_gp(problem)
    assert gp.is_gp, gp.explain()
    # 61 grid rows per stress block collapse to the one that dominates
    assert len(gp.rows) < gp.n_rows_before_pruning
    r = solve_gp_problem(problem, nlp_starts=2)
    assert r.status == "optimal"
    assert abs(r.details.gp.gap_gp_nlp_rel) < 1e-3
    assert r.certificate.gap_rel < 1e-6


def test_a_block_without_bounds_is_skipped_and_the_blocks_after_it_still_count(monkeypatch):
    """A plug-in may state rows with no bound (shown, not required): the GP leaves that
    block out and still builds every bounded block after it."""
    problem = problem_from_dict(copy.deepcopy(CS_FIXED))
    plain = build_gp(problem)
    traced = problem.expressions

    def with_a_free_block_first(design, **kwargs):
        ex = traced(design, **kwargs)
        first = ex.constraints[0]
        free = dataclasses.replace(first, name="shown_only", lower=None, upper=None)
        ex.constraints = [free, *ex.constraints]
        return ex

    monkeypatch.setattr(problem, "expressions", with_a_free_block_first)
    gp = build_gp(problem)
    assert gp.is_gp, gp.explain()
    names = [c.name for c in gp.checks if c.what == "constraint"]
    assert "shown_only" not in names
    assert names == [c.name for c in plain.checks if c.what == "constraint"] and len(names) > 2
    assert len(gp.rows) == len(plain.rows)


def test_the_cvxpy_gps_bound_rows_read_as_x_over_upper_and_lower_over_x():
    """to_cvxpy lists each variable's bounds beside the constraints as GP rows
    c exp(A log x) <= 1: x / upper and lower / x, equal to 1 on the bound."""
    gp = build_gp(problem_from_dict(copy.deepcopy(CS_FIXED)))
    _, xs, t, cons = to_cvxpy(gp)
    rows = {(r.name, r.label): r for r, _ in cons if r.name.startswith("bound:")}
    assert all(key[1] == row.kind for key, row in rows.items())  # "upper" / "lower"
    assert len(rows) == 2 * len(gp.names) == 2 * len(xs)
    assert [x.name() for x in xs] == list(gp.names) and t.name() == "t"  # as cvxpy prints
    lo, hi = np.asarray(gp.lower, dtype=float), np.asarray(gp.upper, dtype=float)
    mid = np.sqrt(lo * hi)

    def value(row, x):
        return float(row.c @ np.exp(row.A @ np.log(x)))

    for k, name in enumerate(gp.names):
        up, down = rows[(f"bound:{name}", "upper")], rows[(f"bound:{name}", "lower")]
        at_upper, at_lower = mid.copy(), mid.copy()
        at_upper[k], at_lower[k] = hi[k], lo[k]
        assert value(up, at_upper) == pytest.approx(1.0, rel=1e-12)
        assert value(down, at_lower) == pytest.approx(1.0, rel=1e-12)
        assert value(up, mid) == pytest.approx(mid[k] / hi[k], rel=1e-12)
        assert value(down, mid) == pytest.approx(lo[k] / mid[k], rel=1e-12)


def test_a_ripple_limit_that_depends_on_the_design_is_named_as_no_gp():
    """With a free arm the ratio's spread varies with the design: a ripple limit is then
    a ratio of a difference of posynomials, and the check names the ripple as the term."""
    data = copy.deepcopy(CS_FIXED)
    data["variables"]["R"] = {"lower": 75, "upper": 105}
    data["requirements"]["ripple_max"] = 0.2
    gp = build_gp(problem_from_dict(data))
    (check,) = [c for c in gp.checks if c.name == "ripple_max"]
    assert (check.what, check.ok, check.term) == ("constraint", False, "ripple")
    assert check.reason == (
        "ripple = (max - min)/(max + min) over the grid is a ratio of a difference of posynomials"
    )
    assert not gp.is_gp


def test_a_gp_optimum_on_a_variable_bound_names_that_bounds_multiplier():
    """Pins of at least 20 mm (the optimum's 7.6 mm excluded): the GP ends on the bound,
    and its multipliers name it as the reports do, bound:d[lower]."""
    data = copy.deepcopy(CS_FIXED)
    data["variables"]["d"] = {"lower": 20, "upper": 30}
    result = solve_gp_problem(problem_from_dict(data), nlp_starts=1)
    assert result.status == "optimal"
    assert result.design["d"] == pytest.approx(20.0, rel=1e-6)
    multipliers = result.details.gp.dual.multipliers
    assert multipliers["bound:d[lower]"] > 0.1
    assert not [k for k in multipliers if k.startswith("bound:") and k != "bound:d[lower]"]


def test_a_constraint_the_tracer_cannot_represent_carries_its_reason_and_term():
    """The crank-slider's rows go through cos(phi0 - a): each such constraint's check
    says why it is not a GP and names that sub-term."""
    checks = {
        c.name: c
        for c in build_gp(load_problem(ROOT / "problems" / "cs_min_backlash.toml")).checks
        if c.what == "constraint" and not c.ok
    }
    for name in ("transmission_angle", "pin_shear_stress", "nut_travel"):
        assert re.fullmatch(r"(cos|sin)\(phi0 [-+] 0\.5236\)", checks[name].term)
        assert checks[name].reason == f"{checks[name].term} of a design variable is not a monomial"


def test_diagnosis_names_the_offending_term():
    data = copy.deepcopy(CS_FIXED)
    data["variables"]["R"] = {"lower": 75, "upper": 105}  # free arm: u = R cos a - n
    problem = problem_from_dict(data)
    gp = build_gp(problem)
    assert not gp.is_gp
    bad = {c.name: c for c in gp.failures()}
    # the assembly margin l^2 - (R cos a - n)^2 is a signomial in R; cvxpy agrees
    margin = bad["assembly_margin"]
    assert "signomial" in margin.reason and "R^2" in margin.term
    assert margin.cvxpy_is_dgp is False
    assert "backlash" in bad and "R" in bad["backlash"].term
    with pytest.raises(ProblemError, match=r"assembly_margin.*signomial"):
        require_gp(problem)


def test_cli_gp_on_a_non_gp_problem_names_the_variable(capsys):
    from optdesign.cli import main

    code = main(["solve", str(ROOT / "problems" / "cs_min_backlash.toml"), "--formulation", "gp"])
    err = capsys.readouterr().err
    assert code == 2
    assert "variable phi0" in err and "cos(phi0" in err


def test_auto_picks_gp_for_the_fork_and_nlp_for_the_crank_slider():
    from optdesign.cli import _load_plugins
    from optdesign.studies.formulation_registry import choose_formulation

    _load_plugins()
    assert choose_formulation(load_problem(FORK), "auto") == "gp"
    assert choose_formulation(load_problem(ROOT / "problems/cs_min_backlash.toml"), "auto") == "nlp"


def test_auto_decides_with_the_chosen_objective():
    """The fork is a GP in backlash (worst case) but not in backlash_rss (a power of a
    sum): ``auto`` with ``objective="backlash_rss"`` takes the NLP, where it used to
    pick gp and refuse "not a geometric program"."""

    import optdesign as od
    from optdesign.studies.formulation_registry import choose_formulation

    problem = od.load(FORK)
    assert choose_formulation(problem, "auto") == "gp"
    assert choose_formulation(problem, "auto", "backlash_rss") == "nlp"
    # the library predicate says the same, objective by objective
    assert is_gp(problem) and is_gp(problem, "backlash")
    assert not is_gp(problem, "backlash_rss")
    result = od.solve(problem, "auto", objective="backlash_rss", ranges=False)
    assert result.formulation == "nlp-epigraph" and result.status == "optimal"
    assert result.objective_name == "backlash_rss"
    assert result.objective == pytest.approx(FORK_NLP_OPTIMUM, rel=1e-4)
    # an explicit gp still refuses, naming the objective that breaks DGP form
    with pytest.raises(ProblemError, match="objective backlash_rss: not DGP"):
        od.solve(problem, "gp", objective="backlash_rss")


def test_auto_decides_with_the_chosen_objective_on_the_command_line(tmp_path, capsys):
    import json

    from optdesign.cli import main

    args = ["solve", str(FORK), "--objective", "backlash_rss", "--no-ranges"]
    assert main([*args, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["formulation"] == "nlp-epigraph" and doc["status"] == "optimal"
    assert doc["objective"]["name"] == "backlash_rss"
    assert doc["objective"]["value"] == pytest.approx(FORK_NLP_OPTIMUM, rel=1e-4)
    assert main([*args, "--out", str(tmp_path / "out")]) == 0
    text = capsys.readouterr().out
    assert "nlp-epigraph" in text
    assert re.search(r"objective +backlash_rss = 0\.019498", text)


def test_a_bound_that_puts_a_sum_of_terms_above_a_constant_is_named_with_its_side():
    """posynomial >= constant is not DGP: a lower bound on p + d, or an upper bound on
    -(p + d), each named with its side and the terms."""
    lower = problem_from_dict(copy.deepcopy(CS_FIXED))
    lower.add_constraint(
        "p_plus_d", lambda q: q.design["p"] + q.design["d"], lower="20 mm", unit="mm"
    )
    upper = problem_from_dict(copy.deepcopy(CS_FIXED))
    upper.add_constraint(
        "p_plus_d", lambda q: -q.design["p"] - q.design["d"], upper="-20 mm", unit="mm"
    )
    reasons = [[c.reason for c in build_gp(p).checks if not c.ok] for p in (lower, upper)]
    assert reasons == [
        ["p_plus_d: a lower bound 20 on a sum of terms (p + d); posynomial >= constant is not DGP"],
        [
            "p_plus_d: an upper bound -20 on a sum of terms (-p - d); posynomial >= constant "
            "is not DGP"
        ],
    ]
