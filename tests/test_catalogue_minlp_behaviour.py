"""optdesign/formulations/catalogue_minlp.py as a whole: at every integer point the
one-hot MINLP is exactly the NLP of the chosen items (objective and rows, on a problem
whose pins carry table data and on the fin actuator, whose screw pairs carry ratings),
its bounds and flags, the grouping's fallback to one group when the valid combinations
are no product, and its refusals."""

import itertools
import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

import optdesign as od
from optdesign.errors import ProblemError
from optdesign.formulations import catalogue_minlp
from optdesign.formulations.catalogue_minlp import build_catalogue_minlp, item_groups
from optdesign.formulations.nlp import build_nlp
from optdesign.problem import problem_from_dict

ROOT = Path(__file__).resolve().parents[1]


def _small():
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "6 mm", "8 mm"]}
    return problem_from_dict(data)


def _check_every_integer_point(problem, target_name, eps=None, n_max=None, objectives=None):
    nlp = build_nlp(problem, objectives)
    target = nlp.target(target_name)
    minlp = build_catalogue_minlp(problem, nlp, target, eps)
    fg = ca.Function("fg", [minlp.x], [minlp.f, minlp.g])
    node = ca.Function("node", [nlp.z, nlp.p], [nlp.f, nlp.g])
    names = list(nlp.design_names)
    x = problem.start()
    n_g = int(nlp.g.numel())
    combos = list(itertools.product(*(range(len(g.items)) for g in minlp.groups)))
    rng = np.random.default_rng(0)
    if n_max is not None and len(combos) > n_max:
        combos = [combos[i] for i in sorted(rng.choice(len(combos), n_max, replace=False))]
    for combo in combos:
        b = []
        box = {}
        for grp, j in zip(minlp.groups, combo, strict=True):
            one = np.zeros(len(grp.items))
            one[j] = 1.0
            b.append(one)
            for name, value in zip(grp.names, grp.items[j], strict=True):
                x[names.index(name)] = value
                box[name] = (value, value)
        z = nlp.z_from_x(x)
        f, g = fg(np.concatenate([z, *b]))
        params = nlp.params(
            target, nlp.bounds(box=box, parameters=problem.parameter_values(box)).parameters
        )
        f_node, g_node = node(z, params)
        assert float(f) == pytest.approx(float(f_node), rel=1e-12, abs=1e-15)
        g = np.asarray(g, dtype=float).ravel()
        assert np.allclose(g[:n_g], np.asarray(g_node, dtype=float).ravel(), rtol=1e-12, atol=1e-14)
        assert np.allclose(g[n_g:], 0.0, atol=1e-12)  # one item per group, x on it
        assert minlp.items(np.concatenate([z, *b])) == {k: v[0] for k, v in box.items()}
    return nlp, minlp


def test_at_every_integer_point_the_minlp_is_the_nodes_nlp():
    problem = _small()
    nlp, minlp = _check_every_integer_point(problem, "backlash")
    n_b = 2 + 3
    assert minlp.n_z == int(nlp.z.numel())
    assert minlp.discrete == [False] * minlp.n_z + [True] * n_b
    assert [g.offset for g in minlp.groups] == [minlp.n_z, minlp.n_z + 2]
    bounds = nlp.bounds()
    assert minlp.lbx.tolist() == [*bounds.lbz.tolist(), *[0.0] * n_b]
    assert minlp.ubx.tolist() == [*bounds.ubz.tolist(), *[1.0] * n_b]
    n_link = 2 + 2  # per group: the sum of its binaries, one row per variable
    assert minlp.lbg.tolist() == [*bounds.lbg.tolist(), *[0.0] * n_link]
    assert minlp.ubg.tolist() == [*bounds.ubg.tolist(), *[0.0] * n_link]
    assert int(minlp.g.numel()) == int(nlp.g.numel()) + n_link


def test_the_targets_weights_and_epsilon_limits_reach_the_minlp():
    problem = _small()
    _check_every_integer_point(problem, "size", objectives=("backlash", "size"))
    _check_every_integer_point(problem, "size", {"backlash": 0.3}, objectives=("backlash", "size"))
    nlp = build_nlp(problem, ("backlash", "size"))
    eps = {"backlash": 0.3}
    minlp = build_catalogue_minlp(problem, nlp, nlp.target("size"), eps)
    assert minlp.ubg[: len(nlp.ubg)].tolist() == nlp.bounds(eps=eps).ubg.tolist()
    assert minlp.ubg[: len(nlp.ubg)].tolist() != nlp.ubg.tolist()


def test_the_screw_pairs_ratings_reach_the_minlp_at_every_pair():
    fin = od.load(ROOT / "problems" / "fin_actuator.toml")
    _, minlp = _check_every_integer_point(fin, fin.objective_names[0], n_max=12)
    assert [g.names for g in minlp.groups] == [("d0", "p"), ("d",)]


def test_items_are_the_largest_binary_of_each_group():
    problem = _small()
    nlp = build_nlp(problem)
    minlp = build_catalogue_minlp(problem, nlp, nlp.target("backlash"))
    z = np.zeros(minlp.n_z)
    x = np.concatenate([z, [0.4, 0.6], [0.2, 0.3, 0.5]])
    assert minlp.items(x) == {"p": 6.0, "d": 8.0}
    tie = np.concatenate([z, [0.5, 0.5], [0.4, 0.4, 0.2]])
    assert minlp.items(tie) == {"p": 5.0, "d": 5.0}  # the first of equal binaries


def test_combinations_that_are_no_product_make_one_group(monkeypatch):
    """A validity rule joining the variables (here: lead 6 only with pin 8) makes the
    valid combinations no product of per-variable items: one group of the valid pairs."""
    problem = _small()
    real = catalogue_minlp.box_has_item

    def only_some(problem, box):
        p, d = box["p"][0], box["d"][0]
        return real(problem, box) and (p == 5.0 or d == 8.0)

    monkeypatch.setattr(catalogue_minlp, "box_has_item", only_some)
    groups = item_groups(problem)
    assert [g.names for g in groups] == [("p", "d")]
    assert groups[0].items == [(5.0, 5.0), (5.0, 6.0), (5.0, 8.0), (6.0, 8.0)]
    assert set(groups[0].data) == {"fit_ratio_max", "fit_ratio_min"}
    assert len(groups[0].data["fit_ratio_max"]) == 4


def test_the_refusals_name_the_count_or_the_lack_of_items(monkeypatch):
    problem = _small()
    monkeypatch.setattr(catalogue_minlp, "MAX_COMBINATIONS", 5)
    with pytest.raises(
        ProblemError, match=r"catalogue MINLP: 6 item combinations \(at most 5 for the encoding\)"
    ):
        item_groups(problem)
    monkeypatch.setattr(catalogue_minlp, "MAX_COMBINATIONS", 6)
    assert len(item_groups(problem)) == 2
    monkeypatch.setattr(catalogue_minlp, "box_has_item", lambda problem, box: False)
    with pytest.raises(
        ProblemError, match="catalogue MINLP: no valid combination of catalogue items"
    ):
        item_groups(problem)
