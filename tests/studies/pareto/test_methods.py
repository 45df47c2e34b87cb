"""The front methods (studies/pareto/methods.py), pinned function by function.

How a method is built from a name and settings (and refused), which time limits it
takes, its settings and store identity, the weight grid, NSGA-II's vectorised problem
(its objectives and signed relative violations against numpy at fixed designs) and
short runs of each method on the crank-slider, their records checked one by one.
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.argument_checks import ArgumentError
from optdesign.errors import InputError, ProblemError
from optdesign.problem import load_problem
from optdesign.studies.pareto import (
    NSGA2,
    EpsilonConstraint,
    compute_front,
    make_method,
)
from optdesign.studies.pareto.catalogue_front import CatalogueEpsilon
from optdesign.studies.pareto.methods import (
    WeightedSum,
    _weight_grid,
    check_time_limit,
    pymoo_problem,
)

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"
#: Designs of cs_min_backlash (R, l, n, p, phi0, d): feasible, and two corners (the
#: first one's geometry does not close: NaN objectives and rows).
X = np.array(
    [
        [100.0, 60.0, 100.0, 5.0, 0.2, 7.0],
        [120.0, 40.0, 150.0, 2.0, 0.6, 4.0],
        [30.0, 200.0, 0.0, 10.0, -0.6, 30.0],
    ]
)


@pytest.fixture(scope="module")
def cs():
    return load_problem(PROBLEMS / "cs_min_backlash.toml")


@pytest.fixture(scope="module")
def cat():
    return load_problem(PROBLEMS / "cs_min_backlash_catalogue.toml")


# --- settings -----------------------------------------------------------------------------
def test_an_epsilon_sweeps_settings_are_refused_naming_the_field():
    with pytest.raises(InputError, match=r"^spacing: 'even': use 'arc' or 'uniform'$"):
        EpsilonConstraint(spacing="even").check_settings()
    with pytest.raises(InputError, match=r"^points: a front needs at least 2 points, got 1$"):
        EpsilonConstraint(points=1).check_settings()
    with pytest.raises(InputError, match=r"^points: .* got 1$"):
        EpsilonConstraint(points=5, eps_values=[0.1]).check_settings()
    EpsilonConstraint(points=2).check_settings()
    EpsilonConstraint(points=2, spacing="uniform").check_settings()
    # explicit epsilon values set the count whatever ``points`` says
    EpsilonConstraint(points=1, eps_values=[0.1, 0.2]).check_settings()
    assert EpsilonConstraint(points=9, eps_values=[0.1, 0.2, 0.3]).n_points == 3
    assert EpsilonConstraint(points=9).n_points == 9


def test_an_epsilon_sweeps_identity_holds_every_setting_but_its_name():
    method = EpsilonConstraint(points=4, starts=None, seed=None, solver="ipopt", name="mine")
    expected = {
        "points": 4,
        "spacing": "arc",
        "eps_values": None,
        "starts": 3,
        "seed": 8,
        "agree": 3,
        "solver": "ipopt",
        "retry_starts": 4,
        "extra_starts": 0,
        "deterministic": True,
    }
    assert method.settings(3, 8, ["a", "b"]) == expected
    assert method.identity(3, 8, ["a", "b"]) == ("ipopt", {"method": "epsilon", **expected})


def test_the_other_methods_identity_and_settings():
    assert WeightedSum(points=5).identity(2, 7, ["a", "b"]) == (
        "ipopt",
        {"method": "weighted_sum", "n": 5, "starts": 2, "seed": 7},
    )
    assert NSGA2(pop_size=12, generations=3, seed=4).settings(2, 7, ["a", "b"]) == {
        "pop_size": 12,
        "generations": 3,
        "seed": 4,
    }


def test_the_weight_grids_of_two_and_three_objectives():
    assert _weight_grid(2, 3) == [(0.0, 1.0), (0.5, 0.5), (1.0, 0.0)]
    # three objectives: the smallest triangle side s with s (s + 1) / 2 >= points
    assert _weight_grid(3, 6) == [
        (0.0, 0.0, 1.0),
        (0.0, 0.5, 0.5),
        (0.0, 1.0, 0.0),
        (0.5, 0.0, 0.5),
        (0.5, 0.5, 0.0),
        (1.0, 0.0, 0.0),
    ]
    assert len(_weight_grid(3, 7)) == 10  # side 4
    assert len(_weight_grid(3, 1)) == 3  # side at least 2


# --- time limits --------------------------------------------------------------------------
def test_only_a_continuous_epsilon_sweep_takes_a_time_limit():
    check_time_limit(EpsilonConstraint(), 5.0)
    for method in (WeightedSum(), NSGA2(), CatalogueEpsilon(), object()):
        check_time_limit(method, None)
    with pytest.raises(ArgumentError) as err:
        check_time_limit(WeightedSum(name="ws"), 5.0)
    assert err.value.argument == "time_limit"
    assert str(err.value) == (
        "time_limit: not applied by the ws method: only a continuous epsilon sweep stops "
        "at a time limit"
    )
    with pytest.raises(ArgumentError, match=r"^limit: not applied by a catalogue front: "):
        check_time_limit(CatalogueEpsilon(), 1.0, field="limit")

    class Mine:  # a method object that says nothing about itself
        pass

    with pytest.raises(ArgumentError, match=r"^time_limit: not applied by the Mine method: "):
        check_time_limit(Mine(), 0.5)
    named = Mine()
    named.name = "sweep"
    with pytest.raises(ArgumentError, match=r"^time_limit: not applied by the sweep method: "):
        check_time_limit(named, 0.5)


# --- building a method --------------------------------------------------------------------
def test_a_method_is_built_from_its_name_and_settings(cs):
    assert make_method(cs, "epsilon", 7) == EpsilonConstraint(points=7)
    # by default, the epsilon method of 50 points
    assert make_method(cs) == EpsilonConstraint(points=50)
    assert make_method(cs, "epsilon", 9, agree=None) == EpsilonConstraint(points=9, agree=None)
    assert make_method(cs, "uniform", 4, starts=2) == EpsilonConstraint(
        points=4, spacing="uniform", name="uniform", starts=2
    )
    assert make_method(cs, "weighted_sum", 5, seed=3) == WeightedSum(points=5, seed=3)
    # NSGA-II has no points nor solver: the shared ones are left out
    assert make_method(cs, "nsga2", 5, solver="ipopt", pop_size=6) == NSGA2(pop_size=6)


def test_a_method_name_or_option_not_known_is_refused_naming_it(cs):
    with pytest.raises(InputError) as err:
        make_method(cs, "grid")
    assert (err.value.field, err.value.reason) == (
        "method",
        "unknown method 'grid' (known: epsilon, uniform, weighted_sum, nsga2)",
    )
    with pytest.raises(InputError) as err:
        make_method(cs, "weighted_sum", 5, spacing="arc")
    assert err.value.field == "pareto"
    assert err.value.reason.startswith("option not understood by 'weighted_sum': ")
    assert "spacing" in err.value.reason


def test_a_method_object_is_taken_as_given_and_its_options_go_into_it(cs):
    method = WeightedSum(points=3)
    assert make_method(cs, method, 50) is method
    with pytest.raises(ProblemError, match=r"options \['seed', 'starts'\] go into the method"):
        make_method(cs, method, 50, starts=2, seed=1)


def test_a_catalogue_problems_epsilon_is_the_catalogue_front(cat):
    built = make_method(cat, "epsilon", 7, starts=2, seed=5, solver="ipopt", agree=1)
    assert built == CatalogueEpsilon(points=7, starts=2, seed=5)
    assert make_method(cat, "uniform", 3) == CatalogueEpsilon(points=3)
    assert make_method(cat, "epsilon", 6, seed=9) == CatalogueEpsilon(points=6, seed=9)
    assert make_method(cat, "nsga2", 6, pop_size=4) == NSGA2(pop_size=4)
    with pytest.raises(InputError) as err:
        make_method(cat, "weighted_sum", 6)
    assert (err.value.field, err.value.reason) == (
        "method",
        "weighted_sum would leave the catalogue: with catalogue variables use epsilon or nsga2",
    )


def test_a_front_refuses_no_worker_and_an_unapplied_time_limit_before_any_work(cs, tmp_path):
    with pytest.raises(InputError, match=r"^workers: need at least 1 worker, got 0$"):
        compute_front(cs, ["size", "backlash"], 3, "epsilon", workers=0, out=tmp_path / "a")
    with pytest.raises(ArgumentError, match=r"^time_limit: not applied by the weighted_sum"):
        compute_front(cs, ["size", "backlash"], 3, "weighted_sum", time_limit=1.0, out=tmp_path)
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_overwrite_discards_the_methods_own_store_only_when_not_resuming(cs, tmp_path):
    def run(**options):
        compute_front(
            cs, ["size", "backlash"], 3, "nsga2", pop_size=4, generations=1, seed=0, **options
        )

    store, other = tmp_path / "nsga2.jsonl", tmp_path / "epsilon.jsonl"
    store.write_text("old\n")
    other.write_text("old\n")
    run(out=tmp_path, overwrite=True, resume=True)
    assert store.read_text() == "old\n"
    run(out=tmp_path)
    assert store.read_text() == "old\n"
    run(out=tmp_path, overwrite=True)
    assert not store.exists() and other.read_text() == "old\n"


# --- NSGA-II ------------------------------------------------------------------------------
def _g(v, lower, upper):
    """The signed relative violation of lower <= v <= upper, worst over the grid."""
    g = np.full(v.shape, -np.inf)
    if lower is not None:
        g = np.maximum(g, (lower - v) / max(1.0, abs(lower)))
    if upper is not None:
        g = np.maximum(g, (v - upper) / max(1.0, abs(upper)))
    return g.max(axis=1)


def test_nsga2s_problem_is_the_objectives_and_the_relative_violations(cs):
    problem = pymoo_problem(cs, ["size", "backlash"])
    assert (problem.n_var, problem.n_obj, problem.n_ieq_constr) == (6, 2, 8)
    assert problem.xl.tolist() == [30.0, 40.0, 0.0, 2.0, -0.6, 4.0]
    assert problem.xu.tolist() == [120.0, 200.0, 150.0, 10.0, 0.6, 30.0]
    out = {}
    problem._evaluate(X, out)
    ev = cs.evaluate(X)
    assert out["F"].shape == (3, 2)
    assert out["F"][:, 0].tolist() == [160.0, 160.0, 230.0]  # size = R + l
    assert out["F"][[0, 2], 1].tolist() == ev.objectives["backlash"][[0, 2]].tolist()
    assert out["F"][1, 1] == 1e6  # NaN objective: worst
    c = {k: np.asarray(b.values, dtype=float).reshape(3, -1) for k, b in ev.constraints.items()}
    G = out["G"]
    assert G.shape == (3, 8)
    # by hand, each block's own bounds: the ratio's lower 200 and upper 260 scale its
    # violation, a bound below 1 (the transmission angle's cosines, the margin) does not
    expected = np.column_stack(
        [
            1.0 - c["ratio_positive"].min(axis=1),
            _g(c["transmission_angle"], -0.7660444431189779, 0.766044443118978),
            _g(c["rod_inclination"], -0.5, 0.5),
            0.01 - c["assembly_margin"].min(axis=1),
            np.maximum((200.0 - c["mean_ratio"][:, 0]) / 200, (c["mean_ratio"][:, 0] - 260) / 260),
            (c["nut_travel"][:, 0] - 110.0) / 110.0,
            (c["pin_bearing_pressure"].max(axis=1) - 100.0) / 100.0,
            (c["pin_shear_stress"].max(axis=1) - 200.0) / 200.0,
        ]
    )
    assert G[[0, 2]] == pytest.approx(expected[[0, 2]], rel=1e-12, abs=1e-12)
    assert (G[0] < 0).all()  # the feasible design
    assert G[2, 1] > 0 and G[2, 4] > 0  # the corner's transmission angle and its ratio
    # NaN rows of the corner that does not close: the worst violation
    assert G[1, [0, 1, 4, 5, 6, 7]].tolist() == [1e6] * 6


def test_nsga2_records_its_feasible_designs_checked_on_the_numpy_path(cs):
    from pymoo.algorithms.moo.nsga2 import NSGA2 as PymooNSGA2
    from pymoo.optimize import minimize

    # pymoo's own run of the same problem: its final non-dominated feasible designs
    res = minimize(
        pymoo_problem(cs, ["size", "backlash"]),
        PymooNSGA2(pop_size=12),
        ("n_gen", 8),
        seed=1,
        verbose=False,
    )
    assert len(res.X) > 1
    front = compute_front(cs, ["size", "backlash"], 3, "nsga2", pop_size=12, generations=8, seed=1)
    assert front.settings == {"pop_size": 12, "generations": 8, "seed": 1}
    assert front.n_solves == 0 and front.method == "nsga2" and front.store == ""
    points = sorted(front.points + front.rejected, key=lambda p: p.id)
    assert [p.id for p in points] == [f"nsga2-{j:04d}" for j in range(len(res.X))]
    for point, x in zip(points, res.X, strict=True):
        assert [point.design[v.name] for v in cs.free] == x.tolist()
        assert point.kind == "nsga2" and point.target == ""
        assert point.status == "feasible" and point.verified is True
        assert (point.n_solves, point.wall_time_s) == (0, 0.0)
        assert point.design["i_a"] == 2.0 and point.design["pin_length_ratio"] == 1.5
        ev = cs.evaluate(x[None, :])
        assert ev.violation[0] <= 1e-6
        assert point.objectives == {k: float(v[0]) for k, v in ev.objectives.items()}


def test_nsga2_without_a_feasible_design_records_its_least_violating_one(cs, tmp_path):
    from pymoo.algorithms.moo.nsga2 import NSGA2 as PymooNSGA2
    from pymoo.optimize import minimize

    text = (PROBLEMS / "cs_min_backlash.toml").read_text()
    text = text.replace('nut_travel_max = "110 mm"', 'nut_travel_max = "5 mm"')
    (tmp_path / "tight.toml").write_text(text)
    tight = load_problem(tmp_path / "tight.toml")
    res = minimize(
        pymoo_problem(tight, ["size", "backlash"]),
        PymooNSGA2(pop_size=6),
        ("n_gen", 2),
        seed=3,
        verbose=False,
    )
    assert res.X is None
    cv = np.asarray(res.pop.get("CV"), dtype=float).ravel()
    least = res.pop.get("X")[int(np.argmin(cv))]
    assert cv.min() < cv.max()

    front = compute_front(
        tight, ["size", "backlash"], 3, "nsga2", pop_size=6, generations=2, seed=3
    )
    assert front.points == []
    (point,) = front.rejected
    assert point.id == "nsga2-0000" and point.rejected == "failed"
    assert point.status == "infeasible" and point.verified is False
    assert [point.design[v.name] for v in tight.free] == least.tolist()


# --- weighted sums and epsilon sweeps -----------------------------------------------------
def test_a_weighted_sum_front_chains_its_weights_from_the_last_anchor(cs):
    """Without a store: the chain finds its anchor among the records passed on."""
    stored: dict = {}
    front = compute_front(
        cs,
        ["size", "backlash"],
        3,
        "weighted_sum",
        starts=1,
        on_record=lambda r: stored.setdefault(r["id"], r),
    )
    assert [k for k in stored if k.startswith("ws-")] == ["ws-0000", "ws-0001", "ws-0002"]
    weights = [stored[f"ws-000{i}"]["weights"] for i in range(3)]
    assert weights == [
        {"size": 1e-4, "backlash": 1.0},
        {"size": 0.5, "backlash": 0.5},
        {"size": 1.0, "backlash": 1e-4},
    ]
    assert sorted(p.id for p in front.points + front.rejected) == ["ws-0000", "ws-0001", "ws-0002"]
    anchors = sum(stored[k]["n_solves"] for k in ("anchor-size", "anchor-backlash"))
    assert front.n_solves == 3 + anchors
    assert front.settings == {}
    # the size weight rises along the chain: size falls, backlash rises
    size = [stored[f"ws-000{i}"]["objectives"]["size"] for i in range(3)]
    assert size[0] >= size[1] >= size[2]


def _bars(monkeypatch) -> list:
    """The names of the progress bars a run opens (none shows outside a terminal)."""
    import tqdm.auto

    bars: list = []
    real = tqdm.auto.tqdm

    def bar(*args, **kw):
        bars.append(kw.get("desc"))
        return real(*args, **kw)

    monkeypatch.setattr(tqdm.auto, "tqdm", bar)
    return bars


def test_a_three_objective_epsilon_front_runs_its_rows_after_its_anchors(cs, monkeypatch):
    """Without a store, the rows find their anchors only among the records passed on."""
    bars = _bars(monkeypatch)
    stored: dict = {}
    front = compute_front(
        cs,
        ["size", "backlash", "ripple"],
        3,
        "epsilon",
        starts=1,
        name="three",
        progress=True,
        on_record=lambda r: stored.setdefault(r["id"], r),
    )
    assert bars == ["three: points", "three: points"]  # the anchors, then the rows
    ids = [p.id for p in front.points + front.rejected]
    assert ids and all(i.startswith("three-") for i in ids)
    assert {"anchor-size", "anchor-backlash", "anchor-ripple"} <= set(stored)
    assert set(ids) <= set(stored)
    assert all(p.success for p in front.points)
    solves = sum(stored[i]["n_solves"] for i in ids)
    solves += sum(stored[f"anchor-{k}"]["n_solves"] for k in ("size", "backlash", "ripple"))
    assert front.n_solves == solves


def test_a_front_without_progress_opens_no_progress_bar(cs, monkeypatch):
    bars = _bars(monkeypatch)
    compute_front(cs, ["size", "backlash"], 2, "epsilon", starts=1, progress=False)
    assert bars == []
    compute_front(cs, ["size", "backlash"], 2, "epsilon", starts=1, progress=True)
    # the chains' points, then the polish of their seam (one bar per phase)
    assert bars and set(bars) == {"epsilon: points"}


# --- time limits of a run -----------------------------------------------------------------
def _deadline_after(monkeypatch, n_records: int) -> list:
    """The deadline passes once ``n_records`` records are stored (no timing)."""
    # the modules that bind `passed` by name, imported before the patch
    import optdesign.solvers.casadi_nlp
    import optdesign.solvers.multistart  # noqa: F401
    from optdesign.solvers import deadline

    seen: list = []
    monkeypatch.setattr(deadline, "passed", lambda: len(seen) >= n_records)
    return seen


def test_a_time_limit_before_the_anchors_says_the_folders_resume_continues(
    cs, tmp_path, monkeypatch
):
    _deadline_after(monkeypatch, 0)
    with pytest.raises(InputError) as err:
        compute_front(cs, ["size", "backlash"], 4, "epsilon", out=tmp_path, time_limit=2.5)
    assert (err.value.field, err.value.reason) == (
        "time_limit",
        "2.5 s passed before the anchors (size, backlash) were computed: give more time, "
        "or resuming the run in its folder continues",
    )


def test_a_front_stopped_by_its_time_limit_names_the_points_left_out(cs, tmp_path, monkeypatch):
    seen = _deadline_after(monkeypatch, 6)  # the anchors (4 records) and a few points
    front = compute_front(
        cs,
        ["size", "backlash"],
        6,
        "epsilon",
        out=tmp_path,
        time_limit=2.5,
        on_record=seen.append,
        starts=1,
    )
    n = len(front.points) + len(front.rejected)
    assert 0 < n < 6
    assert front.notes == [
        f"time limit of 2.5 s reached: {6 - n} of 6 points not computed (no point begins "
        "after the limit; resuming the run in its folder computes them)"
    ]


def test_a_weighted_sum_without_a_feasible_anchor_names_what_its_best_point_violates(tmp_path):
    """The anchors of a weighted-sum front are checked with the problem: the refusal
    evaluates the best point found, not only the record's list of violated rows."""

    import optdesign as od
    from optdesign.studies.pareto.chains import NoFeasibleAnchor

    data = tomllib.loads((PROBLEMS / "cs_min_backlash.toml").read_text())
    data["requirements"]["nut_travel_max"] = "40 mm"
    data["requirements"]["mean_ratio"] = {"min": 250, "max": 260}
    with pytest.raises(NoFeasibleAnchor) as err:
        od.pareto(
            od.load(data),
            ["backlash", "size"],
            points=3,
            method="weighted_sum",
            starts=2,
            out=tmp_path,
        )
    assert err.value.objective == "backlash"
    assert "at the best point found: mean ratio over the stroke (mean_ratio) = " in str(err.value)
    assert ", min 250: short by " in str(err.value)


ROOT = Path(__file__).resolve().parents[3]


# --- resuming a stored front ------------------------------------------------------------
@pytest.fixture(scope="module")
def weighted_run(tmp_path_factory):
    """A finished 3-point weighted-sum front of cs_min_backlash (its output folder)."""
    out = tmp_path_factory.mktemp("weighted")
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    front = od.pareto(problem, ["backlash", "size"], 3, method="weighted_sum", starts=1, out=out)
    assert len(front.points) >= 2
    return problem, out, front


# --- what a stored front holds ----------------------------------------------------------
def _stored(out: Path, name: str) -> dict[str, dict]:
    lines = (out / f"{name}.jsonl").read_text().splitlines()[1:]
    return {r["id"]: r for r in map(json.loads, lines)}


def test_nsga2_is_a_front_method_of_a_catalogue_problem():
    """NSGA-II searches catalogue variables as item indices: it is not refused on a
    catalogue problem, and every point it gives is a catalogue design."""
    problem = od.load(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
    assert make_method(problem, "nsga2", 7, pop_size=8) == NSGA2(pop_size=8)
    front = od.pareto(
        problem, ["backlash", "motor_torque"], method="nsga2", pop_size=8, generations=3, seed=1
    )
    # a population of 8 over 3 generations may find no feasible design (it depends on
    # the releases' random streams): every design it gave, on the front or not, is read
    assert front.method == "nsga2"
    leads = {2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0}
    designs = [point.design for point in [*front.points, *front.rejected] if point.design]
    assert designs and all(design["p"] in leads for design in designs)
    assert all(point.verified for point in front.points)


def test_a_method_object_with_settings_beside_it_is_refused_naming_them():
    """Settings go into a method object, not beside it: the library front refuses them,
    naming each, before any work."""
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    method = EpsilonConstraint(points=3)
    with pytest.raises(ProblemError, match=r"options \['seed', 'starts'\] go into the method"):
        make_method(problem, method, 7, starts=2, seed=1)
    with pytest.raises(ProblemError, match=r"options \['starts'\] go into the method object"):
        compute_front(problem, ["backlash", "size"], 3, method, starts=2)
    assert make_method(problem, method, 7) is method


def test_a_weighted_sum_fronts_points_are_stored_as_weighted_sum_records(weighted_run):
    _, out, _ = weighted_run
    records = _stored(out, "weighted_sum")
    points = [r for r in records.values() if r["id"].startswith("ws-")]
    assert len(points) == 3
    assert {r["kind"] for r in points} == {"weighted_sum"}
    assert {r["kind"] for k, r in records.items() if k.startswith("anchor-")} == {
        "anchor-multistart",
        "anchor",
    }


def test_an_epsilon_front_solves_the_limits_it_is_given(tmp_path):
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    method = EpsilonConstraint(eps_values=[0.05, 0.1, 0.15], starts=1)
    front = od.pareto(problem, ["backlash", "size"], method=method, out=tmp_path)
    records = _stored(tmp_path, "epsilon")
    assert [records[f"epsilon-{i:04d}"]["eps"] for i in range(3)] == [
        {"backlash": 0.05},
        {"backlash": 0.1},
        {"backlash": 0.15},
    ]
    # each limit is active at its point: backlash on it, to the solver's tolerance
    got = sorted(p.objectives["backlash"] for p in front.points)
    assert got == pytest.approx([0.05, 0.1, 0.15], rel=1e-6)


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


# --- the work a front reports ---------------------------------------------------------------
def test_a_weighted_sum_front_counts_the_solves_of_its_points_and_anchors(
    cs_min_backlash, tmp_path
):
    """A weighted-sum front's ``n_solves`` is one solve a point plus every solve behind its
    anchors (their multistarts and tie-breaks), as its store records them."""
    front = od.pareto(
        cs_min_backlash, ["backlash", "size"], 4, method="weighted_sum", out=tmp_path, starts=1
    )
    lines = (tmp_path / "weighted_sum.jsonl").read_text().splitlines()[1:]
    records = list(map(json.loads, lines))
    points = [r for r in records if r["kind"] == "weighted_sum"]
    anchors = [r for r in records if r["kind"] == "anchor"]
    assert len(points) == 4 and len(anchors) == 2
    assert all(r["n_solves"] >= 2 for r in anchors)  # the multistart's solve and the tie's
    assert front.n_solves == 4 + sum(r["n_solves"] for r in anchors)


def test_nsga2_runs_the_generations_it_is_given(cs_min_backlash, monkeypatch):
    """NSGA-II evaluates one population a generation, for exactly ``generations``."""
    from optdesign.studies.pareto import methods

    calls = []
    real = methods.pymoo_problem

    def counted(problem, objectives):
        inner = real(problem, objectives)
        evaluate = inner._evaluate

        def _evaluate(X, out, *args, **kwargs):
            calls.append(len(X))
            if len(calls) > 10:
                raise RuntimeError("NSGA-II ran past the generations it was given")
            return evaluate(X, out, *args, **kwargs)

        inner._evaluate = _evaluate
        return inner

    monkeypatch.setattr(methods, "pymoo_problem", counted)
    front = od.pareto(
        cs_min_backlash, ["backlash", "size"], method="nsga2", pop_size=8, generations=3, seed=1
    )
    assert calls == [8, 8, 8]
    assert front.settings == {"pop_size": 8, "generations": 3, "seed": 1}


def test_three_objective_weights_are_the_smallest_triangle_holding_the_points():
    """A 3-objective weighted sum: the weights lie on a triangular grid of side s, the
    smallest with s (s + 1) / 2 >= points, and sum to 1."""
    from optdesign.studies.pareto.methods import _weight_grid

    for points, side in ((3, 2), (6, 3), (10, 4), (11, 5), (15, 5)):
        grid = _weight_grid(3, points)
        assert len(grid) == side * (side + 1) // 2
        assert all(min(w) >= 0 and math.isclose(sum(w), 1.0) for w in grid)
        assert len({tuple(round(x, 12) for x in w) for w in grid}) == len(grid)
    assert _weight_grid(2, 5) == [(w, 1 - w) for w in np.linspace(0.0, 1.0, 5)]
