"""Catalogue searches (issue 25): the warm branch and bound and Bonmin against
enumeration on a small catalogue instance; the one-hot encoding; the infeasibility memo."""

from __future__ import annotations

import itertools
import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

import optdesign as od
from optdesign.errors import InputError, ProblemError
from optdesign.formulations.catalogue import minlp_program as catalogue_minlp
from optdesign.formulations.catalogue.bnb import InfeasibleBoxes
from optdesign.formulations.catalogue.minlp_program import build_catalogue_minlp, item_groups
from optdesign.formulations.catalogue.search import NodeSolver, solve_catalogue
from optdesign.problem import problem_from_dict
from optdesign.programs.nlp import build_nlp
from optdesign.solvers.registry import solver_hints

ROOT = Path(__file__).resolve().parents[3]


def _small(leads=("5 mm", "6 mm"), pins=("5 mm", "6 mm", "8 mm")):
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": list(leads)}
    data["variables"]["d"] = {"values": list(pins)}
    return problem_from_dict(data)


@pytest.fixture(scope="module")
def enumerated():
    return solve_catalogue(_small(), method="enumerate", starts=2)


def test_warm_branch_and_bound_equals_enumeration(enumerated):
    bnb = solve_catalogue(_small(), method="bnb", starts=2)
    assert bnb.details.catalogue.items == enumerated.details.catalogue.items
    assert bnb.objective == pytest.approx(enumerated.objective, rel=1e-9)
    assert bnb.objective == pytest.approx(0.0340646, rel=1e-5)  # p = 6, d = 6
    # the typed counts are written to result.json under the catalogue record's names
    extra = bnb.to_dict()["extra"]["catalogue"]
    info = bnb.details.catalogue
    assert (extra["nodes"], extra["leaves"]) == (info.nodes, info.leaves)
    assert extra["seeded"] == info.seeded == 0  # no first incumbent outside a front
    assert extra["warm_fallbacks"] == info.warm_fallbacks
    assert extra["implied_infeasible"] == info.implied_infeasible == 0  # no memo
    assert "minlp" not in extra


def test_bonmin_equals_enumeration(enumerated):
    """od.solve(..., solver="bonmin"): Bonmin's B-BB picks the items, their NLP is the
    design; the same optimum as enumeration, with the relaxation bound below it."""
    res = od.solve(_small(), solver="bonmin", starts=2, ranges=False)
    info = res.details.catalogue
    assert info.method == "minlp" and res.formulation == "catalogue-minlp"
    assert (info.minlp.solver, info.minlp.algorithm) == ("bonmin", "B-BB")
    assert info.minlp.status == "SUCCESS" and info.minlp.items == {"p": 6, "d": 6}
    assert info.items == enumerated.details.catalogue.items == {"p": 6, "d": 6}
    assert res.objective == pytest.approx(enumerated.objective, rel=1e-9)
    assert res.bound < res.objective and res.verified
    minlp = res.to_dict()["extra"]["catalogue"]["minlp"]
    assert (minlp["solver"], minlp["status"], minlp["binaries"]) == ("bonmin", "SUCCESS", 5)
    # the neighbouring items, re-solved by the nodes' NLP back-end (Bonmin only picks)
    steps = {(s.variable, s.item): s.objective for s in res.item_steps}
    assert steps[("d", 5.0)] is None
    assert steps[("p", 5.0)] == pytest.approx(0.0347087, rel=1e-5)


def test_bonmin_refuses_an_unknown_algorithm():
    with pytest.raises(InputError, match=r"algorithm.*'B-XX' is not a Bonmin algorithm"):
        solve_catalogue(_small(), solver="bonmin", starts=1, options={"algorithm": "B-XX"})
    # through the API: refused before any solve, naming the argument
    with pytest.raises(InputError, match=r"options\.algorithm: 'B-XX' is not a Bonmin"):
        od.solve(_small(), solver="bonmin", options={"algorithm": "B-XX"})


def test_the_registry_routes_a_catalogue_problem_to_its_minlp_back_end():
    """Bonmin declares a MINLP solve and its time-limit option; method "minlp" with an
    NLP-only back-end is refused, naming the back-ends that solve MINLPs."""
    hints = solver_hints("bonmin")
    assert hints.minlp == "optdesign.solvers.bonmin:solve_minlp"
    assert hints.time_limit(30) == {"time_limit": 30.0} and not hints.multipliers
    assert solver_hints("ipopt").minlp is None
    with pytest.raises(ProblemError, match=r"back-end 'ipopt' solves no MINLP .*: bonmin\)"):
        solve_catalogue(_small(), method="minlp", solver="ipopt", starts=1)


def test_one_hot_groups_follow_the_item_data():
    """Leads and pins carry their own data (none for an ISO 3408 lead, the table fit for
    a pin): two groups of 2 and 3 items, the pin's group holding the fit ratios."""
    groups = item_groups(_small())
    assert [g.names for g in groups] == [("p",), ("d",)]
    assert [len(g.items) for g in groups] == [2, 3]
    assert set(groups[1].data) == {"fit_ratio_max", "fit_ratio_min"}
    assert not groups[0].data


def test_a_catalogue_screw_makes_its_diameter_and_lead_one_group():
    """fin_actuator: d0 and p select one screw row (its ratings, and whether the pair
    exists), so they form one group of the catalogue's valid pairs; the pin its own."""
    import optdesign as od
    from optdesign.problem.drive import catalogue_items

    fin = od.load(ROOT / "problems" / "fin_actuator.toml")
    groups = item_groups(fin)
    assert [g.names for g in groups] == [("d0", "p"), ("d",)]
    (screw, pin) = groups
    d0 = {v.name: v for v in fin.free}["d0"]
    p = {v.name: v for v in fin.free}["p"]
    pairs = {
        (a, b)
        for a, b in catalogue_items(fin.spec.screw.catalogue, fin.spec.screw.nut)
        if d0.lower <= a <= d0.upper and p.lower <= b <= p.upper
    }
    assert set(screw.items) == pairs and len(pin.items) == len(fin.by_name["d"].values)
    assert {"screw_Ca", "screw_d1"} <= set(screw.data)


def test_infeasible_boxes_imply_sub_boxes_under_tighter_limits():
    memo = InfeasibleBoxes({"p": (2.0, 10.0), "d": (4.0, 25.0)})
    memo.add_infeasible({"d": (4.0, 5.0)}, {"motor_torque": 3.0})
    assert memo.known_infeasible({"d": (4.0, 4.0), "p": (5.0, 6.0)}, {"motor_torque": 2.5})
    assert memo.known_infeasible({"d": (5.0, 5.0)}, {"motor_torque": 3.0})
    # a looser limit, no limit, or a box reaching outside: not implied
    assert not memo.known_infeasible({"d": (4.0, 5.0)}, {"motor_torque": 3.5})
    assert not memo.known_infeasible({"d": (4.0, 5.0)}, {})
    assert not memo.known_infeasible({"d": (4.0, 6.0)}, {"motor_torque": 2.0})


def test_a_memo_proof_skips_the_nlp():
    """A node solver with a memo answers an implied box without a solve."""
    problem = _small()
    ns = NodeSolver(problem, starts=1)
    ns.memo = InfeasibleBoxes({"p": (5.0, 6.0), "d": (5.0, 8.0)})
    ns.memo.add_infeasible({"d": (5.0, 5.0)}, {})
    r = ns.solve({"d": (5.0, 5.0), "p": (6.0, 6.0)})
    assert r.status == "infeasible" and "wider box" in r.message
    assert (ns.n_solves, ns.n_implied) == (0, 1)


@pytest.mark.slow
def test_bench_configurations_of_the_catalogue_searches(tmp_path):
    """`optdesign bench --solvers catalogue-bnb,bonmin-b-bb` on a small catalogue
    instance: both are configurations of the bench and reach the same optimum."""
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "6 mm", "8 mm"]}
    rep = od.bench(problems=[data], solvers=["catalogue-bnb", "bonmin-b-bb"], out=tmp_path)
    frame = rep.to_frame().set_index("config")
    assert set(frame.index) == {"catalogue-bnb", "bonmin-b-bb"}
    assert frame.loc["catalogue-bnb", "objective"] == pytest.approx(0.0340646, rel=1e-5)
    assert frame.loc["bonmin-b-bb", "objective"] == pytest.approx(
        frame.loc["catalogue-bnb", "objective"], rel=1e-9
    )


def _relaxation_on_an_item():
    """A catalogue whose node relaxation sits on an item (d = 8 mm) with the fit data
    of the box's most favourable pin, while the best pin is the next one (10 mm)."""
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["8 mm", "10 mm", "12 mm", "16 mm"]}
    req = data["requirements"]
    req["hinge_moment"] = "585.9 N*m"
    req["deflection"] = {"min": "-28.38 deg", "max": "28.38 deg", "points": 61}
    req["mean_ratio"] = {"min": 200, "max": 245.6}
    return problem_from_dict(data)


def test_a_relaxation_on_an_item_still_branches_the_rest_of_its_box():
    """The box p = 6, d in [8, 16] relaxes to d = 8 (its fit data the best of 8..16 mm);
    the leaf d = 8 is worse, and the search goes on to d = 10 (0.0352439 deg,
    enumeration's optimum) instead of taking the leaf for the box."""
    problem = _relaxation_on_an_item()
    bnb = solve_catalogue(problem, method="bnb", starts=2)
    enum = solve_catalogue(problem, method="enumerate", starts=2)
    assert enum.details.catalogue.items == {"p": 6, "d": 10}
    assert bnb.details.catalogue.items == {"p": 6, "d": 10}
    assert bnb.objective == pytest.approx(enum.objective, rel=1e-9)
    assert bnb.objective == pytest.approx(0.0352439, rel=1e-5)


@pytest.mark.parametrize("planted", ["file", "link"])
def test_a_bonmin_opt_in_the_working_directory_is_refused_before_any_work(
    tmp_path, monkeypatch, capsys, planted
):
    """Bonmin reads ./bonmin.opt at every solve whatever its options say; one planted
    there could write Bonmin's log over any file. The solve is refused, naming it, from
    Python and in both output modes of the command line, and nothing is written."""
    from optdesign.cli import main

    monkeypatch.chdir(tmp_path)
    victim = tmp_path / "victim.txt"
    victim.write_text("keep me")
    opt = tmp_path / "bonmin.opt"
    if planted == "file":
        opt.write_text(f"output_file {victim}\n")
    else:
        opt.symlink_to(tmp_path / "missing.opt")  # even a broken link would be opened
    with pytest.raises(InputError, match=r"solver: bonmin: refused: .*bonmin\.opt would be read"):
        od.solve(_small(), solver="bonmin", ranges=False)
    path = tmp_path / "small.toml"
    path.write_text((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    for extra in ([], ["--json"]):
        code = main(
            ["solve", str(path), "--solver", "bonmin", "--out", str(tmp_path / "o"), *extra]
        )
        err = capsys.readouterr().err
        assert code == 2 and "bonmin.opt would be read by Bonmin" in err
    assert victim.read_text() == "keep me"
    assert not (tmp_path / "o" / "result.json").exists()
    # the default back-end is not concerned by the file
    opt.unlink()
    assert solver_hints("ipopt").preflight is None


def test_a_minlp_start_puts_each_groups_one_binary_on_the_nearest_item():
    """Bonmin's start: the NLP's scaled design, then per catalogue group binaries of 0
    and 1 with the 1 on the item nearest the design (relative distance)."""
    problem = _small()
    nlp = build_nlp(problem)
    minlp = build_catalogue_minlp(problem, nlp, nlp.target("backlash"))
    x = problem.start()
    names = list(nlp.design_names)
    cases = [(5.2, 7.5, [1, 0, 0, 0, 1], (5.0, 8.0)), (5.5, 6.5, [0, 1, 0, 1, 0], (6.0, 6.0))]
    for p, d, binaries, (lead, pin) in cases:
        x[names.index("p")], x[names.index("d")] = p, d
        start = minlp.start(x)
        assert start[: minlp.n_z] == pytest.approx(nlp.z_from_x(x), rel=1e-12)
        assert start[minlp.n_z :].tolist() == binaries
        assert minlp.items(start) == {"p": lead, "d": pin}


def test_a_nodes_first_start_is_the_hint_clipped_into_the_nodes_box(monkeypatch):
    """The hint (the parent's optimum) may lie outside a child's box on either side: the
    node's first start is it clipped into the box, whatever the back-end does with bounds."""
    problem = _small()
    solver = NodeSolver(problem, starts=1)
    names = [v.name for v in problem.free]
    seen = []
    real = solver._solve_start
    monkeypatch.setattr(solver, "_solve_start", lambda item: seen.append(item[1]) or real(item))
    hint = problem.start()
    hint[names.index("p")], hint[names.index("d")] = 8.0, 4.0  # above p's box, below d's
    solver.solve({"p": (5.0, 6.0), "d": (6.0, 8.0)}, x_hint=hint)
    first = seen[0]
    assert (first[names.index("p")], first[names.index("d")]) == (6.0, 6.0)
    others = [k for k, n in enumerate(names) if n not in ("p", "d")]
    assert first[others].tolist() == hint[others].tolist()


def test_a_nodes_starts_are_its_seeds_sobol_points_and_a_retry_draws_new_ones(monkeypatch):
    """A cold node starts from the problem's start, then the Sobol points of the solver's
    seed (the same on every run); when every start fails, the retry tries RETRY_STARTS
    Sobol points of the next seed, not the ones it tried."""
    from optdesign.formulations.catalogue import search as catalogue
    from optdesign.solvers.multistart import sobol_starts
    from optdesign.solvers.result import Result

    problem = _small()
    solver = NodeSolver(problem, starts=3, seed=5)
    seen = []

    def fails(item):
        seen.append(item[1])
        return Result(status="failed", objective=float("nan"), formulation="nlp", message="x")

    monkeypatch.setattr(solver, "_solve_start", fails)
    bounds = {"p": (5.0, 6.0), "d": (6.0, 8.0)}
    solver.solve(bounds)
    names = [v.name for v in problem.free]
    lo, hi = problem.lower().copy(), problem.upper().copy()
    for name, (a, b) in bounds.items():
        lo[names.index(name)], hi[names.index(name)] = a, b
    assert len(seen) == 3 + catalogue.RETRY_STARTS
    np.testing.assert_array_equal(seen[0], np.clip(problem.start(), lo, hi))
    np.testing.assert_array_equal(np.array(seen[1:3]), sobol_starts(lo, hi, 2, 5))
    retry = sobol_starts(lo, hi, catalogue.RETRY_STARTS, 6)
    np.testing.assert_array_equal(np.array(seen[3:]), retry)
    assert not np.isin(retry, np.array(seen[1:3])).all(axis=1).any()


def test_search_coordinates_map_to_the_nearest_catalogue_items_leaving_the_population():
    """A population method's coordinates: a catalogue variable's index rounds to its item
    (clipped to the list), continuous ones pass; the population itself is not changed."""
    from optdesign.formulations.catalogue.discrete import CatalogueCoordinates

    coordinates = CatalogueCoordinates(_small())  # p in (5, 6), d in (5, 6, 8)
    population = np.array([[75, 120, 75, 0.6, 0, 1.4], [80, 100, 70, 1.7, 0.1, 2.2]], float)
    before = population.copy()
    designs = coordinates.to_design(population)
    np.testing.assert_array_equal(designs[:, [3, 5]], [[6.0, 6.0], [6.0, 8.0]])
    np.testing.assert_array_equal(designs[:, [0, 1, 2, 4]], before[:, [0, 1, 2, 4]])
    np.testing.assert_array_equal(population, before)


# optdesign/formulations/catalogue/minlp_program.py as a whole: at every integer point the
# one-hot MINLP is exactly the NLP of the chosen items (objective and rows, on a problem
# whose pins carry table data and on the fin actuator, whose screw pairs carry ratings),
# its bounds and flags, the grouping's fallback to one group when the valid combinations
# are no product, and its refusals.


def _small_catalogue():
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
    problem = _small_catalogue()
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
    problem = _small_catalogue()
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
    problem = _small_catalogue()
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
    problem = _small_catalogue()
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
    problem = _small_catalogue()
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
