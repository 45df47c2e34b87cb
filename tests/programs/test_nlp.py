"""The NLP formulation's observable behaviour, pinned row by row.

Issue 21 (mutation deliverable): every array, name and message that
:mod:`optdesign.programs.nlp` produces - the rows, their bounds, scales, names and
units, the auxiliary variables and their starts, the targets and their scales, the
epsilon rows, the bounds of a solve, the starts, the refusals - against the NumPy path
of the same problem (:meth:`DesignProblem.expressions` / :meth:`DesignProblem.evaluate`)
and hand formulas. The robust formulation is pinned in ``test_robust.py``.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

import optdesign as od
from optdesign.errors import ProblemError
from optdesign.problem import load_problem, problem_from_dict
from optdesign.problem.load import load
from optdesign.programs.nlp import (
    VAR,
    ConstraintRows,
    Target,
    _vec,
    build_nlp,
    numeric_value,
    typical,
)

ROOT = Path(__file__).resolve().parents[2]
CS = ROOT / "problems" / "cs_min_backlash.toml"
CATALOGUE = ROOT / "problems" / "cs_min_backlash_catalogue.toml"
#: A design of cs_min_backlash inside its bounds (near its optimum).
X = np.array([107.2, 54.3, 102.9, 5.16, 0.205, 5.74])
OBJ = ["backlash", "ripple", "size"]  # one of each kind: max, spread, scalar


@pytest.fixture(scope="module")
def problem():
    return load_problem(CS)


@pytest.fixture(scope="module")
def nlp(problem):
    return build_nlp(problem, OBJ)


def _grid(problem, x, name):
    return np.ravel(np.asarray(problem.expressions(problem.design_dict(x)).objectives[name].expr))


def _g(nlp, x, theta=None):
    """Raw rows (scaled rows times their scales) at the design x, aux at their starts."""
    z = nlp.z_from_x(x)
    theta = nlp.param_defaults if theta is None else theta
    return np.ravel(np.asarray(nlp.g_fun(z, theta))) * nlp.g_scale


def _blocks(problem, x):
    return [
        b
        for b in problem.expressions(problem.design_dict(x)).constraints
        if b.lower is not None or b.upper is not None
    ]


# --------------------------------------------------------------------------------------
# build_nlp: the rows
# --------------------------------------------------------------------------------------
def test_the_rows_are_the_envelopes_then_the_requirements_then_the_epsilon_rows(problem, nlp):
    """Names, units, scales and bounds of every row, in order, from the NumPy path."""
    labels = list(problem.phi_labels)
    n_phi = len(labels)
    mid = problem.midpoint()
    b_mid, r_mid = _grid(problem, mid, "backlash"), _grid(problem, mid, "ripple")
    names = [f"backlash_envelope[{lab}]" for lab in labels]
    names += [f"ripple_lower_envelope[{lab}]" for lab in labels]
    names += [f"ripple_upper_envelope[{lab}]" for lab in labels]
    terms = problem.expressions(problem.design_dict(mid)).objectives
    ub, ur, us = (terms[k].unit for k in OBJ)
    assert (ub, ur, us) == ("deg", "", "mm")
    units = [ub] * n_phi + [ur] * (2 * n_phi)
    scales = [np.max(np.abs(b_mid))] * n_phi + [np.max(np.abs(r_mid))] * (2 * n_phi)
    lower = [0.0] * (3 * n_phi)
    upper = [np.inf] * (3 * n_phi)
    ref = {b.name: b for b in _blocks(problem, mid)}
    for b in _blocks(problem, X):
        k = np.size(b.expr)
        names += [f"{b.name}[{lab}]" if lab else b.name for lab in b.labels]
        units += [b.unit] * k
        bound = max(abs(b.lower or 0.0), abs(b.upper or 0.0))
        scales += [bound if bound > 0 else np.max(np.abs(ref[b.name].expr))] * k
        lower += [-np.inf if b.lower is None else b.lower] * k
        upper += [np.inf if b.upper is None else b.upper] * k
    names += ["backlash_max", "ripple_max", "size_max"]
    units += [ub, ur, us]
    ev = problem.evaluate(mid).objectives
    scales += [ev["backlash"], ev["ripple"], ev["size"]]
    lower += [-np.inf] * 3
    upper += [np.inf] * 3
    assert nlp.g_names == names
    assert nlp.g_units == units
    np.testing.assert_allclose(nlp.g_scale, scales, rtol=1e-12)
    np.testing.assert_allclose(nlp.lbg * nlp.g_scale, lower, rtol=1e-12)
    np.testing.assert_allclose(nlp.ubg * nlp.g_scale, upper, rtol=1e-12)
    assert nlp.eps_rows == {
        "backlash": len(names) - 3,
        "ripple": len(names) - 2,
        "size": len(names) - 1,
    }
    assert nlp.g.shape == (len(names), 1)


def test_the_rows_values_at_a_design_are_the_numpy_paths(problem, nlp):
    """g at a design with the auxiliaries at their tightest values: each envelope's gap,
    each requirement's value, each objective's value."""
    b, r = _grid(problem, X, "backlash"), _grid(problem, X, "ripple")
    want = [*(b.max() - b), *(r - r.min()), *(r.max() - r)]
    for block in _blocks(problem, X):
        want += list(np.ravel(np.asarray(block.expr, dtype=float)) * np.ones(np.size(block.expr)))
    ev = problem.evaluate(X).objectives
    want += [ev["backlash"], (r.max() - r.min()) / (r.max() + r.min()), ev["size"]]
    np.testing.assert_allclose(_g(nlp, X), want, rtol=1e-9, atol=1e-12)


def test_the_auxiliaries_their_bounds_and_their_starts(problem, nlp):
    """One t per max objective, (lo, hi) per spread objective, none for a scalar; each
    scaled by its grid expression's size at the middle of the bounds."""
    assert nlp.aux_names == ["backlash_max", "ripple_lo", "ripple_hi"]
    mid = problem.midpoint()
    sb = np.max(np.abs(_grid(problem, mid, "backlash")))
    sr = np.max(np.abs(_grid(problem, mid, "ripple")))
    n = nlp.n_design
    assert n == 6 and nlp.z.shape == (n + 3, 1)
    np.testing.assert_array_equal(nlp.lbz[:n], np.zeros(n))
    np.testing.assert_array_equal(nlp.ubz[:n], np.ones(n))
    assert nlp.lbz[n] == -np.inf and nlp.lbz[n + 1] == 0.0
    assert nlp.lbz[n + 2] == pytest.approx(1e-6 / sr, rel=1e-12)
    assert list(nlp.ubz[n:]) == [np.inf] * 3
    b, r = _grid(problem, X, "backlash"), _grid(problem, X, "ripple")
    aux = nlp.z_from_x(X)[n:]
    np.testing.assert_allclose(aux, [b.max() / sb, r.min() / sr, r.max() / sr], rtol=1e-12)
    assert len(nlp.z_from_x(X)) == n + 3


def test_the_targets_their_scales_and_the_weighted_objective(problem, nlp):
    """Targets: the objectives then every variable; scales: each objective's value and
    each variable's magnitude at the middle of the bounds (1 for a zero middle)."""
    mid = problem.midpoint()
    assert nlp.targets == [*OBJ, *(VAR + v for v in ["R", "l", "n", "p", "phi0", "d"])]
    ev = problem.evaluate(mid).objectives
    want = [ev["backlash"], ev["ripple"], ev["size"], *np.abs(mid)]
    want[-2] = 1.0  # phi0's middle is 0
    assert mid[4] == 0.0
    np.testing.assert_allclose(nlp.target_scales, want, rtol=1e-12)
    assert nlp.default_target == "backlash" and nlp.form == "epigraph"
    f = ca.Function("f", [nlp.z, nlp.p], [nlp.f])
    z = nlp.z_from_x(X)
    values = np.ravel(np.asarray(nlp.values_fun(z, nlp.param_defaults)))
    ex = problem.evaluate(X).objectives
    np.testing.assert_allclose(values[:3], [ex["backlash"], ex["ripple"], ex["size"]], rtol=1e-9)
    np.testing.assert_allclose(values[3:], X, rtol=1e-12)
    for k, name in enumerate(nlp.targets):
        got = float(f(z, nlp.params(nlp.target(name))))
        assert got == pytest.approx(values[k] / nlp.target_scales[k], rel=1e-9), name
    mix = nlp.target({"size": 2.0, "var:d": -3.0})
    got = float(f(z, nlp.params(mix)))
    assert got == pytest.approx(2.0 * ex["size"] / want[2] - 3.0 * X[5] / want[-1], rel=1e-9)
    assert nlp.objective_of(mix, values) == pytest.approx(2.0 * ex["size"] - 3.0 * X[5])


def test_the_default_objectives_are_the_problems_and_a_string_is_one_objective(problem):
    """No objectives: the problem's own; a string: that one objective; a repeated name
    once; the objective limits of the requirements join the set."""
    assert build_nlp(problem).targets[:1] == ["backlash"]
    assert build_nlp(problem).default_target == "backlash"
    one = build_nlp(problem, "size")
    assert (
        one.targets[0] == "size"
        and one.aux_names == []
        and one.eps_rows == {"size": len(one.g_names) - 1}
    )
    twice = build_nlp(problem, ["size", "size", "backlash"])
    assert twice.targets[:2] == ["size", "backlash"]
    data = tomllib.loads(CS.read_text())
    data["requirements"]["ripple_max"] = 0.05
    limited = problem_from_dict(data)
    nlp = build_nlp(limited, ["size"])
    assert nlp.targets[:2] == ["size", "ripple"]
    assert nlp.limits == {"ripple": 0.05}
    row = nlp.eps_rows["ripple"]
    assert nlp.ubg[row] * nlp.g_scale[row] == pytest.approx(0.05, rel=1e-12)
    assert nlp.ubg[nlp.eps_rows["size"]] == np.inf


def test_an_objective_with_no_set_has_no_default_target(problem):
    """objectives=[] (the robust formulation's base): no targets but the variables."""
    nlp = build_nlp(problem, [])
    assert nlp.default_target == "" and nlp.eps_rows == {} and nlp.aux_names == []
    assert nlp.aux_init is None and nlp.targets[0] == "var:R"
    assert nlp.z_from_x(X).shape == (6,)


def test_an_unknown_objective_or_form_is_refused_naming_it(problem):
    with pytest.raises(ProblemError, match=r"^formulation form 'x': use 'epigraph' or 'naive'$"):
        build_nlp(problem, form="x")
    with pytest.raises(
        ProblemError,
        match=r"^objective 'mass' is not available for this problem \(available: ripple, "
        r"backlash, backlash_rss, size, nut_travel, motor_torque, drive_loss\)$",
    ):
        build_nlp(problem, ["size", "mass"])


def test_the_naive_form_puts_max_and_spread_in_the_objective(problem):
    """form="naive": no auxiliaries and no envelope rows; the values are the max and the
    grid spread of the expressions themselves."""
    nlp = build_nlp(problem, OBJ, form="naive")
    assert nlp.form == "naive" and nlp.aux_names == [] and nlp.aux_init is None
    assert not any("envelope" in g for g in nlp.g_names)
    values = np.ravel(np.asarray(nlp.values_fun(nlp.z_from_x(X), nlp.param_defaults)))
    ev = problem.evaluate(X).objectives
    np.testing.assert_allclose(values[:3], [ev["backlash"], ev["ripple"], ev["size"]], rtol=1e-9)


def test_a_requirement_bound_of_zero_takes_the_blocks_size_as_its_scale(problem):
    """A block whose bounds are both 0 (or absent on one side) is scaled by its size at
    the middle of the bounds; one bounded by 0.5 by 0.5."""
    data = tomllib.loads(CS.read_text())
    p = problem_from_dict(data)
    p.add_constraint(
        "gap", lambda q: q.design["l"] - q.design["R"], lower=0.0, unit="mm", over="design"
    )
    p.add_constraint("lead_ratio", lambda q: q.design["p"] / 20.0, upper=0.5, over="design")
    nlp = build_nlp(p, ["size"])
    k = nlp.g_names.index("lead_ratio")
    assert (nlp.g_scale[k], nlp.ubg[k], nlp.lbg[k]) == (0.5, 1.0, -np.inf)  # its own bound
    k = nlp.g_names.index("gap")
    mid = p.midpoint()
    assert nlp.g_scale[k] == pytest.approx(abs(mid[1] - mid[0]), rel=1e-12)
    assert nlp.lbg[k] == 0.0 and nlp.ubg[k] == np.inf and nlp.g_units[k] == "mm"
    assert _g(nlp, X)[k] == pytest.approx(X[1] - X[0], rel=1e-12)


# --------------------------------------------------------------------------------------
# the parameters (a catalogue problem's item data)
# --------------------------------------------------------------------------------------
def test_the_parameters_sit_at_the_tail_of_p_with_their_defaults():
    p = load_problem(CATALOGUE)
    nlp = build_nlp(p)
    assert nlp.param_names == list(p.parameters())
    np.testing.assert_array_equal(nlp.param_defaults, list(p.parameters().values()))
    assert nlp.param_defaults.dtype == np.float64
    t = nlp.target()
    w = nlp.params(t)
    assert len(w) == len(nlp.targets) + len(nlp.param_names)
    np.testing.assert_array_equal(w[len(nlp.targets) :], nlp.param_defaults)
    given = np.arange(len(nlp.param_names), dtype=float) + 3.0
    np.testing.assert_array_equal(nlp.params(t, given)[len(nlp.targets) :], given)
    np.testing.assert_array_equal(nlp.params(t, [3, 4])[len(nlp.targets) :], given)
    assert nlp.theta.shape == (len(nlp.param_names), 1)
    name = nlp.param_names[1]
    vec = nlp.parameter_vector({name: 7})
    want = nlp.param_defaults.copy()
    want[1] = 7.0
    np.testing.assert_array_equal(vec, want)
    np.testing.assert_array_equal(nlp.param_defaults, list(p.parameters().values()))  # a copy
    assert nlp.parameter_vector({}) is None and nlp.parameter_vector(None) is None
    np.testing.assert_array_equal(nlp.parameter_values(None), nlp.param_defaults)
    np.testing.assert_array_equal(nlp.parameter_values([1, 2]), [1.0, 2.0])
    assert nlp.parameter_values([1, 2]).dtype == np.float64
    assert nlp.bounds(parameters={name: 7}).parameters.tolist() == want.tolist()
    assert nlp.bounds().parameters is None


# --------------------------------------------------------------------------------------
# NLP: targets, bounds, starts
# --------------------------------------------------------------------------------------
def test_a_target_from_a_name_a_mapping_or_nothing(nlp):
    assert nlp.target() == Target((("backlash", 1.0),))
    assert nlp.target("size") == Target((("size", 1.0),))
    t = nlp.target({"size": 2, "var:R": 1})
    assert t.coefficients == (("size", 2.0), ("var:R", 1.0))
    assert isinstance(t.coefficients[0][1], float)
    assert nlp.target(t) is t
    assert t.name == "weighted_sum" and nlp.target("size").name == "size"
    assert Target((("size", 2.0),)).name == "weighted_sum"
    with pytest.raises(
        ProblemError,
        match=r"^objective 'mass' is not in this formulation \(available: backlash, ripple, size\)$",
    ):
        nlp.target({"size": 1.0, "mass": 1.0})


def test_the_weights_add_up_over_a_repeated_target(nlp):
    """params: each coefficient divided by its target's scale, repeated names summed."""
    t = Target((("size", 1.0), ("size", 2.0), ("var:l", 4.0)))
    w = nlp.params(t)
    want = np.zeros(len(nlp.targets))
    want[2] = 3.0 / nlp.target_scales[2]
    want[4] = 4.0 / nlp.target_scales[4]
    np.testing.assert_allclose(w, want, rtol=1e-15)
    assert nlp.objective_of(t, np.arange(10.0)) == pytest.approx(1.0 * 2 + 2.0 * 2 + 4.0 * 4)


def test_epsilon_limits_are_tightened_by_the_requirements_own_limit(problem):
    data = tomllib.loads(CS.read_text())
    data["requirements"]["ripple_max"] = 0.05
    nlp = build_nlp(problem_from_dict(data), OBJ)
    rb, rr = nlp.eps_rows["backlash"], nlp.eps_rows["ripple"]
    b = nlp.bounds(eps={"backlash": 0.001, "ripple": 0.2})
    assert b.ubg[rb] * nlp.g_scale[rb] == pytest.approx(0.001, rel=1e-12)
    assert b.ubg[rr] * nlp.g_scale[rr] == pytest.approx(0.05, rel=1e-12)  # the requirement's
    b = nlp.bounds(eps={"ripple": 0.01})
    assert b.ubg[rr] * nlp.g_scale[rr] == pytest.approx(0.01, rel=1e-12)  # tighter: the eps
    assert b.ubg[rb] == np.inf
    np.testing.assert_array_equal(b.lbg, nlp.lbg)
    assert nlp.ubg[rr] * nlp.g_scale[rr] == pytest.approx(0.05)  # the default is not changed
    with pytest.raises(
        ProblemError,
        match=r"^epsilon bound on 'mass': not an objective of this formulation "
        r"\(backlash, ripple, size\)$",
    ):
        nlp.bounds(eps={"mass": 1.0})


def test_a_box_maps_each_variables_limits_into_the_scaled_variable(problem, nlp):
    b = nlp.bounds(box={"l": (60.0, 100.0), "d": (4.0, 30.0)})
    lo, hi = problem.lower(), problem.upper()
    want_lo = nlp.lbz.copy()
    want_hi = nlp.ubz.copy()
    want_lo[1], want_hi[1] = (60 - lo[1]) / (hi[1] - lo[1]), (100 - lo[1]) / (hi[1] - lo[1])
    np.testing.assert_allclose(b.lbz, want_lo, rtol=1e-15)
    np.testing.assert_allclose(b.ubz, want_hi, rtol=1e-15)
    assert (b.lbz[5], b.ubz[5]) == (0.0, 1.0)
    assert nlp.lbz[1] == 0.0 and nlp.ubz[1] == 1.0  # the defaults are not changed
    plain = nlp.bounds()
    assert plain.lbz is nlp.lbz and plain.ubg is nlp.ubg and plain.lbg is nlp.lbg


def test_x_from_z_scales_and_clips_into_the_bounds(problem, nlp):
    lo, hi = problem.lower(), problem.upper()
    z = np.array([0.5, -0.1, 1.2, 0.0, 1.0, 0.25, 9.0, 9.0, 9.0])
    x = nlp.x_from_z(z)
    want = lo + (hi - lo) * np.clip(z[:6], 0, 1)
    np.testing.assert_allclose(x, want, rtol=1e-15)
    assert x.shape == (6,)
    np.testing.assert_allclose(nlp.x_from_z([list(z)]), want, rtol=1e-15)
    np.testing.assert_allclose(nlp.x_from_z(nlp.z_from_x(X)), X, rtol=1e-14)


def test_a_start_from_a_design_or_a_vector_and_its_multipliers(nlp):
    s = nlp.start(x0=X)
    np.testing.assert_allclose(s.z0, nlp.z_from_x(X), rtol=1e-15)
    assert s.lam_x0 is None and s.lam_g0 is None
    z = [[0.5] * 9]
    s = nlp.start(z0=z, lam_x0=[[1, 2]], lam_g0=[3])
    assert s.z0.tolist() == [0.5] * 9 and s.z0.dtype == np.float64
    assert s.lam_x0.tolist() == [1.0, 2.0] and s.lam_x0.dtype == np.float64
    assert s.lam_g0.tolist() == [3.0]
    s = nlp.start(x0=X + 100.0, z0=[0] * 9)  # z0 wins, as floats
    assert s.z0.tolist() == [0.0] * 9 and s.z0.dtype == np.float64
    with pytest.raises(ValueError, match=r"^give x0 or z0$"):
        nlp.start()
    assert _vec(None) is None and _vec([[1], [2]]).tolist() == [1.0, 2.0]


def test_the_aux_starts_take_the_parameters_of_the_solve():
    """z_from_x evaluates the auxiliaries with the given parameters (default: theirs)."""
    p = load_problem(CATALOGUE)
    nlp = build_nlp(p, ["backlash"])
    x = p.midpoint()
    default = nlp.z_from_x(x)
    same = nlp.z_from_x(x, nlp.param_defaults)
    np.testing.assert_array_equal(default, same)
    other = nlp.param_defaults * 1.3
    moved = nlp.z_from_x(x, other)
    assert moved[-1] != default[-1]
    g = np.ravel(np.asarray(nlp.g_fun(moved, other)))
    envelope = [k for k, name in enumerate(nlp.g_names) if name.startswith("backlash_envelope")]
    assert min(g[envelope]) == pytest.approx(0.0, abs=1e-12)  # tight at the solve's values


def test_the_fingerprint_differs_with_the_objective_set(problem, nlp):
    assert nlp.fingerprint == build_nlp(problem, OBJ).fingerprint
    assert nlp.fingerprint != build_nlp(problem, ["backlash", "ripple"]).fingerprint


# --------------------------------------------------------------------------------------
# ConstraintRows, typical, numeric_value
# --------------------------------------------------------------------------------------
def test_constraint_rows_divide_by_the_scale_and_name_each_row():
    rows = ConstraintRows()
    x = ca.SX.sym("x", 2)
    rows.add(x, 1.0, None, 2.0, "a", ["p", "q"], "mm")
    rows.add(x[0] * 0, None, 6.0, 3.0, "b", [""], "N")
    rows.add(x, -4.0, 8.0, 4.0, "c", ["only one"], "")
    assert rows.names == ["a[p]", "a[q]", "b", "c[0]", "c[1]"]
    assert rows.units == ["mm", "mm", "N", "", ""]
    assert rows.scales == [2.0, 2.0, 3.0, 4.0, 4.0]
    assert rows.lbg == [0.5, 0.5, -np.inf, -1.0, -1.0]
    assert rows.ubg == [np.inf, np.inf, 2.0, 2.0, 2.0]
    g = ca.Function("g", [x], [rows.g()])
    assert np.ravel(np.asarray(g([4.0, 6.0]))).tolist() == [2.0, 3.0, 0.0, 1.0, 1.5]
    assert rows.g().shape == (5, 1)
    assert ConstraintRows().g().shape == (0, 1)


def test_typical_is_the_largest_finite_magnitude_or_one():
    assert typical([-3.0, 2.0]) == 3.0
    assert typical(-0.5) == 0.5
    assert typical([np.nan, -2.0, 1.0]) == 2.0
    assert typical([np.nan, np.nan]) == 1.0
    assert typical([]) == 1.0
    assert typical([0.0, 0.0]) == 1.0
    assert typical([np.inf, 2.0]) == 1.0
    assert isinstance(typical(np.float32(2.5)), float)


def test_numeric_value_of_each_kind_of_term():
    class T:
        def __init__(self, kind, expr):
            self.kind, self.expr = kind, expr

    assert numeric_value(T("spread", [[1.0, 3.0], [2.0, 2.5]])) == pytest.approx(0.5)
    assert numeric_value(T("max", [1.0, -4.0, 2.0])) == 2.0
    assert numeric_value(T("scalar", [[7.0, 8.0]])) == 7.0
    assert numeric_value(T("scalar", 5)) == 5.0


def test_first_order_flattening_reaches_the_values_and_the_scales(problem):
    """first_order=True: the rows, values and scales are the first-order Hertz model's."""
    nlp = build_nlp(problem, ["backlash"], first_order=True)
    plain = build_nlp(problem, ["backlash"])

    def grid(x):
        ex = problem.expressions(problem.design_dict(x), first_order=True)
        return np.ravel(np.asarray(ex.objectives["backlash"].expr, dtype=float))

    b, mid = grid(X), grid(problem.midpoint())
    value = np.ravel(np.asarray(nlp.values_fun(nlp.z_from_x(X), [])))[0]
    assert value == pytest.approx(b.max(), rel=1e-9)
    assert abs(value - problem.evaluate(X).objectives["backlash"]) > 1e-6 * value
    assert nlp.target_scales[0] == pytest.approx(mid.max(), rel=1e-12)
    assert nlp.target_scales[0] != pytest.approx(plain.target_scales[0], rel=1e-9)
    assert nlp.g_scale[0] == pytest.approx(np.max(np.abs(mid)), rel=1e-12)


def test_a_variables_target_scale_is_its_middles_magnitude_even_below_one():
    """phi0 in [-0.6, 1.0] rad: its middle 0.2 rad is its scale (1 only for a zero middle)."""
    data = tomllib.loads(CS.read_text())
    data["variables"]["phi0"] = {"lower": "-0.6 rad", "upper": "1.0 rad"}
    data["variables"]["n"] = {"lower": "-1.5 mm", "upper": "1.0 mm"}
    nlp = build_nlp(problem_from_dict(data), ["size"])
    assert nlp.targets[3:5] == ["var:n", "var:p"]
    assert nlp.target_scales[3] == pytest.approx(0.25, rel=1e-12)
    assert nlp.target_scales[5] == pytest.approx(0.2, rel=1e-12)


PROBLEMS = ROOT / "problems"


# --- NLP rows: both bounds scaled by the row's divisor -------------------------------------
def test_nlp_rows_are_scaled_on_both_sides():
    from optdesign.formulations.nlp.solve import formulation_for

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


def test_an_nlp_of_one_objective_named_by_a_string_holds_that_objective():
    from optdesign.programs.nlp import build_nlp

    fork = load(ROOT / "problems" / "fork_min_backlash.toml")
    assert list(build_nlp(fork, "size").objective_values) == ["size"]
    assert list(build_nlp(fork, ["size", "backlash"]).objective_values) == ["size", "backlash"]


def test_an_epsilon_bound_on_a_quantity_the_formulation_lacks_is_refused_naming_them():
    from optdesign.errors import ProblemError
    from optdesign.formulations.nlp.solve import formulation_for
    from optdesign.problem import load_problem

    problem = load_problem(ROOT / "problems" / "cs_min_backlash.toml")
    nlp = formulation_for(problem, ("backlash", "ripple"))
    with pytest.raises(ProblemError) as caught:
        nlp.bounds(eps={"size": 1.0})
    assert str(caught.value) == (
        "epsilon bound on 'size': not an objective of this formulation (backlash, ripple)"
    )
