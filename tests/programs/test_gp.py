"""Geometric-programming formulation (issue 4): tracer algebra, GP vs exact NLP, diagnosis."""

from __future__ import annotations

import copy
import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.errors import ProblemError
from optdesign.formulations.gp.solve import require_gp, solve_gp_problem
from optdesign.models.fit_formulas import fit_clearance
from optdesign.problem import load_problem, problem_from_dict
from optdesign.programs import gp as gpmod
from optdesign.programs.gp import (
    DGPCheck,
    GPData,
    GPRow,
    NotGP,
    Signomial,
    _as_row,
    _classify_block,
    _constant_spread,
    _cvxpy_flag,
    _fmt_row,
    _prune,
    _rows_of,
    build_gp,
    is_gp,
    to_cvxpy,
)
from programs.test_signomial import _terms, _vars

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
    from optdesign.formulations.registry import choose_formulation

    _load_plugins()
    assert choose_formulation(load_problem(FORK), "auto") == "gp"
    assert choose_formulation(load_problem(ROOT / "problems/cs_min_backlash.toml"), "auto") == "nlp"


def test_auto_decides_with_the_chosen_objective():
    """The fork is a GP in backlash (worst case) but not in backlash_rss (a power of a
    sum): ``auto`` with ``objective="backlash_rss"`` takes the NLP, where it used to
    pick gp and refuse "not a geometric program"."""

    from optdesign.formulations.registry import choose_formulation

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


# The GP builder's observable behaviour, pinned case by case.
#
# Issue 21 (mutation deliverable): every value, name and message that
# :mod:`optdesign.programs.gp` produces - each branch of a row's classification, the
# pruning, the diagnosis, the fork's rows, the cvxpy problem - against hand computations or
# the NumPy model. The signomial tracer is pinned in ``test_signomial.py``.


def _row(terms: dict, name: str = "blk") -> GPRow:
    return GPRow(name, "", np.array(list(terms), dtype=float), np.array(list(terms.values())))


# --------------------------------------------------------------------------------------
# gp.py: one block's classification
# --------------------------------------------------------------------------------------
def _classify(expr, lower, upper, labels=("a", "b"), unit="mm"):
    return _classify_block("blk", expr, lower, upper, list(labels), unit, ["R", "d"], 2)


# --------------------------------------------------------------------------------------
# gp.py: the fork's GP against the NumPy model
# --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def fork():
    return load_problem(FORK)


def _posy(row: GPRow, x: np.ndarray) -> float:
    return float(row.c @ np.exp(row.A @ np.log(x)))


def _designs(problem, n=4, seed=3):
    rng = np.random.default_rng(seed)
    lo, hi = problem.lower(), problem.upper()
    return [lo + (hi - lo) * rng.random(lo.size) for _ in range(n)]


def _cs_fixed():

    return problem_from_dict(copy.deepcopy(CS_FIXED))


# --------------------------------------------------------------------------------------
# gp.py: the diagnosis records
# --------------------------------------------------------------------------------------
def test_a_checks_describe_line_for_each_verdict():
    """The one line per item that explain() and the refusals show."""
    assert DGPCheck("constraint", "x", True).describe() == "constraint x: DGP"
    ok = DGPCheck("constraint", "x", True, "2 posynomial rows")
    assert ok.describe() == "constraint x: DGP (2 posynomial rows)"
    bad = DGPCheck("objective", "b", False, "why", "t", False)
    assert bad.describe() == "objective b: not DGP: why [offending term: t] [cvxpy is_dgp(): False]"
    assert DGPCheck("objective", "b", False, "why").describe() == "objective b: not DGP: why"
    flag = DGPCheck("variable", "p", False, "why", "", True)
    assert flag.describe() == "variable p: not DGP: why [cvxpy is_dgp(): True]"


def test_explain_lists_only_the_failures_one_per_line():
    """is_gp is all checks DGP; explain() joins the failures' lines, empty for a GP."""
    good = DGPCheck("constraint", "a", True, "1 posynomial rows")
    bad1 = DGPCheck("constraint", "b", False, "r1")
    bad2 = DGPCheck("objective", "c", False, "r2", "t")
    gp = GPData(["x"], np.ones(1), np.ones(1), "c", "", [], [], [good, bad1, bad2])
    assert not gp.is_gp and gp.failures() == [bad1, bad2]
    assert gp.explain() == "constraint b: not DGP: r1\nobjective c: not DGP: r2 [offending term: t]"
    fine = GPData(["x"], np.ones(1), np.ones(1), "c", "", [], [], [good])
    assert fine.is_gp and fine.explain() == "" and fine.failures() == []
    assert fine.infeasible == [] and fine.n_rows_before_pruning == 0


# --------------------------------------------------------------------------------------
# gp.py: rows
# --------------------------------------------------------------------------------------
def test_rows_of_splits_each_grid_row_into_its_variable_terms_and_constant():
    """Per grid row: the non-zero variable terms and the sum of the constant terms."""
    R, d = _vars()
    expr = 2.0 * R + np.array([1.0, 2.0]) + d * np.array([0.0, 5.0])
    rows, consts = _rows_of(expr, 2)
    assert rows == [{(1.0, 0.0): 2.0}, {(1.0, 0.0): 2.0, (0.0, 1.0): 5.0}]
    assert consts == [1.0, 2.0]
    assert _rows_of(3.0, 2) == ([{}, {}], [3.0, 3.0])
    assert _rows_of(np.array([1, 4]), 2) == ([{}, {}], [1.0, 4.0])
    assert _rows_of(R, 3) == ([{(1.0, 0.0): 1.0}] * 3, [0, 0, 0])


def test_a_row_is_written_with_its_constant_last():
    """_fmt_row shows a row's terms then its constant (left out when zero)."""
    assert _fmt_row(["R", "d"], {(1.0, 0.0): 2.0}, -3.0) == "2*R - 3"
    assert _fmt_row(["R", "d"], {(1.0, 0.0): 2.0, (0.0, -1.0): 1.0}, 0.0) == "2*R + d^-1"


def test_a_gp_row_holds_the_exponents_and_the_coefficients_over_the_scale():
    """_as_row: one exponent row per term, coefficients divided by the scale, the labels."""
    row = _as_row(
        "blk", "lab", ["R", "d"], {(1.0, 0.0): 2.0, (0.0, -1.0): 4.0}, 2.0, "lower", 5.0, "mm"
    )
    assert (row.name, row.label, row.kind, row.bound, row.unit) == (
        "blk",
        "lab",
        "lower",
        5.0,
        "mm",
    )
    assert row.A.tolist() == [[1.0, 0.0], [0.0, -1.0]] and row.c.tolist() == [1.0, 2.0]
    assert row.A.dtype == np.float64 and row.c.dtype == np.float64
    default = GPRow("n", "", np.zeros((1, 2)), np.ones(1))
    assert (default.kind, default.bound, default.unit) == ("upper", 1.0, "")


def test_pruning_drops_rows_implied_by_another_and_keeps_the_first_of_equal_rows():
    """A row whose monomials and coefficients another row covers is implied by it."""
    r0 = _row({(1.0, 0.0): 1.0})  # <= r1 (R <= 2 R)
    r1 = _row({(1.0, 0.0): 2.0})
    r2 = _row({(1.0, 0.0): 2.0})  # equal to r1: the first one stays
    r3 = _row({(1.0, 0.0): 1.0, (0.0, 1.0): 1.0})  # covers r0 (more monomials)
    r4 = _row({(0.0, 1.0): 3.0})  # larger than r3's d term: not implied
    kept = _prune([r0, r1, r2, r3, r4])
    assert [id(r) for r in kept] == [id(r1), id(r3), id(r4)]
    assert _prune([r2, r1]) == [r2]
    assert _prune([]) == []
    # one coefficient larger than the other row's: both stay
    a, b = _row({(1.0, 0.0): 3.0, (0.0, 1.0): 1.0}), _row({(1.0, 0.0): 1.0, (0.0, 1.0): 2.0})
    assert len(_prune([a, b])) == 2


def test_cvxpy_judges_a_row_of_positive_variables():
    """A posynomial row is DGP for cvxpy; a negative term or constant is not."""
    names = ["R", "d"]
    assert _cvxpy_flag(names, {(1.0, 0.0): 1.0, (0.0, 2.0): 3.0}, 0.0) is True
    assert _cvxpy_flag(names, {(1.0, 0.0): 1.0}, 2.0) is True
    assert _cvxpy_flag(names, {(1.0, 0.0): 1.0}, -2.0) is False
    assert _cvxpy_flag(names, {(1.0, 0.0): 1.0, (0.0, 1.0): -1.0}, 0.0) is False
    assert _cvxpy_flag(names, {(-1.0, 0.5): -1.0}, 0.0) is False
    assert _cvxpy_flag(names, {(-1.0, 0.0): 2.0, (0.0, -2.0): 1.0}, 0.0) is True
    assert _cvxpy_flag(["R"], {(1.0, 0.0): 1.0}, 0.0) is None  # a malformed row: no verdict


def test_a_block_that_is_not_a_signomial_keeps_its_reason_and_term():
    """A NotGP block: a failed check with the tracer's reason and term, no rows."""
    check, rows, infeasible = _classify(NotGP("why", "cos(R)"), None, 1.0)
    assert check == DGPCheck("constraint", "blk", False, "why", "cos(R)")
    assert (rows, infeasible) == ([], [])


def test_constant_rows_outside_their_band_are_infeasible_named_at_their_angle():
    """A row without design terms holds or not: outside [lower, upper] it is listed."""
    check, rows, infeasible = _classify(np.array([1.0, 5.0]), 2.0, 4.0)
    assert check == DGPCheck("constraint", "blk", True, "no row depends on the design")
    assert rows == []
    assert infeasible == ["blk[a] = 1 mm outside [2.0, 4.0]", "blk[b] = 5 mm outside [2.0, 4.0]"]
    _, _, inside = _classify(np.array([2.0, 4.0]), 2.0, 4.0)
    assert inside == []
    # labels that do not fit the rows are left out; a missing bound shows as None
    _, _, one = _classify(np.array([1.0, 5.0]), None, 4.0, labels=("a",))
    assert one == ["blk = 5 mm outside [None, 4.0]"]
    R, _ = _vars()
    _, _, traced = _classify(R - R + np.array([3.0, 6.0]), 2.0, 4.0)
    assert traced == ["blk[b] = 6 mm outside [2.0, 4.0]"]


def test_constant_rows_are_compared_with_a_relative_tolerance_of_1e_9():
    """1e-9 of the bound (at least 1e-9) is no violation; twice that is."""
    for bound in (100.0, 0.5):
        tol = 1e-9 * max(1.0, bound)
        values = np.array([bound + 0.5 * tol, bound + 2 * tol])
        _, _, above = _classify(values, None, bound)
        assert [s.split(" = ")[0] for s in above] == ["blk[b]"]
        values = np.array([bound - 0.5 * tol, bound - 2 * tol])
        _, _, below = _classify(values, bound, None)
        assert [s.split(" = ")[0] for s in below] == ["blk[b]"]


def test_a_posynomial_upper_bound_becomes_a_row_over_the_bound_minus_the_constant():
    """[2, 4] R + 3 <= 11: rows R/4 and R/2 (posy <= 11 - 3); the lower bound 1 always holds."""
    R, _ = _vars()
    check, rows, infeasible = _classify(R * np.array([2.0, 4.0]) + 3.0, 1.0, 11.0)
    assert check == DGPCheck("constraint", "blk", True, "2 posynomial rows")
    assert infeasible == []
    assert [(r.name, r.label, r.kind, r.bound, r.unit) for r in rows] == [
        ("blk", "a", "upper", 11.0, "mm"),
        ("blk", "b", "upper", 11.0, "mm"),
    ]
    assert [r.A.tolist() for r in rows] == [[[1.0, 0.0]], [[1.0, 0.0]]]
    assert [r.c.tolist() for r in rows] == [[0.25], [0.5]]


def test_a_monomial_lower_bound_becomes_its_inverse_row():
    """2 R d >= 4 is 2 R^-1 d^-1 <= 1 (kind lower, bound 4)."""
    R, d = _vars()
    check, rows, _ = _classify(2.0 * R * d, 4.0, None, labels=())
    assert check.ok and check.reason == "1 posynomial rows"
    ((row,),) = [rows]
    assert (row.label, row.kind, row.bound) == ("", "lower", 4.0)
    assert row.A.tolist() == [[-1.0, -1.0]] and row.c.tolist() == [2.0]


def test_a_negative_monomial_plus_a_constant_flips_its_bounds():
    """-2 R + 10 <= 4 is R >= 3 (row 3/R <= 1); -2 R + 10 >= 12 no positive R meets."""
    R, _ = _vars()
    check, rows, infeasible = _classify(-2.0 * R + 10.0, 12.0, 4.0, labels=())
    assert check.ok and check.reason == "1 posynomial rows"
    ((row,),) = [rows]
    assert (row.kind, row.bound, row.A.tolist(), row.c.tolist()) == (
        "upper",
        4.0,
        [[-1.0, 0.0]],
        [3.0],
    )
    assert infeasible == ["blk: -2*R + 10 cannot meet 12.0"]
    # only the unmeetable side: no row at all
    check, rows, infeasible = _classify(-2.0 * R + 10.0, 12.0, None, labels=())
    assert (check.reason, rows, infeasible) == (
        "no row depends on the design",
        [],
        ["blk: -2*R + 10 cannot meet 12.0"],
    )
    # -2 R + 10 >= -4 always holds for... R <= 7: a posynomial <= 7 row (kind lower)
    _, rows, _ = _classify(-2.0 * R + 10.0, -4.0, None, labels=())
    assert [(r.kind, r.bound, r.A.tolist(), r.c.tolist()) for r in rows] == [
        ("lower", -4.0, [[1.0, 0.0]], [2.0 / 14.0])
    ]


def test_a_posynomial_bounded_below_a_positive_constant_cannot_meet_it():
    """2 R + 3 <= 2 at each angle: named with the row, its terms and the bound."""
    R, _ = _vars()
    check, rows, infeasible = _classify(2.0 * R + 3.0 * np.ones(2), None, 2.0)
    assert check.ok and rows == []
    assert infeasible == ["blk[a]: 2*R + 3 cannot meet 2.0", "blk[b]: 2*R + 3 cannot meet 2.0"]


def test_a_row_of_both_signs_is_a_signomial_named_at_its_angle():
    """R - d + 2 at angle b: the whole block fails there, with the row and cvxpy's verdict."""
    R, d = _vars()
    check, rows, infeasible = _classify(R - d * np.array([0.0, 1.0]) + 2.0, None, 5.0)
    assert (rows, infeasible) == ([], [])
    assert check == DGPCheck(
        "constraint",
        "blk",
        False,
        "blk[b] is a signomial (terms of both signs): R - d + 2",
        "R - d + 2",
        False,
    )


def test_a_posynomial_bounded_from_below_names_the_angle_and_side():
    """R + d >= 20 at angle a: posynomial >= constant, not DGP; cvxpy's verdict False."""
    R, d = _vars()
    check, rows, _ = _classify(R + d, 20.0, None, labels=("a",))
    assert rows == []
    assert check == DGPCheck(
        "constraint",
        "blk",
        False,
        "blk[a]: a lower bound 20 on a sum of terms (R + d); posynomial >= constant is not DGP",
        "R + d",
        False,
    )
    check, _, _ = _classify(R + d + 1.0, 20.0, None, labels=("a",))
    assert (check.reason, check.term) == (
        "blk[a]: a lower bound 20 on a sum of terms (R + d + 1); posynomial >= constant is not DGP",
        "R + d + 1",
    )
    # at or below zero the lower bound always holds: no failure, no row
    check, rows, _ = _classify(R + d + 1.0, 1.0, None, labels=("a",))
    assert (check.ok, check.reason, rows) == (True, "no row depends on the design", [])


def test_the_forks_gp_is_diagnosed_block_by_block(fork):
    """Variables, objective, units, per-block row counts before and after pruning."""
    gp = build_gp(fork)
    assert gp.names == ["R", "p", "d"] and gp.objective == "backlash"
    assert gp.lower.tolist() == [30.0, 2.0, 4.0] and gp.upper.tolist() == [120.0, 10.0, 30.0]
    assert gp.objective_unit == "deg" and gp.infeasible == [] and gp.is_gp
    assert [(c.what, c.name, c.ok, c.reason) for c in gp.checks] == [
        ("objective", "backlash", True, "max over the grid of posynomials, 1 rows kept"),
        ("constraint", "ratio_positive", True, "61 posynomial rows"),
        ("constraint", "mean_ratio", True, "2 posynomial rows"),
        ("constraint", "nut_travel", True, "1 posynomial rows"),
        ("constraint", "pin_bearing_pressure", True, "61 posynomial rows"),
        ("constraint", "pin_shear_stress", True, "61 posynomial rows"),
    ]
    # 61 objective rows + 61 + 2 + 1 + 61 + 61 constraint rows, before pruning
    assert gp.n_rows_before_pruning == 61 + 61 + 2 + 1 + 61 + 61
    assert [(r.name, r.label, r.kind, r.bound, r.unit) for r in gp.rows] == [
        ("ratio_positive", "phi=+0.0deg", "lower", 1.0, ""),
        ("mean_ratio", "", "upper", 260.0, ""),
        ("mean_ratio", "", "lower", 200.0, ""),
        ("nut_travel", "", "upper", 110.0, "mm"),
        ("pin_bearing_pressure", "phi=+0.0deg", "upper", 100.0, "MPa"),
        ("pin_shear_stress", "phi=+0.0deg", "upper", 200.0, "MPa"),
    ]


def test_every_gp_row_is_the_numpy_models_row_over_its_bound(fork):
    """At random designs each GP row times its bound (upper) or the bound over it (lower)
    is the first-order model's value at the row's angle; the objective row is the
    objective there, and the kept rows give each block's worst value over the grid."""
    gp = build_gp(fork)
    labels = fork.phi_labels
    for x in _designs(fork):
        ex = fork.expressions(fork.design_dict(x), first_order=True)
        blocks = {b.name: b for b in ex.constraints}
        for row in gp.rows:
            values = np.broadcast_to(np.asarray(blocks[row.name].expr, dtype=float), (61,))
            v = values[labels.index(row.label)] if row.label else values[0]
            p = _posy(row, x)
            assert (p * row.bound if row.kind == "upper" else row.bound / p) == pytest.approx(
                v, rel=1e-9
            )
        for name in ("pin_bearing_pressure", "pin_shear_stress"):
            kept = [r for r in gp.rows if r.name == name]
            worst = np.max(np.asarray(blocks[name].expr, dtype=float))
            assert max(_posy(r, x) for r in kept) * kept[0].bound == pytest.approx(worst, rel=1e-9)
        backlash = np.asarray(ex.objectives["backlash"].expr, dtype=float)
        assert max(_posy(r, x) for r in gp.objective_rows) == pytest.approx(
            backlash.max(), rel=1e-9
        )


def test_a_scalar_or_max_objective_of_the_fork_has_its_rows_and_unit(fork):
    """size and nut_travel are one posynomial row; motor_torque a max over the grid;
    each row's value is the model's objective at random designs."""
    expected = {
        "size": ("mm", "posynomial, 1 rows kept", ""),
        "nut_travel": ("mm", "posynomial, 1 rows kept", ""),
        "motor_torque": ("N*mm", "max over the grid of posynomials, 1 rows kept", "phi=+0.0deg"),
    }
    for name, (unit, reason, label) in expected.items():
        gp = build_gp(fork, name)
        check = next(c for c in gp.checks if c.what == "objective")
        assert (gp.objective, gp.objective_unit, check.ok, check.reason) == (
            name,
            unit,
            True,
            reason,
        )
        assert [(r.name, r.label, r.kind) for r in gp.objective_rows] == [
            (name, label, "objective")
        ]
        # one scalar row instead of the 61 grid rows of backlash
        assert gp.n_rows_before_pruning == 186 + (61 if label else 1)
        for x in _designs(fork, 2):
            value = np.max(np.asarray(fork.expressions(fork.design_dict(x)).objectives[name].expr))
            assert _posy(gp.objective_rows[0], x) == pytest.approx(float(value), rel=1e-9)


def test_the_forks_ripple_objective_is_the_constant_one_seventh(fork):
    """The fork's ratio goes as 1/cos^2: max/min = 4/3 over +-30 deg, spread 1/7, whatever
    the design; the GP keeps it as one constant row."""
    gp = build_gp(fork, "ripple")
    check = next(c for c in gp.checks if c.what == "objective")
    assert (check.ok, check.reason) == (True, "constant 0.142857 (design-independent)")
    ((row,),) = [gp.objective_rows]
    assert (row.name, row.label) == ("ripple", "")
    assert row.A.tolist() == [[0.0, 0.0, 0.0]] and row.c[0] == pytest.approx(1.0 / 7.0, rel=1e-12)


def test_the_spread_of_a_constant_or_single_term_grid_value():
    """(max - min)/(max + min) of numbers or of one positive term; None otherwise."""
    R, _ = _vars()
    assert _constant_spread(np.array([1.0, 3.0])) == pytest.approx(0.5)
    assert _constant_spread(R * np.array([1.0, 3.0])) == pytest.approx(0.5)
    assert _constant_spread(R * np.array([2.0, 2.0])) == 0.0
    assert _constant_spread(R * np.array([0.0, 3.0])) is None
    assert _constant_spread(R * np.array([1.0, 3.0]) + 1.0) is None
    assert _constant_spread(NotGP("x")) is None


def test_an_objective_of_the_model_that_is_not_dgp_names_its_power_of_a_sum(fork):
    """backlash_rss is the root of a sum of squares: not DGP, the sum as its term."""
    gp = build_gp(fork, "backlash_rss")
    check = next(c for c in gp.checks if c.what == "objective")
    assert (
        check.ok is False
        and check.term
        and check.reason
        == (
            f"({check.term})^0.5: a power of a sum of terms is not a posynomial "
            "(generalised posynomials are not supported by optdesign's GP builder)"
        )
    )
    assert gp.objective_unit == "deg" and gp.objective_rows == []


def test_a_model_that_raises_while_traced_is_named_and_nothing_else_is_checked(fork, monkeypatch):
    """The model's exception becomes the problem's check; no objective or block after it."""
    seen = {}

    def boom(design, **kwargs):
        seen.update(kwargs)
        seen["design"] = design
        raise ValueError("boom")

    problem = copy.deepcopy(fork)
    monkeypatch.setattr(problem, "expressions", boom)
    gp = build_gp(problem)
    assert [(c.what, c.name, c.ok, c.reason) for c in gp.checks] == [
        ("problem", "fork_min_backlash", False, "model not traceable (ValueError: boom)")
    ]
    assert gp.rows == [] and gp.objective_rows == [] and gp.objective_unit == ""
    assert gp.explain() == (
        "problem fork_min_backlash: not DGP: model not traceable (ValueError: boom)"
    )
    # the tracers: first-order Hertz, one variable per free name, at the bounds' middle
    assert seen["first_order"] is True
    R = seen["design"]["R"]
    assert isinstance(R, Signomial) and R.names == ("R", "p", "d")
    assert _terms(seen["design"]["d"]) == {(0.0, 0.0, 1.0): 1.0}
    assert R.ref.tolist() == [75.0, 6.0, 17.0]
    assert seen["design"]["i_a"] == 2.0


def test_a_non_positive_lower_bound_is_named_with_its_unit_and_the_log_reason():
    """A GP variable must live in (0, inf): its check says so with its bound."""
    cs = load_problem(ROOT / "problems" / "cs_min_backlash.toml")
    n = next(c for c in build_gp(cs).checks if c.what == "variable" and c.name == "n")
    assert n.reason == (
        "lower bound 0 mm is not positive; GP variables live in (0, inf) (log change of variables)"
    )


def test_is_gp_refuses_catalogue_or_non_positive_variables_without_tracing(fork, monkeypatch):
    """The cheap tests first: build_gp is not called for those; it is for the rest, with
    the objective asked."""
    asked = []

    def fake_build(problem, objective=None):
        asked.append(objective)
        return GPData([], np.ones(0), np.ones(0), "", "", [], [], [DGPCheck("o", "o", True)])

    monkeypatch.setattr(gpmod, "build_gp", fake_build)
    assert is_gp(load_problem(ROOT / "problems" / "cs_min_backlash_catalogue.toml")) is False
    assert is_gp(load_problem(ROOT / "problems" / "cs_min_backlash.toml")) is False
    assert asked == []
    assert is_gp(fork, "size") is True and asked == ["size"]


# --------------------------------------------------------------------------------------
# gp.py: the cvxpy problem
# --------------------------------------------------------------------------------------
def test_the_cvxpy_problem_holds_the_rows_then_the_bounds_and_solves_by_hand():
    """min 1/(x y) s.t. x/8 + y/8 <= 1 in [1, 10]^2: x = y = 4, t = 1/16 (AM-GM)."""
    obj = GPRow("f", "", np.array([[-1.0, -1.0]]), np.array([1.0]), "objective", 0.0)
    con = GPRow("sum", "", np.array([[1.0, 0.0], [0.0, 1.0]]), np.array([0.125, 0.125]))
    gp = GPData(["x", "y"], np.array([1.0, 1.0]), np.array([10.0, 5.0]), "f", "", [obj], [con], [])
    prob, xs, t, cons = to_cvxpy(gp)
    assert [r.name for r, _ in cons] == ["f", "sum", "bound:x", "bound:x", "bound:y", "bound:y"]
    assert cons[0][0] is obj and cons[1][0] is con
    bounds = [(r.label, r.kind, r.bound, r.A.tolist(), r.c.tolist()) for r, _ in cons[2:]]
    assert bounds == [
        ("upper", "upper", 10.0, [[1.0, 0.0]], [0.1]),
        ("lower", "lower", 1.0, [[-1.0, -0.0]], [1.0]),
        ("upper", "upper", 5.0, [[0.0, 1.0]], [0.2]),
        ("lower", "lower", 1.0, [[-0.0, -1.0]], [1.0]),
    ]
    assert [x.name() for x in xs] == ["x", "y"] and t.name() == "t"
    assert prob.is_dgp()
    prob.solve(gp=True)
    assert prob.value == pytest.approx(1.0 / 16.0, rel=1e-5)
    assert [float(x.value) for x in xs] == pytest.approx([4.0, 4.0], rel=1e-4)
    # the bound on y binds when it is below 4: y = 3, x = 5, t = 1/15
    gp.upper = np.array([10.0, 3.0])
    prob, xs, _, _ = to_cvxpy(gp)
    prob.solve(gp=True)
    assert prob.value == pytest.approx(1.0 / 15.0, rel=1e-5)
    assert [float(x.value) for x in xs] == pytest.approx([5.0, 3.0], rel=1e-4)


def test_the_cvxpy_problem_of_a_constant_objective_is_its_value():
    """A design-independent objective row (zero exponents): the optimum is that constant."""
    obj = GPRow("ripple", "", np.zeros((1, 1)), np.array([0.25]))
    gp = GPData(["x"], np.array([1.0]), np.array([2.0]), "ripple", "", [obj], [], [])
    prob, _, _, cons = to_cvxpy(gp)
    assert len(cons) == 3
    prob.solve(gp=True)
    assert prob.value == pytest.approx(0.25, rel=1e-6)


def test_a_crank_slider_with_its_linkage_fixed_keeps_its_constant_angle_rows_out_of_the_gp():
    """Constant rows are checked, not sent to cvxpy: the transmission angle's 61 rows
    leave no row; the lead and pin rows remain."""

    data = copy.deepcopy(CS_FIXED)
    data["requirements"]["transmission_angle"] = {"min": "30 deg", "max": "150 deg"}
    gp = build_gp(problem_from_dict(data))
    check = next(c for c in gp.checks if c.name == "transmission_angle")
    assert (check.ok, check.reason) == (True, "no row depends on the design")
    assert "transmission_angle" not in {r.name for r in gp.rows} and gp.infeasible == []
    assert gp.names == ["p", "d"]


def test_an_objective_that_is_zero_at_every_design_is_no_gp_and_auto_takes_the_nlp(fork):
    """The fork has no drive: its drive_loss is 0 whatever the design. The GP refuses it
    (cvxpy's min t over no row was reported "failed: unbounded"); auto solves the NLP."""

    gp = build_gp(fork, "drive_loss")
    check = next(c for c in gp.checks if c.what == "objective")
    assert (check.ok, check.term, check.reason) == (
        False,
        "drive_loss",
        "drive_loss is 0 whatever the design: a GP minimises a positive posynomial",
    )
    assert not is_gp(fork, "drive_loss") and gp.objective_rows == []
    result = od.solve(fork, "auto", objective="drive_loss", ranges=False)
    assert (result.formulation, result.status, result.objective) == ("nlp-epigraph", "optimal", 0.0)


def test_an_objectives_constant_term_is_a_row_of_zero_exponents():
    """p + 2 mm (scalar): one row, the monomial p and the constant 2 (exponents 0)."""
    problem = _cs_fixed()
    problem.add_objective("lead_plus", lambda q: q.design["p"] + 2.0, unit="mm")
    gp = build_gp(problem, "lead_plus")
    check = next(c for c in gp.checks if c.what == "objective")
    assert (check.ok, check.reason, gp.objective_unit) == (True, "posynomial, 1 rows kept", "mm")
    ((row,),) = [gp.objective_rows]
    assert (row.name, row.label, row.kind, row.bound) == ("lead_plus", "", "objective", 0.0)
    assert row.A.tolist() == [[1.0, 0.0], [0.0, 0.0]] and row.c.tolist() == [1.0, 2.0]


def test_a_grid_objective_keeps_the_row_of_its_largest_coefficient_at_its_angle():
    """d (1 + phi_k / 30 deg) / 2 over the grid: of 61 rows the one at +30 deg (d) stays."""
    problem = _cs_fixed()
    weights = np.linspace(0.0, 1.0, 61)
    problem.add_objective("wave", lambda q: q.design["d"] * weights, unit="mm")
    gp = build_gp(problem, "wave")
    ((row,),) = [gp.objective_rows]
    assert (row.label, row.A.tolist(), row.c.tolist()) == ("phi=+30.0deg", [[0.0, 1.0]], [1.0])
    # the weight 0 at -30 deg leaves no term there: 60 rows before pruning
    constraint_rows = build_gp(problem).n_rows_before_pruning - 61  # backlash: 61 rows
    assert gp.n_rows_before_pruning == constraint_rows + 60


def test_a_grid_objective_with_a_negative_term_is_named_at_its_angle():
    """d (phi_k / 30 deg) is -d at -30 deg: not DGP, named at that angle; cvxpy agrees."""
    problem = _cs_fixed()
    weights = np.linspace(-1.0, 1.0, 61)
    problem.add_objective("wave", lambda q: q.design["d"] * weights + 1.0, unit="mm")
    check = next(c for c in build_gp(problem, "wave").checks if c.what == "objective")
    assert (check.ok, check.term, check.cvxpy_is_dgp) == (False, "-d + 1", False)
    assert check.reason == "wave[phi=-30.0deg] has a negative term: -d + 1 (a signomial)"


def test_a_limit_on_a_non_spread_objective_is_an_upper_bounded_block(fork, monkeypatch):
    """The generic objective-limit path (only ripple_max uses it today, a spread): a
    limit of 100 mm on size (= R) is the block size_max with the row R/100 <= 1."""
    problem = copy.deepcopy(fork)
    monkeypatch.setattr(problem, "objective_limits", lambda: {"size": 100.0})
    gp = build_gp(problem)
    check = next(c for c in gp.checks if c.name == "size_max")
    assert (check.what, check.ok, check.reason) == ("constraint", True, "1 posynomial rows")
    row = gp.rows[-1]
    assert (row.name, row.label, row.kind, row.bound, row.unit) == (
        "size_max",
        "",
        "upper",
        100.0,
        "mm",
    )
    assert row.A.tolist() == [[1.0, 0.0, 0.0]] and row.c.tolist() == [0.01]
    assert len(gp.rows) == 7 and gp.infeasible == []


def test_a_positive_lower_bound_at_or_below_one_is_a_gp_variable():
    """Only a lower bound <= 0 breaks the log change of variables: 1 mm and 0.5 mm do not."""

    for lower in (1.0, 0.5):
        data = copy.deepcopy(CS_FIXED)
        data["variables"]["p"] = {"lower": lower, "upper": 10}
        problem = problem_from_dict(data)
        gp = build_gp(problem)
        assert [c for c in gp.checks if c.what == "variable"] == [] and gp.is_gp
        assert is_gp(problem)


def test_a_bound_that_leaves_a_small_or_no_margin_over_the_constant():
    """2 R + 3 <= 3.5 is 4 R <= 1; <= 3 no positive R meets; -2 R + 10 <= 9.5 is
    0.25/R <= 1."""
    R, _ = _vars()
    _, rows, infeasible = _classify(2.0 * R + 3.0, None, 3.5, labels=())
    assert [(r.A.tolist(), r.c.tolist()) for r in rows] == [([[1.0, 0.0]], [4.0])]
    assert infeasible == []
    _, rows, infeasible = _classify(2.0 * R + 3.0, None, 3.0, labels=())
    assert rows == [] and infeasible == ["blk: 2*R + 3 cannot meet 3.0"]
    _, rows, infeasible = _classify(-2.0 * R + 10.0, None, 9.5, labels=())
    assert [(r.A.tolist(), r.c.tolist()) for r in rows] == [([[-1.0, 0.0]], [0.25])]
    assert infeasible == []


def test_a_spread_objective_that_depends_on_the_design_is_not_dgp():
    """(max - min)/(max + min) of d w_k + 1 over the grid: a difference of posynomials
    over a sum; the term is the expression at the first angle."""
    problem = _cs_fixed()
    weights = np.linspace(1.0, 2.0, 61)
    problem.add_objective("wobble", lambda q: q.design["d"] * weights + 1.0, kind="spread")
    gp = build_gp(problem, "wobble")
    check = next(c for c in gp.checks if c.what == "objective")
    assert (check.ok, check.term, check.cvxpy_is_dgp) == (False, "d + 1", False)
    assert check.reason == (
        "wobble = (max - min)/(max + min) over the grid: a difference of posynomials "
        "divided by a sum is not log-log convex"
    )
    assert gp.objective_rows == []


# --- what is not a GP: a negative term, a ratio ripple limit, an objective the tracer cannot read
def test_a_gp_objective_with_a_negative_term_is_not_a_gp():
    """A user objective that is a signomial (12 mm - p): the GP diagnosis refuses it,
    names the term, and cvxpy agrees; the problem's own objective stays a GP."""
    import copy

    from optdesign.programs.gp import build_gp

    problem = problem_from_dict(copy.deepcopy(CS_FIXED))
    problem.add_objective("lead_margin", lambda q: 12.0 - q.design["p"], unit="mm")
    gp = build_gp(problem, "lead_margin")
    check = {c.name: c for c in gp.checks}["lead_margin"]
    assert not gp.is_gp and check in gp.failures() and check.what == "objective"
    assert check.reason == "lead_margin[] has a negative term: -p + 12 (a signomial)"
    assert check.cvxpy_is_dgp is False
    assert build_gp(problem, "backlash").is_gp


def test_a_ratio_ripple_limit_is_not_a_gp_and_the_diagnosis_says_why():
    """ripple_max bounds (max - min)/(max + min) over the grid, a difference of
    posynomials over a sum: the GP diagnosis names it as a constraint that is not DGP."""
    import copy

    from optdesign.programs.gp import build_gp

    data = copy.deepcopy(CS_FIXED)
    data["requirements"]["ripple_max"] = 0.2
    data["variables"]["R"] = {"lower": 60, "upper": 120}  # the ratio's shape depends on R
    gp = build_gp(problem_from_dict(data))
    check = {c.name: c for c in gp.checks}["ripple_max"]
    assert (check.what, check.ok, check.cvxpy_is_dgp) == ("constraint", False, False)
    assert check.reason == (
        "ripple = (max - min)/(max + min) over the grid is a ratio of a difference of posynomials"
    )
    assert not gp.is_gp and check in gp.failures()


def test_an_objective_the_gp_cannot_trace_is_a_failed_check_not_an_unknown_one():
    import copy

    from optdesign import math as m
    from optdesign.programs.gp import build_gp

    problem = problem_from_dict(copy.deepcopy(CS_FIXED))
    problem.add_objective("wavy", lambda q: m.sin(q.design["p"]), unit="")
    check = next(c for c in build_gp(problem, "wavy").checks if c.what == "objective")
    assert check.name == "wavy" and check.ok is False and check.reason


def test_a_design_independent_ripple_limit_is_checked_by_the_gp_against_its_value():
    """With the linkage fixed the ripple does not depend on the design: the GP checks
    ripple_max against the value itself (the NumPy model's at any design) - met at 0.3,
    named as the infeasible requirement at 0.2."""
    import copy

    from optdesign.programs.gp import build_gp

    ripple = None
    for limit, lead in ((0.3, None), (0.2, None), (0.2, 5.0)):
        data = copy.deepcopy(CS_FIXED)
        data["requirements"]["ripple_max"] = limit
        if lead is not None:  # the ratio then depends on no free variable at all
            data["variables"]["p"] = lead
        problem = problem_from_dict(data)
        if ripple is None:
            q = problem.quantities(problem.design_dict(problem.midpoint()))
            ratio = np.asarray(q.ratio, dtype=float).ravel()
            ripple = (ratio.max() - ratio.min()) / (ratio.max() + ratio.min())
            assert ripple == pytest.approx(0.238162, abs=1e-6)
        gp = build_gp(problem)
        assert gp.is_gp and "ripple_max" not in {c.name for c in gp.checks}
        expected = [] if limit > ripple else [f"ripple = {ripple:.6g} > ripple_max = 0.2"]
        assert gp.infeasible == expected
        # the ripple as the objective: a constant, the GP a feasibility check
        check = next(c for c in build_gp(problem, "ripple").checks if c.what == "objective")
        assert (check.ok, check.reason) == (True, f"constant {ripple:.6g} (design-independent)")
