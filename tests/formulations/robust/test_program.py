"""Robust design (issue 7 part 5): tolerances, sampled fit, SAA CVaR NLP, independent MC."""

from __future__ import annotations

import tomllib
from pathlib import Path
from types import SimpleNamespace

import casadi as ca
import numpy as np
import pytest

from optdesign.errors import InputError, ProblemError
from optdesign.formulations.nlp.solve import solve_nlp
from optdesign.formulations.robust.program import (
    STD_EPS,
    Samples,
    build_robust_nlp,
    draw_samples,
    perturb,
    pin_count,
    risk_label,
    sampled_objective,
    tolerances_of,
)
from optdesign.formulations.robust.solve import (
    compare_nominal_robust,
    empirical_cvar,
    monte_carlo,
    paired_bootstrap,
    solve_robust,
)
from optdesign.problem import load_problem, problem_from_dict

ROOT = Path(__file__).resolve().parents[3]
FILE = ROOT / "problems" / "cs_min_backlash_robust.toml"

#: Nominal optimum of cs_min_backlash (api notes: 0.0362197 deg; p non-unique).
X_NOMINAL = np.array([107.198786, 54.3237177, 102.864978, 5.15655733, 0.205121213, 5.74099157])


def _data(**tolerances):
    data = tomllib.loads(FILE.read_text())
    if tolerances:
        data["tolerances"] = tolerances
    return data


@pytest.fixture(scope="module")
def problem():
    return problem_from_dict(_data())


@pytest.fixture(scope="module")
def nominal(problem):
    return solve_nlp(problem, starts=2, x0=X_NOMINAL)


def test_tolerances_parse_to_internal_units(problem):
    tol = problem.spec.tolerances
    assert tol.R.band == pytest.approx(0.05) and tol.R.distribution == "normal"
    assert tol.phi0.band == pytest.approx(np.radians(0.1)) and tol.phi0.distribution == "uniform"
    assert (tol.fit, tol.samples, tol.risk, tol.alpha) == ("uniform", 32, "cvar", 0.9)


def test_tolerance_errors_name_the_field():
    with pytest.raises(ProblemError, match=r"tolerances\.R.*band must be >= 0"):
        problem_from_dict(_data(R="-0.05 mm"))
    with pytest.raises(ProblemError, match=r"tolerances\.phi0\.band"):
        problem_from_dict(_data(phi0={"band": "0.1 mm"}))
    with pytest.raises(ProblemError, match=r"tolerances\.Q: unknown field"):
        problem_from_dict(_data(Q="1 mm"))


def test_a_tolerances_table_that_names_no_tolerance_is_refused_on_load(tmp_path):
    """An empty [tolerances] (or one of settings only) scatters nothing: refused naming
    the table, not later as "need at least one sample"."""
    hint = 'give a variable\'s band (e.g. R = "0.05 mm") or fit = "uniform", or leave the table out'
    data = _data()
    data["tolerances"] = {}
    with pytest.raises(ProblemError) as err:
        problem_from_dict(data)
    assert str(err.value).startswith(
        f"problem: tolerances: the table is empty: it names no tolerance; {hint}"
    )
    data["tolerances"] = {"samples": 8, "seed": 2}
    with pytest.raises(ProblemError) as err:
        problem_from_dict(data)
    assert str(err.value).startswith(
        f"problem: tolerances: names no tolerance, only settings (samples, seed); {hint}"
    )
    path = tmp_path / "p.toml"
    path.write_text(FILE.read_text().split("[tolerances]")[0] + "[tolerances]\n")
    with pytest.raises(ProblemError) as err:
        load_problem(path)
    assert str(err.value).startswith(f"{path}: tolerances: the table is empty")
    data["tolerances"] = {"fit": "uniform"}  # the fits scatter: a tolerance
    assert problem_from_dict(data).spec.tolerances.fit == "uniform"


def test_draws_have_the_declared_spread(problem):
    s = draw_samples(problem, 40_000, 3)
    assert np.std(s.deltas["R"]) == pytest.approx(0.05 / 3, rel=0.02)  # normal, sigma = band/3
    assert np.abs(s.deltas["phi0"]).max() <= np.radians(0.1)  # uniform +-band
    assert np.std(s.deltas["phi0"]) == pytest.approx(np.radians(0.1) / np.sqrt(3), rel=0.02)
    assert s.fit.shape == (40_000, 2)  # the two rod pins D and E, drawn independently
    assert abs(np.corrcoef(s.fit.T)[0, 1]) < 0.02
    again = draw_samples(problem, 40_000, 3)
    assert np.array_equal(again.deltas["n"], s.deltas["n"])


def test_sampled_fit_spans_min_to_max_clearance(problem):
    # u = 1 on both pins is the nominal model (largest clearance), u = 0 the 'min' model.
    data = _data()
    data["requirements"] = dict(data["requirements"], fit_clearance="min")
    p_min = problem_from_dict(data)
    design = problem.design_dict(X_NOMINAL)
    nominal_max = problem.evaluate(X_NOMINAL).objectives["backlash"]
    nominal_min = p_min.evaluate(X_NOMINAL).objectives["backlash"]
    hi, _ = sampled_objective(problem, design, "backlash", [1.0, 1.0])
    lo, _ = sampled_objective(problem, design, "backlash", [0.0, 0.0])
    assert np.max(hi.expr) == pytest.approx(nominal_max, rel=1e-12)
    assert np.max(lo.expr) == pytest.approx(nominal_min, rel=1e-12)
    assert nominal_min < 0.6 * nominal_max  # the fit band matters: not a no-op


def test_empirical_cvar_is_the_rockafellar_uryasev_minimum():
    v = np.random.default_rng(1).gamma(2.0, size=257)
    brute = min(c + np.mean(np.maximum(v - c, 0.0)) / 0.1 for c in v)
    assert empirical_cvar(v, 0.9) == pytest.approx(brute, rel=1e-12)
    assert empirical_cvar(v, 0.0) == pytest.approx(v.mean(), rel=1e-12)


def test_zero_tolerances_give_the_nominal_optimum(nominal):
    zero = problem_from_dict(
        _data(R="0 mm", l="0 mm", phi0="0 deg", fit="fixed", samples=3, alpha=0.5)
    )
    robust = solve_robust(zero, x0=X_NOMINAL + 0.01)
    assert robust.status == "optimal" and robust.verified
    assert robust.objective == pytest.approx(0.0362197, rel=1e-5)
    assert robust.objective == pytest.approx(nominal.objective, rel=1e-6)
    for name in ("R", "l", "n", "phi0", "d"):  # p is not unique at this optimum
        assert robust.design[name] == pytest.approx(nominal.design[name], rel=1e-4)


def test_robust_beats_nominal_in_an_independent_monte_carlo(problem, nominal):
    saa = draw_samples(problem, 16, seed=0)
    cmp = compare_nominal_robust(problem, n_mc=20_000, mc_seed=777, nominal=nominal, samples=saa)
    rob = cmp.robust
    assert rob.status == "optimal" and rob.verified  # nominal requirements hold (NumPy check)
    # The SAA statistic recomputed on the NumPy path from the same samples equals Ipopt's.
    assert rob.details.robust.saa_check == pytest.approx(rob.objective, rel=1e-7)
    assert rob.objective < cmp.nominal_saa  # in-sample: better by construction
    # Out of sample (different seed, 1250x the samples, same draws for both designs):
    # The optimised statistic, CVaR_0.9, is lower for the robust design, and the paired
    # bootstrap interval of the difference excludes 0. (The plain 95 % quantile is not
    # optimised: its difference is within the MC noise and of either sign by seed.)
    assert cmp.mc_robust.cvar < cmp.mc_nominal.cvar
    _, hi = paired_bootstrap(
        cmp.mc_nominal.values, cmp.mc_robust.values, lambda v: empirical_cvar(v, 0.9), seed=1
    )
    assert hi < 0.0
    # ... but only a little: the optimum is pinned by the nut travel and the pin pressure.
    assert cmp.mc_robust.cvar > 0.99 * cmp.mc_nominal.cvar
    # The nominal design's worst-case-fit backlash overstates the CVaR_0.9 of real builds.
    assert cmp.mc_nominal.cvar < 0.95 * nominal.objective
    # Its active requirements (nut travel, pin pressure) fail in most perturbed builds.
    assert cmp.mc_nominal.p_violation > 0.9


def test_monte_carlo_with_no_scatter_is_the_nominal_value(problem):
    samples = Samples({"R": np.zeros(5)}, np.ones((5, 2)), seed=0)
    mc = monte_carlo(
        problem, dict(zip("R l n p phi0 d".split(), X_NOMINAL, strict=True)), samples=samples
    )
    assert mc.quantile == pytest.approx(0.0362197, rel=1e-5) and mc.std < 1e-12


def test_auto_picks_robust_for_a_file_with_tolerances():
    from optdesign.cli import build_parser
    from optdesign.formulations.registry import choose_formulation

    build_parser()  # registers the formulations and their auto predicates
    from optdesign.problem import load_problem

    robust = load_problem(FILE)
    plain = load_problem(ROOT / "problems" / "cs_min_backlash.toml")
    assert choose_formulation(robust, "auto") == "robust"
    assert choose_formulation(plain, "auto") == "nlp"
    assert choose_formulation(robust, "nlp") == "nlp"


def test_a_robust_ripple_equals_its_numpy_statistic_at_the_optimum(problem):
    """The ripple (a spread over the stroke) enters the robust NLP by two envelope rows per
    sample (lo <= ratio <= hi); the statistic the NLP minimised equals the one recomputed
    on the NumPy path from the same samples (an envelope row dropped or mis-scaled would
    let the NLP report less than the design's own ripple)."""
    robust = solve_robust(problem, x0=X_NOMINAL, objective="ripple", starts=1)
    assert robust.status == "optimal" and robust.verified
    check = robust.details.robust.saa_check
    assert check is not None and robust.objective == pytest.approx(check, rel=1e-6)
    assert "ripple" in robust.details.robust.risk_label


def test_requirements_held_at_every_sample_cost_something_and_hold():
    """constrain_samples=True writes every requirement once per sample: the optimum is
    verified and no better than with the requirements at the nominal design only."""
    data = _data(
        R="0.5 mm", l="0.5 mm", n="0.5 mm", phi0="0.5 deg", fit="uniform", samples=4, seed=1
    )
    small = problem_from_dict(data)
    free = solve_robust(small, x0=X_NOMINAL, starts=1)
    held = solve_robust(small, x0=X_NOMINAL, starts=1, constrain_samples=True)
    assert free.status == held.status == "optimal" and held.verified
    assert held.objective >= free.objective * (1 - 1e-9)
    assert held.details.robust.constrain_samples and not free.details.robust.constrain_samples


def test_a_robust_nlp_offers_the_nominal_objective_as_its_second_target(problem):
    """The robust formulation's targets: the risk measure and the nominal objective, which
    at a design equals the NumPy path's value there (and names the NLP's fingerprint)."""
    nlp = build_robust_nlp(problem, samples=draw_samples(problem, 4, seed=0))
    assert nlp.targets == ["CVaR_0.9(backlash)", "backlash (nominal)"]
    assert len(nlp.fingerprint) == 16
    value = ca.Function("nominal", [nlp.z, nlp.p], [nlp.objective_values["backlash (nominal)"]])
    z = nlp.z_from_x(X_NOMINAL)
    nominal = float(value(z, nlp.params(nlp.target("backlash (nominal)"))))
    assert nominal == pytest.approx(problem.evaluate(X_NOMINAL).objectives["backlash"], rel=1e-9)
    assert nominal == pytest.approx(0.0362197, rel=1e-5)


def test_sampled_fit_draws_one_per_pin_and_a_wrong_count_is_refused(problem):
    """Robust design draws one fit fraction per sized pin (0: the fit's least clearance,
    1: its largest); a count that differs from the chain's pins is refused, saying both."""
    design = problem.design_dict(X_NOMINAL)
    n_pins = sum(j.pin is not None for j in problem.quantities(design).joints)
    assert n_pins == 2

    def worst(u):
        q = problem.quantities(design, fit_fractions=[u] * n_pins)
        return float(np.max(q.backlash.worst_case))

    assert worst(0.0) < worst(0.5) < worst(1.0)
    assert worst(0.5) == pytest.approx(0.5 * (worst(0.0) + worst(1.0)), rel=0.05)
    with pytest.raises(InputError, match=r"^tolerances\.fit: 3 fit draws for 2 pin joints$"):
        problem.quantities(design, fit_fractions=[0.5] * 3).joints  # noqa: B018


def test_the_robust_nlp_is_finite_everywhere_inside_the_bounds(problem):
    """Ipopt may step to any design in the box: the sampled linkages are guarded like
    the nominal one, so the objective, the rows and their derivatives stay finite
    (at designs where a sampled linkage cannot assemble, too)."""
    nlp = build_robust_nlp(problem, samples=draw_samples(problem, 4, seed=0))
    fg = ca.Function(
        "fg",
        [nlp.z, nlp.p],
        [nlp.f, nlp.g, ca.gradient(nlp.f, nlp.z), ca.jacobian(nlp.g, nlp.z)],
    )
    weights = nlp.params(nlp.target())
    rng = np.random.default_rng(0)
    for zd in rng.random((200, nlp.n_design)):
        z = nlp.z_from_x(nlp.x_from_z(np.concatenate([zd, np.zeros(len(nlp.aux_names))])))
        for out in fg(z, weights):
            assert np.all(np.isfinite(np.asarray(out.full()))), nlp.x_from_z(z)


# The robust (sample-average) formulation's observable behaviour, pinned row by row.
#
# Issue 21 (mutation deliverable): every array, name and message that
# :mod:`optdesign.formulations.robust.program` produces - the draws, the perturbed designs, the
# per-sample epigraph rows and variables, the risk measures (CVaR, mean + k std) and
# their starts, the nominal target, the refusals - against a NumPy recomputation from the
# same draws (:meth:`DesignProblem.expressions` with the sampled fit fractions) and hand
# formulas. The nominal NLP is pinned in ``test_nlp.py``.


X = np.array([107.2, 54.3, 102.9, 5.16, 0.205, 5.74])


S = 3


def _robust_data(**tolerances):
    data = tomllib.loads(FILE.read_text())
    data["tolerances"].update(tolerances)
    return data


@pytest.fixture(scope="module")
def samples(problem):
    return draw_samples(problem, S, seed=5)


def _sample_grids(problem, samples, x, objective):
    """Each sample's objective grid on the NumPy path: the design plus the sample's
    deviations, the pins at the sample's fit fractions."""
    out = []
    for s in range(samples.n):
        design = problem.design_dict(x)
        for name, delta in samples.deltas.items():
            design[name] = design[name] + delta[s]
        fit = None if samples.fit is None else list(samples.fit[s])
        ex = problem.expressions(design, fit_fractions=fit)
        out.append(np.ravel(np.asarray(ex.objectives[objective].expr, dtype=float)))
    return out


def _mid_grid(problem, objective):
    ex = problem.expressions(problem.design_dict(problem.midpoint()))
    return np.ravel(np.asarray(ex.objectives[objective].expr, dtype=float))


def _at(nlp, x, *outputs):
    """The outputs (CasADi expressions of z, p) at the design x, aux at their starts."""
    z = nlp.z_from_x(x)
    fun = ca.Function("at", [nlp.z, nlp.p], list(outputs))
    p = nlp.params(nlp.target())
    res = fun(z, p)
    res = res if isinstance(res, tuple | list) else [res]
    out = [np.ravel(np.asarray(r, dtype=float)) for r in res]
    return [r[0] if r.size == 1 else r for r in out]


# --------------------------------------------------------------------------------------
# the draws
# --------------------------------------------------------------------------------------
def test_the_draws_are_the_seeds_numbers_in_the_variable_tables_order():
    """normal: band/3 x N(0, 1); uniform: band x U(-1, 1); then the fits U(0, 1) per pin,
    all from one generator in the mechanism's variable order (phi0 before p)."""
    data = tomllib.loads(FILE.read_text())
    data["tolerances"] = {
        "p": "0.3 mm",
        "phi0": {"band": "0.5 deg", "distribution": "uniform"},
        "R": "0.06 mm",
        "fit": "uniform",
    }
    p = problem_from_dict(data)
    s = draw_samples(p, 4, seed=9)
    rng = np.random.default_rng(9)
    r = 0.02 * rng.standard_normal(4)
    phi0 = np.radians(0.5) * rng.uniform(-1.0, 1.0, 4)
    pp = 0.1 * rng.standard_normal(4)
    fit = rng.uniform(0.0, 1.0, (4, 2))
    assert list(s.deltas) == ["R", "phi0", "p"]
    np.testing.assert_allclose(s.deltas["R"], r, rtol=1e-12)
    np.testing.assert_allclose(s.deltas["phi0"], phi0, rtol=1e-12)
    np.testing.assert_allclose(s.deltas["p"], pp, rtol=1e-12)
    np.testing.assert_allclose(s.fit, fit, rtol=1e-12)
    assert s.seed == 9 and s.n == 4


def test_a_fixed_fit_draws_no_fractions_and_the_files_tolerances_are_the_default(problem):
    data = _robust_data(fit="fixed")
    p = problem_from_dict(data)
    s = draw_samples(p, 5, seed=1)
    assert s.fit is None and s.n == 5
    tol = tolerances_of(problem)
    assert (
        draw_samples(problem, 2, 3, tol).deltas.keys() == draw_samples(problem, 2, 3).deltas.keys()
    )
    np.testing.assert_array_equal(
        draw_samples(problem, 2, 3).fit, draw_samples(problem, 2, 3, tol).fit
    )


def test_a_fit_draw_without_a_pin_is_refused_naming_the_field():
    data = tomllib.loads((ROOT / "problems" / "cs_min_ripple.toml").read_text())
    data["tolerances"] = {"R": "0.05 mm", "fit": "uniform"}
    p = problem_from_dict(data)
    assert pin_count(p) == 0
    with pytest.raises(
        ProblemError, match=r"^tolerances\.fit: the problem has no pin joint to draw a fit for$"
    ):
        draw_samples(p, 3, 0)


def test_a_problem_without_tolerances_is_refused_naming_the_section():
    p = load_problem(ROOT / "problems" / "cs_min_backlash.toml")
    msg = (
        r"^tolerances: robust design needs a \[tolerances\] section \(e\.g\. "
        r'R = "0\.05 mm", phi0 = "0\.1 deg", fit = "uniform"\)$'
    )
    with pytest.raises(ProblemError, match=msg):
        tolerances_of(p)
    with pytest.raises(ProblemError, match=msg):
        draw_samples(p, 3, 0)
    with pytest.raises(ProblemError, match=msg):
        build_robust_nlp(p)


def test_pin_count_counts_the_sized_pins(problem):
    assert pin_count(problem) == 2
    assert pin_count(load_problem(ROOT / "problems" / "fork_min_backlash.toml")) == 1


def test_the_sample_count_from_the_deltas_or_the_fits():
    assert Samples({"R": np.zeros(4)}, np.zeros((2, 1)), 0).n == 4
    assert Samples({}, np.zeros((3, 2)), 0).n == 3
    assert Samples({}, None, 0).n == 0


def test_perturb_adds_one_samples_deviation_or_a_column_per_sample():
    samples = Samples({"R": np.array([0.1, 0.2, 0.3]), "l": np.array([1.0, 2.0, 3.0])}, None, 0)
    design = {"R": 10.0, "l": 20.0, "n": 5.0}
    one = perturb(design, samples, 1)
    assert one == {"R": 10.2, "l": 22.0, "n": 5.0}
    assert isinstance(one["R"], float)
    assert design == {"R": 10.0, "l": 20.0, "n": 5.0}
    many = perturb(design, samples, slice(0, 2))
    assert many["R"].shape == (2, 1) and many["R"][:, 0].tolist() == [10.1, 10.2]
    assert many["l"][:, 0].tolist() == [21.0, 22.0] and many["n"] == 5.0


def test_the_sampled_objective_at_the_fit_fractions_and_a_refused_name(problem):
    design = problem.design_dict(X)
    term, ex = sampled_objective(problem, design, "backlash", [0.25, 0.75])
    direct = problem.expressions(design, fit_fractions=[0.25, 0.75])
    np.testing.assert_allclose(term.expr, direct.objectives["backlash"].expr, rtol=1e-15)
    assert term.kind == "max" and [b.name for b in ex.constraints] == [
        b.name for b in direct.constraints
    ]
    nominal, _ = sampled_objective(problem, design, "backlash")
    assert np.max(nominal.expr) == pytest.approx(problem.evaluate(X).objectives["backlash"])
    sym = problem.design_dict(ca.SX.sym("x", 6))
    guarded, _ = sampled_objective(problem, sym, "backlash", guarded=True)
    plain, _ = sampled_objective(problem, sym, "backlash")
    assert str(guarded.expr) != str(plain.expr)
    with pytest.raises(
        ProblemError,
        match=r"^objective 'mass' is not available for this problem \(available: ripple, ",
    ):
        sampled_objective(problem, design, "mass")


def test_the_risk_labels():
    assert risk_label("cvar", 0.95, 2.0, "backlash") == "CVaR_0.95(backlash)"
    assert risk_label("mean_std", 0.95, 1.5, "ripple") == "mean+1.5std(ripple)"
    assert risk_label("mean_std", 0.9, 2.0, "size") == "mean+2std(size)"


# --------------------------------------------------------------------------------------
# build_robust_nlp: CVaR of a max objective
# --------------------------------------------------------------------------------------
def test_the_cvar_nlp_of_the_worst_case_backlash(problem, samples):
    """Per sample an epigraph t_s over the grid, then VaR and the excesses u_s; at the
    start VaR is the sample mean and every excess is tight."""
    nlp = build_robust_nlp(problem, samples=samples)
    labels = list(problem.phi_labels)
    n_phi = len(labels)
    scale = np.max(np.abs(_mid_grid(problem, "backlash")))
    label = "CVaR_0.9(backlash)"
    assert nlp.targets == [label, "backlash (nominal)"]
    np.testing.assert_allclose(nlp.target_scales, [scale, scale], rtol=1e-12)
    assert nlp.default_target == label and nlp.form == "robust-saa" and nlp.eps_rows == {}
    names = [f"backlash_max[s{s}]" for s in range(S)] + ["VaR"]
    names += [f"cvar_excess[s{s}]" for s in range(S)]
    assert nlp.aux_names == names
    n = nlp.n_design
    assert n == 6 and nlp.z.shape == (n + 2 * S + 1, 1)
    assert nlp.lbz.tolist() == [0.0] * n + [-np.inf] * (S + 1) + [0.0] * S
    assert nlp.ubz.tolist() == [1.0] * n + [np.inf] * (2 * S + 1)
    from optdesign.programs.nlp import build_nlp

    base = build_nlp(problem, [])
    nb = len(base.g_names)
    rows = [f"backlash_envelope[s{s}][{lab}]" for s in range(S) for lab in labels]
    rows += [f"cvar_excess[s{s}]" for s in range(S)]
    assert nlp.g_names == base.g_names + rows
    assert nlp.g_units == base.g_units + ["deg"] * (S * n_phi) + [""] * S
    np.testing.assert_allclose(nlp.g_scale, [*base.g_scale, *[scale] * (S * n_phi + S)])
    np.testing.assert_array_equal(nlp.lbg, [*base.lbg, *[0.0] * (S * n_phi + S)])
    np.testing.assert_array_equal(nlp.ubg, [*base.ubg, *[np.inf] * (S * n_phi + S)])

    grids = _sample_grids(problem, samples, X, "backlash")
    v = np.array([g.max() for g in grids]) / scale
    mean = v.mean()
    z = nlp.z_from_x(X)
    np.testing.assert_allclose(z[n : n + S], v, rtol=1e-9)
    assert z[n + S] == pytest.approx(mean, rel=1e-12)
    np.testing.assert_allclose(z[n + S + 1 :], np.maximum(v - mean, 0.0), atol=1e-12)
    g, f, risk, nominal = _at(nlp, X, nlp.g, nlp.f, *(nlp.objective_values[t] for t in nlp.targets))
    raw = g * nlp.g_scale
    np.testing.assert_allclose(
        raw[:nb], np.ravel(np.asarray(base.g_fun(base.z_from_x(X), []), dtype=float)) * base.g_scale
    )
    want = np.concatenate([gr.max() - gr for gr in grids])
    np.testing.assert_allclose(raw[nb : nb + S * n_phi], want, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(raw[nb + S * n_phi :], scale * np.maximum(mean - v, 0.0), atol=1e-12)
    cvar = mean + np.maximum(v - mean, 0.0).sum() / ((1 - 0.9) * S)
    assert float(f) == pytest.approx(cvar, rel=1e-9)  # weight 1/scale on cvar * scale
    assert float(risk) == pytest.approx(cvar * scale, rel=1e-9)
    assert float(nominal) == pytest.approx(problem.evaluate(X).objectives["backlash"], rel=1e-9)
    p_nominal = nlp.params(nlp.target("backlash (nominal)"))
    f_nominal = ca.Function("f", [nlp.z, nlp.p], [nlp.f])(z, p_nominal)
    assert float(f_nominal) == pytest.approx(float(nominal) / scale, rel=1e-9)


def test_the_risk_and_its_parameters_default_to_the_files_and_can_be_given(problem, samples):
    nlp = build_robust_nlp(problem, samples=samples, alpha=0.5)
    assert nlp.targets[0] == "CVaR_0.5(backlash)"
    grids = _sample_grids(problem, samples, X, "backlash")
    scale = np.max(np.abs(_mid_grid(problem, "backlash")))
    v = np.array([g.max() for g in grids]) / scale
    (f,) = _at(nlp, X, nlp.f)
    assert float(f) == pytest.approx(v.mean() + np.maximum(v - v.mean(), 0).sum() / (0.5 * S))
    zero = build_robust_nlp(problem, samples=samples, alpha=0.0)
    (f0,) = _at(zero, X, zero.f)
    assert float(f0) == pytest.approx(v.mean() + np.maximum(v - v.mean(), 0).sum() / S, rel=1e-9)
    std = build_robust_nlp(problem, samples=samples, risk="mean_std", k=1.5)
    assert std.targets[0] == "mean+1.5std(backlash)"
    assert "VaR" not in std.aux_names and not any("cvar" in g for g in std.g_names)
    (fs,) = _at(std, X, std.f)
    assert float(fs) == pytest.approx(v.mean() + 1.5 * np.sqrt(v.var() + STD_EPS), rel=1e-9)
    p = problem_from_dict(_robust_data(risk="mean_std", k=0.5, alpha=0.3))
    from_file = build_robust_nlp(p, samples=samples)
    assert from_file.targets[0] == "mean+0.5std(backlash)"
    (ff,) = _at(from_file, X, from_file.f)
    assert float(ff) == pytest.approx(v.mean() + 0.5 * np.sqrt(v.var() + STD_EPS), rel=1e-9)
    assert build_robust_nlp(p, samples=samples, risk="cvar").targets[0] == "CVaR_0.3(backlash)"
    assert build_robust_nlp(p, samples=samples, k=0.0).targets[0] == "mean+0std(backlash)"


def test_the_files_samples_are_drawn_when_none_are_given():
    p = problem_from_dict(_robust_data(samples=2, seed=4))
    nlp = build_robust_nlp(p)
    assert nlp.aux_names == [
        "backlash_max[s0]",
        "backlash_max[s1]",
        "VaR",
        "cvar_excess[s0]",
        "cvar_excess[s1]",
    ]
    given = build_robust_nlp(p, samples=draw_samples(p, 2, 4))
    np.testing.assert_array_equal(nlp.z_from_x(X), given.z_from_x(X))
    other = build_robust_nlp(p, samples=draw_samples(p, 2, 5))
    assert not np.array_equal(nlp.z_from_x(X), other.z_from_x(X))


def test_bad_risk_settings_are_refused_naming_the_field(problem, samples):
    with pytest.raises(
        ProblemError, match=r"^tolerances\.risk: 'var' is not 'cvar' or 'mean_std'$"
    ):
        build_robust_nlp(problem, samples=samples, risk="var")
    with pytest.raises(ProblemError, match=r"^tolerances\.alpha: 1\.0 must lie in \[0, 1\)$"):
        build_robust_nlp(problem, samples=samples, alpha=1.0)
    with pytest.raises(ProblemError, match=r"^tolerances\.alpha: -0\.1 must lie in \[0, 1\)$"):
        build_robust_nlp(problem, samples=samples, alpha=-0.1)
    with pytest.raises(ProblemError, match=r"^tolerances\.samples: need at least one sample$"):
        build_robust_nlp(problem, samples=Samples({}, None, 0))
    with pytest.raises(ProblemError, match=r"^objective 'mass' is not available"):
        build_robust_nlp(problem, "mass", samples=samples)


# --------------------------------------------------------------------------------------
# build_robust_nlp: a spread objective, a scalar one, requirements per sample
# --------------------------------------------------------------------------------------
def test_the_robust_ripple_has_an_envelope_pair_per_sample(problem, samples):
    nlp = build_robust_nlp(problem, "ripple", samples=samples, risk="mean_std", k=2.0)
    labels = list(problem.phi_labels)
    mid = _mid_grid(problem, "ripple")
    scale = np.max(np.abs(mid))
    v_scale = (mid.max() - mid.min()) / (mid.max() + mid.min())
    assert nlp.targets == ["mean+2std(ripple)", "ripple (nominal)"]
    np.testing.assert_allclose(nlp.target_scales, [v_scale, v_scale], rtol=1e-12)
    names = []
    for s in range(S):
        names += [f"ripple_lo[s{s}]", f"ripple_hi[s{s}]"]
    assert nlp.aux_names == names
    n = nlp.n_design
    assert nlp.lbz[n:].tolist() == [0.0, 1e-6] * S
    assert nlp.ubz[n:].tolist() == [np.inf] * (2 * S)
    rows = []
    for s in range(S):
        rows += [f"ripple_lower[s{s}][{lab}]" for lab in labels]
        rows += [f"ripple_upper[s{s}][{lab}]" for lab in labels]
    nb = len(nlp.g_names) - len(rows)
    assert nlp.g_names[nb:] == rows
    assert nlp.g_units[nb:] == [""] * len(rows)
    np.testing.assert_allclose(nlp.g_scale[nb:], scale, rtol=1e-12)
    assert nlp.lbg[nb:].tolist() == [0.0] * len(rows) and nlp.ubg[nb:].tolist() == [np.inf] * len(
        rows
    )
    grids = _sample_grids(problem, samples, X, "ripple")
    z = nlp.z_from_x(X)
    want = np.ravel([[gr.min() / scale, gr.max() / scale] for gr in grids])
    np.testing.assert_allclose(z[n:], want, rtol=1e-9)
    g, f, nominal = _at(nlp, X, nlp.g, nlp.f, nlp.objective_values["ripple (nominal)"])
    raw = (g * nlp.g_scale)[nb:]
    want = np.concatenate([np.concatenate([gr - gr.min(), gr.max() - gr]) for gr in grids])
    np.testing.assert_allclose(raw, want, rtol=1e-9, atol=1e-12)
    v = np.array([(gr.max() - gr.min()) / (gr.max() + gr.min()) for gr in grids]) / v_scale
    assert float(f) == pytest.approx(v.mean() + 2.0 * np.sqrt(v.var() + STD_EPS), rel=1e-9)
    assert float(nominal) == pytest.approx(problem.evaluate(X).objectives["ripple"], rel=1e-9)


def test_a_scalar_objective_has_no_per_sample_variable(problem, samples):
    nlp = build_robust_nlp(problem, "size", samples=samples, alpha=0.5)
    assert nlp.aux_names == ["VaR"] + [f"cvar_excess[s{s}]" for s in range(S)]
    scale = problem.evaluate(problem.midpoint()).objectives["size"]
    np.testing.assert_allclose(nlp.target_scales, [scale, scale], rtol=1e-12)
    v = []
    for s in range(S):
        d = problem.design_dict(X)
        for name, delta in samples.deltas.items():
            d[name] = d[name] + delta[s]
        v.append(float(np.ravel(problem.expressions(d).objectives["size"].expr)[0]) / scale)
    v = np.array(v)
    z = nlp.z_from_x(X)
    assert z[6] == pytest.approx(v.mean(), rel=1e-12)
    np.testing.assert_allclose(z[7:], np.maximum(v - v.mean(), 0), atol=1e-12)
    f, nominal = _at(nlp, X, nlp.f, nlp.objective_values["size (nominal)"])
    assert float(f) == pytest.approx(v.mean() + np.maximum(v - v.mean(), 0).sum() / (0.5 * S))
    assert float(nominal) == pytest.approx(problem.evaluate(X).objectives["size"], rel=1e-12)


def test_requirements_at_every_sample_are_rows_scaled_by_their_bound(problem, samples):
    """constrain_samples: each requirement once per sample, named ``block[sS]``, divided
    by its largest bound (1 when both are 0), valued at the perturbed design."""
    free = build_robust_nlp(problem, samples=samples)
    held = build_robust_nlp(problem, samples=samples, constrain_samples=True)
    extra = [k for k, name in enumerate(held.g_names) if name not in free.g_names]
    blocks = [b for b in problem.expressions(problem.design_dict(X)).constraints]
    blocks = [b for b in blocks if b.lower is not None or b.upper is not None]
    names, scales, lower, upper, units, values = [], [], [], [], [], []
    for s in range(S):
        d = problem.design_dict(X)
        for name, delta in samples.deltas.items():
            d[name] = d[name] + delta[s]
        ex = problem.expressions(d, fit_fractions=list(samples.fit[s]))
        for b in ex.constraints:
            if b.lower is None and b.upper is None:
                continue
            k = np.size(b.expr)
            names += [f"{b.name}[s{s}][{lab}]" if lab else f"{b.name}[s{s}]" for lab in b.labels]
            bound = max(abs(b.lower or 0.0), abs(b.upper or 0.0))
            scales += [bound if bound > 0 else 1.0] * k
            lower += [-np.inf if b.lower is None else b.lower] * k
            upper += [np.inf if b.upper is None else b.upper] * k
            units += [b.unit] * k
            values += list(np.ravel(np.asarray(b.expr, dtype=float)) * np.ones(k))
    assert len(blocks) == 8
    assert [held.g_names[k] for k in extra] == names
    np.testing.assert_allclose(held.g_scale[extra], scales, rtol=1e-12)
    np.testing.assert_allclose(held.lbg[extra] * held.g_scale[extra], lower, rtol=1e-12)
    np.testing.assert_allclose(held.ubg[extra] * held.g_scale[extra], upper, rtol=1e-12)
    assert [held.g_units[k] for k in extra] == units
    (g,) = _at(held, X, held.g)
    np.testing.assert_allclose((g * held.g_scale)[extra], values, rtol=1e-9, atol=1e-12)


def test_an_objective_limit_keeps_its_nominal_row_and_its_auxiliaries_start(samples):
    """A ripple limit in the requirements: the base NLP's ripple envelope (two auxiliaries)
    comes first in z, with its own starts, before the samples' variables."""
    data = _robust_data()
    data["requirements"]["ripple_max"] = 0.2
    p = problem_from_dict(data)
    nlp = build_robust_nlp(p, samples=samples)
    assert nlp.aux_names[:3] == ["ripple_lo", "ripple_hi", "backlash_max[s0]"]
    assert "ripple_max" in nlp.g_names
    row = nlp.g_names.index("ripple_max")
    assert nlp.ubg[row] * nlp.g_scale[row] == pytest.approx(0.2)
    r = np.ravel(np.asarray(p.expressions(p.design_dict(X)).objectives["ripple"].expr))
    mid = _mid_grid(p, "ripple")
    z = nlp.z_from_x(X)
    np.testing.assert_allclose(z[6:8], [r.min() / np.max(mid), r.max() / np.max(mid)], rtol=1e-9)
    (g,) = _at(nlp, X, nlp.g)
    assert (g * nlp.g_scale)[row] == pytest.approx((r.max() - r.min()) / (r.max() + r.min()))


def test_the_parameters_of_a_solve_reach_every_sample_and_the_nominal_value():
    """A catalogue problem's parameters (the table fit's ratios, placeholders 1 by
    default) sit at the tail of p: with an item's values the samples' envelopes and the
    nominal value are the NumPy path's table-fit values at that item (ISO 2338 d = 6)."""
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["tolerances"] = {"R": "0.05 mm", "fit": "uniform"}
    p = problem_from_dict(data)
    samples = draw_samples(p, 2, 0)
    nlp = build_robust_nlp(p, samples=samples)
    assert nlp.param_names == ["fit_ratio_max", "fit_ratio_min"]
    assert nlp.param_defaults.tolist() == [1.0, 1.0]
    x = np.array([107.2, 54.3, 102.9, 5.0, 0.205, 6.0])
    values = p.parameter_values({"d": (6.0, 6.0), "p": (5.0, 5.0)})
    theta = np.array([values[k] for k in nlp.param_names])
    assert abs(theta[0] - 1.0) > 0.05 and abs(theta[1] - 1.0) > 0.05
    fun = ca.Function("g", [nlp.z, nlp.p], [nlp.g, nlp.objective_values["backlash (nominal)"]])
    g, nominal = fun(nlp.z_from_x(x, theta), np.concatenate([[0.0, 1.0], theta]))
    _, placeholder = fun(nlp.z_from_x(x), np.array([0.0, 1.0, 1.0, 1.0]))
    table = p.evaluate(x).objectives["backlash"]
    assert float(nominal) == pytest.approx(table, rel=1e-9)
    assert abs(float(placeholder) - table) > 1e-3 * table  # the parameters matter here
    raw = np.ravel(np.asarray(g, dtype=float)) * nlp.g_scale
    n_phi = len(p.phi_labels)
    first = nlp.g_names.index(f"backlash_envelope[s0][{p.phi_labels[0]}]")
    for s in range(2):
        d = p.design_dict(x)
        d["R"] = d["R"] + samples.deltas["R"][s]
        ex = p.expressions(d, fit_fractions=list(samples.fit[s]))
        gs = np.ravel(np.asarray(ex.objectives["backlash"].expr, dtype=float))
        rows = raw[first + s * n_phi : first + (s + 1) * n_phi]
        np.testing.assert_allclose(rows, gs.max() - gs, rtol=1e-9, atol=1e-12)


def test_a_fixed_fit_keeps_the_requirements_clearance_in_every_sample(problem):
    """fit = "fixed": no fit draw; every sample's pins keep the nominal fit clearance."""
    p = problem_from_dict(_robust_data(fit="fixed"))
    samples = draw_samples(p, 2, 1)
    nlp = build_robust_nlp(p, samples=samples)
    z = nlp.z_from_x(X)
    scale = np.max(np.abs(_mid_grid(p, "backlash")))
    want = []
    for s in range(2):
        d = problem.design_dict(X)
        for name, delta in samples.deltas.items():
            d[name] = d[name] + delta[s]
        want.append(np.max(p.expressions(d).objectives["backlash"].expr) / scale)
    np.testing.assert_allclose(z[6:8], want, rtol=1e-9)


def test_a_sampled_requirement_bounded_by_zero_is_scaled_by_one(samples):
    """constrain_samples: a requirement whose bound is 0 keeps the scale 1 per sample
    (the nominal row takes its size at the middle of the bounds)."""
    p = problem_from_dict(_robust_data())
    p.add_constraint(
        "gap", lambda q: q.design["l"] - q.design["R"], lower=0.0, unit="mm", over="design"
    )
    nlp = build_robust_nlp(p, samples=samples, constrain_samples=True)
    rows = [k for k, name in enumerate(nlp.g_names) if name.startswith("gap[s")]
    assert [nlp.g_names[k] for k in rows] == [f"gap[s{s}]" for s in range(S)]
    assert nlp.g_scale[rows].tolist() == [1.0] * S
    assert nlp.lbg[rows].tolist() == [0.0] * S and nlp.ubg[rows].tolist() == [np.inf] * S
    (g,) = _at(nlp, X, nlp.g)
    want = [X[1] + samples.deltas["l"][s] - X[0] - samples.deltas["R"][s] for s in range(S)]
    np.testing.assert_allclose(g[rows], want, rtol=1e-9)
    mid = p.midpoint()
    assert nlp.g_scale[nlp.g_names.index("gap")] == pytest.approx(abs(mid[1] - mid[0]))


def test_the_tolerances_given_are_drawn_rather_than_the_files(problem):
    """draw_samples(tol=...) draws the given section, not the problem's own."""
    other = problem_from_dict(
        _robust_data(R="0.2 mm", l="0 mm", n="0 mm", phi0="0 deg", fit="fixed")
    )
    tol = tolerances_of(other)
    s = draw_samples(problem, 3, 2, tol)
    assert s.fit is None
    rng = np.random.default_rng(2)
    np.testing.assert_allclose(s.deltas["R"], 0.2 / 3 * rng.standard_normal(3), rtol=1e-12)
    assert draw_samples(problem, 3, 2).fit.shape == (3, 2)


def test_a_fit_draw_for_a_single_pin_has_one_column():
    """The fork's one sized pin: one fit fraction per sample."""
    data = tomllib.loads((ROOT / "problems" / "fork_min_backlash.toml").read_text())
    data["tolerances"] = {"R": "0.05 mm", "fit": "uniform"}
    p = problem_from_dict(data)
    s = draw_samples(p, 3, 0)
    rng = np.random.default_rng(0)
    rng.standard_normal(3)
    np.testing.assert_allclose(s.fit, rng.uniform(0.0, 1.0, (3, 1)), rtol=1e-12)


def test_one_sample_is_enough_and_no_scatter_leaves_only_the_variance_guard(problem):
    """S = 1 is accepted; with every sample at the nominal design the mean + k std
    measure is the nominal value plus k sqrt(STD_EPS) (the guard keeps sqrt smooth)."""
    one = build_robust_nlp(problem, samples=Samples({"R": np.array([0.01])}, None, 0))
    assert one.aux_names == ["backlash_max[s0]", "VaR", "cvar_excess[s0]"]
    flat = Samples({"R": np.zeros(3)}, None, 0)
    nlp = build_robust_nlp(problem, samples=flat, risk="mean_std", k=3.0)
    scale = np.max(np.abs(_mid_grid(problem, "backlash")))
    v = problem.evaluate(X).objectives["backlash"] / scale
    (f,) = _at(nlp, X, nlp.f)
    assert float(f) == pytest.approx(v + 3.0 * np.sqrt(STD_EPS), rel=1e-12)
    assert float(f) - v == pytest.approx(3e-6, rel=1e-6)


def test_a_requirement_bound_below_one_is_its_own_scale_in_every_sample(samples):
    """A requirement bounded above by 0.5 only is divided by 0.5 (not by 1) per sample."""
    p = problem_from_dict(_robust_data())
    p.add_constraint("lead_ratio", lambda q: q.design["p"] / 20.0, upper=0.5, over="design")
    nlp = build_robust_nlp(p, samples=samples, constrain_samples=True)
    rows = [k for k, name in enumerate(nlp.g_names) if name.startswith("lead_ratio")]
    assert [nlp.g_names[k] for k in rows] == ["lead_ratio"] + [
        f"lead_ratio[s{s}]" for s in range(S)
    ]
    assert nlp.g_scale[rows].tolist() == [0.5] * (S + 1)
    assert nlp.ubg[rows].tolist() == [1.0] * (S + 1) and nlp.lbg[rows].tolist() == [-np.inf] * (
        S + 1
    )


def test_a_robust_nlp_takes_the_callers_risk_measure_over_the_files():
    """``build_robust_nlp(..., risk=...)`` (od.solve's robust formulation with a risk of
    the caller's): the caller's measure is minimised, the file's only by default."""
    from optdesign.formulations.robust.program import build_robust_nlp
    from optdesign.problem import load_problem

    problem = load_problem(ROOT / "problems" / "cs_min_backlash_robust.toml")  # risk = "cvar"
    assert build_robust_nlp(problem).default_target == "CVaR_0.9(backlash)"
    assert build_robust_nlp(problem, risk="mean_std").default_target == "mean+2std(backlash)"
    # and the caller's k of mean + k std, and alpha of CVaR, over the file's (2 and 0.9)
    assert build_robust_nlp(problem, risk="mean_std", k=3.0).default_target == (
        "mean+3std(backlash)"
    )
    assert build_robust_nlp(problem, alpha=0.8).default_target == "CVaR_0.8(backlash)"


def test_a_robust_nlp_of_no_sample_is_refused_naming_the_field():

    from optdesign.errors import ProblemError
    from optdesign.formulations.robust.program import build_robust_nlp
    from optdesign.problem import load_problem

    problem = load_problem(ROOT / "problems" / "cs_min_backlash_robust.toml")
    with pytest.raises(ProblemError) as caught:
        build_robust_nlp(problem, samples=SimpleNamespace(n=0))
    assert str(caught.value) == "tolerances.samples: need at least one sample"


def test_a_robust_ripple_names_every_samples_envelope_variables():
    """A spread objective (the ratio ripple) under scatter: two envelope variables per
    sample, each named, as many names as auxiliary variables."""
    from optdesign.formulations.robust.program import build_robust_nlp, draw_samples
    from optdesign.problem import load_problem

    problem = load_problem(ROOT / "problems" / "cs_min_backlash_robust.toml")
    samples = draw_samples(problem, 3, 0)
    nlp = build_robust_nlp(problem, "ripple", samples=samples)
    assert nlp.z.shape[0] == nlp.n_design + len(nlp.aux_names)
    for s in range(3):
        assert {f"ripple_lo[s{s}]", f"ripple_hi[s{s}]"} <= set(nlp.aux_names)
