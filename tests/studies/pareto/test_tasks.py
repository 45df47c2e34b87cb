"""The tasks of a front's computation (studies/pareto/tasks.py), pinned function by function.

Each task runs here on a stand-in epsilon solver whose answers the test scripts (the
results of successive solves, in order) and which logs every call: the target, the
limits, the start and the back-end of each solve. So every count, every limit, every
start and every branch (agreeing starts, the fallback re-run, a tie-break kept or not, a
point retried and why, the cold starts and which of them wins) is checked against values
worked out by hand. The record of a result is the stand-in too (it logs what the task
hands it: problem, kind, target, limits, id, fingerprint); the real records of real
solves are the pareto tests' (tests/studies/pareto/test_pareto.py, test_methods.py).
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import optdesign as od
from optdesign.problem.load import load
from optdesign.solvers.multistart import sobol_starts
from optdesign.solvers.result import Result
from optdesign.studies.pareto import (
    PointRecord,
    tasks,
)
from optdesign.studies.pareto.tasks import ANCHOR_SLACK, arc_eps, front_task, row_eps
from optdesign.tolerances import OBJECTIVE_TIE_TOL

INF = math.inf

#: A stand-in problem of two free variables u in [2, 12] and v in [1, 3], on a grid of five
#: angles (too few to thin: the anchors' starts solve the problem itself).
PROBLEM = SimpleNamespace(
    name="stand-in",
    phi=np.linspace(-0.5, 0.5, 5),
    free=[SimpleNamespace(name="u"), SimpleNamespace(name="v")],
    lower=lambda: np.array([2.0, 1.0]),
    upper=lambda: np.array([12.0, 3.0]),
    start=lambda: np.array([5.0, 1.5]),
)


def _res(status="optimal", x=(1.0, 1.0), objective=None, max_violation=math.nan, **objectives):
    """A solve's result: its design ``x`` (u, v) and objectives (``objective``: the
    value a multistart compares, default the first objective given)."""
    if objective is None:
        objective = next(iter(objectives.values()), math.nan)
    design = {"u": x[0], "v": x[1]} if x is not None else {}
    return Result(
        status=status,
        objective=objective,
        formulation="epigraph",
        objectives=dict(objectives),
        design=design,
        max_violation=max_violation,
    )


def _failed(max_violation=1.0, x=(1.0, 1.0)):
    return _res("failed", x=x, objective=math.nan, max_violation=max_violation)


class FakeSolver:
    """The stand-in :class:`EpsSolver`: ``answers`` are the results of its solves (the
    epsilon solves and the fallback back-end's), in order; every call is logged."""

    fingerprint = "nlp-fp"

    def __init__(self, answers, has_fallback=True):
        self.answers = list(answers)
        self.has_fallback = has_fallback
        self.built = []  # (problem, objectives, method) of each EpsSolver(...)
        self.solves = []  # (target, limits, start, fallback, use)
        self.backends = []  # (use, start, target, bounds)
        self.slopes = []
        self.starts_from = []
        self.records = []  # what each record was made of
        self.nlp = self

    # EpsSolver(problem, objectives, method)
    def __call__(self, problem, objectives, method=None):
        self.built.append((problem, objectives, method))
        return self

    # solver.nlp.start / target / bounds
    def start(self, x0):
        return ("x0", tuple(float(v) for v in np.asarray(x0)))

    def target(self, coefs):
        return ("target", dict(coefs))

    def bounds(self):
        return "the bounds"

    def _next(self):
        assert self.answers, "the task solved more often than scripted"
        return self.answers.pop(0)

    def solve(self, target, eps, start, fallback=True, use=None):
        self.solves.append((target, dict(eps), start, fallback, use))
        return self._next()

    def start_from(self, neighbour, x=None):
        given = None if x is None else tuple(float(v) for v in x)
        self.starts_from.append((None if neighbour is None else neighbour.id, given))
        return ("from", self.starts_from[-1])

    def slope(self, target, eps_name, record):
        self.slopes.append((target, eps_name, record.objectives[target]))
        return -2.5

    def backend(self, use="primary"):
        def solve(start, target, bounds):
            self.backends.append((use, start, target, bounds))
            return self._next()

        return SimpleNamespace(solve=solve)


@pytest.fixture
def fake(monkeypatch):
    """Install a stand-in solver; ``fake(answers, has_fallback)`` scripts it."""
    made = []

    def record(problem, result, kind, target, eps, task_id="", fingerprint=""):
        made[-1].records.append((problem, kind, target, dict(eps), task_id, fingerprint))
        x = [result.design["u"], result.design["v"]] if result.design else None
        return PointRecord(
            status=result.status,
            objectives=dict(result.objectives),
            design=dict(result.design),
            id=task_id,
            kind=kind,
            target=target,
            x=x,
            eps={k: float(v) for k, v in eps.items() if np.isfinite(v)},
        )

    def install(answers, has_fallback=True):
        solver = FakeSolver(answers, has_fallback)
        made.append(solver)
        monkeypatch.setattr(tasks, "EpsSolver", solver)
        monkeypatch.setattr(tasks, "record_from_result", record)
        return solver

    return install


def _stored(id_, kind="eps", status="optimal", x=(1.0, 1.0), eps=None, **objectives):
    """A finished task's record as the runner hands it to the next task (a dict)."""
    return PointRecord(
        id=id_,
        kind=kind,
        target="b",
        status=status,
        verified=True if status == "optimal" else None,
        objectives=dict(objectives),
        x=None if x is None else list(x),
        eps=dict(eps or {}),
    ).to_dict()


# --- the solver and the record of a task ---------------------------------------------------
def test_a_task_builds_its_solver_from_its_problem_objectives_and_solver(fake):
    solver = fake([_res(a=1.0, b=2.0)])
    base = {"id": "p-0", "kind": "eps", "problem": PROBLEM, "objectives": ["a", "b"]}
    base.update(target="a", eps={"b": 3.0}, index=0)
    front_task({**base, "solver": "ipopt"}, {})
    assert solver.built == [(PROBLEM, ["a", "b"], "ipopt")]
    solver.answers.append(_res(a=1.0, b=2.0))
    front_task(base, {})  # no solver named: the default (None)
    assert solver.built[-1] == (PROBLEM, ["a", "b"], None)
    # every record is made of the task's problem, id and the solver's fingerprint
    assert solver.records == [(PROBLEM, "eps", "a", {"b": 3.0}, "p-0", "nlp-fp")] * 2


@pytest.mark.parametrize(
    "kind, stored",
    [("anchor-multistart", "anchor-multistart"), ("anchor", "anchor"), ("eps", "eps"),
     ("weighted_sum", "weighted_sum")],
)  # fmt: skip
def test_each_kind_of_task_makes_its_kind_of_record(fake, draws, kind, stored):
    fake([_res(a=1.0, b=2.0), _res(a=1.0, b=2.0)])
    ms = _stored("ms", "anchor-multistart", a=1.0, b=2.0)
    task = {"id": "t", "kind": kind, "problem": PROBLEM, "objectives": ["a", "b"]}
    task.update(order=["a", "b"], starts=1, seed=0, multistart="ms", target="a")
    task.update(eps={"b": 3.0}, index=0, weights={"a": 1.0}, normalise={"a": [0, 1]}, x0=[1, 1])
    record = front_task(task, {"ms": ms})
    assert record["kind"] == stored and record["id"] == "t"


# --- an anchor's global search ---------------------------------------------------------------
class Draws:
    """Stand-in tilted starts (:class:`optdesign.search.starts.TiltedStarts`): start k is
    (2 + k, 1 + k / 10), whatever is asked before."""

    lower = np.array([2.0, 1.0])

    def first(self, n):
        return np.array([[2.0 + k, 1.0 + 0.1 * k] for k in range(n)])


def _draw(k):
    return ("x0", (2.0 + k, 1.0 + 0.1 * k))


@pytest.fixture
def draws(monkeypatch):
    """The anchor's random starts are :class:`Draws`; logs (objective, seed) of each."""
    asked = []

    def tilted(problem, objective, seed):
        asked.append((objective, seed))
        return Draws()

    monkeypatch.setattr(tasks, "tilted_starts", tilted)
    monkeypatch.setattr(tasks, "own_starts", lambda problem: [])
    return asked


def _ms_task(**kw):
    task = {"id": "anchor-a-ms", "kind": "anchor-multistart", "problem": PROBLEM}
    task.update(objectives=["a", "b", "c"], order=["a", "b", "c"], starts=4, seed=5, agree=None)
    task.update(kw)
    return task


def test_an_anchor_search_solves_the_first_objective_from_its_draws_in_order(fake, draws):
    solver = fake([_res(a=3.0), _res(a=1.0), _res(a=2.0), _res(a=5.0)])
    record = front_task(_ms_task(), {})
    free = {"b": INF, "c": INF}
    assert draws == [("a", 5)]
    assert solver.solves == [("a", free, _draw(k), False, None) for k in range(4)]
    assert record["objectives"] == {"a": 1.0} and record["status"] == "optimal"
    assert record["kind"] == "anchor-multistart" and record["target"] == "a"
    # four starts, four optima: too few to estimate anything; the cap ended it
    assert record["multistart"] == {"n_starts": 4, "n_planned": 4, "n_at_best": 1,
                                    "agree": None, "stopped_early": False, "optima": 4,
                                    "counted": 4, "p_better": 1.0,
                                    "stop": "all starts run"}  # fmt: skip
    assert record["order"] == ["a", "b", "c"] and record["n_solves"] == 4
    assert record["eps"] == {} and solver.records[0][1:4] == ("anchor-multistart", "a", {})
    assert 0.0 <= record["wall_time_s"] < 60.0


def test_an_anchor_search_of_one_start_solves_its_first_draw_only(fake, draws):
    solver = fake([_res(a=3.0)])
    record = front_task(_ms_task(starts=1, order=["b", "a"]), {})
    assert solver.solves == [("b", {"a": INF}, _draw(0), False, None)]
    assert record["multistart"]["n_planned"] == 1 and record["n_solves"] == 1


def test_an_anchor_search_stops_when_its_odds_settle(fake, draws):
    """Eight starts at one optimum: fewer than half an optimum is expected unseen (2/5),
    so the ninth start is never solved; the odds of a better one, 2/56."""
    near = 1.0 * (1 + 0.5 * OBJECTIVE_TIE_TOL)
    answers = [_res(a=1.0, x=(1, 0))] + [_res(a=near, x=(2, 0))] * 8
    solver = fake(answers)
    record = front_task(_ms_task(starts=30), {})
    assert len(solver.solves) == 8 and record["n_solves"] == 8
    assert record["x"] == [1.0, 0.0]  # the first start at the best
    ms = record["multistart"]
    assert (ms["n_starts"], ms["optima"], ms["counted"], ms["stop"]) == (8, 1, 8, "odds")
    assert ms["p_better"] == pytest.approx(2 / 56) and ms["stopped_early"]


def test_an_anchor_search_waits_for_agree_starts_at_the_best(fake, draws):
    """agree=9: the odds settle after eight starts at one optimum, but nine must agree."""
    solver = fake([_res(a=1.0)] * 12)
    record = front_task(_ms_task(starts=30, agree=9), {})
    assert len(solver.solves) == 9
    assert record["multistart"]["n_at_best"] == 9 and record["multistart"]["agree"] == 9


def test_an_anchor_search_none_of_whose_starts_succeeds_is_run_again_with_the_fallback(fake, draws):
    answers = [_failed(3.0), _failed(2.0), _failed(4.0), _res(a=7.0, x=(7, 1)), _failed(1.0)]
    solver = fake(answers)
    record = front_task(_ms_task(starts=2, agree=1), {})
    assert [s[3] for s in solver.solves] == [False, False, True, True]
    assert [s[2] for s in solver.solves[2:]] == [s[2] for s in solver.solves[:2]]
    assert record["status"] == "optimal" and record["x"] == [7.0, 1.0]
    # the second search ran its two starts: 2 + 2 solves, its record the second's
    assert record["n_solves"] == 4
    ms = record["multistart"]
    assert (ms["n_starts"], ms["n_planned"], ms["n_at_best"], ms["agree"]) == (2, 2, 1, 1)
    assert len(solver.answers) == 1  # the last scripted answer was never asked for


def test_an_anchor_search_that_fails_throughout_reports_its_least_violated_start(fake, draws):
    fake([_failed(3.0, x=(3, 0)), _failed(2.0, x=(2, 0))] * 2)
    record = front_task(_ms_task(starts=2), {})
    assert record["status"] == "failed" and record["x"] == [2.0, 0.0]
    assert record["n_solves"] == 4 and record["multistart"]["n_at_best"] == 0
    assert record["multistart"]["n_starts"] == 2 and record["multistart"]["p_better"] is None


def test_an_anchor_search_without_a_fallback_is_not_run_again(fake, draws):
    solver = fake([_failed(3.0), _failed(2.0)], has_fallback=False)
    record = front_task(_ms_task(starts=2), {})
    assert len(solver.solves) == 2 and record["n_solves"] == 2
    assert record["status"] == "failed"


def test_an_anchor_search_with_one_success_is_not_run_again(fake, draws):
    solver = fake([_failed(3.0), _res(a=2.0)])
    record = front_task(_ms_task(starts=2), {})
    assert len(solver.solves) == 2 and record["n_solves"] == 2
    assert record["multistart"]["n_at_best"] == 1


# --- an anchor's tie-breaks --------------------------------------------------------------------
def _tie_task(order=("a", "b", "c")):
    task = {"id": "anchor-a", "kind": "anchor", "problem": PROBLEM, "multistart": "ms"}
    task.update(objectives=sorted(order), order=list(order))
    return task


def _ms_record(status="optimal", **objectives):
    d = _stored("ms", "anchor-multistart", status=status, x=(4.0, 0.5), **objectives)
    d["n_solves"] = 3
    d["multistart"] = {"n_starts": 3, "n_planned": 4, "n_at_best": 2, "agree": 2,
                       "stopped_early": True, "optima": 1, "counted": 3, "p_better": 0.5,
                       "stop": "odds"}  # fmt: skip
    return d


def _held(value):
    return value * (1 + ANCHOR_SLACK) + 1e-12


def test_tie_breaks_hold_each_objective_at_its_optimum_and_minimise_the_next(fake):
    solver = fake([_res(x=(3, 1), a=2.0, b=4.0, c=9.0), _res(x=(2, 1), a=2.0, b=4.0, c=6.0)])
    ms = _ms_record(a=2.0, b=5.0, c=7.0)
    record = front_task(_tie_task(), {"ms": ms})
    held_a, held_b = _held(2.0), _held(4.0)
    assert solver.solves == [
        ("b", {"a": held_a, "c": INF}, ("x0", (4.0, 0.5)), True, "tie"),
        ("c", {"a": held_a, "b": held_b}, ("x0", (3.0, 1.0)), True, "tie"),
    ]
    assert [r[1:5] for r in solver.records] == [
        ("anchor", "b", {"a": held_a}, "anchor-a"),
        ("anchor", "c", {"a": held_a, "b": held_b}, "anchor-a"),
    ]
    assert record["id"] == "anchor-a" and record["kind"] == "anchor"
    assert record["target"] == "c" and record["x"] == [2.0, 1.0]
    assert record["objectives"] == {"a": 2.0, "b": 4.0, "c": 6.0}
    assert record["order"] == ["a", "b", "c"] and record["n_solves"] == 3 + 2
    assert record["multistart"] == ms["multistart"]
    assert 0.0 <= record["wall_time_s"] < 60.0


def test_a_tie_break_that_fails_keeps_the_point_before_it(fake):
    """A first tie-break that fails with both back-ends (the small barrier's, then
    Ipopt's defaults, from the same start) keeps the multistart's point; the next
    tie-break holds the second objective at that point's value."""
    solver = fake([_failed(), _failed(), _res(x=(2, 1), a=2.0, b=5.0, c=6.5)])
    record = front_task(_tie_task(), {"ms": _ms_record(a=2.0, b=5.0, c=7.0)})
    held = {"a": _held(2.0), "c": INF}
    assert [s[4] for s in solver.solves] == ["tie", "fallback", "tie"]
    assert solver.solves[0][:3] == solver.solves[1][:3] == ("b", held, ("x0", (4.0, 0.5)))
    assert solver.solves[2][:3] == ("c", {"a": _held(2.0), "b": _held(5.0)}, ("x0", (4.0, 0.5)))
    assert record["objectives"]["c"] == 6.5 and record["n_solves"] == 6
    assert record["multistart"]["n_starts"] == 3


def test_a_tie_break_the_small_barrier_fails_is_taken_from_ipopts_defaults(fake):
    solver = fake([_failed(), _res(x=(2, 2), a=2.0, b=4.0)])
    record = front_task(_tie_task(("a", "b")), {"ms": _ms_record(a=2.0, b=5.0)})
    assert [s[4] for s in solver.solves] == ["tie", "fallback"]
    assert record["x"] == [2.0, 2.0] and record["objectives"]["b"] == 4.0
    assert record["n_solves"] == 5


@pytest.mark.parametrize(
    "value, kept",
    [(5.0, True), (5.0 * (1 + 1e-9) + 1e-15, True), (5.0 * (1 + 2e-9), False), (6.0, False)],
)
def test_a_tie_break_worse_than_its_start_is_a_solver_failure(fake, value, kept):
    """The tie-break's start is feasible with its own value: a result worse than it (by
    more than 1e-9 relative) is not taken."""
    # a result not taken is tried again with Ipopt's defaults (here: as bad)
    fake([_res(x=(2, 2), a=2.0, b=value)] * (1 if kept else 2))
    record = front_task(_tie_task(("a", "b")), {"ms": _ms_record(a=2.0, b=5.0)})
    assert record["x"] == ([2.0, 2.0] if kept else [4.0, 0.5])
    assert record["objectives"]["b"] == (value if kept else 5.0)
    assert record["kind"] == "anchor" and record["n_solves"] == (4 if kept else 5)


def test_a_tie_break_of_an_objective_at_zero_keeps_a_result_within_1e_15(fake):
    fake([_res(x=(2, 2), a=2.0, b=1e-15)])
    record = front_task(_tie_task(("a", "b")), {"ms": _ms_record(a=2.0, b=0.0)})
    assert record["x"] == [2.0, 2.0]
    fake([_res(x=(2, 2), a=2.0, b=3e-15)] * 2)
    record = front_task(_tie_task(("a", "b")), {"ms": _ms_record(a=2.0, b=0.0)})
    assert record["x"] == [4.0, 0.5]


def test_an_anchor_whose_multistart_failed_is_that_record_without_a_tie_break(fake):
    solver = fake([])
    ms = _ms_record(status="failed", a=2.0, b=5.0)
    record = front_task(_tie_task(), {"ms": ms})
    assert solver.solves == []
    assert record["id"] == "anchor-a" and record["kind"] == "anchor"
    assert record["status"] == "failed" and record["n_solves"] == 3
    assert record["order"] == ["a", "b", "c"]


# --- an epsilon point ------------------------------------------------------------------------
def _eps_task(**kw):
    task = {"id": "epsilon-0003", "kind": "eps", "problem": PROBLEM, "index": 3}
    task.update(objectives=["a", "b"], target="b", eps={"a": 2.0})
    task.update(kw)
    return task


def test_an_epsilon_point_with_its_limit_solves_once_from_the_problems_start(fake):
    solver = fake([_res(a=2.0, b=4.0)])
    record = front_task(_eps_task(), {})
    assert solver.starts_from == [(None, None)]
    assert solver.solves == [("b", {"a": 2.0}, ("from", (None, None)), True, None)]
    assert solver.records[0][1:] == ("eps", "b", {"a": 2.0}, "epsilon-0003", "nlp-fp")
    assert record["kind"] == "eps" and record["target"] == "b" and record["eps"] == {"a": 2.0}
    assert record["retried"] == "" and record["n_solves"] == 1 and record["warm"] is None
    # one limit: the front's local slope, from the solver's multiplier
    assert solver.slopes == [("b", "a", 4.0)] and record["slope"] == -2.5
    assert 0.0 <= record["wall_time_s"] < 60.0


def test_an_epsilon_point_of_two_limits_has_no_slope(fake):
    solver = fake([_res(a=2.0, c=1.0, b=4.0)])
    record = front_task(_eps_task(eps={"a": 2.0, "c": 1.5}), {})
    assert solver.slopes == [] and record["slope"] is None


def test_a_failed_epsilon_point_has_no_slope_and_says_it_failed(fake):
    solver = fake([_failed()])
    record = front_task(_eps_task(), {})
    assert solver.slopes == [] and record["slope"] is None
    assert record["retried"] == "failed" and record["n_solves"] == 1  # no retry starts


def test_an_epsilon_point_starts_from_its_solved_neighbour(fake):
    solver = fake([_res(a=2.0, b=4.0)])
    nb = _stored("epsilon-0002", a=1.5, b=4.5, eps={"a": 1.5})
    record = front_task(_eps_task(warm="epsilon-0002"), {"epsilon-0002": nb})
    assert solver.starts_from == [("epsilon-0002", None)]
    assert record["warm"] == "epsilon-0002" and record["retried"] == ""


def test_an_epsilon_point_whose_neighbour_failed_starts_from_the_problems_start(fake):
    """A failed neighbour is no start and no yardstick: a worse point is not retried."""
    solver = fake([_res(a=2.0, b=9.0, x=(9, 1))])
    nb = _stored("epsilon-0002", status="failed", a=1.5, b=4.5, eps={"a": 1.5})
    record = front_task(_eps_task(warm="epsilon-0002", retry_starts=2), {"epsilon-0002": nb})
    assert solver.starts_from == [(None, None)]
    assert record["retried"] == "" and record["n_solves"] == 1
    assert record["warm"] == "epsilon-0002"


def test_a_grid_point_takes_its_limit_from_its_row_head(fake):
    solver = fake([_res(a=2.0, b=4.0, c=1.0)])
    head = _stored("head", a=1.0, b=2.0, c=3.0)
    task = _eps_task(target="c", b_name="b", b_hi=6.0, frac=0.25, eps_row={"a": 1.5})
    del task["eps"]
    task["row_head"] = "head"
    front_task(task, {"head": head})
    assert solver.solves[0][1] == row_eps(task, PointRecord.from_dict(head))
    assert solver.solves[0][1]["b"] == pytest.approx(_held(2.0) + 0.25 * (6 - _held(2.0)))


def test_an_arc_point_takes_its_limit_from_its_neighbour(fake):
    solver = fake([_res(a=2.0, b=4.0)])
    frame = {"a0": 1.0, "b0": 10.0, "ra": 4.0, "rb": 8.0, "a_lo": 1.5, "a_hi": 4.5}
    task = _eps_task(frame=frame, eps_name="a", arc=1.0, fallback_eps=3.0, warm="nb")
    del task["eps"]
    nb = _stored("nb", a=2.0, b=7.0, eps={"a": 2.5})
    nb["slope"] = -3.0
    front_task(task, {"nb": nb})
    assert solver.solves[0][1] == {"a": pytest.approx(3.1)}  # arc_eps, worked out below


@pytest.mark.parametrize(
    "value, retried",
    [(4.0, False), (4.0 * (1 + OBJECTIVE_TIE_TOL) + 1e-12, False), (4.0 * (1 + 2e-6), True)],
)
def test_a_point_worse_than_a_neighbour_with_a_tighter_limit_is_retried(fake, value, retried):
    """The point's limit is looser (or equal): its optimum cannot be worse than the
    neighbour's, beyond the tie tolerance; if it is, it is re-solved from cold starts."""
    answers = [_res(a=2.0, b=value, x=(1.0, 1.0))]
    answers += [_res(a=2.0, b=3.0, x=(2.0, 1.0)), _res(a=2.0, b=3.5, x=(3.0, 1.0))]
    solver = fake(answers)
    nb = _stored("nb", a=2.0, b=4.0, eps={"a": 2.0}, x=(1.0, 1.0))
    record = front_task(_eps_task(warm="nb", retry_starts=1, seed=4), {"nb": nb})
    if not retried:
        assert record["retried"] == "" and record["n_solves"] == 1
        return
    assert record["retried"] == "worse than its neighbour with a looser bound"
    # the neighbour's design first, then the Sobol starts of the point (seed + 7919 index)
    sobol = sobol_starts(PROBLEM.lower(), PROBLEM.upper(), 1, 4 + 7919 * 3)
    assert [s[2] for s in solver.solves[1:]] == [("x0", (1.0, 1.0)), ("x0", tuple(sobol[0]))]
    assert all(s[:2] == ("b", {"a": 2.0}) for s in solver.solves)
    assert record["n_solves"] == 3 and record["objectives"]["b"] == 3.0
    assert record["x"] == [2.0, 1.0] and record["slope"] == -2.5


def test_a_point_worse_than_a_neighbour_without_that_limit_is_retried(fake):
    """A neighbour without the point's limit counts as unlimited below: looser."""
    fake([_res(a=2.0, b=5.0), _res(a=2.0, b=4.0), _res(a=2.0, b=4.5)])
    nb = _stored("nb", a=2.0, b=4.0, eps={"c": 1.0})
    record = front_task(_eps_task(warm="nb", retry_starts=1), {"nb": nb})
    assert record["retried"] == "worse than its neighbour with a looser bound"


def test_a_point_with_a_tighter_limit_than_its_neighbour_may_be_worse(fake):
    fake([_res(a=1.0, b=5.0)])
    nb = _stored("nb", a=2.0, b=4.0, eps={"a": 2.5})
    record = front_task(_eps_task(warm="nb", retry_starts=1), {"nb": nb})
    assert record["retried"] == ""
    # one limit tighter, one looser: not looser
    fake([_res(a=1.0, c=1.0, b=5.0)])
    nb = _stored("nb", a=2.0, b=4.0, eps={"a": 1.0, "c": 2.0})
    task = _eps_task(warm="nb", retry_starts=1, eps={"a": 2.0, "c": 1.0})
    assert front_task(task, {"nb": nb})["retried"] == ""


@pytest.mark.parametrize(
    "x, jump, retried",
    [
        ((5.0, 2.0), None, False),  # (5 - 3) / 10 = 0.2: not more than the default 0.2
        ((3.0, 2.5), None, True),  # (2.5 - 2) / 2 = 0.25 on the second variable
        ((3.0, 1.5), None, True),  # -0.25: the distance is the absolute change
        ((3.0, 2.5), 0.25, False),
        ((3.0, 2.5), 0.24, True),
        ((11.0, 1.0), "off", False),  # jump None: the check is off
    ],
)
def test_a_point_far_in_design_space_from_its_neighbour_is_retried(fake, x, jump, retried):
    """The distance is the largest change of a variable relative to its span."""
    fake([_res(a=2.0, b=4.0, x=x)] + [_res(a=2.0, b=4.0, x=(3.0, 2.0))] * 2)
    nb = _stored("nb", a=1.5, b=4.5, eps={"a": 1.5}, x=(3.0, 2.0))
    task = _eps_task(warm="nb", retry_starts=1)
    if jump is not None:
        task["jump"] = None if jump == "off" else jump
    record = front_task(task, {"nb": nb})
    assert record["retried"] == ("jump in design space" if retried else "")
    assert record["n_solves"] == (3 if retried else 1)  # the neighbour's design, one Sobol


def test_cold_starts_keep_the_first_of_equal_points_and_take_a_better_one(fake):
    """Cold starts replace the point only by a better one (beyond the tie tolerance); a
    failed warm solve is replaced by the first successful start."""
    tie = 3.0 * (1 - 0.5 * OBJECTIVE_TIE_TOL)
    answers = [_failed(), _failed(x=(9, 0)), _res(a=2.0, b=3.0, x=(2, 0))]
    answers += [_res(a=2.0, b=tie, x=(3, 0)), _res(a=2.0, b=2.5, x=(4, 0))]
    answers += [_res(a=2.0, b=2.5 * (1 - 2e-6), x=(5, 0))]
    solver = fake(answers)
    record = front_task(_eps_task(retry_starts=5, seed=1), {})
    assert record["retried"] == "failed" and record["n_solves"] == 6
    assert record["x"] == [5.0, 0.0]
    assert record["kind"] == "eps" and record["target"] == "b" and record["eps"] == {"a": 2.0}
    every = (PROBLEM, "eps", "b", {"a": 2.0}, "epsilon-0003", "nlp-fp")
    assert solver.records == [every] * 6
    sobol = sobol_starts(PROBLEM.lower(), PROBLEM.upper(), 5, 1 + 7919 * 3)
    assert [s[2] for s in solver.solves[1:]] == [("x0", tuple(p)) for p in sobol]
    # the slope is asked for the point kept
    assert solver.slopes == [("b", "a", 2.5 * (1 - 2e-6))]


def test_cold_starts_keep_the_warm_point_on_a_tie(fake):
    fake([_res(a=2.0, b=3.0, x=(1, 0)), _res(a=2.0, b=3.0, x=(2, 0))])
    record = front_task(_eps_task(extra_starts=1), {})
    assert record["x"] == [1.0, 0.0] and record["n_solves"] == 2


def test_extra_starts_run_whether_or_not_the_point_is_retried(fake):
    """``extra_starts`` cold starts always run (seed 0 when the task gives none);
    ``retry_starts`` only for a retried point; a retried point runs the larger number."""
    solver = fake([_res(a=2.0, b=3.0)] + [_res(a=2.0, b=3.0)] * 2)
    record = front_task(_eps_task(extra_starts=2, retry_starts=7), {})
    sobol = sobol_starts(PROBLEM.lower(), PROBLEM.upper(), 2, 7919 * 3)
    assert [s[2] for s in solver.solves[1:]] == [("x0", tuple(p)) for p in sobol]
    assert record["retried"] == "" and record["n_solves"] == 3
    solver = fake([_failed()] + [_failed()] * 3)
    record = front_task(_eps_task(extra_starts=3, retry_starts=2), {})
    assert record["n_solves"] == 4 and record["retried"] == "failed"
    solver = fake([_failed()] + [_failed()] * 2)
    record = front_task(_eps_task(extra_starts=1, retry_starts=2), {})
    assert record["n_solves"] == 3
    assert [s[0] for s in solver.solves] == ["b"] * 3


def test_a_retried_point_without_retry_starts_is_solved_once(fake):
    solver = fake([_failed()])
    record = front_task(_eps_task(), {})
    assert len(solver.solves) == 1 and record["retried"] == "failed"


def test_cold_starts_begin_at_the_neighbours_design_even_when_it_failed(fake):
    """A neighbour that failed but has a design: its design is still the first cold start
    (the warm start was the problem's start)."""
    solver = fake([_failed(), _failed(), _res(a=2.0, b=3.0, x=(2, 0))])
    nb = _stored("nb", status="failed", a=1.5, b=4.5, x=(7.0, 0.25))
    record = front_task(_eps_task(warm="nb", retry_starts=1), {"nb": nb})
    assert solver.solves[1][2] == ("x0", (7.0, 0.25))
    assert record["x"] == [2.0, 0.0]
    # a neighbour without a design: the Sobol starts only
    solver = fake([_failed(), _res(a=2.0, b=3.0)])
    nb = _stored("nb", status="failed", x=None)
    record = front_task(_eps_task(warm="nb", retry_starts=1), {"nb": nb})
    sobol = sobol_starts(PROBLEM.lower(), PROBLEM.upper(), 1, 7919 * 3)
    assert solver.solves[1][2] == ("x0", tuple(sobol[0])) and record["n_solves"] == 2


# --- the limit of an arc-length point -------------------------------------------------------
FRAME = {"a0": 1.0, "b0": 10.0, "ra": 4.0, "rb": 8.0, "a_lo": 1.5, "a_hi": 4.5}


def _arc(arc, **nb):
    task = {"frame": FRAME, "eps_name": "a", "target": "b", "arc": arc, "fallback_eps": 3}
    fields = {"objectives": {"a": 2.0, "b": 7.0}, "eps": {"a": 2.5}, "slope": -3.0}
    fields.update(nb)
    status = fields.pop("status", "optimal")
    record = PointRecord(id="nb", kind="eps", target="b", status=status, verified=True, **fields)
    return arc_eps(task, record)


def test_an_arc_step_is_a_newton_step_along_the_normalised_front():
    """The neighbour at (a, b) = (2, 7) sits at arc (2 - 1)/4 + (10 - 7)/8 = 0.625; with
    slope |dB/dA| = 3 the arc grows by 1/4 + 3/8 = 0.625 per unit of A: to reach 1.0 the
    limit moves 0.6 past the larger of the neighbour's value and its limit (2.5)."""
    assert _arc(1.0) == {"a": pytest.approx(3.1, rel=1e-14)}
    assert _arc(1.0, slope=3.0) == {"a": pytest.approx(3.1, rel=1e-14)}  # |slope|
    assert _arc(1.0, eps={}) == {"a": pytest.approx(2.6, rel=1e-14)}  # from its value
    assert _arc(1.0, eps={"a": 1.8}) == {"a": pytest.approx(2.6, rel=1e-14)}
    # without a usable slope, the frame's: rb / ra = 2, so 1/4 + 2/8 = 0.5 per unit
    assert _arc(1.0, slope=None) == {"a": pytest.approx(3.25, rel=1e-14)}
    assert _arc(1.0, slope=math.nan) == {"a": pytest.approx(3.25, rel=1e-14)}
    assert _arc(1.0, slope=math.inf) == {"a": pytest.approx(3.25, rel=1e-14)}


def test_an_arc_step_back_starts_from_the_lower_of_value_and_limit():
    assert _arc(0.5) == {"a": pytest.approx(1.8, rel=1e-14)}  # 2 - 0.125 / 0.625
    assert _arc(0.5, eps={"a": 1.9}) == {"a": pytest.approx(1.7, rel=1e-14)}
    assert _arc(0.5, eps={}) == {"a": pytest.approx(1.8, rel=1e-14)}  # from its value
    # no step: the lower of the two, not the larger
    assert _arc(0.625) == {"a": 2.0}


def test_an_arc_step_is_clipped_to_the_frame():
    assert _arc(3.0) == {"a": 4.5}
    assert _arc(0.0) == {"a": 1.5}


def test_an_arc_point_whose_neighbour_failed_takes_its_fallback_limit():
    result = _arc(1.0, status="failed")
    assert result == {"a": 3.0} and type(result["a"]) is float


# --- the limit of a three-objective grid point ------------------------------------------------
def _row(head, frac=0.25):
    task = {"b_name": "b", "b_hi": 6.0, "frac": frac, "eps_row": {"a": 1.5}}
    return row_eps(task, head)


def test_a_grid_point_lies_at_its_fraction_between_the_row_heads_b_and_b_max():
    head = PointRecord(id="h", kind="eps", target="c", status="optimal", objectives={"b": 2.0})
    lo = 2.0 * (1 + 1e-7) + 1e-12
    assert _row(head) == {"a": 1.5, "b": pytest.approx(lo + 0.25 * (6.0 - lo), rel=1e-15)}
    assert _row(head, frac=0.0) == {"a": 1.5, "b": pytest.approx(lo, rel=1e-15)}
    assert _row(head, frac=1.0) == {"a": 1.5, "b": pytest.approx(6.0, rel=1e-15)}


def test_a_grid_point_without_a_solved_row_head_is_at_b_max():
    failed = PointRecord(id="h", kind="eps", target="c", status="failed", objectives={"b": 2.0})
    assert _row(None) == {"a": 1.5, "b": 6.0}
    assert _row(failed) == {"a": 1.5, "b": 6.0}
    # a row head past B_max: the limit is B_max
    above = PointRecord(id="h", kind="eps", target="c", status="optimal", objectives={"b": 7.0})
    assert _row(above, frac=0.5) == {"a": 1.5, "b": 6.0}


# --- a weighted-sum point ----------------------------------------------------------------------
def _ws_task(**kw):
    task = {"id": "ws-0001", "kind": "weighted_sum", "problem": PROBLEM}
    task.update(objectives=["a", "b"], weights={"b": 0.75, "a": 0.25}, x0=[6, 0.5])
    task.update(normalise={"a": [1.0, 5.0], "b": [2.0, 2.0]})
    task.update(kw)
    return task


def test_a_weighted_sum_point_minimises_the_normalised_sum_with_the_fallback(fake):
    """Each weight is divided by its objective's range (nadir - ideal); a range of 0
    counts as 1e-300, not a division by zero."""
    solver = fake([_res(a=2.0, b=3.0, x=(2, 1))])
    record = front_task(_ws_task(), {})
    assert solver.starts_from == [(None, (6.0, 0.5))]
    ((use, start, target, bounds),) = solver.backends
    assert use == "fallback" and start == ("from", (None, (6.0, 0.5)))
    assert target == ("target", {"b": 0.75 / 1e-300, "a": 0.0625})
    assert bounds == "the bounds" and solver.solves == []
    assert solver.records == [(PROBLEM, "weighted_sum", "b", {}, "ws-0001", "nlp-fp")]
    assert record["kind"] == "weighted_sum" and record["target"] == "b"
    assert record["weights"] == {"b": 0.75, "a": 0.25} and record["eps"] == {}
    assert record["x"] == [2.0, 1.0] and 0.0 <= record["wall_time_s"] < 60.0


def test_a_weighted_sum_point_starts_from_its_solved_neighbour(fake):
    solver = fake([_res(a=2.0, b=3.0)])
    nb = _stored("ws-0000", a=1.0, b=4.0)
    front_task(_ws_task(warm="ws-0000"), {"ws-0000": nb})
    assert solver.starts_from == [("ws-0000", (6.0, 0.5))]
    solver = fake([_res(a=2.0, b=3.0)])
    failed = _stored("ws-0000", status="failed", a=1.0, b=4.0)
    front_task(_ws_task(warm="ws-0000"), {"ws-0000": failed})
    assert solver.starts_from == [(None, (6.0, 0.5))]


# --- a point's polish -------------------------------------------------------------------------
def _polish_task(sources):
    task = {"id": "eps-0002-polish1", "kind": "polish", "problem": PROBLEM, "index": 2}
    task.update(objectives=["a", "b"], point="p2", sources=list(sources))
    return task


def _point(**kw):
    d = _stored("p2", eps={"a": 3.0}, x=(3.0, 1.0), a=3.0, b=6.0, **kw)
    d["n_solves"] = 2
    return d


def test_a_polish_keeps_the_best_of_its_starts_and_says_where_it_came_from(fake):
    solver = fake([_res(x=(4, 1), a=2.9, b=6.5), _res(x=(5, 1), a=3.0, b=4.0)])
    deps = {"p2": _point(), "p1": _stored("p1", a=2.0, b=7.0), "p3": _stored("p3", a=4.0, b=4.0)}
    record = front_task(_polish_task(["p1", "p3"]), deps)
    # each start from its source's record, the point's own target and bound
    assert solver.starts_from == [("p1", None), ("p3", None)]
    assert [s[:2] for s in solver.solves] == [("b", {"a": 3.0}), ("b", {"a": 3.0})]
    assert record["id"] == "eps-0002-polish1" and record["kind"] == "eps"
    assert record["objectives"] == {"a": 3.0, "b": 4.0} and record["x"] == [5.0, 1.0]
    assert record["warm"] == "p3" and record["retried"] == "polished from p3"
    assert record["n_solves"] == 2 + 2 and record["slope"] == -2.5


def test_a_polish_that_finds_nothing_better_keeps_the_point(fake):
    near = 6.0 * (1 - 0.5 * OBJECTIVE_TIE_TOL)  # a tie is no improvement
    fake([_res(x=(4, 1), a=3.0, b=near)])
    record = front_task(_polish_task(["p1"]), {"p2": _point(), "p1": _stored("p1", a=2, b=7)})
    assert record["objectives"] == {"a": 3.0, "b": 6.0} and record["x"] == [3.0, 1.0]
    assert record["id"] == "eps-0002-polish1" and record["retried"] == ""
    assert record["n_solves"] == 3 and record["slope"] is None


def test_a_polish_whose_solve_fails_from_a_better_design_takes_that_design(fake):
    fake([_failed()])
    better = _stored("seen", x=(7.0, 2.0), a=2.5, b=5.0)
    record = front_task(_polish_task(["seen"]), {"p2": _point(), "seen": better})
    assert record["x"] == [7.0, 2.0] and record["objectives"] == {"a": 2.5, "b": 5.0}
    assert record["eps"] == {"a": 3.0} and record["retried"] == "polished from seen"
    assert record["fallback"].startswith("kept seen's design: the solve from it failed")


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
def _stored_records(out: Path, name: str) -> dict[str, dict]:
    lines = (out / f"{name}.jsonl").read_text().splitlines()[1:]
    return {r["id"]: r for r in map(json.loads, lines)}


def test_an_anchors_tie_break_minimises_its_second_objective_within_its_first(weighted_run):
    """The anchor of backlash holds backlash at its optimum (plus the anchors' slack) and
    then minimises size: no design the front found within that backlash is smaller."""
    _, out, _ = weighted_run
    records = _stored_records(out, "weighted_sum")
    anchor, first = records["anchor-backlash"], records["anchor-backlash-ms"]
    assert anchor["order"] == ["backlash", "size"]
    # the bound, to the solver's feasibility tolerance
    bound = (first["objectives"]["backlash"] * (1 + ANCHOR_SLACK) + 1e-12) * (1 + 1e-6)
    assert anchor["objectives"]["backlash"] <= bound
    within = [r for r in records.values() if r["objectives"]["backlash"] <= bound]
    assert len(within) >= 3  # the first stage and a weighted point too
    assert all(anchor["objectives"]["size"] <= r["objectives"]["size"] for r in within)


def test_a_three_objective_grid_point_lies_at_its_fraction_between_the_row_head_and_b_max():
    head = PointRecord(
        id="row-head",
        kind="eps",
        status="optimal",
        verified=True,
        target="size",
        objectives={"backlash": 1.0, "size": 2.0, "ripple": 0.1},
    )
    task = {"b_name": "size", "b_hi": 10.0, "frac": 0.25, "eps_row": {"backlash": 1.5}}
    lo = 2.0 * (1 + ANCHOR_SLACK) + 1e-12
    assert row_eps(task, head) == {"backlash": 1.5, "size": pytest.approx(lo + 0.25 * (10 - lo))}
    # a failed head gives no lower end: the point sits at B_max
    failed = replace(head, status="failed", verified=None)
    assert row_eps(task, failed) == {"backlash": 1.5, "size": 10.0}


def test_an_arc_step_from_a_neighbour_without_a_slope_takes_the_frames_slope():
    """The next limit of an arc-spaced sweep is a Newton step along the front's arc; a
    neighbour whose multiplier gave no slope steps with the frame's mean slope rb / ra."""
    frame = {"a0": 0.0, "b0": 1.0, "ra": 1.0, "rb": 2.0, "a_lo": 0.0, "a_hi": 1.0}
    task = {"frame": frame, "eps_name": "a", "target": "b", "arc": 1.0, "fallback_eps": 0.9}
    nb = PointRecord(
        id="p",
        kind="eps",
        status="optimal",
        verified=True,
        target="b",
        objectives={"a": 0.2, "b": 1.6},
        eps={"a": 0.2},
    )
    # s1 = 0.2 / 1 + (1 - 1.6) / 2 = -0.1; slope 2 / 1 = 2; ds/da = 1 + 2 / 2 = 2
    assert arc_eps(task, nb) == {"a": pytest.approx(0.2 + 1.1 / 2)}
    # the neighbour's own slope -6: ds/da = 1 + 6 / 2 = 4
    assert arc_eps(task, replace(nb, slope=-6.0)) == {"a": pytest.approx(0.2 + 1.1 / 4)}
    # no neighbour's design: the task's fallback limit
    assert arc_eps(task, None) == {"a": 0.9}


def test_a_point_far_from_its_neighbours_design_is_retried_saying_so():
    """An epsilon point whose design lies more than a fifth of the box from its warm
    neighbour's is re-solved from cold starts, and its record says why."""
    from optdesign.studies.pareto.tasks import front_task

    problem = od.load(ROOT / "problems" / "fork_min_backlash.toml")
    common = {"problem": problem, "objectives": ["backlash", "size"], "solver": "ipopt"}
    first = {**common, "id": "p-0", "kind": "eps", "target": "backlash", "index": 0}
    solo = front_task({**first, "eps": {"size": 1e9}}, {})
    assert solo["retried"] == ""
    # a neighbour no better (so not the "worse" retry) at the far corner of the box
    neighbour = {**solo, "id": "p-1", "objectives": {**solo["objectives"]}}
    neighbour["objectives"]["backlash"] *= 1.1
    neighbour["eps"], neighbour["x"] = {"size": 5e8}, [float(v) for v in problem.lower()]
    task = {**first, "eps": {"size": 1e9}, "warm": "p-1", "retry_starts": 1, "seed": 3}
    rec = front_task(task, {"p-1": neighbour})
    assert rec["retried"] == "jump in design space"


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


# --- the chains of an epsilon front -------------------------------------------------------
def _record(id_, kind, objectives):
    return PointRecord(
        id=id_,
        kind=kind,
        target="size",
        status="optimal",
        verified=True,
        objectives=objectives,
    ).to_dict()


def _arc_chain():
    """The first two tasks of a 5-point arc sweep between anchor A (backlash 1, size 10)
    and B's multistart optimum (backlash 5, size 2)."""
    from optdesign.studies.pareto.chains import TwoChains

    chains = TwoChains(["backlash", "size"], 5, "epsilon", {}, "arc", None)
    done = {
        "anchor-backlash": _record("anchor-backlash", "anchor", {"backlash": 1.0, "size": 10.0}),
        "anchor-size-ms": _record(
            "anchor-size-ms", "anchor-multistart", {"backlash": 5.0, "size": 2.0}
        ),
    }
    (first,) = chains({"id": "anchor-size-ms"}, done["anchor-size-ms"], done)
    (second,) = chains(first, {}, done)
    return first, second


# --- the sweep's solves -------------------------------------------------------------------
def test_an_epsilon_point_that_needs_no_retry_is_solved_once(cs_min_backlash, tmp_path):
    """Without extra starts, a point whose warm start succeeds (not worse than its
    neighbour, no jump) costs one solve, and its record says so."""
    od.pareto(cs_min_backlash, ["backlash", "size"], 5, out=tmp_path, starts=1)
    lines = (tmp_path / "epsilon.jsonl").read_text().splitlines()[1:]
    eps = [r for r in map(json.loads, lines) if r["kind"] == "eps" and "polish" not in r["id"]]
    plain = [r for r in eps if not r["retried"]]
    assert len(eps) == 5 and len(plain) >= 3
    assert [r["n_solves"] for r in plain] == [1] * len(plain)


def test_a_weighted_sum_point_whose_neighbour_failed_restarts_from_its_chains_anchor(
    cs_min_backlash, tmp_path, monkeypatch
):
    """The weighted-sum chain starts at the last objective's anchor (weight 0 on the
    first); a point whose neighbour failed starts again from that anchor's design."""
    from optdesign.studies.pareto import tasks

    real = tasks.TASK_KINDS["weighted_sum"]
    given = {}

    def weighted(task, deps):
        given[task["id"]] = task["x0"]
        if task["id"] == "ws-0001":  # a failed point: the next one starts without it
            return PointRecord(
                id=task["id"], kind="weighted_sum", target="backlash", status="failed"
            ).to_dict()
        return real(task, deps)

    monkeypatch.setitem(tasks.TASK_KINDS, "weighted_sum", weighted)
    front = od.pareto(
        cs_min_backlash, ["backlash", "size"], 3, method="weighted_sum", out=tmp_path, starts=1
    )
    lines = (tmp_path / "weighted_sum.jsonl").read_text().splitlines()[1:]
    anchors = {r["id"]: r["x"] for r in map(json.loads, lines) if r["kind"] == "anchor"}
    assert anchors["anchor-size"] != anchors["anchor-backlash"]
    assert given == {f"ws-000{i}": anchors["anchor-size"] for i in range(3)}
    assert "ws-0002" in {p.id for p in front.points}


def test_an_arc_point_whose_neighbour_failed_takes_the_evenly_spaced_limit():
    """An arc-spaced point whose neighbour has no design cannot predict its limit from
    the neighbour: it takes its place on an even spacing between the frame's ends."""
    from optdesign.studies.pareto.tasks import ANCHOR_SLACK, arc_eps

    first, second = _arc_chain()
    assert second["index"] == 1 and second["eps_name"] == "backlash"
    lo = 1.0 * (1 + ANCHOR_SLACK) + 1e-12
    assert first["eps"] == {"backlash": lo}
    failed = PointRecord(id=first["id"], kind="eps", target="size", status="failed")
    assert arc_eps(second, failed) == {"backlash": pytest.approx(lo + (5.0 - lo) / 4, rel=1e-12)}
    assert arc_eps(second, None) == arc_eps(second, failed)


def test_an_arc_step_never_asks_below_the_first_anchors_limit():
    """A neighbour already past the point's arc position steps back, but never below
    the frame's lower end (anchor A's optimum plus the anchors' slack): no limit
    tighter than the best A can reach."""
    from optdesign.studies.pareto.tasks import ANCHOR_SLACK, arc_eps

    _, second = _arc_chain()
    lo = 1.0 * (1 + ANCHOR_SLACK) + 1e-12
    past = PointRecord(
        id="epsilon-0000",
        kind="eps",
        target="size",
        status="optimal",
        verified=True,
        objectives={"backlash": 1.0, "size": 2.0},
    )
    assert arc_eps(second, past) == {"backlash": lo}


# --- anchors ------------------------------------------------------------------------------
def test_an_anchor_whose_starts_succeed_solves_each_start_once(cs_min_backlash, tmp_path):
    """An anchor's multistart re-runs its starts with the fallback back-end only when no
    start reached a solution: starts that succeed cost one solve each (two starts: too
    few to search a thinned grid, so no polish either)."""
    od.pareto(cs_min_backlash, ["backlash", "size"], 3, out=tmp_path, starts=2)
    lines = (tmp_path / "epsilon.jsonl").read_text().splitlines()[1:]
    ms = [r for r in map(json.loads, lines) if r["kind"] == "anchor-multistart"]
    assert len(ms) == 2
    for r in ms:
        assert r["status"] == "optimal" and r["multistart"]["n_at_best"] >= 1
        assert r["n_solves"] == r["multistart"]["n_starts"] == 2


def test_an_anchor_multistart_whose_starts_succeed_is_not_solved_again_with_the_fallback():
    """The fallback re-run is for a search none of whose starts succeeded: one start
    that reaches the optimum is one solve, and the search stops on its odds (8 starts at
    one optimum leave fewer than half an optimum expected unseen; six free variables ask
    for 12 counted starts)."""
    from optdesign.studies.pareto.tasks import multistart_task

    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    order = ["backlash", "size"]
    # one start solves the problem itself; a search its thinned grid, then polishes
    for starts, agree, n_starts, solves in [(1, None, 1, 1), (20, 3, 12, 13)]:
        task = {"problem": problem, "order": order, "objectives": order, "starts": starts,
                "seed": 0, "agree": agree, "id": "anchor-backlash-ms"}  # fmt: skip
        record = multistart_task(task, {})
        assert record["status"] == "optimal" and record["n_solves"] == solves
        assert record["multistart"]["n_starts"] == n_starts
        assert record["objectives"]["backlash"] == pytest.approx(0.0362197, rel=1e-5)


def test_an_anchor_whose_best_start_fails_its_polish_is_searched_again_with_the_fallback(
    monkeypatch,
):
    """A search whose starts agree on the thinned grid but whose polish on the whole grid
    fails has no optimum: it runs again with the fallback back-end, as one with no
    successful start does (CasADi's sqpmethod as a front's primary left the pivoting
    screw's ripple anchor at such a point: "no feasible design found")."""
    import dataclasses

    from optdesign.studies.pareto import tasks

    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    searched = tasks.global_search
    calls: list[bool] = []

    def search(solve, *args, **kw):
        best = searched(solve, *args, **kw)
        calls.append(best.success)
        if len(calls) == 1:  # the first search's optimum, as if its polish had failed
            return dataclasses.replace(best, status="failed", message="polish stopped")
        return best

    monkeypatch.setattr(tasks, "global_search", search)
    order = ["backlash", "size"]
    task = {"problem": problem, "order": order, "objectives": order, "starts": 1,
            "seed": 0, "agree": None, "id": "anchor-backlash-ms"}  # fmt: skip
    record = tasks.multistart_task(task, {})
    assert len(calls) == 2  # searched again, with the fallback behind the primary
    assert record["status"] == "optimal"
    assert record["objectives"]["backlash"] == pytest.approx(0.0362197, rel=1e-5)


def test_an_arc_step_back_starts_from_the_tighter_of_the_neighbours_value_and_limit():
    """Stepping back along the arc (the target lies before the neighbour), the new limit
    is a step below the lower of the neighbour's value and its own limit."""
    from dataclasses import replace

    from optdesign.studies.pareto.records import PointRecord
    from optdesign.studies.pareto.tasks import arc_eps

    frame = {"a0": 0.0, "b0": 1.0, "ra": 1.0, "rb": 2.0, "a_lo": 0.0, "a_hi": 1.0}
    task = {"frame": frame, "eps_name": "a", "target": "b", "arc": 0.0, "fallback_eps": 0.9}
    nb = PointRecord(id="p", kind="eps", status="optimal", verified=True, target="b",
                     objectives={"a": 0.5, "b": 1.2}, eps={"a": 0.45})  # fmt: skip
    # s1 = 0.5 + (1 - 1.2) / 2 = 0.4; ds/da = 1 + 2 / 2 = 2; step = (0 - 0.4) / 2 = -0.2
    assert arc_eps(task, nb) == {"a": pytest.approx(0.45 - 0.2)}
    assert arc_eps(task, replace(nb, eps={"a": 0.7})) == {"a": pytest.approx(0.5 - 0.2)}


# --- a point worse than its looser neighbour is solved again on its own target
def test_a_point_worse_than_its_looser_neighbour_is_retried_on_its_own_target(monkeypatch):
    """An epsilon point whose warm solve is worse than a neighbour with a tighter bound is
    re-solved from cold starts, every solve on the point's own objective, and the record
    says why."""
    from optdesign.studies.pareto import tasks
    from optdesign.studies.pareto.eps_solver import EpsSolver
    from optdesign.studies.pareto.records import PointRecord

    problem = load(ROOT / "problems" / "fork_min_backlash.toml")
    common = {"problem": problem, "objectives": ["backlash", "size"], "solver": "ipopt"}
    first = {**common, "id": "p-0", "kind": "eps", "target": "backlash", "index": 0}
    solo = tasks.front_task({**first, "eps": {"size": 1e9}}, {})
    assert PointRecord.from_dict(solo).success and solo["retried"] == ""
    # a neighbour claiming a better backlash under a tighter size bound: the point, whose
    # bound is looser, cannot be worse, so it doubts its warm solve
    neighbour = {**solo, "id": "p-1", "objectives": {**solo["objectives"]}}
    neighbour["objectives"]["backlash"] *= 0.9
    neighbour["eps"] = {"size": 5e8}
    targets = []
    original = EpsSolver.solve

    def spy(self, target, eps, start):
        targets.append(target)
        return original(self, target, eps, start)

    monkeypatch.setattr(EpsSolver, "solve", spy)
    boxes = []
    sobol = tasks.sobol_starts

    def drawn(lo, hi, n, seed):
        boxes.append((np.array(lo), np.array(hi), n, seed))
        return sobol(lo, hi, n, seed)

    monkeypatch.setattr(tasks, "sobol_starts", drawn)
    task = {**first, "eps": {"size": 1e9}, "warm": "p-1", "retry_starts": 2, "seed": 3}
    rec = tasks.front_task(task, {"p-1": neighbour})
    assert rec["retried"] == "worse than its neighbour with a looser bound"
    assert rec["n_solves"] == 4 and targets == ["backlash"] * 4  # warm, neighbour, 2 Sobol
    # the cold starts are drawn over the whole box, seeded by the point's index
    ((lo, hi, n, seed),) = boxes
    assert np.array_equal(lo, problem.lower()) and np.array_equal(hi, problem.upper())
    assert (n, seed) == (2, 3)
    assert rec["objectives"]["backlash"] == pytest.approx(solo["objectives"]["backlash"], rel=1e-6)
