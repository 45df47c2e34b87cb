"""Pareto fronts: metrics by hand, certified epsilon-constraint fronts, resume, NSGA-II,
three objectives, the CLI."""

import csv
import itertools
import json
import time
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
import optdesign.solvers.casadi_nlp
import optdesign.solvers.multistart
from optdesign.cli import main
from optdesign.errors import InputError
from optdesign.formulations.verify import verify_design
from optdesign.problem import load_problem
from optdesign.problem.evaluation import relative_violation
from optdesign.problem.load import load
from optdesign.runtime.runner import read_store
from optdesign.solvers import deadline
from optdesign.studies.pareto import compute_front
from optdesign.studies.pareto.methods import pymoo_problem
from optdesign.studies.pareto.metrics import (
    front_metrics,
    hypervolume,
    non_dominated,
    reference_point,
    spacing,
    spread,
)

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"


def epsilon_constraint_front(problem, objectives, points, **options):
    return compute_front(problem, objectives, points, "epsilon", **options)


@pytest.fixture(scope="module")
def cs():
    return load_problem(PROBLEMS / "cs_min_backlash.toml")


@pytest.fixture(scope="module")
def fork():
    return load_problem(PROBLEMS / "fork_min_backlash.toml")


# --- metrics -------------------------------------------------------------------------------
def test_hypervolume_of_a_staircase_by_hand():
    F = np.array([[1.0, 3.0], [2.0, 2.0], [3.0, 1.0]])
    # Boxes to (4, 4): x in [1,2] height 1, [2,3] height 2, [3,4] height 3 -> 6.
    assert hypervolume(F, np.array([4.0, 4.0])) == pytest.approx(6.0)
    # A dominated point adds nothing.
    assert hypervolume(np.vstack([F, [3.5, 3.5]]), np.array([4.0, 4.0])) == pytest.approx(6.0)
    # Default reference: nadir (3, 3) + 10 % of the range (2) = (3.2, 3.2).
    assert reference_point(F) == pytest.approx([3.2, 3.2])
    assert hypervolume(F) == pytest.approx(0.2 * 1.0 + 1.2 * 1.0 + 2.2 * 0.2)


def test_non_dominated_and_spacing():
    F = np.array([[1, 3], [2, 2], [2, 2], [3, 1], [2.5, 2.5], [np.nan, 0]], dtype=float)
    assert non_dominated(F).tolist() == [True, True, False, True, False, False]
    line = np.column_stack([np.linspace(0, 1, 6), np.linspace(1, 0, 6)])
    assert spacing(line) == pytest.approx(0.0, abs=1e-12)
    assert spread(line) == pytest.approx(0.0, abs=1e-12)
    uneven = np.array([[0, 1], [0.1, 0.9], [0.2, 0.8], [1, 0]], dtype=float)
    assert spacing(uneven) > 0.2
    assert spread(uneven) > 0.5
    # normalised by wider bounds the gaps shrink (their sum below 1), not their evenness
    wide = (np.zeros(2), np.full(2, 10.0))
    assert spread(uneven, bounds=wide) == pytest.approx(spread(uneven), rel=1e-12)
    # Deb's Delta with the true extremes (given in any order): even gaps of 0.4 sqrt(2)
    # between the points, 0.1 sqrt(2) from each end to its extreme: 0.2 / (0.2 + 0.8)
    # the metrics against a given reference point: the hypervolume of the front there
    metrics = front_metrics(uneven, ref=[2.0, 2.0])
    assert metrics["hypervolume"] == pytest.approx(hypervolume(uneven, np.array([2.0, 2.0])))
    # by hand, strips between consecutive points: 0.1 x 1 + 0.1 x 1.1 + 0.8 x 1.2 + 1 x 2
    assert metrics["hypervolume"] == pytest.approx(3.17)
    inner = np.array([[0.1, 0.9], [0.5, 0.5], [0.9, 0.1]])
    unit = (np.zeros(2), np.ones(2))
    for extremes in ([[0.0, 1.0], [1.0, 0.0]], [[1.0, 0.0], [0.0, 1.0]]):
        assert spread(inner, np.array(extremes), unit) == pytest.approx(0.2, rel=1e-12)


# --- epsilon-constraint --------------------------------------------------------------------
@pytest.fixture(scope="module")
def cs_front(cs, tmp_path_factory):
    out = tmp_path_factory.mktemp("cs_front")
    t0 = time.perf_counter()
    front = epsilon_constraint_front(cs, ["ripple", "backlash"], 10, out=out, starts=2)
    front.test_elapsed_s = time.perf_counter() - t0
    return front


def test_each_point_records_the_time_it_took(cs_front):
    times = [p.wall_time_s for p in [*cs_front.points, *cs_front.rejected]]
    assert times and all(0.0 < t < cs_front.test_elapsed_s for t in times)
    assert sum(times) < cs_front.test_elapsed_s  # one worker: the points one after another


def test_epsilon_front_anchors_are_the_known_optima(cs_front):
    anchors = cs_front.anchors
    assert anchors["ripple"]["ripple"] == pytest.approx(0.0121114, rel=1e-4)
    assert anchors["backlash"]["backlash"] == pytest.approx(0.0362197, rel=1e-4)
    # Lexicographic tie-break: at least ripple the backlash is far below the ~0.07 deg an
    # arbitrary minimum-ripple design (scaled linkage) has.
    assert anchors["ripple"]["backlash"] < 0.045
    F = cs_front.F
    assert len(F) == 10 and cs_front.metrics["n_nondominated"] == 10
    assert F[0, 0] == pytest.approx(0.0121114, rel=1e-4)
    assert F[-1, 1] == pytest.approx(0.0362197, rel=1e-4)
    # Monotone trade-off: ripple up, backlash down.
    assert np.all(np.diff(F[:, 0]) > 0) and np.all(np.diff(F[:, 1]) < 0)


def test_every_epsilon_point_is_feasible_by_the_numpy_check(cs, cs_front):
    for p in cs_front.points:
        x = np.array([p.design[v.name] for v in cs.free])
        ok, violated, objectives = verify_design(cs, x, tol=1e-6)
        assert ok, (p.id, [v.describe() for v in violated])
        assert relative_violation(objectives["ripple"], None, p.eps["ripple"]) <= 1e-6
        assert objectives["backlash"] == pytest.approx(p.objectives["backlash"], rel=1e-9)
        assert p.status == "optimal" and p.verified
        assert "ripple_max" in p.active or p is cs_front.points[-1]


def test_points_are_evenly_spread_along_the_front(cs_front):
    F = cs_front.F
    Z = (F - F.min(axis=0)) / (F.max(axis=0) - F.min(axis=0))
    gaps = np.abs(np.diff(Z, axis=0)).sum(axis=1)  # L1, total 2 for a monotone front
    assert gaps.sum() == pytest.approx(2.0, rel=1e-6)
    assert gaps.max() < 1.6 * gaps.mean()  # uniform epsilon gives 5x on this front


def test_interrupted_run_resumes_to_the_same_front(fork, tmp_path):
    objectives = ["size", "backlash"]
    full = epsilon_constraint_front(fork, objectives, 8, out=tmp_path / "a", starts=2)
    seen = []

    def interrupt(rec):
        seen.append(rec["id"])
        if len(seen) == 7:  # 2 anchors (multistart + tie-break each) + 3 points
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        epsilon_constraint_front(
            fork, objectives, 8, out=tmp_path / "b", starts=2, on_record=interrupt
        )
    store = tmp_path / "b" / "epsilon.jsonl"
    assert len(read_store(store)[1]) == 7
    again = []
    resumed = epsilon_constraint_front(
        fork,
        objectives,
        8,
        out=tmp_path / "b",
        starts=2,
        resume=True,
        on_record=lambda r: again.append(r["id"]),
    )
    # the other 5 points, then the polish of the chains' seam
    assert [i for i in again if "polish" not in i] == again[:5] and len(again) >= 5
    assert resumed.F == pytest.approx(full.F, rel=1e-9)
    assert len(resumed.points) == 8


def test_epsilon_front_on_local_processes_matches_in_process(fork, tmp_path):
    one = epsilon_constraint_front(fork, ["size", "backlash"], 8, out=tmp_path / "1", starts=2)
    two = epsilon_constraint_front(
        fork, ["size", "backlash"], 8, out=tmp_path / "2", starts=2, workers=2
    )
    # Two chains (one from each anchor) instead of one: the epsilon values differ a little
    # (each chain predicts its own), but the points lie on the same curve.
    assert len(two.points) == 8
    A, B = one.F, two.F
    assert B[[0, -1]] == pytest.approx(A[[0, -1]], rel=1e-6)  # the anchors
    assert B[:, 1] == pytest.approx(np.interp(B[:, 0], A[:, 0], A[:, 1]), rel=1.5e-2)
    assert two.metrics["hypervolume"] == pytest.approx(one.metrics["hypervolume"], rel=1e-2)


def test_front_on_a_dask_cluster_matches_local(fork, tmp_path):
    distributed = pytest.importorskip("distributed")
    local = epsilon_constraint_front(fork, ["size", "backlash"], 6, out=tmp_path / "l", starts=2)
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        remote = epsilon_constraint_front(
            fork,
            ["size", "backlash"],
            6,
            out=tmp_path / "d",
            starts=2,
            scheduler=client.scheduler.address,
        )
    assert len(remote.points) == 6 and all(p.verified for p in remote.points)
    assert remote.F[[0, -1]] == pytest.approx(local.F[[0, -1]], rel=1e-6)
    assert remote.metrics["hypervolume"] == pytest.approx(local.metrics["hypervolume"], rel=1e-2)


@pytest.mark.slow
def test_three_objective_front(cs, tmp_path):
    from optdesign.plots.front import plot_fronts

    front = epsilon_constraint_front(cs, ["ripple", "backlash", "size"], 4, out=tmp_path, starts=2)
    F = front.F
    assert F.shape[1] == 3 and len(F) >= 4
    assert non_dominated(F).all()
    for p in front.points:
        x = np.array([p.design[v.name] for v in cs.free])
        assert verify_design(cs, x)[0]
        for k, e in p.eps.items():
            assert p.objectives[k] <= e * (1 + 1e-6) + 1e-12
    # The size anchor is the smallest linkage; its size is on the front.
    assert F[:, 2].min() == pytest.approx(front.anchors["size"]["size"], rel=1e-6)
    from optdesign.plots import save_figure

    png = save_figure(plot_fronts(cs, [front]), tmp_path / "front3.png")
    assert png.stat().st_size > 10_000


# --- baselines -----------------------------------------------------------------------------
def test_nsga2_uses_the_vectorised_numpy_path(cs):
    pp = pymoo_problem(cs, ["ripple", "backlash"])
    X = np.vstack([cs.start(), cs.lower() + 0.3 * (cs.upper() - cs.lower())])
    out = {}
    pp._evaluate(X, out)
    ev = cs.evaluate(X)
    assert out["F"][:, 1] == pytest.approx(ev.objectives["backlash"])
    # G <= 0 exactly when the problem's own relative violation is 0.
    assert ((out["G"].max(axis=1) <= 0) == (ev.violation <= 0)).all()
    front = compute_front(
        cs, ["ripple", "backlash"], method="nsga2", pop_size=20, generations=15, seed=1
    )
    assert front.points and all(p.verified for p in front.points)
    for p in front.points:
        x = np.array([p.design[v.name] for v in cs.free])
        assert verify_design(cs, x)[0]


def test_weighted_sum_points_lie_on_the_epsilon_front(fork, tmp_path):
    ws = compute_front(fork, ["size", "backlash"], 5, "weighted_sum", out=tmp_path, starts=2)
    eps = epsilon_constraint_front(fork, ["size", "backlash"], 12, out=tmp_path, starts=2)
    # Five weights reach two distinct designs only: the two ends (size at its bound, the
    # backlash optimum); the other weights land on the backlash end again, to 1e-11, and
    # count as duplicates.
    assert len(ws.points) == 2
    assert sorted(p.objectives["size"] for p in ws.points)[0] == pytest.approx(30.0, rel=1e-6)
    assert min(p.objectives["backlash"] for p in ws.points) == pytest.approx(0.0194989, rel=1e-5)
    # No weighted-sum point beats the epsilon front (the fork's front is convex, so the
    # weighted sum finds true front points): each is within 1e-5 of being dominated.
    E = eps.F
    for f in ws.F:
        backlash_at = np.interp(f[0], E[:, 0], E[:, 1])
        assert f[1] >= backlash_at * (1 - 1e-2)


def test_cli_writes_front_files(fork, tmp_path):
    from optdesign.cli import main

    out = tmp_path / "run"
    code = main(
        [
            "pareto",
            str(PROBLEMS / "fork_min_backlash.toml"),
            "--objectives",
            "size,backlash",
            "--points",
            "6",
            "--out",
            str(out),
            "--workers",
            "2",
            "--starts",
            "2",
            "--deterministic",
            "--no-progress",
        ]
    )
    assert code == 0
    rows = list(csv.DictReader((out / "front.csv").open()))
    assert len(rows) == 6
    heads = {"size [mm]", "backlash [deg]", "R [mm]", "p [mm]", "d [mm]", "status", "active"}
    assert heads <= set(rows[0])
    assert all(r["status"] == "optimal" for r in rows)
    assert (out / "front.json").exists() and (out / "front.png").exists()
    assert (
        main(
            [
                "pareto",
                str(PROBLEMS / "fork_min_backlash.toml"),
                "--objectives",
                "size,bogus",
                "--out",
                str(out / "x"),
                "--no-progress",
            ]
        )
        == 2
    )


@pytest.fixture
def threaded_blas():
    """Every OpenBLAS of this process at two threads (as a machine with OPENBLAS_NUM_THREADS
    unset or 2 starts them), the counts restored after: the main process then differs
    from the one-thread workers unless the solves set their own count."""
    from optdesign.formulations.nlp.solve import solver_for
    from optdesign.solvers.blas import blas_libraries

    solver_for(load_problem(PROBLEMS / "fork_min_backlash.toml"), "ipopt")  # CasADi's BLAS
    before = [(lib, lib.get_threads()) for lib in blas_libraries()]
    for lib, _ in before:
        lib.set_threads(2)
    yield
    for lib, n in before:
        lib.set_threads(n)


@pytest.mark.usefixtures("threaded_blas")
def test_deterministic_front_is_the_same_for_any_workers_and_after_resume(fork, tmp_path):
    objectives = ["size", "backlash"]
    kw = dict(starts=2, deterministic=True)
    one = epsilon_constraint_front(fork, objectives, 8, out=tmp_path / "1", **kw)
    two = epsilon_constraint_front(fork, objectives, 8, out=tmp_path / "2", workers=2, **kw)
    assert len(one.points) == len(two.points) == 8
    # the same front bit for bit: the same tasks, the same tie rules and the same BLAS
    # thread count in every process do the same arithmetic
    assert two.F.tolist() == one.F.tolist()
    seen = []

    def interrupt(rec):
        seen.append(rec["id"])
        if len(seen) == 7:  # the 4 anchor records and 3 points
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        epsilon_constraint_front(
            fork, objectives, 8, out=tmp_path / "r", workers=2, on_record=interrupt, **kw
        )
    resumed = epsilon_constraint_front(
        fork, objectives, 8, out=tmp_path / "r", workers=2, resume=True, **kw
    )
    assert resumed.F.tolist() == one.F.tolist()
    # The chains met in the middle: points 1-3 started from their left neighbour, 4-6
    # from their right one (0 and 7 from the anchors).
    _, recs = read_store(tmp_path / "r" / "epsilon.jsonl")
    warm = [recs[f"epsilon-{i:04d}"]["warm"] for i in range(8)]
    assert warm[0] == "anchor-size" and warm[7] == "anchor-backlash"
    assert warm[1:7] == [f"epsilon-{i:04d}" for i in (0, 1, 2, 5, 6, 7)]


def test_catalogue_problem_fronts_stay_on_the_catalogue_or_are_refused(tmp_path, capsys):
    from optdesign.cli import main
    from optdesign.studies.pareto import NSGA2, WeightedSum
    from optdesign.studies.pareto.methods import RunOptions

    problem = load_problem(PROBLEMS / "cs_min_backlash_catalogue.toml")
    # a weighted sum of continuous NLPs would report off-catalogue designs as optimal
    with pytest.raises(Exception, match="leave the catalogue"):
        WeightedSum(points=3).run(problem, ["backlash", "ripple"], RunOptions(out=tmp_path))
    code = main(
        [
            "pareto",
            str(PROBLEMS / "cs_min_backlash_catalogue.toml"),
            "--objectives",
            "backlash,ripple",
            "--method",
            "weighted_sum",
            "--out",
            str(tmp_path / "ws"),
            "--no-progress",
        ]
    )
    assert code == 2
    assert "--method: weighted_sum would leave the catalogue" in capsys.readouterr().err
    assert not (tmp_path / "ws").exists()  # refused before any output
    # NSGA-II searches the catalogue variables as item indices
    front = NSGA2(pop_size=20, generations=10, seed=1).run(
        problem, ["backlash", "ripple"], RunOptions()
    )
    items = {v.name: set(v.values) for v in problem.free if v.discrete}
    assert items and len(front.points) > 0
    for p in front.points:
        for name, values in items.items():
            assert p.design[name] in values


def test_the_front_solver_reaches_every_point(fork, tmp_path):
    """solver="ipopt" solves every epsilon point with Ipopt (the primary throughout);
    by default the registry's primary (CasADi's sqpmethod) solves the points it can."""
    ipopt = od.pareto(fork, ["size", "backlash"], 6, out=tmp_path / "i", starts=2, solver="ipopt")
    assert ipopt.points and {p.solver for p in ipopt.points} == {"ipopt"}
    default = od.pareto(fork, ["size", "backlash"], 6, out=tmp_path / "d", starts=2)
    assert "sqpmethod" in {p.solver for p in default.points}


def test_each_epsilon_record_names_the_neighbour_it_started_from(fork, tmp_path):
    """The store says which chain computed each point: an epsilon point starts from the
    nearer anchor or the point before it in its chain, which the store holds."""
    import json

    od.pareto(fork, ["size", "backlash"], 6, out=tmp_path, starts=2)
    lines = (tmp_path / "epsilon.jsonl").read_text().splitlines()[1:]
    records = [json.loads(line) for line in lines]
    ids = {r["id"] for r in records}
    eps = [r for r in records if r["kind"] == "eps" and "polish" not in r["id"]]
    assert len(eps) == 6
    assert all(r["warm"] in ids and r["warm"] != r["id"] for r in eps)
    assert {r["warm"] for r in eps} >= {"anchor-size", "anchor-backlash"}


def test_extra_cold_starts_at_every_point_keep_the_front(fork, tmp_path):
    """extra_starts=2: every epsilon point also runs its neighbour's design and two
    seeded Sobol starts (a front's check against local optima); on the fork's front they
    find nothing better, so the front is the warm-started one, point for point, and each
    record counts its solves."""
    import json

    plain = od.pareto(fork, ["size", "backlash"], 6, out=tmp_path / "p", starts=2)
    extra = od.pareto(fork, ["size", "backlash"], 6, out=tmp_path / "e", starts=2, extra_starts=2)
    for a, b in zip(plain.points, extra.points, strict=True):
        assert b.objectives["size"] == pytest.approx(a.objectives["size"], rel=1e-6)
        assert b.objectives["backlash"] == pytest.approx(a.objectives["backlash"], rel=1e-6)
    lines = (tmp_path / "e" / "epsilon.jsonl").read_text().splitlines()[1:]
    eps = [r for r in map(json.loads, lines) if r["kind"] == "eps" and "polish" not in r["id"]]
    # the warm start, the neighbour's design and two Sobol starts; a point retried (a
    # jump in design space, say) runs the larger of its retry starts and the extra ones
    assert all(r["n_solves"] == 4 for r in eps if not r["retried"])
    assert all(r["n_solves"] >= 4 for r in eps) and sum(not r["retried"] for r in eps) >= 4


def test_a_front_given_out_writes_the_files_the_command_writes(tmp_path):
    """optdesign.api.pareto with ``out``: front.csv, front.json, front.png and report.html
    beside the store, as ``optdesign pareto`` writes them; ``files=False``: the store
    alone. The CSV's rows are the front's points."""
    import csv

    front = od.pareto(
        PROBLEMS / "cs_min_ripple.toml", ["ripple", "size"], points=4, out=tmp_path / "a"
    )
    names = {p.name for p in (tmp_path / "a").iterdir()}
    assert {"front.csv", "front.json", "front.png", "report.html", "epsilon.jsonl"} <= names
    with (tmp_path / "a" / "front.csv").open(newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r["on_front"] == "True"]
    assert len(rows) == len(front.points)
    od.pareto(
        PROBLEMS / "cs_min_ripple.toml",
        ["ripple", "size"],
        points=4,
        out=tmp_path / "b",
        files=False,
    )
    assert not {"front.csv", "front.png", "report.html"} & {
        p.name for p in (tmp_path / "b").iterdir()
    }


# --- what each limit costs at a front point --------------------------------------------------
def _resolved_log_sensitivity(problem, front, point, name, rel=1e-3):
    """d log(target) / d log(limit ``name``) at ``point``: its own epsilon problem (its
    target, the others held at its epsilon bounds) solved again by Ipopt from its design
    with the limit moved by ``rel`` to either side."""
    from optdesign.problem.parameters import limit_value, perturbed
    from optdesign.studies.pareto.eps_solver import EpsSolver

    p = limit_value(problem, name)
    h = rel * abs(p)
    values = []
    for q in (p + h, p - h):
        other = perturbed(problem, name, q)
        solver = EpsSolver(other, front.objectives, "ipopt")
        x0 = np.array([point.design[v.name] for v in other.free])
        r = solver.solve(point.target, point.eps, solver.nlp.start(x0=x0), use="fallback")
        assert r.success, (name, q, r.status)
        values.append(r.objective)
    return (values[0] - values[1]) / (2 * h) * p / point.objectives[point.target]


def test_each_front_points_page_shows_what_its_limits_cost(cs_front, tmp_path):
    """Issue 35: a front point's page listed the limits that bind it, then "what each
    limit costs: none". Each point now shows the costs of its own solve, and says of what."""
    import json

    page = od.report(cs_front, tmp_path / "report.html").read_text()
    start = page.index(">", page.index('id="report-data"')) + 1
    data = json.loads(page[start : page.index("</script>", start)])
    assert len(data["designs"]) == len(cs_front.points)
    for point, view in zip(cs_front.points, data["designs"], strict=True):
        assert view["costs_note"].startswith(f"costs in {point.target}, from this point's own")
        assert view["limits"] and view["sensitivities"]
        assert all(f" -> {point.target} " in line for line in view["sensitivities"])
        assert any(line.startswith("nut_travel_max 110 mm: ") for line in view["sensitivities"])


def test_a_front_points_costs_equal_resolves_of_its_own_problem(cs):
    """The costs at a point of a ripple-size front (SLSQP's points: the rows' multipliers
    from SLSQP, the bounds' from stationarity) equal re-solves of the point's own epsilon
    problem with the requirement or bound moved."""
    from optdesign.studies.pareto.costs import point_costs

    front = epsilon_constraint_front(cs, ["ripple", "size"], 3, starts=2)
    checked = set()
    for point in front.points[1:]:
        costs = point_costs(cs, front.objectives, point)
        assert costs.why == "" and costs.target == point.target == "size"
        assert costs.held == point.eps and set(point.eps) == {"ripple"}
        for s in costs.sensitivities:
            fd = _resolved_log_sensitivity(cs, front, point, s.name)
            assert s.log_sensitivity == pytest.approx(fd, rel=0.01, abs=1e-4), s.name
            checked.add(s.name)
    # a bound that SLSQP returned no multiplier for, and a requirement
    assert {"variables.p.lower", "requirements.mean_ratio.min"} <= checked


def test_a_fronts_costs_evaluated_together_equal_each_points_own(cs, cs_front, monkeypatch):
    """``Front.point_costs`` evaluates the points' models as one population per moved
    requirement: the same records, to the last digits, as each point's own evaluation,
    and far fewer model evaluations (one per moved requirement, not one per point)."""
    from optdesign.problem.design_problem import DesignProblem
    from optdesign.studies.pareto.costs import point_costs

    point_costs(cs, cs_front.objectives, cs_front.points[0])  # the per-problem caches filled
    calls = []
    build = DesignProblem._build
    monkeypatch.setattr(
        DesignProblem, "_build", lambda self, *a, **k: calls.append(1) or build(self, *a, **k)
    )
    together = cs_front.point_costs(cs)
    n_together = len(calls)
    alone = [point_costs(cs, cs_front.objectives, point) for point in cs_front.points]
    assert len(cs_front.points) >= 8 and n_together * 4 < len(calls) - n_together
    for a, b in zip(together, alone, strict=True):
        assert a.why == b.why == "" and a.basis == b.basis
        assert [s.name for s in a.sensitivities] == [s.name for s in b.sensitivities]
        for s, t in zip(a.sensitivities, b.sensitivities, strict=True):
            assert s.d_objective_d_limit == pytest.approx(t.d_objective_d_limit, rel=1e-9)
            assert (s.limit, s.unit) == (t.limit, t.unit)


def test_a_front_point_whose_costs_cannot_be_known_says_why(cs, cs_front):
    from dataclasses import replace

    from optdesign.reports.costs_text import front_point_costs

    point = cs_front.points[len(cs_front.points) // 2]
    shown = front_point_costs(cs, cs_front.objectives, replace(point, multipliers=None))
    assert shown == {
        "sensitivities": [],
        "costs_note": "not known for this point: the point's record keeps no multipliers of "
        "its solve",
    }
    # multipliers that leave the gradient of its Lagrangian far from zero: no KKT point's;
    # the point's problem is solved again from its design, and its costs are that solve's
    raw = point.multipliers
    wrong = replace(point, multipliers=replace(raw, lam_g=3 * raw.lam_g))
    again = front_point_costs(cs, cs_front.objectives, wrong)
    right = front_point_costs(cs, cs_front.objectives, point)
    assert again["costs_note"].startswith(
        f"costs in {point.target}, from its problem solved again from its design (the "
        "front's solve left multipliers that miss the optimality conditions by "
    )
    assert right["costs_note"].startswith(f"costs in {point.target}, from this point's own solve")
    assert [ln.split(" -> ")[0] for ln in again["sensitivities"]] == [
        ln.split(" -> ")[0] for ln in right["sensitivities"]
    ]
    # ... unless that solve ends elsewhere: then the costs are not known, and it says why
    elsewhere = {**wrong.objectives, wrong.target: 2 * wrong.objectives[wrong.target]}
    shown = front_point_costs(cs, cs_front.objectives, replace(wrong, objectives=elsewhere))
    assert shown["sensitivities"] == []
    assert shown["costs_note"].startswith(
        "not known for this point: its solve's multipliers do not satisfy the optimality"
    )
    assert shown["costs_note"].endswith(
        "nor did a solve again from its design end at its value or just below"
    )
    # a point its front's solver left just short of its optimum (SLSQP's tie-breaks with
    # the oldest releases): the solve again ends lower, and the note says by how much
    short = {**wrong.objectives, wrong.target: (1 + 1e-4) * wrong.objectives[wrong.target]}
    shown = front_point_costs(cs, cs_front.objectives, replace(wrong, objectives=short))
    names = [ln.split(" -> ")[0] for ln in shown["sensitivities"]]
    assert names == [ln.split(" -> ")[0] for ln in again["sensitivities"]]
    assert "; the solve again ended 0.0001 lower)" in shown["costs_note"]


# A time limit for a Pareto study (``od.pareto(..., time_limit=)``, ``optdesign pareto
# --time-limit``): no point begins after it, the points running finish and are stored, the
# front says how many were left out, and a resume computes them - to the front an
# uninterrupted run gives. The deadline is replaced by a counter of stored records here,
# so that no test depends on timing.


ROOT = Path(__file__).resolve().parents[3]


FILE = ROOT / "problems" / "cs_min_backlash.toml"


OBJECTIVES = ["ripple", "backlash"]


def passes_after(monkeypatch, n_records: int) -> list:
    """The deadline passes once ``n_records`` records are stored (the on_record list)."""
    seen: list = []
    monkeypatch.setattr(deadline, "passed", lambda: len(seen) >= n_records)
    return seen


def test_a_front_stopped_by_its_time_limit_says_so_and_a_resume_completes_it(tmp_path, monkeypatch):
    problem = od.load(FILE)
    seen = passes_after(monkeypatch, 8)  # the anchors (4 records) and a few points
    front = od.pareto(
        problem, OBJECTIVES, points=12, out=tmp_path, time_limit=60, on_record=seen.append
    )
    n = len(front.points) + len(front.rejected)
    assert 0 < n < 12
    note = f"time limit of 60 s reached: {12 - n} of 12 points not computed"
    assert front.notes and front.notes[0].startswith(note)
    assert f"note      epsilon: {note}" in front.summary()
    assert front.to_dict()["notes"] == front.notes
    monkeypatch.undo()
    resumed = od.pareto(problem, OBJECTIVES, points=12, out=tmp_path, resume=True)
    whole = od.pareto(problem, OBJECTIVES, points=12)
    assert resumed.notes == [] and len(resumed.points) == 12
    # no optimum lost: the same front as an uninterrupted run (one worker)
    assert np.array_equal(resumed.F, whole.F)


def test_a_time_limit_before_the_anchors_is_refused_naming_it(monkeypatch):
    passes_after(monkeypatch, 0)
    with pytest.raises(od.InputError) as caught:
        od.pareto(od.load(FILE), OBJECTIVES, points=6, time_limit=5)
    assert caught.value.field == "time_limit"
    text = str(caught.value)
    assert "5 s passed before the anchors (ripple, backlash) were computed" in text
    assert text.endswith("give more time, or a run with an out folder continues")


def test_time_limit_is_refused_where_no_point_would_watch_it(tmp_path, capsys):
    # the command line's refusal, word for word (below)
    with pytest.raises(od.InputError, match="time_limit: not applied by the nsga2 method"):
        od.pareto(FILE, OBJECTIVES, points=6, method="nsga2", time_limit=5)
    with pytest.raises(od.InputError, match=r"time_limit: 0 is outside \(0, 86400\]"):
        od.pareto(FILE, OBJECTIVES, points=6, time_limit=0)
    argv = ["pareto", str(FILE), "--objectives", "ripple,backlash", "--points", "4"]
    code = main([*argv, "--method", "weighted_sum", "--time-limit", "5", "--out", str(tmp_path)])
    assert code == 2
    err = capsys.readouterr().err
    assert "--time-limit: not applied by the weighted_sum method" in err
    assert not (tmp_path / "front.csv").exists()


def test_pareto_time_limit_on_the_command_line(tmp_path, monkeypatch, capsys):
    # the command line's own runs: the deadline passes once 6 records are stored (counted
    # by the store's lines, as a user's folder shows them)
    out = tmp_path / "front"
    store = out / "epsilon.jsonl"

    def stored() -> int:
        return len(store.read_text().splitlines()) - 1 if store.exists() else 0

    monkeypatch.setattr(deadline, "passed", lambda: stored() >= 6)
    argv = ["pareto", str(FILE), "--objectives", "ripple,backlash", "--points", "10"]
    code = main([*argv, "--time-limit", "30", "--out", str(out), "--no-plot", "--no-progress"])
    text = capsys.readouterr().out
    assert code == 0
    assert "note      epsilon: time limit of 30 s reached:" in text
    assert "of 10 points not computed" in text
    data = json.loads((out / "front.json").read_text())
    assert any("time limit of 30 s reached" in n for f in data["fronts"] for n in f["notes"])


# --- a three-objective front, fast -----------------------------------------------------------
def test_three_objective_front_small(tmp_path):
    """The crank-slider's (ripple, backlash, size) front on a 2 x 2 grid.

    Checked against properties an epsilon-constraint front must have, not its own
    output: three columns; every point meets its epsilons; the ripple and backlash ends
    are the single-objective optima found (and checked against a global search) in
    test_solve (0.0121114, 0.0362197 deg); within a row (same ripple bound) a looser
    backlash bound never gives a larger size; no point is dominated by another.
    """
    from optdesign.studies.pareto import compute_front
    from optdesign.studies.pareto.metrics import non_dominated

    cs = load_problem(PROBLEMS / "cs_min_backlash.toml")
    front = compute_front(
        cs, ["ripple", "backlash", "size"], 3, "epsilon", out=tmp_path, starts=2, workers=1
    )
    F = front.F
    assert F.shape[1] == 3 and len(F) >= 4
    assert all(p.verified for p in front.points)
    for p in front.points:
        for k, e in p.eps.items():
            assert p.objectives[k] <= e * (1 + 1e-6) + 1e-12, (p.eps, p.objectives)
    assert F[:, 0].min() == pytest.approx(0.0121114, rel=1e-4)
    assert F[:, 1].min() == pytest.approx(0.0362197, rel=1e-4)
    # the smallest linkage of the box is on the front
    assert F[:, 2].min() == pytest.approx(front.anchors["size"]["size"], rel=1e-6)
    # rows: points with both a ripple and a backlash bound, grouped by the ripple bound
    rows: dict[float, list] = {}
    for p in front.points:
        if "ripple" in p.eps and "backlash" in p.eps:
            rows.setdefault(round(p.eps["ripple"], 9), []).append(p)
    assert len(rows) == 2 and all(len(r) >= 2 for r in rows.values())
    for row in rows.values():
        row.sort(key=lambda p: p.eps["backlash"])
        sizes = [p.objectives["size"] for p in row]
        assert all(b <= a * (1 + 1e-6) for a, b in itertools.pairwise(sizes)), sizes
    # distinct points only: near-duplicates (same point reached twice) are not dominated
    uniq = np.unique(np.round(F / np.abs(F).max(axis=0), 6), axis=0)
    assert non_dominated(uniq).all()


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


# --- the front's objectives ---------------------------------------------------------------
def test_a_library_front_of_a_repeated_objective_is_refused_naming_the_field(cs_min_backlash):
    """``compute_front`` (below the API's own check) refuses an objective given twice,
    naming the field and the list, before any solve."""
    with pytest.raises(InputError) as caught:
        compute_front(cs_min_backlash, ["backlash", "backlash"], 3)
    assert caught.value.field == "objectives"
    assert str(caught.value) == "objectives: repeated objective in ['backlash', 'backlash']"


def test_a_library_front_of_an_unknown_method_is_refused_naming_the_known_ones(cs_min_backlash):
    """``compute_front`` refuses a method name it does not know, listing the known ones."""
    with pytest.raises(InputError) as caught:
        compute_front(cs_min_backlash, ["backlash", "size"], 3, method="simplex")
    assert caught.value.field == "method"
    assert str(caught.value).startswith("method: unknown method 'simplex' (known: epsilon, ")


def test_the_library_front_refuses_a_wrong_number_of_objectives_naming_the_field():
    """``compute_front`` (the studies layer, under od.pareto's own checks) refuses one or
    four objectives itself, naming ``objectives``."""
    from optdesign.studies.pareto import compute_front

    fork = load(ROOT / "problems" / "fork_min_backlash.toml")
    for objectives in (["size"], ["size", "backlash", "ripple", "motor_torque"]):
        with pytest.raises(InputError) as caught:
            compute_front(fork, objectives, 3)
        assert caught.value.field == "objectives"
        assert caught.value.reason == f"give two or three objectives, got {objectives}"
