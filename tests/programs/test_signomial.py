"""The signomial tracer's observable behaviour, pinned case by case.

Issue 21 (mutation deliverable): the terms, texts and refusals of
:mod:`optdesign.programs.signomial` - construction, arithmetic, powers, ``abs``, the
NumPy protocol and grid reductions - against hand computations. The GP builder that
reads them is pinned in the GP part of ``test_gp.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from optdesign.programs.signomial import NotGP, Signomial

NAMES = ("R", "d")
REF = np.array([2.0, 3.0])


def _vars():
    return Signomial.variable(NAMES, 0, REF), Signomial.variable(NAMES, 1, REF)


def _terms(s) -> dict:
    """The terms of a signomial as plain floats (lists for grid coefficients)."""
    return {k: np.asarray(v, dtype=float).tolist() for k, v in s.terms.items()}


def _sig(terms: dict) -> Signomial:
    return Signomial(NAMES, terms, REF)


# --------------------------------------------------------------------------------------
# Signomial: construction, values, text
# --------------------------------------------------------------------------------------
def test_a_variable_is_one_unit_term_at_its_position():
    """variable(names, k) is x_k (exponent 1 at k, coefficient 1), valued at the reference."""
    R, d = _vars()
    assert _terms(d) == {(0.0, 1.0): 1.0} and _terms(R) == {(1.0, 0.0): 1.0}
    assert d.names == NAMES and d.ref is REF
    assert (float(R), float(d)) == (2.0, 3.0)
    assert not R.is_constant and R.shape == ()


def test_zero_coefficients_and_cancelled_terms_are_dropped():
    """A term zero everywhere on the grid is no term; like terms that cancel vanish."""
    s = _sig({(1.0, 0.0): 0.0, (0.0, 1.0): np.zeros(3), (0.0, 0.0): np.array([0.0, 1.0])})
    assert _terms(s) == {(0.0, 0.0): [0.0, 1.0]}
    # exponents equal to 12 digits are one term: 2 R - 2 R^(1 + 1e-13) is nothing
    gone = _sig({(1.0, 0.0): 2.0, (1.0 + 1e-13, 0.0): -2.0})
    assert gone.terms == {} and gone.is_constant and gone.constant_value() == 0.0
    R, _ = _vars()
    assert (R - R).terms == {} and (R - R).describe() == "0"
    # three terms merging into one key keep the sum of all three
    three = _sig({(0.5, 0.0): 1.0, (0.5 + 1e-14, 0.0): 2.0, (0.5 - 1e-14, 0.0): 4.0})
    assert _terms(three) == {(0.5, 0.0): 7.0}


def test_evaluate_sums_the_monomials_and_float_is_the_grid_maximum_at_the_reference():
    """2 R^2 / d + 3 at (2, 3) is 8/3 + 3; float() of a grid value is its largest entry."""
    R, d = _vars()
    s = 2.0 * R**2 / d + 3.0
    assert s.evaluate(np.array([2.0, 3.0])) == pytest.approx(8.0 / 3.0 + 3.0, rel=1e-15)
    assert s.evaluate(np.array([1.0, 4.0])) == pytest.approx(0.5 + 3.0, rel=1e-15)
    grid = R * np.array([1.0, 3.0, 2.0]) + d
    assert np.asarray(grid.evaluate(np.array([2.0, 3.0]))).tolist() == [5.0, 9.0, 7.0]
    assert float(grid) == 9.0  # at REF (2, 3): the largest of 5, 9, 7
    assert (R - R).evaluate(np.array([2.0, 3.0])) == 0.0


def test_shape_constancy_and_constant_value():
    """The shape broadcasts the coefficients; a constant's value is its zero-exponent term."""
    R, _ = _vars()
    assert (R * np.ones(3) + np.ones((2, 1))).shape == (2, 3)
    c = R - R + np.array([1.0, 2.0])
    assert c.is_constant and np.asarray(c.constant_value()).tolist() == [1.0, 2.0]
    assert (R + 1.0).is_constant is False


def test_describe_writes_terms_as_the_reports_show_them():
    """Coefficients to 4 significant digits, unit ones left out, signs between terms."""
    assert _sig({(1.0, 0.0): 0.8660254, (0.0, 0.0): -50.0}).describe() == "0.866*R - 50"
    assert _sig({(1.0, 0.0): 0.8660254, (0.0, 0.0): -50.0}).describe(digits=2) == "0.87*R - 50"
    assert _sig({(1.0, 0.0): -2.0, (0.0, 1.0): 1.0}).describe() == "-2*R + d"
    assert _sig({(1.0, 0.0): -1.0}).describe() == "-R"
    assert _sig({(2.0, -1.0): 1.0}).describe() == "R^2*d^-1"
    assert _sig({(0.5, 0.0): 3.0}).describe() == "3*R^0.5"
    assert _sig({(1.0 / 3.0, 0.0): 1.0}).describe() == "R^0.3333"
    assert _sig({(0.0, 0.0): 1.0}).describe() == "1"
    assert _sig({(0.0, 0.0): -1.0}).describe() == "-1"
    assert _sig({(1.0, 0.0): 12345.678}).describe() == "1.235e+04*R"
    assert _sig({(1.0, 1.0): 2.0, (0.0, 0.0): 0.25}).describe() == "2*R*d + 0.25"


def test_describe_reads_the_coefficients_of_the_grid_row_asked():
    """describe(row) takes each grid coefficient at that row (the last past the end) and
    leaves out the terms that are zero there."""
    s = _sig({(1.0, 0.0): np.array([1.0, 2.0, 3.0])})
    assert [s.describe(r) for r in (None, 0, 1, 2, 7)] == ["R", "R", "2*R", "3*R", "3*R"]
    part = _sig({(1.0, 0.0): np.array([0.0, 2.0]), (0.0, 0.0): 1.0})
    assert (part.describe(0), part.describe(1)) == ("1", "2*R + 1")


def test_a_grid_row_where_every_term_is_zero_reads_0():
    """Every coefficient zero at the row asked: "0" (it read "-")."""
    assert _sig({(1.0, 0.0): np.array([0.0, 2.0])}).describe(0) == "0"
    assert (
        _sig({(1.0, 0.0): np.array([0.0, 2.0]), (0.0, 0.0): np.array([0.0, 1.0])}).describe() == "0"
    )


# --------------------------------------------------------------------------------------
# Signomial: arithmetic
# --------------------------------------------------------------------------------------
def test_sums_differences_and_negation_give_the_exact_terms():
    """+, - and unary - on signomials and numbers, on either side."""
    R, d = _vars()
    assert _terms(5.0 - R) == {(0.0, 0.0): 5.0, (1.0, 0.0): -1.0}
    assert _terms(R - 5) == {(1.0, 0.0): 1.0, (0.0, 0.0): -5.0}
    assert _terms(2 + R) == {(1.0, 0.0): 1.0, (0.0, 0.0): 2.0}
    assert _terms(R - d) == {(1.0, 0.0): 1.0, (0.0, 1.0): -1.0}
    assert _terms(-(2.0 * R + 1.0)) == {(1.0, 0.0): -2.0, (0.0, 0.0): -1.0}
    assert +R is R
    assert _terms(R + np.float64(2.0)) == {(1.0, 0.0): 1.0, (0.0, 0.0): 2.0}
    assert isinstance((R + np.int64(2)).terms[(0.0, 0.0)], float)
    assert isinstance((R + np.array(2.0)).terms[(0.0, 0.0)], float)
    grid = R + np.array([1, 2])  # an integer array becomes a float coefficient
    assert grid.terms[(0.0, 0.0)].dtype == np.float64
    assert _terms(grid) == {(1.0, 0.0): 1.0, (0.0, 0.0): [1.0, 2.0]}


def test_products_and_quotients_give_the_exact_terms():
    """Products merge like terms; a quotient by a monomial inverts it."""
    R, d = _vars()
    assert _terms(R / 2) == {(1.0, 0.0): 0.5}
    assert _terms(6.0 / R) == {(-1.0, 0.0): 6.0}
    assert _terms(R / d) == {(1.0, -1.0): 1.0}
    assert _terms((R * d) / (2.0 * R)) == {(0.0, 1.0): 0.5}
    assert _terms((R + d) * (R - d)) == {(2.0, 0.0): 1.0, (0.0, 2.0): -1.0}
    assert _terms(3 * R * d) == {(1.0, 1.0): 3.0}
    assert _terms(R / (R * np.array([0.5, 4.0]))) == {(0.0, 0.0): [2.0, 0.25]}


def test_anything_but_numbers_and_tracers_is_refused_by_the_operators():
    """A string or None in an expression is Python's TypeError, not a silent term."""
    R, _ = _vars()
    for op in (
        lambda: R + "x",
        lambda: "x" + R,
        lambda: R - "x",
        lambda: "x" - R,
        lambda: R * None,
        lambda: None * R,
        lambda: R / "x",
        lambda: "x" / R,
    ):
        with pytest.raises(TypeError):
            op()


def test_division_by_a_sum_of_terms_is_not_a_gp_and_says_why():
    """R/(R + d) and 2/(R + 1) are not monomials: each NotGP names the divisor."""
    R, d = _vars()
    over_sum = R / (R + d)
    assert isinstance(over_sum, NotGP)
    assert (over_sum.reason, over_sum.term) == (
        "division by a sum of terms (R + d) is not a posynomial",
        "R + d",
    )
    rover = 2.0 / (R + 1.0)
    assert (rover.reason, rover.term) == (
        "division by a sum of terms (R + 1) is not a posynomial",
        "R + 1",
    )


def test_division_by_a_term_zero_at_some_angle_names_the_term():
    """1/(R [0, 2]): NotGP naming the divisor where it is not zero (it read "division by -")."""
    R, _ = _vars()
    zero = 1.0 / (R * np.array([0.0, 2.0]))
    assert isinstance(zero, NotGP)
    assert (zero.reason, zero.term) == ("division by 2*R, which is zero on the grid", "2*R")
    assert isinstance(R / (R * np.array([1.0, 0.0])), NotGP)


def test_not_gp_values_pass_through_every_operation_unchanged():
    """Once a value is not a signomial, that first reason reaches the block."""
    R, _ = _vars()
    n = NotGP("first reason", "t")
    assert (n.reason, n.term, NotGP("r").term) == ("first reason", "t", "")
    assert repr(n) == "NotGP('first reason')"
    assert float(n) == 1.0
    results = [
        n + 1, 1 + n, n - 1, 1 - n, n * 2, 2 * n, n / 2, 2 / n, n**2, 2**n, -n, +n, abs(n),
        np.cos(n), n.mean(), n.max(), n.min(), n.sum(),
        R + n, n + R, R - n, R * n, n * R, R / n, np.add(R, n), np.multiply(n, R),
    ]  # fmt: skip
    assert all(r is n for r in results)


# --------------------------------------------------------------------------------------
# Signomial: powers and abs
# --------------------------------------------------------------------------------------
def test_powers_of_a_monomial_scale_its_exponents():
    """(c x^a)^e = c^e x^(a e); an integer power of a negative term stays a monomial."""
    R, d = _vars()
    assert _terms((2.0 * R) ** 3) == {(3.0, 0.0): 8.0}
    root = (2.0 * R * d**2) ** 0.5
    assert list(root.terms) == [(0.5, 1.0)]
    assert root.terms[(0.5, 1.0)] == pytest.approx(math.sqrt(2.0), rel=1e-15)
    assert _terms((-2.0 * R) ** 2) == {(2.0, 0.0): 4.0}
    assert _terms((-2.0 * R) ** 3) == {(3.0, 0.0): -8.0}
    assert _terms(R**-1) == {(-1.0, 0.0): 1.0}
    assert (R - R) ** 2 is not None and ((R - R) ** 2).terms == {}
    assert _terms((R - R) ** 0) == {(0.0, 0.0): 1.0}


def test_a_fractional_power_of_a_negative_term_is_not_a_gp():
    """(-2 R)^0.5, or a grid coefficient negative at one angle: NotGP naming the term."""
    R, _ = _vars()
    neg = (-2.0 * R) ** 0.5
    assert isinstance(neg, NotGP)
    assert (neg.reason, neg.term) == ("(-2*R)^0.5 of a negative term", "-2*R")
    assert isinstance((R * np.array([1.0, -1.0])) ** 1.5, NotGP)
    assert isinstance((R * np.array([1.0, 0.0])) ** 1.5, Signomial)


def test_integer_powers_of_a_sum_up_to_six_are_expanded():
    """(R + 1)^6 has the binomial coefficients; ^7 or ^0 of a sum is not expanded."""
    R, _ = _vars()
    six = (R + 1.0) ** 6
    assert _terms(six) == {(float(k), 0.0): float(math.comb(6, k)) for k in range(7)}
    assert _terms((R + 1.0) ** 2) == {(2.0, 0.0): 1.0, (1.0, 0.0): 2.0, (0.0, 0.0): 1.0}
    tail = "a power of a sum of terms is not a posynomial (generalised posynomials are not "
    tail += "supported by optdesign's GP builder)"
    for e in (7, 0, 0.5, -1):
        p = (R + 1.0) ** e
        assert isinstance(p, NotGP) and (p.reason, p.term) == (f"(R + 1)^{e:g}: {tail}", "R + 1")
    neg = (-R - 1.0) ** 0.5  # one sign: the same refusal, not "both signs"
    assert neg.reason == f"(-R - 1)^0.5: {tail}"


def test_a_power_of_a_sum_of_both_signs_is_named_a_signomial():
    """(R - 1)^0.5 names both signs; zero grid entries carry no sign."""
    R, _ = _vars()
    p = (R - 1.0) ** 0.5
    assert (p.reason, p.term) == (
        "(R - 1)^0.5: power of a signomial (terms of both signs)",
        "R - 1",
    )
    zero_at_one = (R * np.array([0.0, 1.0]) + 1.0) ** 0.5
    assert "not a posynomial" in zero_at_one.reason and "both signs" not in zero_at_one.reason


def test_an_exponent_that_depends_on_the_design_is_not_a_gp():
    """R^d, R^(not GP) and 2^R: the exponent's own message."""
    R, d = _vars()
    for p in (R**d, R ** NotGP("other"), np.power(2.0, R)):
        assert isinstance(p, NotGP)
        assert p.reason == "a design variable in an exponent is not a monomial"


def test_abs_keeps_a_posynomial_negates_a_negative_sum_and_refuses_mixed_signs():
    """|R + 1| is itself, |-R - 2| is R + 2, |R - 1| and |R [-1, 1]| are not GP."""
    R, _ = _vars()
    pos = R + 1.0
    assert abs(pos) is pos
    assert _terms(abs(-R - 2.0)) == {(1.0, 0.0): 1.0, (0.0, 0.0): 2.0}
    mixed = abs(R - 1.0)
    assert (mixed.reason, mixed.term) == ("|R - 1|: absolute value of a signomial", "R - 1")
    assert isinstance(abs(R * np.array([-1.0, 1.0])), NotGP)
    assert _terms(abs(R * np.array([-1.0, 0.0]))) == {(1.0, 0.0): [1.0, 0.0]}
    empty = R - R
    assert abs(empty) is empty


# --------------------------------------------------------------------------------------
# Signomial: NumPy protocol and grid reductions
# --------------------------------------------------------------------------------------
def test_numpy_arithmetic_ufuncs_give_the_operators_terms():
    """np.add/subtract/multiply/divide/power and the unary ones trace like the operators."""
    R, d = _vars()
    assert _terms(np.add(2.0, R)) == {(0.0, 0.0): 2.0, (1.0, 0.0): 1.0}
    assert _terms(np.subtract(5.0, R)) == {(0.0, 0.0): 5.0, (1.0, 0.0): -1.0}
    assert _terms(np.subtract(R, d)) == {(1.0, 0.0): 1.0, (0.0, 1.0): -1.0}
    assert _terms(np.multiply(3.0, R)) == {(1.0, 0.0): 3.0}
    assert _terms(np.true_divide(6.0, R)) == {(-1.0, 0.0): 6.0}
    assert _terms(np.power(R, 2.0)) == {(2.0, 0.0): 1.0}
    assert _terms(np.array([1.0, 2.0]) * R) == {(1.0, 0.0): [1.0, 2.0]}
    assert _terms(np.array([1.0, 2.0]) - R) == {(0.0, 0.0): [1.0, 2.0], (1.0, 0.0): -1.0}
    assert _terms(np.negative(R)) == {(1.0, 0.0): -1.0}
    assert np.positive(R) is R
    assert _terms(np.absolute(-2.0 * R)) == {(1.0, 0.0): 2.0}
    assert _terms(np.fabs(-2.0 * R)) == {(1.0, 0.0): 2.0}
    assert _terms(np.sqrt(4.0 * R**2)) == {(1.0, 0.0): 2.0}
    assert _terms(np.square(R + 1.0)) == {(2.0, 0.0): 1.0, (1.0, 0.0): 2.0, (0.0, 0.0): 1.0}
    cube = np.cbrt(8.0 * d**3)
    assert list(cube.terms) == [(0.0, 1.0)] and cube.terms[(0.0, 1.0)] == pytest.approx(2.0)


def test_numpy_ufuncs_of_constants_are_numbers():
    """A ufunc of design-independent tracers is NumPy's value of their constants."""
    R, _ = _vars()
    assert np.cos(R - R + 0.5) == pytest.approx(math.cos(0.5), rel=1e-15)
    assert np.exp(R - R) == 1.0
    assert np.maximum(R - R + 3.0, 2.0) == 3.0
    assert np.arctan2(R - R + 1.0, 2.0) == pytest.approx(math.atan2(1.0, 2.0), rel=1e-15)


def test_other_numpy_functions_of_a_design_variable_name_themselves():
    """cos(R), maximum(R, 2), arctan2(R, d): not monomials, each named with its argument."""
    R, d = _vars()
    cases = [
        (np.cos(R), "cos(R)"),
        (np.maximum(R, 2.0), "maximum(R, ...)"),
        (np.arctan2(R, d), "arctan2(R, d)"),
        (np.sin(2.0 * R + 1.0), "sin(2*R + 1)"),
    ]
    for value, term in cases:
        assert isinstance(value, NotGP)
        assert (value.reason, value.term) == (
            f"{term} of a design variable is not a monomial",
            term,
        )
    red = np.add.reduce(R)
    assert isinstance(red, NotGP) and red.reason == "numpy add.reduce on a design variable"
    out = np.add(R, 1.0, out=np.empty(()))
    assert isinstance(out, NotGP) and out.reason == "numpy add.__call__ on a design variable"


def test_a_mean_over_the_grid_stays_a_signomial_and_max_or_min_do_not():
    """mean over the last axis of each coefficient; max/min over the grid are no GP."""
    R, _ = _vars()
    assert _terms((R * np.array([1.0, 3.0]) + 2.0).mean()) == {(1.0, 0.0): 2.0, (0.0, 0.0): 2.0}
    two_d = (R * np.array([[1.0, 3.0], [5.0, 7.0]])).mean()
    assert _terms(two_d) == {(1.0, 0.0): [2.0, 6.0]}
    assert _terms(np.mean(R * np.array([1.0, 3.0]))) == {(1.0, 0.0): 2.0}
    assert R.mean() is R and R.max() is R and R.min() is R  # no grid: nothing to reduce
    grid = R * np.array([2.0, 3.0])
    for how in ("max", "min"):
        reduced = getattr(grid, how)()
        assert isinstance(reduced, NotGP) and reduced.reason == f"{how} over the grid of 2*R"


def test_every_operation_keeps_the_reference_design_for_float():
    """float() of any traced value is its value at the reference design R = 2, d = 3
    (the mechanisms' input checks read it)."""
    R, d = _vars()
    cases = [
        (R + 1.0, 3.0),
        (1.0 + R, 3.0),
        (5.0 - R, 3.0),
        (R - 5.0, -3.0),
        (-(2.0 * R + 1.0), -5.0),
        (R * d, 6.0),
        (R / d, 2.0 / 3.0),
        (6.0 / R, 3.0),
        (R**2, 4.0),
        ((R + 1.0) ** 2, 9.0),
        (abs(-R - 2.0), 4.0),
        (np.add(2.0, R), 4.0),
        (np.subtract(5.0, R), 3.0),
        (np.true_divide(6.0, d), 2.0),
        (np.sqrt(R * d * 6.0), 6.0),
        ((R * np.array([1.0, 3.0])).mean(), 4.0),
    ]
    for value, expected in cases:
        assert value.ref is REF
        assert float(value) == pytest.approx(expected, rel=1e-15)
    assert ((R - R) ** 0).ref is REF and float((R - R) ** 0) == 1.0


def test_small_positive_coefficients_are_no_negative_terms():
    """Coefficients in (0, 1) and zeros on the grid are positive enough for a root or abs."""
    R, _ = _vars()
    half = (0.25 * R) ** 0.5
    assert list(half.terms) == [(0.5, 0.0)] and half.terms[(0.5, 0.0)] == pytest.approx(0.5)
    small = 0.5 * R
    assert abs(small) is small
    grid = R * np.array([1.0, 0.0])
    assert abs(grid) is grid
    assert _terms((R + 1.0) ** 1) == {(1.0, 0.0): 1.0, (0.0, 0.0): 1.0}
