"""The GP builder's observable behaviour, pinned case by case.

Issue 21 (mutation deliverable): every value, name and message that
:mod:`optdesign.formulations.gp` produces - each branch of a row's classification, the
pruning, the diagnosis, the fork's rows, the cvxpy problem - against hand computations or
the NumPy model. The signomial tracer is pinned in ``test_signomial_behaviour.py``.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest
from formulations.test_signomial import _terms, _vars

from optdesign.formulations import gp as gpmod
from optdesign.formulations.gp import (
    DGPCheck,
    GPData,
    GPRow,
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
from optdesign.formulations.signomial import NotGP, Signomial
from optdesign.problem import load_problem, problem_from_dict

ROOT = Path(__file__).resolve().parents[1]
FORK = ROOT / "problems" / "fork_min_backlash.toml"


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


def _row(terms: dict, name: str = "blk") -> GPRow:
    return GPRow(name, "", np.array(list(terms), dtype=float), np.array(list(terms.values())))


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


# --------------------------------------------------------------------------------------
# gp.py: one block's classification
# --------------------------------------------------------------------------------------
def _classify(expr, lower, upper, labels=("a", "b"), unit="mm"):
    return _classify_block("blk", expr, lower, upper, list(labels), unit, ["R", "d"], 2)


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
    from formulations.test_gp import CS_FIXED

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
    import optdesign as od

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


def _cs_fixed():
    from formulations.test_gp import CS_FIXED

    return problem_from_dict(copy.deepcopy(CS_FIXED))


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
    from formulations.test_gp import CS_FIXED

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
