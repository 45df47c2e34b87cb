"""Issue 24: what each requirement costs - sensitivities of an optimum from the solver's
multipliers, checked against finite-difference re-solves (warm-started, both sides)."""

import json
from pathlib import Path

import pytest

import optdesign as od
from optdesign.errors import ProblemError
from optdesign.formulations.nlp.sensitivities import finite_difference, nlp_sensitivities
from optdesign.problem.parameters import perturbed, requirement_paths
from optdesign.reports.costs_text import cost_text
from optdesign.reports.result_json import result_document
from optdesign.solvers.result import Sensitivity

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"


def _check_against_resolves(problem, result, rel=0.01):
    """Every sensitivity of ``result`` equals the central difference of two re-solves."""
    assert result.sensitivities
    for s in result.sensitivities:
        d, p = finite_difference(problem, result, s.name)
        fd_log = d * p / result.objective
        assert s.log_sensitivity == pytest.approx(fd_log, rel=rel), s.name


@pytest.fixture(scope="module")
def fork():
    problem = od.load(PROBLEMS / "fork_min_backlash.toml")
    return problem, od.solve(problem, ranges=False)


def test_fork_sensitivities_equal_finite_difference_resolves(fork):
    problem, result = fork
    _check_against_resolves(problem, result)
    names = [s.name for s in result.sensitivities]
    # the binding requirements of this optimum, most costly first
    assert names[0] == "requirements.nut_travel_max"
    assert "requirements.hinge_moment" in names
    assert "requirements.pin_shear_stress_max" not in names  # not binding: no cost
    logs = [float(f"{abs(s.log_sensitivity):.6g}") for s in result.sensitivities]
    assert logs == sorted(logs, reverse=True)  # by the size of the effect to 6 digits


def test_sensitivity_in_the_users_units(fork):
    _problem, result = fork
    s = next(s for s in result.sensitivities if s.name == "requirements.hinge_moment")
    assert (s.limit, s.unit, s.objective, s.objective_unit) == (500.0, "N*m", "backlash", "deg")
    # d(backlash in deg)/d(hinge moment in N*m) from the log-sensitivity
    # (the GP's objective: the log-sensitivity is of the exact NLP's optimum, 1e-4 apart)
    assert s.d_objective_d_limit == pytest.approx(
        s.log_sensitivity * result.objective / 500.0, rel=1e-3
    )
    assert s.text() == (
        f"hinge_moment 500 N*m: raising it by 1 % to 505 N*m -> backlash {s.log_sensitivity:+.3g} %"
    )
    assert s.log_sensitivity == pytest.approx(0.2359, abs=5e-4)


def test_sensitivities_in_summary_json_and_report(fork, tmp_path):
    _problem, result = fork
    text = result.summary()
    assert "what each limit costs" in text
    assert cost_text(result.sensitivities[0]) in text
    doc = result_document(result)
    first = doc["sensitivities"][0]
    assert first["name"] == "requirements.nut_travel_max"
    assert first["limit"] == {"value": 110.0, "unit": "mm"}
    assert first["d_objective_d_limit"]["unit"] == "deg/mm"
    assert first["log_sensitivity"] == pytest.approx(result.sensitivities[0].log_sensitivity)
    assert json.loads(result.to_json())["sensitivities"][0]["name"] == first["name"]
    page = od.report(result, tmp_path / "r.html").read_text()
    assert "what each limit costs" in page
    assert "nut_travel_max 110 mm: raising it by 1 % to 111.1 mm -\\u003e backlash" in page


def test_active_bounds_and_a_scalar_objective():
    # size is a one-value objective (its own parameter dependence counts), and its
    # optimum sits on the bounds of l and p: their multipliers price them
    problem = od.load(PROBLEMS / "cs_min_backlash.toml")
    result = od.solve(problem, objective="size", ranges=False)
    names = [s.name for s in result.sensitivities]
    assert "variables.l.lower" in names and "variables.p.lower" in names
    _check_against_resolves(problem, result)
    bound = next(s for s in result.sensitivities if s.name == "variables.l.lower")
    assert (bound.limit, bound.unit) == (40.0, "mm") and bound.d_objective_d_limit > 0


def test_cli_json_carries_sensitivities(tmp_path, capsys):
    from optdesign.cli import main

    code = main(["solve", str(PROBLEMS / "fork_min_backlash.toml"), "--json", "--no-ranges"])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["sensitivities"][0]["name"] == "requirements.nut_travel_max"


def test_gp_result_takes_the_exact_nlps_sensitivities(fork):
    _problem, result = fork
    assert result.formulation == "gp"
    assert "sensitivities: of the exact NLP's optimum, from Ipopt's multipliers" in result.notes


def test_no_multipliers_no_sensitivities(fork):
    from optdesign.formulations.nlp.solve import solve_nlp

    problem, _ = fork
    result = solve_nlp(problem, starts=1)
    assert nlp_sensitivities(problem, result)  # with Ipopt's multipliers
    result.raw = {"z": result.raw["z"]}
    assert nlp_sensitivities(problem, result) == []


SHIPPED_NLP = ["cs_min_ripple", "cs_min_backlash", "fork_min_backlash", "pivot_min_backlash"]


@pytest.mark.slow
@pytest.mark.parametrize("name", SHIPPED_NLP)
def test_every_shipped_problem_every_objective(name):
    problem = od.load(PROBLEMS / f"{name}.toml")
    checked = 0
    for objective in ("backlash", "ripple", "size", "motor_torque"):
        try:
            result = od.solve(problem, objective=objective, ranges=False)
        except ProblemError:  # not available for this problem (no pin: no backlash)
            continue
        assert result.success
        _check_against_resolves(problem, result)
        checked += 1
    assert checked >= 3


def test_the_gps_own_duals_agree(fork):
    # A GP in log space: the dual of the row posy(x)/L <= 1 is -d log(optimum)/d log(L),
    # the log-sensitivity, computed by cvxpy from the GP alone (first-order Hertz, where
    # the NLP's is exact: 0.5 % apart on the pin's pressure, 2e-5 on the travel)
    import numpy as np

    from optdesign.programs.gp import build_gp, to_cvxpy

    problem, result = fork
    prob, _, _, cons = to_cvxpy(build_gp(problem, "backlash"))
    prob.solve(gp=True, solver="CLARABEL")
    duals: dict[str, float] = {}
    for row, con in cons:
        if row.kind == "upper" and con.dual_value is not None:
            duals[row.name] = duals.get(row.name, 0.0) + float(np.asarray(con.dual_value))
    ours = {s.name: s.log_sensitivity for s in result.sensitivities}
    assert ours["requirements.nut_travel_max"] == pytest.approx(-duals["nut_travel"], rel=1e-3)
    assert ours["requirements.pin_bearing_pressure_max"] == pytest.approx(
        -duals["pin_bearing_pressure"], rel=0.01
    )
    assert duals["pin_shear_stress"] < 1e-6  # not binding: no cost in either
    assert "requirements.pin_shear_stress_max" not in ours


def _cost(name: str, limit: float, unit: str, log: float | None, d: float = 0.0) -> str:
    return cost_text(Sensitivity(name, "backlash", limit, unit, d, "deg", log))


def test_cost_text_says_which_way_each_limit_moves_for_either_sign_and_side():
    """Issue 35: "gx.lower -150 mm: +1 %" did not say that 1 % moves a negative bound
    down, nor whether that widens the bounds: each line says both, whatever the sign."""
    gx = "variables.gx"
    assert _cost(f"{gx}.lower", -150.0, "mm", 1.0) == (
        f"{gx}.lower -150 mm: lowering it by 1 % to -151.5 mm (widens the bounds) -> backlash +1 %"
    )
    assert _cost(f"{gx}.lower", 150.0, "mm", 1.0) == (
        f"{gx}.lower 150 mm: raising it by 1 % to 151.5 mm (narrows the bounds) -> backlash +1 %"
    )
    assert _cost(f"{gx}.upper", -150.0, "mm", -0.5) == (
        f"{gx}.upper -150 mm: lowering it by 1 % to -151.5 mm (narrows the bounds) "
        "-> backlash -0.5 %"
    )
    assert _cost(f"{gx}.upper", 150.0, "mm", -0.5) == (
        f"{gx}.upper 150 mm: raising it by 1 % to 151.5 mm (widens the bounds) -> backlash -0.5 %"
    )
    # a requirement: which way and where to, no "wider" (its meaning is the requirement's)
    assert _cost("requirements.deflection.min", -30.0, "deg", 0.666) == (
        "deflection.min -30 deg: lowering it by 1 % to -30.3 deg -> backlash +0.666 %"
    )
    assert _cost("requirements.hinge_moment", 500.0, "N*m", 0.235) == (
        "hinge_moment 500 N*m: raising it by 1 % to 505 N*m -> backlash +0.235 %"
    )
    # at a zero limit 1 % moves nothing: the derivative, for the limit raised
    assert _cost("variables.n.lower", 0.0, "mm", 0.0, d=0.002) == (
        "variables.n.lower 0 mm: raising it (narrows the bounds) -> "
        "dbacklash/dvariables.n.lower = +0.002 deg/mm"
    )


def test_a_negative_bounds_cost_moves_it_the_way_its_line_says(tmp_path):
    """The pivoting screw's trunnion sits behind the horn (a_T < 0): with its upper
    bound at -150 mm the smallest linkage sits on it. The line says 1 % lowers the bound
    to -151.5 mm and narrows the bounds; the re-solve there costs what the line says."""
    from optdesign.formulations.nlp.solve import solve_nlp

    src = (PROBLEMS / "pivot_min_backlash.toml").read_text()
    old = 'a_T = { lower = "-300 mm", upper = "-40 mm" }'
    assert old in src
    path = tmp_path / "pivot.toml"
    path.write_text(src.replace(old, 'a_T = { lower = "-300 mm", upper = "-150 mm" }'))
    problem = od.load(path)
    result = od.solve(problem, objective="size", starts=2, ranges=False)
    lines = {s.name: cost_text(s) for s in result.sensitivities}
    s = next(s for s in result.sensitivities if s.name == "variables.a_T.upper")
    assert lines[s.name] == (
        "variables.a_T.upper -150 mm: lowering it by 1 % to -151.5 mm (narrows the bounds) "
        f"-> size {s.log_sensitivity:+.3g} %"
    )
    assert s.log_sensitivity > 0.1  # a narrower box: a larger linkage
    assert lines["variables.p.lower"].startswith(
        "variables.p.lower 2 mm: raising it by 1 % to 2.02 mm (narrows the bounds) -> size +"
    )
    assert lines[s.name] in result.summary()
    # the bound where the line puts it, solved again: the change the line states
    x0 = [result.design[v.name] for v in problem.free]
    moved = solve_nlp(perturbed(problem, s.name, -151.5), "size", starts=1, x0=x0)
    assert moved.success
    change = 100 * (moved.objective / result.objective - 1)
    assert change == pytest.approx(s.log_sensitivity, rel=0.02)


def test_a_limit_that_moves_no_model_function_costs_what_a_full_evaluation_says():
    """The sensitivities reuse the design's evaluation for a requirement that only sets a
    limit (a band's ends, a maximum), and evaluate the model again for one the physics
    reads (the hinge moment, the stroke): both give the same derivatives."""
    from optdesign.formulations.nlp import sensitivities as S

    problem = od.load(PROBLEMS / "cs_min_backlash.toml")
    result = od.solve(problem, ranges=False, sensitivities=False)
    p = dict(requirement_paths(problem))
    assert S.moved_limits(problem, "mean_ratio.min", p["mean_ratio.min"] * 1.001, 199.0)
    assert S.moved_limits(problem, "hinge_moment", p["hinge_moment"] * 1.001, 4.9e5) is None
    fast = {s.name: s.d_objective_d_limit for s in S.nlp_sensitivities(problem, result)}
    original = S.moved_limits
    try:
        S.moved_limits = lambda *args: None  # every move evaluated in full
        full = {s.name: s.d_objective_d_limit for s in S.nlp_sensitivities(problem, result)}
    finally:
        S.moved_limits = original
    assert fast.keys() == full.keys() and "requirements.hinge_moment" in full
    assert any(k.startswith("requirements.mean_ratio") or "max" in k for k in full)
    for name, d in full.items():
        assert fast[name] == pytest.approx(d, rel=1e-12), name
