"""The SLSQP back-end used by the Pareto sweeps, and the anchors' early-stopping multistart."""

import json
from pathlib import Path

import numpy as np
import pytest

from optdesign.formulations.nlp import build_nlp
from optdesign.problem import load_problem
from optdesign.solvers.casadi_nlp import CasadiNLPSolver
from optdesign.solvers.scipy_nlp import ScipyNLPSolver
from optdesign.studies.pareto import compute_front

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"


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


def test_anchor_multistart_stops_when_starts_agree(tmp_path):
    problem = load_problem(PROBLEMS / "cs_min_backlash.toml")
    front = compute_front(
        problem, ["ripple", "backlash"], 6, "epsilon", out=tmp_path, starts=8, agree=3
    )
    assert len(front.points) >= 5 and all(p.verified for p in front.points)
    records = [json.loads(line) for line in (tmp_path / "epsilon.jsonl").read_text().splitlines()]
    # One multistart record per objective; each anchor (its tie-break) carries it on.
    ms = [r["multistart"] for r in records if r.get("kind") == "anchor-multistart"]
    assert len(ms) == 2
    ties = [r for r in records if r.get("kind") == "anchor"]
    assert sorted(r["multistart"]["n_starts"] for r in ties) == [3, 3]
    for m in ms:
        assert m["n_planned"] == 8 and m["agree"] == 3
        assert m["n_at_best"] >= 3 and m["n_starts"] == 3 and m["stopped_early"]
