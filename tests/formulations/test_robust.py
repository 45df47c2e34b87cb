"""Robust design (issue 7 part 5): tolerances, sampled fit, SAA CVaR NLP, independent MC."""

from __future__ import annotations

import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from optdesign.errors import InputError, ProblemError
from optdesign.formulations.robust import (
    Samples,
    build_robust_nlp,
    draw_samples,
    sampled_objective,
)
from optdesign.problem.load import load_problem, problem_from_dict
from optdesign.studies.nlp_solve import solve_nlp
from optdesign.studies.robust import (
    compare_nominal_robust,
    empirical_cvar,
    monte_carlo,
    paired_bootstrap,
    solve_robust,
)

ROOT = Path(__file__).resolve().parents[2]
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
    from optdesign.studies.formulation_registry import choose_formulation

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
