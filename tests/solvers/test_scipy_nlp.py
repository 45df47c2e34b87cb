"""The SLSQP back-end used by the Pareto sweeps, and the anchors' early-stopping multistart."""

import json
from pathlib import Path

import numpy as np
import pytest

from optdesign.problem import load_problem
from optdesign.programs.nlp import build_nlp
from optdesign.solvers.casadi_nlp import CasadiNLPSolver
from optdesign.solvers.scipy_nlp import ScipyNLPSolver
from optdesign.studies.pareto import compute_front

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"


@pytest.mark.parametrize("name", ["fork_min_backlash", "cs_min_backlash", "cs_min_ripple"])
def test_slsqp_reaches_ipopt_optimum_with_consistent_multipliers(name):
    problem = load_problem(PROBLEMS / f"{name}.toml")
    nlp = build_nlp(problem)
    ipopt = CasadiNLPSolver(nlp).solve(problem.start())
    slsqp = ScipyNLPSolver(nlp, "SLSQP", "exact").solve(problem.start())
    assert ipopt.status == slsqp.status == "optimal"
    assert slsqp.objective == pytest.approx(ipopt.objective, rel=1e-6)
    li, ls = ipopt.raw["lam_g"], slsqp.raw["lam_g"]
    rows = {n: k for k, n in enumerate(nlp.g_names)}
    if name == "cs_min_ripple":
        # f = (hi - lo)/(hi + lo): KKT gives sum(lam_lower)/sum(lam_upper) = df/dlo / df/dhi
        # = hi/lo = (1 + r)/(1 - r) at the optimum, for both solvers (the optimum's scale
        # is not unique, so the sums themselves differ between solvers).
        r = ipopt.objective
        for lam in (li, ls):
            lower = sum(lam[k] for n, k in rows.items() if "lower_envelope" in n)
            upper = sum(lam[k] for n, k in rows.items() if "upper_envelope" in n)
            assert lower / upper == pytest.approx((1 + r) / (1 - r), rel=1e-4)
    else:
        # f = t: the envelope multipliers sum to df/dt (scaled), however a degenerate
        # optimum splits them between the angles where the maximum is attained.
        env = [k for n, k in rows.items() if "envelope" in n]
        assert np.sum(ls[env]) == pytest.approx(np.sum(li[env]), rel=1e-4)
    # Unique multipliers of requirement rows agree (sign convention included).
    for row in ("nut_travel", "rod_inclination[phi=+30.0deg]"):
        if row in rows and abs(li[rows[row]]) > 1e-6:
            assert ls[rows[row]] == pytest.approx(li[rows[row]], rel=1e-4)


def test_bounds_are_passed_per_solve_and_the_nlp_is_never_changed():
    problem = load_problem(PROBLEMS / "fork_min_backlash.toml")
    nlp = build_nlp(problem, ["backlash", "size"])
    ubg = nlp.ubg.copy()
    solver = ScipyNLPSolver(nlp, "SLSQP", "exact")
    free = solver.solve(problem.start())
    # R <= 80 mm instead of the travel limit 95.3, for this solve only
    tight = solver.solve(problem.start(), bounds=nlp.bounds(eps={"size": 80.0}))
    again = solver.solve(problem.start())
    assert np.array_equal(nlp.ubg, ubg)
    assert again.objective == pytest.approx(free.objective, rel=1e-9)
    assert tight.status == "optimal"
    assert tight.design["R"] == pytest.approx(80.0, rel=1e-7)
    assert tight.objective > free.objective * 1.05


def test_an_anchors_search_stops_on_its_odds(tmp_path):
    """Each anchor's global search on the crank-slider meets one optimum at every start:
    after 8 counted starts fewer than half an optimum is expected unseen, but six free
    variables ask for 12 counted starts; it stops there, well before its cap of 30, with
    the odds of a better optimum, 2 / (12 * 11), recorded."""
    problem = load_problem(PROBLEMS / "cs_min_backlash.toml")
    front = compute_front(
        problem, ["ripple", "backlash"], 6, "epsilon", out=tmp_path, starts=30, agree=3
    )
    assert len(front.points) >= 5 and all(p.verified for p in front.points)
    records = [json.loads(line) for line in (tmp_path / "epsilon.jsonl").read_text().splitlines()]
    # One search record per objective; each anchor (its tie-break) carries it on.
    ms = [r["multistart"] for r in records if r.get("kind") == "anchor-multistart"]
    assert len(ms) == 2
    ties = [r for r in records if r.get("kind") == "anchor"]
    assert sorted(r["multistart"]["n_starts"] for r in ties) == [12, 12]
    for m in ms:
        assert m["n_planned"] == 30 and m["agree"] == 3 and m["stop"] == "odds"
        assert m["n_at_best"] == m["n_starts"] == m["counted"] == 12 and m["stopped_early"]
        assert m["optima"] == 1 and m["p_better"] == pytest.approx(2 / 132)


def _ipopt_and_slsqp(name, **kwargs):
    problem = load_problem(PROBLEMS / f"{name}.toml")
    nlp = build_nlp(problem)
    return problem, nlp, CasadiNLPSolver(nlp).solve(problem.start()), ScipyNLPSolver(nlp, **kwargs)


def test_slsqp_restarts_after_a_positive_directional_derivative_from_its_best_point(monkeypatch):
    # SLSQP's exit 8 ("Positive directional derivative for linesearch") leaves its last
    # point anywhere (a user's six-bar: far outside the feasible set, an epigraph
    # variable at -6321). Here the first run is cut after 6 iterations, told it failed so,
    # and its last point thrown far away: the solve starts again from the best feasible
    # point it passed (not that last point) and reaches Ipopt's optimum.
    import scipy.optimize as so

    from optdesign.solvers import scipy_nlp

    problem, nlp, ipopt, slsqp = _ipopt_and_slsqp("cs_min_backlash", method="SLSQP")
    real, calls, starts = so.minimize, [], []

    def minimize(fun, x0, **kwargs):
        calls.append(1)
        starts.append(np.array(x0))
        if len(calls) > 1:
            return real(fun, x0, **kwargs)
        res = real(fun, x0, **{**kwargs, "options": {**kwargs["options"], "maxiter": 6}})
        res.status, res.message = 8, "Positive directional derivative for linesearch"
        res.x = np.where(np.arange(len(res.x)) < nlp.n_design, 1.0, -6321.0)
        return res

    monkeypatch.setattr(scipy_nlp.so, "minimize", minimize)
    r = slsqp.solve(problem.start())
    assert len(calls) == 2 and not np.array_equal(starts[1][: nlp.n_design], 1.0)
    assert r.status == "optimal" and r.objective == pytest.approx(ipopt.objective, rel=1e-6)
    assert r.message == (
        "Optimization terminated successfully "
        "(restarted once after: Positive directional derivative for linesearch)"
    )
    assert r.iterations > 6


def test_a_stopped_scipy_solve_returns_the_best_point_it_passed_not_its_last():
    # Time up in the middle of a line search: the result is the best iterate (feasible,
    # least objective; else least violation), never the trial point being evaluated.
    from optdesign.solvers.scipy_nlp import _TimeUp

    class Stopped(ScipyNLPSolver):
        def __init__(self, *args, stop_at, **kwargs):
            super().__init__(*args, **kwargs)
            self.stop_at, self.evaluated, self.iterates = stop_at, [], []

        def _tick(self, key, z):
            self.evaluated.append(np.array(z, dtype=float))
            if len(self.evaluated) >= self.stop_at:
                raise _TimeUp

        def _iterate(self, x, *state):
            self.iterates.append(np.array(x, dtype=float))
            super()._iterate(x, *state)

    problem = load_problem(PROBLEMS / "cs_min_ripple.toml")
    nlp = build_nlp(problem)
    worse_last = []
    for method in ("SLSQP", "trust-constr"):
        solver = Stopped(nlp, method, "exact", stop_at=30)
        r = solver.solve(problem.start())
        assert r.status == "time_limit" and solver.iterates
        z = r.raw["z"]
        ranks = [solver._rank(p) for p in [nlp.start(x0=problem.start()).z0, *solver.iterates]]
        assert solver._rank(z) == min(ranks), method
        worse_last.append(solver._rank(solver.evaluated[-1]) > solver._rank(z))
    assert any(worse_last)  # trust-constr's last trial: 9x the violation of its best
