"""A catalogue node of several item combinations solved on every other grid angle
(``thinned_grid.thinned_rows``, ``programs.nlp.with_rows``): the same NLP with fewer rows,
hence a relaxation whose value bounds the node's on the whole grid."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.formulations.catalogue.node_solver import NodeSolver
from optdesign.formulations.catalogue.thinned_grid import thinned_angles, thinned_rows
from optdesign.programs.nlp import build_nlp, with_rows

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def fin():
    problem = od.load(ROOT / "problems" / "fin_actuator.toml")
    return problem, build_nlp(problem)


def test_every_other_angle_and_both_ends_are_kept():
    assert thinned_angles(61) == list(range(0, 61, 2))
    assert thinned_angles(60) == [*range(0, 60, 2), 59]
    assert thinned_angles(20) == list(range(20))  # a small grid keeps its rows


def test_only_rows_of_left_out_angles_are_dropped(fin):
    problem, nlp = fin
    keep = set(thinned_rows(problem, nlp))
    kept_labels = {problem.phi_labels[k] for k in thinned_angles(len(problem.phi))}
    for k, name in enumerate(nlp.g_names):
        label = next((lab for lab in problem.phi_labels if f"[{lab}" in name), None)
        # a row of no angle (mean ratio, nut travel, life, the epsilon rows) stays
        assert (k in keep) == (label is None or label in kept_labels), name
    assert 0 < len(keep) < len(nlp.g_names)
    assert all(row in keep for row in nlp.eps_rows.values())


def test_the_kept_rows_are_the_nlps_own(fin):
    problem, nlp = fin
    keep = thinned_rows(problem, nlp)
    sub = with_rows(nlp, keep)
    theta = nlp.parameter_values(None)
    rng = np.random.default_rng(3)
    for _ in range(5):
        z = rng.uniform(0.05, 0.95, nlp.z.shape[0])
        g_full = np.asarray(nlp.g_fun(z, theta), dtype=float).ravel()
        g_sub = np.asarray(sub.g_fun(z, theta), dtype=float).ravel()
        np.testing.assert_array_equal(g_sub, g_full[keep])
    assert [sub.g_names[r] for r in sub.eps_rows.values()] == [
        nlp.g_names[r] for r in nlp.eps_rows.values()
    ]
    assert sub.f is nlp.f and sub.lbg.shape == sub.ubg.shape == (len(keep),)


def test_an_epsilon_row_cannot_be_dropped(fin):
    _, nlp = fin
    row = next(iter(nlp.eps_rows.values()))
    name = next(iter(nlp.eps_rows))
    with pytest.raises(ValueError, match=f"epsilon rows of {name}"):
        with_rows(nlp, [k for k in range(len(nlp.g_names)) if k != row])


@pytest.mark.parametrize("box", [{"d": (6.0, 10.0)}, {"d0": (20.0, 25.0), "p": (5.0, 10.0)}])
def test_a_thinned_node_bounds_the_same_node_on_the_whole_grid(fin, box):
    """The mean ratio is a row of no angle: kept exactly, so the thinned node is a
    relaxation (a problem on 13 angles, whose mean ratio is another number, is not:
    there a node's value rose above its leaf's)."""
    problem, _ = fin
    ns = NodeSolver(problem, starts=3)
    thinned = ns.solve(box, relaxed=True)
    whole = ns.solve(box)
    assert thinned.details["relaxed_grid"] == 31 and "relaxed_grid" not in whole.details
    assert thinned.success and whole.success
    assert thinned.objective <= whole.objective * (1 + 1e-7)


def test_an_nlp_whose_rows_name_no_angle_is_not_thinned(fin):
    """A user's rows without grid-angle labels: nothing to leave out, so no second solver
    of the same rows (and no start solved twice on it)."""
    from types import SimpleNamespace

    problem, nlp = fin
    unlabelled = SimpleNamespace(g_names=[f"row_{k}" for k in range(len(nlp.g_names))])
    assert thinned_rows(problem, unlabelled) is None
    one_left_out = SimpleNamespace(g_names=["mean_ratio", f"stress[{problem.phi_labels[1]}]"])
    assert thinned_rows(problem, one_left_out) == [0]


def test_a_node_solver_of_another_back_end_thins_its_nodes_with_it(fin):
    """The thinned grid's solver is built by the registry name the node solver was given
    (``slsqp``), not by its back-end's own name (``scipy-slsqp-exact``, unknown to the
    registry: ``optdesign solve fin_actuator.toml --solver slsqp`` stopped there)."""
    problem, _ = fin
    ns = NodeSolver(problem, starts=2, solver="slsqp")
    box = {"d": (6.0, 10.0)}
    thinned = ns.solve(box, relaxed=True)
    assert ns.relaxed_backend().name == ns.backend.name == "scipy-slsqp-exact"
    assert thinned.details["relaxed_grid"] == 31 and thinned.success
    whole = ns.solve(box)
    assert whole.success and thinned.objective <= whole.objective * (1 + 1e-7)
