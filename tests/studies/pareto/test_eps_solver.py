"""The epsilon-constraint solver of a front (studies/pareto/eps_solver.py), pinned method
by method: which back-end each role gets, with which options; the start taken from a
neighbour; what one solve sends to its back-end (start, target, bounds) and when the
fallback solves again; the slope from a multiplier.

The formulation is the real one of cs_min_backlash; the back-ends are stand-ins (the
solver registry's ``solver_for`` replaced) that log what they are given and return
scripted results, so no solve runs."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.errors import ProblemError
from optdesign.formulations.nlp.solve import formulation_for
from optdesign.solvers.registry import solver_hints
from optdesign.solvers.result import Result
from optdesign.studies.pareto import eps_solver
from optdesign.studies.pareto.eps_solver import EpsSolver
from optdesign.studies.pareto.records import PointRecord, RawSolution

OBJECTIVES = ["size", "backlash"]


@pytest.fixture(scope="module")
def cs():
    return od.load("problems/cs_min_backlash.toml")


@pytest.fixture(scope="module")
def nlp(cs):
    return formulation_for(cs, ("backlash", "size"))


def _result(status="optimal", message="", wall=1.0):
    return Result(status=status, objective=1.0, formulation="epigraph", message=message,
                  wall_time_s=wall)  # fmt: skip


@pytest.fixture
def backends(monkeypatch, cs):
    """Stand-in back-ends: ``solver_for`` logs (name, options, objectives) and returns a
    back-end whose solves log (name, start, target, bounds) and pop ``answers``."""
    log = {"built": [], "solves": [], "answers": []}

    class Backend:
        def __init__(self, name):
            self.name = name

        def solve(self, start, target, bounds):
            log["solves"].append((self.name, start, target, bounds))
            return log["answers"].pop(0)

    def solver_for(problem, name, options, objectives):
        assert problem is cs
        log["built"].append((name, options, objectives))
        return Backend(name)

    monkeypatch.setattr(eps_solver, "solver_for", solver_for)
    return log


# --- the solver and its back-ends -------------------------------------------------------
def test_a_front_solver_is_the_sorted_objectives_formulation_with_sqpmethod_first(cs, nlp):
    solver = EpsSolver(cs, OBJECTIVES)
    assert solver.method == "sqpmethod" and solver.has_fallback is True
    assert solver.objectives == ("backlash", "size") and solver.problem is cs
    assert solver.nlp is nlp and solver.fingerprint == nlp.fingerprint
    ipopt = EpsSolver(cs, OBJECTIVES, "ipopt")
    assert ipopt.method == "ipopt" and ipopt.has_fallback is False
    assert EpsSolver(cs, OBJECTIVES, "slsqp").has_fallback is True


def test_a_front_solver_of_an_unknown_back_end_is_refused_naming_the_choices(cs):
    with pytest.raises(ProblemError) as caught:
        EpsSolver(cs, OBJECTIVES, "bonmin")
    assert str(caught.value) == "solver 'bonmin': use one of sqpmethod, slsqp, ipopt"


def test_each_role_gets_its_back_end_with_the_options_it_declares(cs, backends):
    sqp, ipopt = EpsSolver(cs, OBJECTIVES), EpsSolver(cs, OBJECTIVES, "ipopt")
    slsqp = EpsSolver(cs, OBJECTIVES, "slsqp")
    sweep = solver_hints("sqpmethod").sweep_options
    restart = solver_hints("ipopt").restart_options
    warm = solver_hints("ipopt").warm_start_options
    assert sweep and restart and warm
    objectives = ("backlash", "size")
    for solver, use, expected in [
        (sqp, "primary", ("sqpmethod", sweep)),
        (sqp, "tie", ("ipopt", restart)),
        (sqp, "warm", ("ipopt", warm)),
        (sqp, "fallback", ("ipopt", None)),
        (slsqp, "primary", ("slsqp", solver_hints("slsqp").sweep_options)),
        (slsqp, "fallback", ("ipopt", None)),
        (ipopt, "primary", ("ipopt", warm)),  # the fallback throughout: warm-started
        (ipopt, "tie", ("ipopt", restart)),
        (ipopt, "fallback", ("ipopt", None)),
    ]:
        backends["built"].clear()
        solver.backend(use)
        assert backends["built"] == [(*expected, objectives)], (solver.method, use)
    backends["built"].clear()
    sqp.backend()
    assert backends["built"] == [("sqpmethod", sweep, objectives)]


# --- starts ------------------------------------------------------------------------------------
def _neighbour(x=None, raw=None):
    return PointRecord(id="nb", kind="eps", target="size", status="optimal", x=x, raw=raw)


def test_a_start_from_a_neighbour_of_the_same_formulation_is_primal_and_dual(cs, nlp):
    solver = EpsSolver(cs, OBJECTIVES)
    n, m = len(nlp.lbz), len(nlp.lbg)
    raw = RawSolution(np.linspace(0.1, 0.9, n), np.arange(n) * 0.5, -np.arange(m) * 1.0,
                      nlp.fingerprint)  # fmt: skip
    start = solver.start_from(_neighbour(x=list(cs.start()), raw=raw))
    assert np.array_equal(start.z0, raw.z)
    assert np.array_equal(start.lam_x0, raw.lam_x) and np.array_equal(start.lam_g0, raw.lam_g)


def test_a_start_from_a_neighbour_of_another_formulation_is_its_design(cs, nlp):
    solver = EpsSolver(cs, OBJECTIVES)
    x = cs.lower() + 0.25 * (cs.upper() - cs.lower())
    other = RawSolution(np.zeros(3), np.zeros(3), np.zeros(2), "another")
    for neighbour in (_neighbour(x=[int(v) if v == int(v) else v for v in x], raw=other),
                      _neighbour(x=list(x))):  # fmt: skip
        start = solver.start_from(neighbour)
        assert np.allclose(start.z0, nlp.z_from_x(x), rtol=0, atol=1e-15)
        assert start.lam_x0 is None and start.lam_g0 is None


def test_a_start_without_a_neighbours_design_is_the_given_design_else_the_problems(cs, nlp):
    solver = EpsSolver(cs, OBJECTIVES)
    x = cs.lower() + 0.75 * (cs.upper() - cs.lower())
    assert np.array_equal(solver.start_from(None, x).z0, nlp.z_from_x(x))
    assert np.array_equal(solver.start_from(_neighbour(), list(x)).z0, nlp.z_from_x(x))
    assert np.array_equal(solver.start_from(None).z0, nlp.z_from_x(cs.start()))
    assert solver.start_from(None).lam_g0 is None


# --- one solve ---------------------------------------------------------------------------------
def test_a_solve_sends_the_primal_start_the_target_and_the_finite_limits(cs, nlp, backends):
    solver = EpsSolver(cs, OBJECTIVES)
    start = nlp.start(x0=cs.start(), lam_g0=np.ones(len(nlp.lbg)), lam_x0=np.ones(len(nlp.lbz)))
    backends["answers"] = [_result()]
    result = solver.solve("size", {"backlash": 0.05, "ripple": math.inf}, start)
    ((name, sent, target, bounds),) = backends["solves"]
    assert name == "sqpmethod" and target == "size" and result.details.fallback == ""
    assert np.array_equal(sent.z0, start.z0) and sent.lam_g0 is None and sent.lam_x0 is None
    expected = nlp.bounds(eps={"backlash": 0.05})
    assert np.array_equal(bounds.ubg, expected.ubg) and np.array_equal(bounds.lbz, expected.lbz)
    assert not np.array_equal(bounds.ubg, nlp.ubg)  # the limit is in


def test_a_start_the_primary_fails_is_solved_again_by_the_fallback(cs, nlp, backends):
    solver = EpsSolver(cs, OBJECTIVES)
    start = nlp.start(x0=cs.start(), lam_g0=np.ones(len(nlp.lbg)))
    backends["answers"] = [_result("failed", "Iteration limit", 0.25), _result(wall=0.5)]
    result = solver.solve("backlash", {"size": 200.0}, start)
    assert [(s[0], s[2]) for s in backends["solves"]] == [("sqpmethod", "backlash"),
                                                          ("ipopt", "backlash")]  # fmt: skip
    assert backends["built"][-1] == ("ipopt", None, ("backlash", "size"))
    again = backends["solves"][1]
    assert np.array_equal(again[1].z0, start.z0) and again[1].lam_g0 is None
    assert np.array_equal(again[3].ubg, backends["solves"][0][3].ubg)
    assert result.success and result.details.fallback == "failed: Iteration limit"
    assert result.wall_time_s == 0.75


def test_no_fallback_solve_when_asked_for_none_or_a_role(cs, nlp, backends):
    solver = EpsSolver(cs, OBJECTIVES)
    start = nlp.start(x0=cs.start(), lam_g0=np.ones(len(nlp.lbg)))
    backends["answers"] = [_result("failed", "no")]
    result = solver.solve("size", {}, start, fallback=False)
    assert len(backends["solves"]) == 1 and result.status == "failed"
    assert result.details.fallback == ""
    backends["answers"] = [_result("failed", "no")]
    result = solver.solve("size", {}, start, use="tie")
    assert backends["solves"][-1][0] == "ipopt" and len(backends["solves"]) == 2
    assert backends["built"][-1] == ("ipopt", solver_hints("ipopt").restart_options,
                                     ("backlash", "size"))  # fmt: skip
    assert backends["solves"][-1][1].lam_g0 is None  # a tie-break's duals are another's


def test_ipopt_throughout_is_warm_started_with_the_duals_and_has_no_fallback(cs, nlp, backends):
    solver = EpsSolver(cs, OBJECTIVES, "ipopt")
    lam_g = np.arange(len(nlp.lbg), dtype=float)
    start = nlp.start(x0=cs.start(), lam_g0=lam_g)
    backends["answers"] = [_result("failed", "no")]
    result = solver.solve("size", {"backlash": 0.05}, start)
    ((name, sent, _, _),) = backends["solves"]
    assert name == "ipopt" and sent is start and result.status == "failed"
    assert backends["built"] == [("ipopt", solver_hints("ipopt").warm_start_options,
                                  ("backlash", "size"))]  # fmt: skip
    # a tie-break of an Ipopt front drops the duals
    backends["answers"] = [_result()]
    solver.solve("size", {}, start, use="tie")
    assert backends["solves"][-1][1].lam_g0 is None


# --- the slope -------------------------------------------------------------------------------
def test_the_slope_is_minus_the_multiplier_of_the_limits_row_in_the_targets_units(cs, nlp):
    solver = EpsSolver(cs, OBJECTIVES)
    row = nlp.eps_rows["backlash"]
    scale = nlp.target_scales[nlp.targets.index("size")]
    for lam in (-0.5, 0.5):
        lam_g = np.zeros(len(nlp.lbg))
        lam_g[row] = lam
        raw = RawSolution(np.zeros(len(nlp.lbz)), np.zeros(len(nlp.lbz)), lam_g, nlp.fingerprint)
        slope = solver.slope("size", "backlash", _neighbour(raw=raw))
        assert slope == pytest.approx(-0.5 * scale / nlp.g_scale[row], rel=1e-15)
        assert slope < 0
    # of the other objective's row and target
    lam_g = np.zeros(len(nlp.lbg))
    lam_g[nlp.eps_rows["size"]] = 2.0
    raw = RawSolution(np.zeros(len(nlp.lbz)), np.zeros(len(nlp.lbz)), lam_g, nlp.fingerprint)
    expected = -2.0 * nlp.target_scales[nlp.targets.index("backlash")]
    expected /= nlp.g_scale[nlp.eps_rows["size"]]
    assert solver.slope("backlash", "size", _neighbour(raw=raw)) == pytest.approx(expected)
    assert solver.slope("size", "backlash", _neighbour(raw=raw)) == 0.0


def test_no_slope_without_the_multipliers_of_this_formulation(cs, nlp):
    solver = EpsSolver(cs, OBJECTIVES)
    assert solver.slope("size", "backlash", _neighbour()) is None
    other = RawSolution(np.zeros(len(nlp.lbz)), np.zeros(len(nlp.lbz)), np.ones(len(nlp.lbg)), "x")
    assert solver.slope("size", "backlash", _neighbour(raw=other)) is None


ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


# --- the front's back-ends ----------------------------------------------------------------
def test_an_ipopt_front_warm_starts_its_sweep_solves(cs_min_backlash):
    """With Ipopt throughout (``solver="ipopt"``) the sweep's solves are warm-started
    (primal and dual, a small barrier); the plain fallback is not."""
    from optdesign.studies.pareto.eps_solver import EpsSolver

    eps = EpsSolver(cs_min_backlash, ["backlash", "size"], "ipopt")
    assert not eps.has_fallback
    for use in ("primary", "warm"):
        options = eps.backend(use).options["ipopt"]
        assert options["warm_start_init_point"] == "yes"
        assert options["mu_init"] == 1e-6
    assert "warm_start_init_point" not in eps.backend("fallback").options["ipopt"]


def test_a_front_solvers_back_end_is_its_primary_by_default(cs_min_backlash):
    """``EpsSolver.backend()`` with no use named is the primary back-end (the registry's
    front primary, CasADi's sqpmethod), the one every sweep solve tries first."""
    from optdesign.studies.pareto.eps_solver import EpsSolver

    eps = EpsSolver(cs_min_backlash, ["backlash", "size"])
    assert eps.has_fallback
    assert eps.backend() is eps.backend("primary")
    assert eps.backend().name == "sqpmethod"
    assert eps.backend("fallback").name == "ipopt"
