"""Sharing model results inside DesignProblem.expressions changes no value (NumPy and
CasADi paths) and shrinks the expression graph the formulation starts from."""

from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign import math as m
from optdesign.models import crank_slider as cs
from optdesign.problem import load_problem
from optdesign.programs.nlp import build_nlp

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"


@pytest.fixture(scope="module", params=["cs_min_backlash", "fork_min_backlash"])
def problem(request):
    return load_problem(PROBLEMS / f"{request.param}.toml")


def _flat(ex):
    values = {f"obj:{k}": np.asarray(t.expr, dtype=float) for k, t in ex.objectives.items()}
    values.update({f"con:{b.name}": np.asarray(b.expr, dtype=float) for b in ex.constraints})
    return values


@settings(max_examples=25, deadline=None)
@given(u=st.lists(st.floats(0.0, 1.0), min_size=8, max_size=8))
def test_numpy_values_are_the_same_with_and_without_sharing(problem, u):
    x = problem.lower() + np.asarray(u[: len(problem.free)]) * (problem.upper() - problem.lower())
    design = {**problem.fixed_values, **problem.design_dict(x)}
    with np.errstate(invalid="ignore"):  # designs that do not assemble give NaN in both
        shared = _flat(problem.expressions(design))  # shares inside
        plain = _flat(problem.expressions(design, share=False))  # no sharing block
    assert shared.keys() == plain.keys()
    for k in shared:
        np.testing.assert_array_equal(shared[k], plain[k], err_msg=k)


def test_casadi_constraints_are_the_same_and_the_raw_graph_is_smaller(problem):
    nlp = build_nlp(problem, ["backlash"])
    z = ca.SX.sym("z", len(problem.free))
    design = {
        **problem.fixed_values,
        **dict(zip([v.name for v in problem.free], ca.vertsplit(z), strict=True)),
    }
    ex_shared = problem.expressions(design, guarded=True)
    ex_plain = problem.expressions(design, guarded=True, share=False)
    g_shared = ca.vertcat(*[ca.vec(b.expr) for b in ex_shared.constraints])
    g_plain = ca.vertcat(*[ca.vec(b.expr) for b in ex_plain.constraints])
    f_shared, f_plain = ca.Function("s", [z], [g_shared]), ca.Function("p", [z], [g_plain])
    rng = np.random.default_rng(0)
    for _ in range(5):
        x = problem.lower() + rng.uniform(0.2, 0.8, len(problem.free)) * (
            problem.upper() - problem.lower()
        )
        assert np.array_equal(np.asarray(f_shared(x)), np.asarray(f_plain(x)))
    assert f_shared.n_instructions() <= f_plain.n_instructions()
    if problem.mechanism_name == "crank_slider":
        # measured: 5654 -> 2911 SX instructions for the requirement rows
        assert f_shared.n_instructions() < 0.6 * f_plain.n_instructions()
    assert nlp.g.shape[0] > 0


def test_sharing_is_scoped_to_the_block():
    R, l, n = 40.0, 120.0, 30.0
    phi = np.linspace(-0.3, 0.3, 5)
    with m.shared_subexpressions():
        a = cs.nut_velocity(R, l, n, phi)
        assert cs.nut_velocity(R, l, n, phi) is a  # same argument objects: shared
        assert cs.nut_velocity(R, l, n, phi.copy()) is not a  # another array: computed
    assert cs.nut_velocity(R, l, n, phi) is not a  # outside the block: computed anew
