"""Catalogue variables (issue 4): branch and bound vs enumeration, relaxation bound."""

from __future__ import annotations

import csv
import itertools
import math
import os
import time
import tomllib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import optdesign as od
from formulations.catalogue.test_bnb import _infeasible as _failed
from formulations.catalogue.test_bnb import (  # the stand-in problem of catalogue items
    _Problem,
    _Var,
)
from optdesign.errors import ProblemError
from optdesign.formulations.catalogue import bnb as catalogue_bnb
from optdesign.formulations.catalogue import search as catalogue
from optdesign.formulations.catalogue.bnb import (
    PRUNE_TOL,
    InfeasibleBoxes,
    PseudoCosts,
    _prunes_box,
    _value,
    _x_of_design,
    box_cannot_win,
    box_key,
    branch_and_bound_warm,
    cannot_improve,
    combination_key,
    first_feasible,
    first_incumbent,
    fixed_box,
    item_distances,
    on_items,
    split_at_items,
    trusted,
    trusted_value,
    wins,
)
from optdesign.formulations.catalogue.discrete import discrete_variables
from optdesign.formulations.catalogue.search import (
    NodeSolver,
    _no_item,
    catalogue_applies,
    enumerate_catalogue,
    is_on_catalogue,
    minlp_back_end,
    relaxation_bound,
    solve_catalogue,
)
from optdesign.formulations.verify import verify_design
from optdesign.problem import load_problem, problem_from_dict
from optdesign.problem.load import load
from optdesign.runtime.inherited_map import InheritedWorkers
from optdesign.runtime.processes import forks_workers
from optdesign.solvers.result import MultistartInfo, Result

ROOT = Path(__file__).resolve().parents[3]
CATALOGUE = ROOT / "problems" / "cs_min_backlash_catalogue.toml"
#: Relaxation bound of the catalogue problem with its ISO 286-2 table fits: the continuous
#: problem with the fit's table/formula ratio at its most favourable over the catalogue's
#: pins (the smooth-fit relaxation is cs_min_backlash's optimum, 0.0362197).
RELAXED = 0.0339719


def _small_catalogue(fit_values: str | None = None):
    """The shipped problem with 2 leads x 3 pins around the optimum (6 combinations)."""
    data = tomllib.loads(CATALOGUE.read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "6 mm", "8 mm"]}
    if fit_values is not None:
        data["requirements"]["fit_values"] = fit_values
    return problem_from_dict(data)


def test_loader_reads_the_iso_catalogues():
    problem = load_problem(CATALOGUE)
    assert problem.by_name["p"].values == (2, 2.5, 3, 4, 5, 6, 8, 10)
    assert problem.by_name["d"].values == (4, 5, 6, 8, 10, 12, 16, 20, 25)


def test_values_and_a_catalogue_on_one_variable_are_refused_naming_both(tmp_path):
    """The catalogue was silently dropped for the values before."""
    text = CATALOGUE.read_text().replace(
        'p = { catalogue = "ISO 3408", ',
        'p = { values = ["2 mm", "5 mm"], catalogue = "ISO 3408", ',
    )
    path = tmp_path / "p.toml"
    path.write_text(text)
    with pytest.raises(ProblemError) as err:
        load_problem(path)
    assert str(err.value).startswith(
        f"{path}: variables.p: values and catalogue both given: a variable takes its items "
        "from one (values = [...] lists them; catalogue = NAME takes a named catalogue's)"
    )
    data = tomllib.loads(CATALOGUE.read_text())
    data["variables"]["d"] = {"values": ["5 mm"], "catalogue": "ISO 2338"}
    with pytest.raises(ProblemError, match=r"^variables\.d: values and catalogue both given"):
        problem_from_dict(data)


def test_branch_and_bound_equals_enumeration_small_catalogue():
    problem = _small_catalogue()
    enum = solve_catalogue(problem, method="enumerate", starts=2)
    bnb = solve_catalogue(problem, method="bnb", starts=2)
    assert enum.status == "optimal" and bnb.status == "optimal"
    assert bnb.objective == pytest.approx(enum.objective, rel=1e-6)
    # p = 6, d = 6 is the best pair (p = 5 with d = 6 gives 0.03703 deg)
    assert bnb.details.catalogue.items == {"p": 6, "d": 6}
    # ISO 286-2 table H7/g6 at 6 mm: 12 + 12 = 24 um largest clearance (the issue's 0.034065)
    assert bnb.objective == pytest.approx(0.0340646, rel=1e-5)
    assert is_on_catalogue(problem, bnb.design) and bnb.verified
    # the relaxation (p in [5, 6], d in [5, 8] continuous) bounds the discrete optimum
    assert relaxation_bound(bnb) < bnb.objective
    assert len(enum.details.catalogue.enumerated) == 6
    assert bnb.details.catalogue.nlp_solves < enum.details.catalogue.nlp_solves


def test_smooth_fit_values_give_the_formula_optimum():
    """fit_values = "smooth" reproduces the pre-table optimum (H7/g6 from the IT formulas)."""
    problem = _small_catalogue("smooth")
    bnb = solve_catalogue(problem, method="bnb", starts=2)
    assert bnb.status == "optimal"
    assert bnb.details.catalogue.items == {"p": 6, "d": 6}
    assert bnb.objective == pytest.approx(0.0363462, rel=1e-5)


@pytest.mark.slow
def test_shipped_catalogue_problem_equals_exhaustive_enumeration():
    problem = load_problem(CATALOGUE)
    bnb = solve_catalogue(problem, method="bnb", starts=3)
    enum = solve_catalogue(problem, method="enumerate", starts=2)
    assert bnb.objective == pytest.approx(enum.objective, rel=1e-6)
    # the enumeration's relaxation is on the whole grid; the branch and bound's on every
    # other angle (31 of 61), a relaxation of it: no higher, and still a bound
    assert relaxation_bound(enum) == pytest.approx(RELAXED, rel=1e-5)
    assert enum.details.catalogue.relaxation_angles is None
    assert bnb.details.catalogue.relaxation_angles == 31
    assert relaxation_bound(bnb) == pytest.approx(RELAXED, rel=1e-5)
    assert relaxation_bound(bnb) <= relaxation_bound(enum) * (1 + 1e-9)
    assert relaxation_bound(enum) < bnb.objective
    assert bnb.details.catalogue.items == {"p": 6, "d": 6}


def test_catalogue_problem_is_never_solved_as_continuous():
    import optdesign as od
    from optdesign.formulations.registry import choose_formulation

    problem = load_problem(CATALOGUE)
    assert choose_formulation(problem, "auto") == "catalogue"
    with pytest.raises(ProblemError, match="catalogue values"):
        od.solve(problem, "nlp", starts=1)
    with pytest.raises(ProblemError, match=r"variable p: .*catalogue"):
        od.solve(problem, "gp", starts=1)


def test_node_solver_ipopt_options_file_wins_over_node_defaults():
    # Nodes enter Ipopt's restoration phase early (many boxes are infeasible); a problem
    # file's own [solver] ipopt options still decide, and a caller's override both.
    from optdesign.formulations.catalogue.search import NodeSolver
    from optdesign.solvers.registry import solver_hints

    assert solver_hints("ipopt").node_options["expect_infeasible_problem"] == "yes"
    default = NodeSolver(_small_catalogue())
    assert default.backend.options["ipopt"]["expect_infeasible_problem"] == "yes"
    # a restoration phase that makes no progress ends after 200 iterations, not at 500
    assert default.backend.options["ipopt"]["max_resto_iter"] == 200
    data = tomllib.loads(CATALOGUE.read_text())
    data["solver"] = {"ipopt": {"expect_infeasible_problem": "no", "max_resto_iter": 400}}
    own = NodeSolver(problem_from_dict(data))
    assert own.backend.options["ipopt"]["expect_infeasible_problem"] == "no"
    assert own.backend.options["ipopt"]["max_resto_iter"] == 400
    caller = NodeSolver(problem_from_dict(data), options={"expect_infeasible_problem": "yes"})
    assert caller.backend.options["ipopt"]["expect_infeasible_problem"] == "yes"


def _weak_pins():
    """The shipped problem with 4 and 5 mm pins: too weak for the hinge moment whatever
    the lead, so every node is infeasible."""
    data = tomllib.loads(CATALOGUE.read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["4 mm", "5 mm"]}
    return problem_from_dict(data)


def test_a_node_whose_starts_all_say_locally_infeasible_is_not_retried():
    """A verdict on every start decides the node: 2 starts, no retries (the leaf's first
    start Ipopt's own verdict, its second the least violation that sqpmethod, its first
    solver, certified: two NLP solves); a start stopped by its iteration limit, or a
    single start, still gets the RETRY_STARTS retries."""
    from optdesign.formulations.catalogue.search import RETRY_STARTS, NodeSolver

    box = {"p": (5.0, 5.0), "d": (4.0, 4.0)}
    ns = NodeSolver(_weak_pins(), starts=2)
    r = ns.solve(box)
    assert r.status == "infeasible"
    assert r.multistart.outcomes == ["locally infeasible"] * 2
    assert r.multistart.n_starts == 2 and ns.n_solves == 3 and ns.n_first_certified == 1
    assert ns.verdicts == ("Infeasible_Problem_Detected",)
    # 5 iterations stop every start before a verdict: the retries run
    capped = NodeSolver(_weak_pins(), starts=2, options={"max_iter": 5})
    r = capped.solve(box)
    assert r.status != "optimal"
    assert r.multistart.n_starts == capped.n_solves == 2 + RETRY_STARTS
    assert r.multistart.outcomes[:2] == ["iteration limit"] * 2
    # a single start's verdict is retried (e.g. from a neighbouring optimum): the first
    # retry's verdict decides
    one = NodeSolver(_weak_pins(), starts=1)
    r = one.solve(box)
    assert r.multistart.outcomes == ["locally infeasible"] * 2
    # two verdicts end a larger multistart too: its other starts are not run
    four = NodeSolver(_weak_pins(), starts=4)
    r = four.solve(box)
    assert r.status == "infeasible" and r.multistart.n_starts == 2 and four.n_solves == 3
    assert r.multistart.n_planned == 4


def test_a_start_that_reaches_the_nodes_floor_settles_it():
    """A floor (the parent's trusted value) no start can go below: the start that reaches
    it ends the multistart; one it cannot reach leaves the full multistart."""
    from optdesign.formulations.catalogue.bnb import trusted
    from optdesign.formulations.catalogue.search import NodeSolver

    problem = problem_from_dict(tomllib.loads(CATALOGUE.read_text()))
    box = {"p": (6.0, 6.0), "d": (6.0, 6.0)}
    full = NodeSolver(problem, starts=4)
    ref = full.solve(box)
    assert ref.success and ref.multistart.n_starts == 4 and trusted(ref, 4)
    settled = NodeSolver(problem, starts=4)
    r = settled.solve(box, full.x_of(ref), floor=ref.objective * (1 - 1e-7))
    assert r.objective == pytest.approx(ref.objective, rel=1e-6)
    assert (r.multistart.n_starts, r.multistart.stopped_early) == (1, True)
    assert trusted(r, 4)
    # a floor 1 % below the value: no start reaches it, every start runs
    low = NodeSolver(problem, starts=4)
    r = low.solve(box, full.x_of(ref), floor=ref.objective * 0.99)
    assert (r.multistart.n_starts, r.multistart.stopped_early) == (4, False)
    # a warm start whose value the search would prune is settled by the floor alone
    warm = NodeSolver(problem, starts=4)
    r = warm.solve(box, full.x_of(ref), warm=True, prunes=lambda v: True, floor=ref.objective)
    assert r.multistart.n_starts == 1 and warm.n_cold == 0


def test_a_box_proved_infeasible_under_a_limit_is_implied_only_under_tighter_ones():
    """The memo a front's points share: a box the search proved infeasible under an
    epsilon limit is skipped (no NLP) under that limit or a tighter one, and solved again
    under a looser one, where it is feasible."""
    from optdesign.formulations.catalogue.bnb import InfeasibleBoxes
    from optdesign.formulations.catalogue.search import NodeSolver

    problem = problem_from_dict(tomllib.loads(CATALOGUE.read_text()))
    box = {"p": (6.0, 6.0), "d": (6.0, 6.0)}
    free = NodeSolver(problem, "motor_torque", starts=2).solve(box)
    assert free.success
    memo = InfeasibleBoxes({"p": (2.0, 10.0), "d": (4.0, 16.0)})
    least = NodeSolver(problem, "backlash", starts=2).solve(box).objective
    limit = least * 0.9  # below the least backlash of the box: infeasible

    def node(eps):
        ns = NodeSolver(problem, "motor_torque", starts=2, eps=eps)
        ns.memo = memo
        return ns, ns.solve(box)

    tight, r = node({"backlash": limit})
    assert not r.success and tight.n_solves > 0 and tight.n_implied == 0
    tighter, r = node({"backlash": limit * 0.9})
    assert not r.success and tighter.n_solves == 0 and tighter.n_implied == 1
    looser, r = node({"backlash": free.objectives["backlash"] * 2})
    assert r.success and looser.n_implied == 0
    unlimited, r = node({})
    assert r.success and unlimited.n_implied == 0


def test_the_memo_proves_a_box_whose_item_combinations_other_proofs_cover():
    """With the items known, a box is infeasible when each of its item combinations lies
    in some proved box whose limits the query holds at least as tight; one combination
    left uncovered, or a proof at looser limits only, and it is not."""
    from optdesign.formulations.catalogue.bnb import InfeasibleBoxes

    full = {"a": (1.0, 3.0), "b": (1.0, 2.0)}
    memo = InfeasibleBoxes(full, {"a": (1.0, 2.0, 3.0), "b": (1.0, 2.0)})
    memo.add_infeasible({"a": (1.0, 1.0)}, {})  # a = 1, any b
    memo.add_infeasible({"a": (2.0, 3.0), "b": (1.0, 1.0)}, {})
    memo.add_infeasible({"a": (2.0, 3.0), "b": (2.0, 2.0)}, {"f": 5.0})  # only if f <= 5
    assert not memo.known_infeasible({}, {})
    assert memo.known_infeasible({}, {"f": 4.0}) and memo.known_infeasible({}, {"f": 5.0})
    assert not memo.known_infeasible({}, {"f": 6.0})
    assert memo.known_infeasible({"b": (1.0, 1.0)}, {})  # a = 1 and the second proof
    # without the items only a single proof's box counts
    bare = InfeasibleBoxes(full)
    for box, eps in memo.proofs:
        bare.add_infeasible(box, eps)
    assert not bare.known_infeasible({}, {"f": 4.0})
    assert bare.known_infeasible({"a": (1.0, 1.0), "b": (2.0, 2.0)}, {})


def test_a_pruned_box_with_a_trusted_value_is_a_proof_under_a_lower_limit():
    """A box pruned on a value the search trusts (a full multistart) is infeasible under
    any limit on the objective below that value: recorded in a front's memo with the
    search's own limits; a one-start value or a search with no memo records nothing."""
    from types import SimpleNamespace

    from optdesign.formulations.catalogue.bnb import PRUNE_TOL, InfeasibleBoxes, _bound_proof
    from optdesign.solvers.result import MultistartInfo, Result

    def result(n_starts):
        r = Result(
            status="optimal",
            objective=2.0,
            design={"a": 1.0},
            solver="fake",
            formulation="nlp",
            wall_time_s=0.0,
        )
        r.multistart = MultistartInfo(n_starts, n_starts, 1, 1e-6)
        return r

    memo = InfeasibleBoxes({"a": (1.0, 3.0)})
    ns = SimpleNamespace(memo=memo, starts=4, eps={"g": 7.0}, objective="f")
    _bound_proof(ns, {"a": (2.0, 3.0)}, result(4))
    ((box, eps),) = memo.proofs
    assert box == {"a": (2.0, 3.0)}
    assert eps == {"g": 7.0, "f": pytest.approx(2.0 * (1 - PRUNE_TOL), rel=1e-15)}
    assert memo.known_infeasible({"a": (3.0, 3.0)}, {"g": 7.0, "f": 1.9})
    assert not memo.known_infeasible({"a": (3.0, 3.0)}, {"g": 7.0, "f": 2.0})
    assert not memo.known_infeasible({"a": (3.0, 3.0)}, {"f": 1.9})  # g not held
    _bound_proof(ns, {"a": (1.0, 1.0)}, result(1))  # a warm start's value alone
    _bound_proof(SimpleNamespace(memo=None, starts=4, eps={}, objective="f"), {}, result(4))
    assert len(memo.proofs) == 1


def test_the_shared_memos_keep_the_newest_searches_and_evict_the_oldest(monkeypatch):
    """A process keeps the infeasible-box memos of its last eight catalogue searches: a
    ninth search evicts the oldest one (never fails), a known search gets its own back."""
    from optdesign.formulations.catalogue import bnb as catalogue_bnb

    monkeypatch.setattr(catalogue_bnb, "_MEMOS", {})
    full = {"p": (5.0, 8.0)}
    memos = [catalogue_bnb.shared_memo(("search", k), full) for k in range(10)]
    assert list(catalogue_bnb._MEMOS) == [("search", k) for k in range(2, 10)]
    assert catalogue_bnb.shared_memo(("search", 9), full) is memos[9]
    assert catalogue_bnb.shared_memo(("search", 0), full) is not memos[0]  # evicted: a new one
    assert ("search", 2) not in catalogue_bnb._MEMOS


def test_the_catalogue_search_refuses_a_problem_without_catalogue_variables():
    """Through the API and called directly: one message, naming the formulation."""
    import optdesign as od
    from optdesign.formulations.catalogue.search import solve_catalogue

    problem = od.load(Path(__file__).resolve().parents[3] / "problems" / "cs_min_backlash.toml")
    message = "formulation='catalogue': no variable takes catalogue values"
    for call in (lambda: od.solve(problem, "catalogue"), lambda: solve_catalogue(problem)):
        with pytest.raises(ProblemError) as refused:
            call()
        assert str(refused.value) == message


# The catalogue search's observable behaviour, pinned function by function.
#
# Branch and bound, enumeration, first incumbents, the diagnosis's depth-first search and
# the pseudo-costs run here on a fake node solver whose relaxation is known in closed form
# (a separable quadratic over a box, with one linear limit), so every count, value and item
# is checked against a hand trace or a brute-force enumeration; the pure helpers (pruning,
# tie rules, item distances, the infeasible-box memo) against values worked out by hand.


def _result(value: float, design: dict, n_starts: int = 1, early: bool = False) -> Result:
    r = Result(
        status="optimal",
        objective=value,
        design=dict(design),
        solver="fake",
        formulation="nlp",
        wall_time_s=0.0,
    )
    r.multistart = MultistartInfo(
        n_starts=n_starts, n_converged=n_starts, n_at_best=1, tolerance=1e-6, stopped_early=early
    )
    return r


class QuadNodes:
    """A node solver of sum (x - centre)^2 over the box, with x[cap_name] <= cap: the
    relaxation's optimum is the centre clipped into the box (and under the cap), a box
    whose cap variable starts above the cap is infeasible, and so is a combination of
    ``bad`` solved alone (item data worse than the relaxation's: the relaxation of a box
    holding it stays a lower bound). A warm solve (or ``fallback=False``) is one start;
    otherwise the full multistart of ``starts``."""

    def __init__(
        self,
        items: dict,
        centre: dict,
        cap: float = math.inf,
        starts: int = 2,
        bad=(),
        worse_once: float = 0.0,
        warm_worse: float = 0.0,
    ):
        self.problem = _Problem([_Var(k, v) for k, v in items.items()])
        self.names = list(items)
        self.centre = centre
        self.cap_name = self.names[0]
        self.cap = cap
        self.starts = starts
        self.memo = None
        self.eps: dict = {}
        self.objective = "f"
        self.bad = {tuple(float(c) for c in b) for b in bad}
        self.calls: list[tuple[dict, bool, float | None]] = []
        self.hints: list = []
        #: added to a combination's value at its first full multistart (a local optimum
        #: its starts stopped at, which a later start beats)
        self.worse_once = worse_once
        self.worse_seen: set = set()
        #: added to a one-start value of a box of several combinations (a warm start
        #: stopped above the box's optimum, which the full multistart finds)
        self.warm_worse = warm_worse

    def value(self, point: dict) -> float:
        return sum((point[n] - self.centre[n]) ** 2 for n in self.names)

    def solve(
        self, bounds, x_hint=None, warm=False, prunes=None, fallback=True, floor=None, relaxed=False
    ):
        self.calls.append((dict(bounds), warm, floor))
        self.hints.append(None if x_hint is None else np.asarray(x_hint).tolist())
        box = {v.name: bounds.get(v.name, (v.lower, v.upper)) for v in self.problem.free}
        lo, hi = box[self.cap_name]
        if lo > self.cap:
            return _failed()
        if all(a == b for a, b in box.values()) and tuple(a for a, _ in box.values()) in self.bad:
            return _failed()
        box[self.cap_name] = (lo, min(hi, self.cap))
        point = {n: min(max(self.centre[n], box[n][0]), box[n][1]) for n in self.names}
        value = self.value(point)
        fixed = all(a == b for a, b in box.values()) and len(bounds) == len(self.names)
        key = tuple(sorted(bounds.items()))
        if fixed and not warm and self.worse_once and key not in self.worse_seen:
            self.worse_seen.add(key)
            value += self.worse_once
        if warm and x_hint is not None and not fixed:
            value += self.warm_worse
        one = warm and x_hint is not None and (not fallback or prunes is None or not prunes(value))
        if not one and warm and not fixed:
            value -= self.warm_worse  # the full multistart finds the box's optimum
        return _result(value, point, 1 if one else self.starts)

    def x_of(self, result):
        if not result.design:
            return None
        return np.array([result.design[n] for n in self.names])


def _brute(ns: QuadNodes) -> tuple[float, tuple[float, ...]]:
    """The best feasible item combination by enumeration (smallest items on a tie)."""
    best = None
    for combo in itertools.product(*(v.values for v in ns.problem.free)):
        if combo[0] > ns.cap or tuple(float(c) for c in combo) in ns.bad:
            continue
        f = ns.value(dict(zip(ns.names, combo, strict=True)))
        if best is None or f < best[0] - PRUNE_TOL * abs(best[0]):
            best = (f, combo)
    return best


def _root(ns: QuadNodes) -> Result:
    return ns.solve({})


def _cold_leaf_solves(ns: QuadNodes) -> dict:
    """How many full multistarts each combination (a box of one item per variable) got."""
    out: dict = {}
    for box, warm, _ in ns.calls:
        if len(box) == len(ns.names) and all(a == b for a, b in box.values()) and not warm:
            key = tuple(box[n][0] for n in ns.names)
            out[key] = out.get(key, 0) + 1
    return out


def _small(pins=("5 mm", "6 mm", "8 mm"), leads=("5 mm", "6 mm"), solver=None):
    """The shipped catalogue problem with a few leads and pins (6 combinations)."""
    import tomllib
    from pathlib import Path

    from optdesign.problem import problem_from_dict

    path = Path(__file__).resolve().parents[3] / "problems" / "cs_min_backlash_catalogue.toml"
    data = tomllib.loads(path.read_text())
    data["variables"]["p"] = {"values": list(leads)}
    data["variables"]["d"] = {"values": list(pins)}
    if solver:
        data["solver"] = solver
    return problem_from_dict(data)


def _spied_search(monkeypatch, stats=None):
    """solve_catalogue with its searches replaced by spies finding nothing (only the root
    relaxation is solved): the calls they got."""
    from optdesign.formulations.catalogue import search as catalogue

    calls: dict = {}

    def enum(ns, x_hint=None, floor=None):
        calls["enumerate"] = ns
        return None, []

    def bnb(ns, root, incumbents=(), ties=True):
        calls["bnb"] = (ns, root, incumbents, ties)
        keys = ("nodes", "pruned", "infeasible", "leaves", "seeded")
        return None, dict(stats or dict.fromkeys(keys, 0))

    monkeypatch.setattr(catalogue, "enumerate_catalogue", enum)
    monkeypatch.setattr(catalogue, "branch_and_bound", bnb)
    return calls


def test_a_combination_met_again_is_solved_from_the_new_start_only():
    """Centre (2.4, 2.5): the combination (2, 2) is reached from two nodes; the second
    time one warm start (no better) returns the stored full multistart."""
    items = {"a": (1.0, 2.0, 3.0, 4.0), "b": (1.0, 2.0, 3.0)}
    ns = QuadNodes(items, {"a": 2.4, "b": 2.5})
    best, _ = branch_and_bound_warm(ns, _root(ns))
    assert best.design == {"a": 2.0, "b": 2.0} and best.multistart.n_starts == 2
    box = {"a": (2.0, 2.0), "b": (2.0, 2.0)}
    assert [warm for b, warm, _ in ns.calls if b == box] == [False, True]
    revisit = [h for (b, warm, _), h in zip(ns.calls, ns.hints, strict=True) if b == box and warm]
    assert revisit == [[2.0, 2.0]]  # the optimum of the node it was met from
    assert _cold_leaf_solves(ns)[(2.0, 2.0)] == 1
    # a first multistart stuck 0.01 above: the new start beats it, the full multistart
    # runs again and its value is the one reported
    ns = QuadNodes(items, {"a": 2.4, "b": 2.5}, worse_once=0.01)
    best, _ = branch_and_bound_warm(ns, _root(ns))
    assert [warm for b, warm, _ in ns.calls if b == box] == [False, True, False]
    assert best.design == {"a": 2.0, "b": 2.0} and best.objective == pytest.approx(0.41)


def test_branch_and_bound_on_one_variable_follows_the_hand_trace():
    """Items 1..4 around 2.4: two children, one leaf, a split below it, a warm node re-solved
    and pruned: 6 nodes, 2 pruned, 1 leaf, item 2 at 0.16."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 2.4}, cap=3.5)
    best, stats = branch_and_bound_warm(ns, _root(ns))
    assert best.objective == pytest.approx(0.16) and best.design == {"a": 2.0}
    assert stats == {"nodes": 6, "pruned": 2, "infeasible": 0, "leaves": 1, "seeded": 0}
    # children solved warm from the root's optimum with its value as their floor
    assert ns.calls[1] == ({"a": (1.0, 2.0)}, True, 0.0)
    assert ns.calls[2] == ({"a": (3.0, 4.0)}, True, 0.0)
    # the leaf and the warm node's full multistart, cold, with the root's floor
    assert ({"a": (2.0, 2.0)}, False, 0.0) in ns.calls
    assert ns.calls[-1] == ({"a": (3.0, 4.0)}, False, 0.0)
    # each from its parent's optimum: the root's 2.4, then the node's 2; the warm node
    # re-solved from the start it was first solved from
    assert ns.hints == [None, [2.4], [2.4], [2.0], [2.0], [2.4]]


def test_a_candidate_worse_than_the_search_is_seeded_but_not_reported():
    """A first incumbent at item 3 prunes the right child at once; the search's item 2
    wins: 6 nodes, 1 seeded, 2 pruned."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 2.4}, cap=3.5)
    best, stats = branch_and_bound_warm(ns, _root(ns), [{"a": 3.0}])
    assert best.design == {"a": 2.0} and best.objective == pytest.approx(0.16)
    assert stats == {"nodes": 6, "pruned": 2, "infeasible": 0, "leaves": 1, "seeded": 1}
    # the candidate's leaf: one warm start from its design
    assert ns.calls[1] == ({"a": (3.0, 3.0)}, True, None)


def test_a_candidate_that_is_the_optimum_is_reported_after_its_full_multistart():
    """When the search's own leaves cannot beat the candidate (here: none is solved,
    every box pruned by it), the candidate is solved again with the full multistart from
    its own design and the root's floor, and reported."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 1.0}, cap=3.5)
    best, stats = branch_and_bound_warm(ns, _root(ns), [{"a": 1.0}])
    assert best.design == {"a": 1.0} and best.objective == 0.0
    assert best.multistart.n_starts == 2  # the full multistart, not the seed's one start
    assert ns.calls[-1] == ({"a": (1.0, 1.0)}, False, 0.0)
    assert stats["seeded"] == 1 and stats["leaves"] == 0


def test_an_infeasible_side_is_counted_and_the_only_item_under_the_cap_wins():
    """Under a cap of 1.5 only item 1 is feasible: the relaxation sits at 1.5, the right
    side [2, 4] is infeasible, the left one is a leaf: 3 nodes, 1 infeasible, 1 leaf."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 2.4}, cap=1.5)
    best, stats = branch_and_bound_warm(ns, _root(ns))
    assert best.design == {"a": 1.0} and best.objective == pytest.approx(1.96)
    assert stats == {"nodes": 3, "pruned": 0, "infeasible": 1, "leaves": 1, "seeded": 0}


def test_an_infeasible_root_ends_the_search_before_any_candidate():
    """No feasible relaxation: no incumbent, no candidate solved, one node."""
    ns = QuadNodes({"a": (1.0, 2.0)}, {"a": 1.0}, cap=0.5)
    best, stats = branch_and_bound_warm(ns, _root(ns), [{"a": 1.0}])
    assert best is None
    assert stats == {"nodes": 1, "pruned": 0, "infeasible": 0, "leaves": 0, "seeded": 0}
    assert len(ns.calls) == 1


@pytest.mark.parametrize("ca", [0.7, 1.5, 2.4, 2.5, 3.2, 3.5, 4.6])
@pytest.mark.parametrize("cb", [0.2, 1.5, 2.5, 2.9])
@pytest.mark.parametrize("cap", [1.0, 2.5, 4.0])
@pytest.mark.parametrize("warm_worse", [0.0, 0.3])
def test_branch_and_bound_and_enumeration_equal_the_brute_force_optimum(ca, cb, cap, warm_worse):
    """Over a grid of centres (ties at .5 included) and caps, with warm starts exact or
    0.3 above the box's optimum, both searches report the brute-force optimum and its
    smallest tied items."""
    items = {"a": (1.0, 2.0, 3.0, 4.0), "b": (1.0, 2.0, 3.0)}
    ns = QuadNodes(items, {"a": ca, "b": cb}, cap=cap, warm_worse=warm_worse)
    value, combo = _brute(ns)
    best, _ = branch_and_bound_warm(ns, _root(ns))
    assert best.objective == pytest.approx(value, abs=1e-12)
    assert (best.design["a"], best.design["b"]) == combo
    assert max(_cold_leaf_solves(ns).values(), default=0) <= 1
    best, table = enumerate_catalogue(QuadNodes(items, {"a": ca, "b": cb}, cap=cap))
    assert best.objective == pytest.approx(value, abs=1e-12)
    assert (best.design["a"], best.design["b"]) == combo
    assert len(table) == 12


def test_ties_false_keeps_the_value_and_may_report_either_tied_item():
    """``ties=False``: the optimal value is the same; the tied items are not decided by
    size, the first met (the larger item 3, met first by the search here) is kept."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 2.5})
    best, _ = branch_and_bound_warm(ns, _root(ns), [{"a": 3.0}], ties=False)
    assert best.objective == pytest.approx(0.25) and best.design == {"a": 3.0}
    best, _ = branch_and_bound_warm(ns, _root(ns), [{"a": 3.0}], ties=True)
    assert best.objective == pytest.approx(0.25) and best.design == {"a": 2.0}


def test_enumeration_lists_every_combination_in_order_and_keeps_the_first_tie():
    """The table follows the product of the item lists; infeasible items are listed with
    their status; the floor reaches every solve; a tie keeps the earlier combination."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0), "b": (5.0, 6.0)}, {"a": 1.5, "b": 5.0}, cap=2.5)
    best, table = enumerate_catalogue(ns, np.array([1.0, 5.0]), floor=0.125)
    assert [c.items for c in table] == [
        {"a": a, "b": b} for a, b in itertools.product((1.0, 2.0, 3.0), (5.0, 6.0))
    ]
    assert [c.status for c in table] == ["optimal"] * 4 + ["infeasible"] * 2
    assert [c.objective for c in table[:4]] == [0.25, 1.25, 0.25, 1.25]
    assert math.isnan(table[4].objective)
    assert best.design == {"a": 1.0, "b": 5.0}
    assert all(floor == 0.125 and not warm for _, warm, floor in ns.calls)
    assert ns.hints == [[1.0, 5.0]] * 6


def test_enumeration_with_no_feasible_combination_has_no_best():
    """Every combination infeasible: None, and the full table."""
    ns = QuadNodes({"a": (2.0, 3.0)}, {"a": 2.0}, cap=1.0)
    best, table = enumerate_catalogue(ns)
    assert best is None and [c.status for c in table] == ["infeasible", "infeasible"]


def test_first_incumbent_skips_unusable_candidates_and_decides_ties_by_items():
    """Candidates lacking a variable, with a non-number, or repeating an item (after
    snapping) are not solved; of two tied ones the smaller items win, unless ties are
    off (the first stays)."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 2.5})
    cands = [{}, {"a": None}, {"a": "x"}, {"a": 3.1}, {"a": 2.9}, {"a": 2.0}, {"b": 1.0}]
    stats = {"nodes": 0, "seeded": 0}
    best, items = first_incumbent(ns, cands, stats)
    assert items == {"a": 2.0} and best.objective == pytest.approx(0.25)
    assert stats == {"nodes": 2, "seeded": 2}  # 3.1 and 2.0; 2.9 snaps to 3 (seen)
    assert [c[0] for c in ns.calls] == [{"a": (3.0, 3.0)}, {"a": (2.0, 2.0)}]
    assert all(warm for _, warm, _ in ns.calls)
    stats = {"nodes": 0, "seeded": 0}
    best, items = first_incumbent(ns, cands, stats, ties=False)
    assert items == {"a": 3.0}
    # a better candidate after a worse one replaces it
    best, items = first_incumbent(ns, [{"a": 1.0}, {"a": 3.0}], {"nodes": 0, "seeded": 0})
    assert items == {"a": 3.0} and best.objective == pytest.approx(0.25)
    assert first_incumbent(ns, [], {"nodes": 0, "seeded": 0}) == (None, None)


def test_a_candidate_missing_a_continuous_variable_is_no_start():
    """A design vector needs every free variable: one missing gives None, the values in
    the solver's order otherwise."""
    ns = QuadNodes({"a": (1.0, 2.0), "b": (1.0, 2.0)}, {"a": 1.0, "b": 1.0})
    assert _x_of_design(ns, {"a": 1.0}) is None
    assert _x_of_design(ns, {"b": 2.0, "a": 1.0}).tolist() == [1.0, 2.0]


def test_first_feasible_returns_the_leaf_under_the_better_child():
    """Depth first with the better child explored first: item 2 (0.16), not item 3; an
    infeasible relaxation gives None."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 2.4}, cap=3.5)
    leaf = first_feasible(ns)
    assert leaf.design == {"a": 2.0} and leaf.objective == pytest.approx(0.16)
    assert ns.calls[-1][0] == {"a": (2.0, 2.0)}
    assert first_feasible(QuadNodes({"a": (2.0, 3.0)}, {"a": 2.0}, cap=1.0)) is None


def test_first_feasible_on_two_variables_finds_a_feasible_combination():
    """Two variables under a cap: the leaf found is feasible (under the cap) and on items."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0), "b": (1.0, 2.0, 3.0)}, {"a": 3.6, "b": 2.4}, 2.5)
    leaf = first_feasible(ns)
    assert leaf.design == {"a": 2.0, "b": 2.0}


def test_cannot_improve_prunes_within_the_relative_tolerance_only():
    """A bound 1e-6 (relative) below the incumbent is pruned, one further below is not;
    the tolerance scales with the incumbent's magnitude, negative ones included."""
    assert cannot_improve(2.0, 2.0) and cannot_improve(2.0 - 1.9e-6, 2.0)
    assert not cannot_improve(2.0 - 2.1e-6, 2.0)
    assert cannot_improve(-2.0 - 1.9e-6, -2.0) and not cannot_improve(-2.0 - 2.1e-6, -2.0)
    assert cannot_improve(3.0, 2.0)


def test_a_nodes_value_is_trusted_from_a_full_multistart_or_an_early_stop():
    """Trusted: as many starts as the node solver's, or stopped early; not: fewer, no
    multistart, or a failed node (no value)."""
    assert trusted(_result(1.0, {}, 4), 4) and trusted(_result(1.0, {}, 5), 4)
    assert not trusted(_result(1.0, {}, 3), 4)
    assert trusted(_result(1.0, {}, 1, early=True), 4)
    bare = _result(1.0, {})
    bare.multistart = None
    assert not trusted(bare, 1)
    assert trusted_value(_result(1.5, {}, 4), 4) == 1.5
    assert trusted_value(_result(1.5, {}, 1), 4) is None
    failed = _failed()
    failed.multistart = MultistartInfo(4, 0, 0, 1e-6)
    assert trusted_value(failed, 4) is None


def test_tie_rules_compare_values_then_items():
    """wins: better beyond the tolerance wins, a tie goes to smaller items, no best yet
    always loses to the newcomer; box_cannot_win: a tie is kept while the box holds
    smaller items."""
    names = ["a", "b"]
    assert combination_key({"b": 2, "a": 1}, names) == (1.0, 2.0)
    assert box_key({"a": (1, 3), "b": (2, 4)}, names) == (1.0, 2.0)
    assert wins(5.0, (9.0,), None, None) and wins(5.0, (9.0,), 4.0, None)
    assert wins(1.0, (9.0,), 2.0, (1.0,))
    assert not wins(3.0, (0.0,), 2.0, (1.0,))
    assert wins(2.0 + 1e-7, (0.0,), 2.0, (1.0,))  # tie, smaller items
    assert not wins(2.0 - 1e-7, (1.0,), 2.0, (1.0,))  # tie, same items
    assert not wins(2.0, (2.0,), 2.0, (1.0,))
    box = {"a": (1.0, 3.0), "b": (1.0, 1.0)}
    assert not box_cannot_win(1.0, box, names, 2.0, (2.0, 1.0))  # better
    assert box_cannot_win(3.0, box, names, 2.0, (0.0, 0.0))  # worse, whatever the items
    assert not box_cannot_win(2.0, box, names, 2.0, (2.0, 1.0))  # tie, (1, 1) smaller
    assert box_cannot_win(2.0, box, names, 2.0, (1.0, 1.0))  # tie, nothing smaller
    assert box_cannot_win(2.0 + 1.9e-6, box, names, 2.0, (2.0, 1.0)) is False
    assert box_cannot_win(2.0 + 2.1e-6, box, names, 2.0, (2.0, 1.0))


def test_small_helpers_of_the_search():
    """A combination's box, a result's value, a pruning test bound to its box."""
    assert fixed_box({"a": 2.0, "b": 3.0}) == {"a": (2.0, 2.0), "b": (3.0, 3.0)}
    assert _value(None) is None and _value(_result(1.25, {})) == 1.25
    seen = []
    assert _prunes_box(lambda v, b: seen.append((v, b)) or True, {"a": (1, 2)}, 3.0)
    assert seen == [(3.0, {"a": (1, 2)})]


def test_item_distances_and_the_variable_farthest_from_an_item():
    """The nearest item within the box and its distance relative to max(1, item); the
    farthest variable is split, the first of equal distances, none when all sit on items."""
    dvars = [_Var("a", (1.0, 2.0, 3.0, 4.0)), _Var("b", (10.0, 20.0))]
    box = {"a": (3.0, 4.0), "b": (10.0, 20.0)}
    res = _result(0.0, {"a": 2.4, "b": 13.0})
    (va, ia, da), (vb, ib, db) = item_distances(dvars, box, res)
    assert (va.name, ia, vb.name, ib) == ("a", 3.0, "b", 10.0)
    assert da == pytest.approx(0.6 / 3.0) and db == pytest.approx(3.0 / 10.0)
    worst, items = on_items(dvars, box, res)
    assert worst.name == "b" and items == {"a": 3.0, "b": 10.0}
    # below 1, the distance is absolute: 0.5 from item 0.5 counts as 0.5
    ((_, item, dist),) = item_distances(
        [_Var("c", (0.5, 2.0))], {"c": (0.5, 2.0)}, _result(0, {"c": 1.0})
    )
    assert (item, dist) == (0.5, 0.5)
    tied = _result(0.0, {"a": 1.5, "b": 15.0})  # both 0.5 from an item
    assert on_items(dvars, {"a": (1.0, 4.0), "b": (10.0, 20.0)}, tied)[0].name == "a"
    on = _result(0.0, {"a": 2.0 + 1e-7, "b": 20.0})
    assert on_items(dvars, {"a": (1.0, 4.0), "b": (10.0, 20.0)}, on) == (
        None,
        {"a": 2.0, "b": 20.0},
    )


def test_split_at_items_cuts_the_first_wide_variable_below_at_and_above():
    """The first variable whose range holds more than one item is cut around the item the
    relaxation sits on (a side may be empty)."""
    dvars = [_Var("a", (1.0, 2.0, 3.0)), _Var("b", (1.0, 2.0, 3.0, 4.0))]
    sides = split_at_items(dvars, {"a": (2.0, 2.0), "b": (1.0, 4.0)}, {"a": 2.0, "b": 3.0})
    assert [(v.name, s) for v, s in sides] == [("b", [1.0, 2.0]), ("b", [3.0]), ("b", [4.0])]
    sides = split_at_items(dvars, {"a": (1.0, 2.0), "b": (1.0, 4.0)}, {"a": 1.0, "b": 3.0})
    assert [(v.name, s) for v, s in sides] == [("a", []), ("a", [1.0]), ("a", [2.0])]


def test_pseudo_costs_gain_record_and_choice():
    """Gains are relative rises (infeasible: 1); a branching's cost the product of its two
    gains floored at 1e-6 (one side: its square); the highest mean is split once every
    variable off its items has a history, the first of equal ones."""
    pc = PseudoCosts()
    assert pc.gain(2.0, _result(3.0, {})) == 0.5
    assert pc.gain(2.0, _result(1.0, {})) == 0.0
    assert pc.gain(-2.0, _result(-1.0, {})) == 0.5
    assert pc.gain(2.0, _failed()) == PseudoCosts.INFEASIBLE_GAIN == 1.0
    assert pc.gain(0.0, _result(1e-300, {})) == pytest.approx(1.0)
    pc.record("a", [0.5, 0.2])
    pc.record("a", [0.3])
    pc.record("b", [0.0, 0.5])
    assert pc.scores["a"] == pytest.approx([0.1, 0.09])
    assert pc.scores["b"] == pytest.approx([5e-7])
    dvars = [_Var("a", (1.0, 2.0, 3.0)), _Var("b", (1.0, 2.0, 3.0)), _Var("c", (1.0, 2.0))]
    box = {"a": (1.0, 3.0), "b": (1.0, 3.0), "c": (1.0, 2.0)}
    both_off = _result(0.0, {"a": 1.5, "b": 2.2, "c": 1.0})
    assert pc.choose(dvars, box, both_off, dvars[1]).name == "a"
    assert pc.choose(dvars, box, both_off, None) is None
    one_off = _result(0.0, {"a": 1.5, "b": 2.0, "c": 1.0})
    assert pc.choose(dvars, box, one_off, dvars[1]).name == "b"  # one off: the search's
    c_off = _result(0.0, {"a": 1.5, "b": 2.0, "c": 1.5})
    assert pc.choose(dvars, box, c_off, dvars[2]).name == "c"  # c has no history
    pc.record("b", [0.1, 0.95])  # mean of b: (5e-7 + 0.095) / 2 < a's 0.095
    assert pc.choose(dvars, box, both_off, dvars[1]).name == "a"
    even = PseudoCosts()
    even.record("a", [0.5])
    even.record("b", [0.5])
    assert even.choose(dvars, box, both_off, dvars[1]).name == "a"  # the first of a tie


def test_the_memo_counts_copies_and_rebuilds_its_proofs():
    """len counts proofs; proofs are copies in order; from_proofs rebuilds the same
    verdicts; a proof's box is completed with the full ranges."""
    full = {"a": (1.0, 4.0), "b": (1.0, 3.0)}
    memo = InfeasibleBoxes(full)
    assert len(memo) == 0
    memo.add_infeasible({"a": (2.0, 3.0)}, {"f": 1.0})
    memo.add_infeasible({"b": (3.0, 3.0)}, {})
    assert len(memo) == 2
    proofs = memo.proofs
    assert proofs == [
        ({"a": (2.0, 3.0), "b": (1.0, 3.0)}, {"f": 1.0}),
        ({"a": (1.0, 4.0), "b": (3.0, 3.0)}, {}),
    ]
    proofs[0][0]["a"] = (0.0, 9.0)
    proofs[0][1]["f"] = 99.0
    assert memo.proofs[0] == ({"a": (2.0, 3.0), "b": (1.0, 3.0)}, {"f": 1.0})
    again = InfeasibleBoxes.from_proofs(full, memo.proofs)
    assert again.proofs == memo.proofs and len(again) == 2
    assert again.known_infeasible({"a": (2.5, 3.0), "b": (1.0, 1.0)}, {"f": 0.5})
    assert not again.known_infeasible({"a": (2.5, 3.5), "b": (1.0, 1.0)}, {"f": 0.5})
    assert again.known_infeasible({"a": (1.0, 4.0), "b": (3.0, 3.0)}, {})
    assert not again.known_infeasible({"b": (2.0, 3.0)}, {})


def test_a_box_inside_a_proof_within_a_relative_1e_12_only():
    """A box edge past a proof's by 1e-13 of it is inside (the NLP's bound slack), by 1e-11
    it is not; at magnitudes below 1 the slack is 1e-12 absolute."""
    memo = InfeasibleBoxes({"a": (0.0, 300.0)})
    memo.add_infeasible({"a": (100.0, 200.0)}, {})
    assert memo.known_infeasible({"a": (100.0 - 1e-11, 200.0 + 1e-11)}, {})
    assert not memo.known_infeasible({"a": (100.0 - 1e-9, 200.0)}, {})
    assert not memo.known_infeasible({"a": (100.0, 200.0 + 1e-9)}, {})
    small = InfeasibleBoxes({"a": (0.0, 1.0)})
    small.add_infeasible({"a": (0.1, 0.2)}, {})
    assert small.known_infeasible({"a": (0.1 - 5e-13, 0.2 + 5e-13)}, {})
    assert not small.known_infeasible({"a": (0.1 - 5e-12, 0.2)}, {})


def test_the_memo_checks_item_combinations_one_by_one_only_up_to_its_limit():
    """Two proofs covering the items between them prove the box; a single one, or a box
    of more than MAX_COVER_COMBINATIONS combinations, is not checked item by item."""
    assert catalogue_bnb.MAX_COVER_COMBINATIONS == 4096
    values = tuple(float(k) for k in range(1, 4098))  # 4097 items
    memo = InfeasibleBoxes({"a": (1.0, 4097.0)}, {"a": values[::-1]})
    assert memo.items == {"a": values}  # sorted
    memo.add_infeasible({"a": (1.0, 2048.0)}, {})
    assert not memo.known_infeasible({"a": (1.0, 4096.0)}, {})  # one proof: no cover
    memo.add_infeasible({"a": (2049.0, 4097.0)}, {})
    assert memo.known_infeasible({"a": (1.0, 4096.0)}, {})  # 4096 combinations
    assert not memo.known_infeasible({}, {})  # 4097: too many to check


def test_shared_memos_carry_the_items_and_are_found_by_key(monkeypatch):
    """A shared memo made with items checks combinations; the same key returns it."""
    monkeypatch.setattr(catalogue_bnb, "_MEMOS", {})
    assert catalogue_bnb._MEMO_MAX == 8
    memo = catalogue_bnb.shared_memo(("k",), {"a": (1.0, 3.0)}, {"a": (3.0, 1.0, 2.0)})
    assert memo.items == {"a": (1.0, 2.0, 3.0)}
    assert catalogue_bnb.shared_memo(("k",), {}) is memo
    assert catalogue_bnb.shared_memo(("j",), {"a": (1.0, 3.0)}).items is None


def test_a_pruned_warm_node_leaves_a_proof_only_from_a_trusted_value():
    """A search with a memo records, for every box pruned on a full multistart, the box
    under a limit just below its value; the proofs' limits sit PRUNE_TOL under the
    pruned values."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 2.4}, cap=3.5)
    ns.memo = InfeasibleBoxes({"a": (1.0, 4.0)})
    ns.eps = {"g": 5.0}
    branch_and_bound_warm(ns, _root(ns))
    proofs = ns.memo.proofs
    assert [box for box, _ in proofs] == [{"a": (1.0, 1.0)}, {"a": (3.0, 4.0)}]
    assert proofs[0][1] == {"g": 5.0, "f": pytest.approx(1.96 * (1 - PRUNE_TOL), rel=1e-15)}
    assert proofs[1][1]["f"] == pytest.approx(0.36 * (1 - PRUNE_TOL), rel=1e-15)


def test_verdicts_decide_needs_two_starts_all_with_the_backends_verdict():
    """Two or more starts, a back-end that has verdicts, and every message one of them."""
    ns = object.__new__(NodeSolver)
    ns.verdicts = ("Infeasible_Problem_Detected",)

    def res(msg):
        r = _failed()
        r.message = msg
        return r

    v, other = res("Infeasible_Problem_Detected"), res("Maximum_Iterations_Exceeded")
    assert ns.verdicts_decide([v, v]) and ns.verdicts_decide([v, v, v])
    assert not ns.verdicts_decide([v]) and not ns.verdicts_decide([])
    assert not ns.verdicts_decide([v, other])
    ns.verdicts = ()
    assert not ns.verdicts_decide([v, v])


def test_a_result_without_design_has_no_vector_and_a_missing_item_is_infeasible():
    """x_of: None for no design, the values in the free variables' order otherwise;
    _no_item: an infeasible catalogue result with its reason and no value."""
    ns = object.__new__(NodeSolver)
    ns.names = ["b", "a"]
    assert ns.x_of(_failed()) is None
    assert ns.x_of(_result(0.0, {"a": 1.0, "b": 2.0})).tolist() == [2.0, 1.0]
    r = _no_item("ipopt", "no catalogue item in this box")
    assert (r.status, r.formulation, r.solver) == ("infeasible", "catalogue", "ipopt")
    assert r.message == "no catalogue item in this box" and math.isnan(r.objective)
    assert not r.success


def test_the_minlp_back_end_is_a_registered_minlp_solver_or_refused_naming_them():
    """None: the first MINLP back-end (bonmin); bonmin itself; ipopt refused, naming it
    and the ones that do solve a MINLP."""
    assert minlp_back_end(None) == "bonmin" and minlp_back_end("bonmin") == "bonmin"
    with pytest.raises(ProblemError) as err:
        minlp_back_end("ipopt")
    assert str(err.value) == (
        "catalogue method minlp: back-end 'ipopt' solves no MINLP (those that do: bonmin)"
    )


def test_catalogue_predicates_and_the_relaxation_bound():
    """catalogue_applies names why not; is_on_catalogue within 1e-12; the bound NaN when
    none was recorded."""
    problem = _Problem([_Var("a", (1.0, 2.5))])
    assert catalogue_applies(problem) is True
    plain = _Problem([_Var("x", (0.0, 1.0), discrete=False)])
    assert catalogue_applies(plain) == "no variable takes catalogue values"
    assert is_on_catalogue(problem, {"a": 2.5 + 1e-13})
    assert not is_on_catalogue(problem, {"a": 2.5 + 1e-9})
    assert not is_on_catalogue(problem, {"a": 1.75})
    assert is_on_catalogue(plain, {"x": 0.3})  # no catalogue variable
    r = _result(1.0, {})
    assert math.isnan(relaxation_bound(r))
    r.bound = 0.75
    assert relaxation_bound(r) == 0.75


def test_solve_catalogue_refuses_what_it_cannot_search():
    """No catalogue variable, or an unknown method: a ProblemError saying so."""
    plain = _Problem([_Var("x", (0.0, 1.0), discrete=False)])
    with pytest.raises(ProblemError, match="no variable takes catalogue values"):
        solve_catalogue(plain)
    with pytest.raises(ProblemError) as err:
        solve_catalogue(_small(), method="exhaustive")
    assert str(err.value) == "catalogue method 'exhaustive': use auto, enumerate, bnb or minlp"


def test_an_enumerated_catalogue_result_records_its_search():
    """auto enumerates 6 combinations: the details, the gap to the relaxation computed
    from the two values, the snapped items and the summary note."""
    problem = _small()
    # a catalogue variable without a unit (display only): its item has no trailing space
    object.__setattr__(problem.by_name["d"], "unit", "")
    r = solve_catalogue(problem, starts=2)
    info = r.details.catalogue
    assert r.formulation == "catalogue-enumerate" and info.method == "enumerate"
    assert info.combinations == 6 and info.starts_per_node == 2
    assert info.variables == {"p": [5.0, 6.0], "d": [5.0, 6.0, 8.0]}
    assert info.items == {"p": 6.0, "d": 6.0} and r.design["d"] == 6.0
    assert info.relaxation_status == "optimal"
    assert r.bound == info.relaxation_bound < r.objective
    assert info.gap_to_relaxation_rel == pytest.approx((r.objective - r.bound) / abs(r.bound))
    assert sorted(info.relaxation_design) == sorted(v.name for v in _small().free)
    assert len(info.enumerated) == 6 and info.nlp_solves >= 7
    note = next(n for n in r.notes if n.startswith("catalogue items chosen"))
    gap = 100 * info.gap_to_relaxation_rel
    # enumeration relaxes no node; its combinations' starts are solved on every other
    # grid angle first, kept or solved again on the whole grid (both counted)
    assert info.thinned_solves == 0 and info.checked_starts + info.resolved_starts > 0
    grid = [f"{info.checked_starts} starts first, kept: their points met every row"]
    if info.resolved_starts:
        grid.append(f"{info.resolved_starts} starts first, then on the whole grid")
    # the root holds several combinations: its starts are sqpmethod's first
    assert info.first_solver == "sqpmethod" and info.first_starts >= 2
    failed = (
        f" ({info.first_failed} not solved: {info.first_certified} certified locally "
        f"infeasible by its phase 1, {info.first_failed - info.first_certified} solved "
        "again by the node's back-end)"
    )
    grid.append(
        f"{info.first_starts} starts of nodes with several item combinations by sqpmethod "
        f"first{failed if info.first_failed else ''}"
    )
    learnt = " and at " + ", ".join(info.learned_angles) if info.learned_angles else ""
    assert note == (
        f"catalogue items chosen: p = 6 mm, d = 6; continuous relaxation bound "
        f"{r.bound:.8g} (discrete optimum {gap:+.3f} % above it); enumerate, "
        f"{info.nlp_solves} NLP solves (on every other grid angle{learnt}: {'; '.join(grid)})"
    )


def test_an_infeasible_catalogue_names_the_relaxation_as_infeasible():
    """Pins too weak for any lead: status infeasible, the relaxation's verdict, no items."""
    r = solve_catalogue(_small(pins=("4 mm", "5 mm")), method="bnb", starts=2)
    assert r.status == "infeasible" and r.formulation == "catalogue-bnb"
    assert r.message == "the continuous relaxation has no feasible design"
    info = r.details.catalogue
    assert info.relaxation_bound is None and info.relaxation_status != "optimal"
    assert info.items is None and info.nodes == 1 and r.design == {}
    # the root's two starts: sqpmethod (the first solver) solves neither, and its phase 1
    # certifies a positive least violation from each - two verdicts: no retries (four NLP
    # solves), and the whole box is this search's one proof
    assert (info.first_solver, info.first_starts, info.first_failed) == ("sqpmethod", 2, 2)
    assert info.first_certified == 2
    assert info.nlp_solves == 4
    assert info.infeasible_boxes == [({"p": (5.0, 6.0), "d": (4.0, 5.0)}, {})]


def test_a_node_solver_clamps_its_settings_and_records_its_multistart():
    """starts, workers and agree below their least are raised to 1, 1 and 0; a node's
    multistart records its starts, seed, values and plan; ``agree`` 2 stops it after two
    agreeing starts (settled), 0 runs every start."""
    problem = _small()
    box = {"p": (6.0, 6.0), "d": (6.0, 6.0)}
    low = NodeSolver(problem, starts=0, workers=0, agree=-2)
    assert (low.starts, low.workers, low.agree) == (1, 1, 0)
    assert low.objective == "backlash" and low.names == [v.name for v in problem.free]
    assert (low.n_solves, low.n_cold, low.n_implied, low.memo, low.proofs) == (0, 0, 0, None, None)
    r = low.solve(box)
    assert r.objective == pytest.approx(0.0340646, rel=1e-5)  # H7/g6 at 6 mm, lead 6
    assert (r.multistart.n_starts, r.multistart.n_planned, low.n_solves) == (1, 1, 1)
    every = NodeSolver(problem, starts=3, seed=5, agree=0)
    r = every.solve(box)
    ms = r.multistart
    assert (ms.n_starts, ms.n_converged, ms.n_planned, ms.seed) == (3, 3, 3, 5)
    assert ms.stopped_early is False and ms.outcomes == ["converged"] * 3 and ms.failed == {}
    # the three tie (within 1e-6): the first start's value is the node's
    assert len(ms.objectives) == 3 and r.objective == ms.objectives[0]
    assert ms.n_at_best == 3 and every.n_solves == 3
    two = NodeSolver(problem, starts=3, seed=5, agree=2)
    r = two.solve(box)
    assert (r.multistart.n_starts, r.multistart.stopped_early, two.n_solves) == (2, True, 2)
    # agreement needs two starts at least, even when one start would be "agreed"
    one = NodeSolver(problem, starts=3, seed=5, agree=1)
    assert one.solve(box).multistart.n_starts == 2


def test_a_warm_node_decides_alone_unless_its_value_would_prune_it():
    """A warm start whose value the search would prune runs the rest of the multistart
    (a cold fallback counted); with ``fallback=False`` its own result comes back at once;
    a warm start not pruned decides the node with one solve."""
    problem = _small()
    box = {"p": (6.0, 6.0), "d": (6.0, 6.0)}
    ref = NodeSolver(problem, starts=3)
    assert (ref.seed, ref.workers, ref.agree, ref.eps) == (0, 1, 0, {})  # the defaults
    x = ref.x_of(ref.solve(box))
    pruned = NodeSolver(problem, starts=3)
    r = pruned.solve(box, x, warm=True, prunes=lambda v: True)
    assert (pruned.n_cold, pruned.n_solves, r.multistart.n_starts) == (1, 3, 3)
    alone = NodeSolver(problem, starts=3)
    r = alone.solve(box, x, warm=True, prunes=lambda v: True, fallback=False)
    assert (alone.n_cold, alone.n_solves, r.multistart) == (0, 1, None)
    assert r.objective == pytest.approx(0.0340646, rel=1e-5)
    kept = NodeSolver(problem, starts=3)
    r = kept.solve(box, x, warm=True, prunes=lambda v: False)
    assert (kept.n_cold, kept.n_solves, r.multistart.n_starts) == (0, 1, 1)
    assert r.multistart.n_planned == 3


@pytest.mark.parametrize(
    "bad",
    [
        [(2.0, 1.0)],
        [(2.0, 1.0), (3.0, 1.0), (2.0, 2.0)],
        [(a, 1.0) for a in (1.0, 2.0, 3.0, 4.0)],
        [(a, b) for a in (1.0, 2.0, 3.0) for b in (1.0, 2.0, 3.0)],
    ],
)
@pytest.mark.parametrize("ca,cb", [(2.0, 1.0), (2.4, 1.3), (2.5, 1.5)])
def test_a_relaxation_on_an_infeasible_combination_still_searches_its_box(bad, ca, cb):
    """A relaxation sitting on items whose combination is infeasible alone: branch and
    bound and enumeration still find the brute-force optimum among the box's others,
    and the diagnosis's search some feasible combination."""
    items = {"a": (1.0, 2.0, 3.0, 4.0), "b": (1.0, 2.0, 3.0)}
    ns = QuadNodes(items, {"a": ca, "b": cb}, bad=bad)
    value, combo = _brute(ns)
    best, _ = branch_and_bound_warm(ns, _root(ns))
    assert (best.design["a"], best.design["b"]) == combo
    assert best.objective == pytest.approx(value, abs=1e-12)
    best, _ = enumerate_catalogue(QuadNodes(items, {"a": ca, "b": cb}, bad=bad))
    assert (best.design["a"], best.design["b"]) == combo
    leaf = first_feasible(QuadNodes(items, {"a": ca, "b": cb}, bad=bad))
    assert (leaf.design["a"], leaf.design["b"]) not in ns.bad


def test_first_feasible_splits_a_box_whose_relaxations_items_fail():
    """The relaxation sits on item 2, whose combination fails alone: the box is split
    below, at and above it; the side above (item 3, explored first on the tie) works.
    Every child is solved from its parent's optimum."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 2.0}, bad=[(2.0,)])
    leaf = first_feasible(ns)
    assert leaf.design == {"a": 3.0} and leaf.objective == 1.0
    assert [c[0] for c in ns.calls] == [
        {},
        {"a": (2.0, 2.0)},
        {"a": (1.0, 1.0)},
        {"a": (3.0, 4.0)},
        {"a": (3.0, 3.0)},
    ]
    assert ns.hints == [None, [2.0], [2.0], [2.0], [3.0]]


def test_candidates_are_solved_from_their_own_designs_with_one_start():
    """A candidate's leaf starts from its design as given (not snapped) and is one start."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0, 4.0)}, {"a": 2.5})
    best, items = first_incumbent(ns, [{"a": 3.1}], {"nodes": 0, "seeded": 0})
    assert ns.hints == [[3.1]] and items == {"a": 3.0}
    assert best.multistart.n_starts == 1


def test_a_tied_candidate_with_smaller_items_prunes_the_search_and_is_reported():
    """Items 2 and 3 tie around 2.5; the candidates 3 then 2 make 2 the first incumbent,
    which prunes both leaves (neither can win the tie) and is reported after its full
    multistart: 6 nodes, 2 pruned, no leaf."""
    ns = QuadNodes({"a": (2.0, 3.0)}, {"a": 2.5})
    best, stats = branch_and_bound_warm(ns, _root(ns), [{"a": 3.0}, {"a": 2.0}])
    assert best.design == {"a": 2.0} and best.multistart.n_starts == 2
    assert stats == {"nodes": 6, "pruned": 2, "infeasible": 0, "leaves": 0, "seeded": 2}


def test_enumeration_starts_from_the_relaxation_and_trusts_its_value(monkeypatch):
    """solve_catalogue enumerates from the relaxation's optimum, with its value as the
    floor (a full multistart's value is trusted)."""
    from optdesign.formulations.catalogue import search as catalogue

    seen = []

    def spy(ns, x_hint=None, floor=None):
        seen.append((x_hint, floor))
        return None, []

    monkeypatch.setattr(catalogue, "enumerate_catalogue", spy)
    r = solve_catalogue(_small(), method="enumerate", starts=2)
    ((x_hint, floor),) = seen
    info = r.details.catalogue
    assert floor == info.relaxation_bound
    assert x_hint.tolist() == [info.relaxation_design[n] for n in info.relaxation_design]
    # no combination found although the relaxation is feasible: a failed search, said so
    assert (r.status, r.formulation, r.design) == ("failed", "catalogue-enumerate", {})
    assert r.message == (
        "no catalogue combination gave a feasible design although the continuous "
        "relaxation is feasible (more starts may find one)"
    )
    assert math.isnan(r.objective) and info.enumerated == []


def test_auto_enumerates_up_to_sixteen_combinations_and_branches_above(monkeypatch):
    """2 x 8 = 16 combinations are enumerated, 2 x 9 = 18 searched by branch and bound."""
    calls = _spied_search(monkeypatch)
    eight = [f"{k} mm" for k in (4, 5, 6, 8, 10, 12, 16, 20)]
    r = solve_catalogue(_small(pins=eight), starts=1)
    assert r.formulation == "catalogue-enumerate" and r.details.catalogue.combinations == 16
    assert "bnb" not in calls
    r = solve_catalogue(_small(pins=[*eight, "25 mm"]), starts=1)
    assert r.formulation == "catalogue-bnb" and r.details.catalogue.combinations == 18
    assert "bnb" in calls


def test_branch_and_bound_gets_the_root_candidates_and_tie_rule_and_reports_its_counts(
    monkeypatch,
):
    """The search's counts land in the details field by field; the candidates, the tie
    rule and the memo reach it; the memo's proofs are the details' boxes."""
    stats = {"nodes": 11, "pruned": 12, "infeasible": 13, "leaves": 14, "seeded": 15}
    calls = _spied_search(monkeypatch, stats)
    memo = InfeasibleBoxes({"p": (5.0, 6.0)})
    memo.add_infeasible({"p": (9.0, 9.0)}, {"backlash": 1.0})
    cands = [{"p": 6.0}]
    r = solve_catalogue(_small(), method="bnb", starts=1, incumbents=cands, ties=False, memo=memo)
    ns, root, incumbents, ties = calls["bnb"]
    assert incumbents is cands and ties is False and ns.memo is memo and ns.proofs is memo
    info = r.details.catalogue
    assert root.objective == info.relaxation_bound
    assert (info.nodes, info.pruned, info.infeasible, info.leaves, info.seeded) == (
        11,
        12,
        13,
        14,
        15,
    )
    assert (info.warm_fallbacks, info.implied_infeasible) == (0, 0)
    assert info.infeasible_boxes == [({"p": (9.0, 9.0)}, {"backlash": 1.0})]
    assert info.nlp_solves == ns.n_solves == 1 and r.status == "failed"


def test_the_files_solver_settings_are_the_nodes_defaults(monkeypatch):
    """Without arguments a node takes the file's starts (at most 4), seed and agree."""
    calls = _spied_search(monkeypatch)
    solve_catalogue(_small(solver={"starts": 7, "seed": 3, "agree": 2}), method="enumerate")
    ns = calls["enumerate"]
    assert (ns.starts, ns.seed, ns.agree) == (4, 3, 2)
    solve_catalogue(_small(solver={"starts": 2, "seed": 1, "agree": 0}), method="enumerate")
    ns = calls["enumerate"]
    assert (ns.starts, ns.seed, ns.agree) == (2, 1, 0)
    r = solve_catalogue(
        _small(), method="enumerate", starts=3, seed=9, agree=1, objective="backlash"
    )
    ns = calls["enumerate"]
    assert (ns.starts, ns.seed, ns.agree, ns.objective) == (3, 9, 1, "backlash")
    assert r.details.catalogue.starts_per_node == 3
    # the caller's back-end and its options serve every node
    solve_catalogue(_small(), method="enumerate", starts=1, solver="sqpmethod", options={})
    assert calls["enumerate"].solver == "sqpmethod"


def test_a_node_implied_infeasible_by_the_memo_is_not_solved():
    """A box a stored proof covers: infeasible with the memo's reason and no NLP solve."""
    ns = NodeSolver(_small(), starts=2)
    ns.memo = InfeasibleBoxes({"p": (5.0, 6.0), "d": (5.0, 8.0)})
    ns.memo.add_infeasible({"p": (6.0, 6.0)}, {})
    r = ns.solve({"p": (6.0, 6.0), "d": (5.0, 6.0)})
    assert (r.status, r.formulation) == ("infeasible", "catalogue")
    assert r.message == "infeasible: a wider box was at looser limits"
    assert (ns.n_implied, ns.n_solves) == (1, 0)
    assert ns.solve({"p": (5.0, 5.0), "d": (6.0, 6.0)}).success and ns.n_implied == 1


def test_an_infeasible_node_is_one_proof_in_the_memo_or_the_searchs_own_record():
    """A node with no feasible start is recorded once: in the memo, and in the proofs
    when they are another record; freeing the failing requirement's rows makes it feasible."""
    weak = _small(pins=("4 mm", "5 mm"))
    box = {"p": (5.0, 5.0), "d": (4.0, 4.0)}
    full = {"p": (5.0, 6.0), "d": (4.0, 5.0)}
    ns = NodeSolver(weak, starts=2)
    ns.memo = ns.proofs = InfeasibleBoxes(full)
    r = ns.solve(box)
    assert not r.success and r.multistart.failed == {"locally infeasible": 2}
    assert (r.multistart.n_starts, r.multistart.n_converged) == (2, 0)
    assert ns.memo.proofs == [({"p": (5.0, 5.0), "d": (4.0, 4.0)}, {})]
    own = NodeSolver(weak, starts=2, eps={"backlash": 1.0})
    own.proofs = InfeasibleBoxes(full)
    assert not own.solve(box).success
    assert own.proofs.proofs == [({"p": (5.0, 5.0), "d": (4.0, 4.0)}, {"backlash": 1.0})]
    # the 4 mm pin fails on its bearing pressure alone: that requirement's rows left
    # unbounded (the diagnosis's search), the node is feasible
    rows = tuple(
        k for k, g in enumerate(own.nlp.g_names) if g.split("[", 1)[0] == "pin_bearing_pressure"
    )
    assert rows and NodeSolver(weak, starts=2, free_rows=rows).solve(box).success


def test_a_candidate_without_every_free_variable_is_not_solved():
    """A candidate holding the items but not a continuous variable gives no start: it is
    skipped, nothing solved or counted."""
    ns = QuadNodes({"a": (1.0, 2.0, 3.0)}, {"a": 2.0})
    ns.names = ["a", "z"]  # a continuous variable z besides the catalogue one
    stats = {"nodes": 0, "seeded": 0}
    assert first_incumbent(ns, [{"a": 2.0}], stats) == (None, None)
    assert stats == {"nodes": 0, "seeded": 0} and ns.calls == []
    assert _x_of_design(ns, {"a": 2.0, "z": 0.5}).tolist() == [2.0, 0.5]


def test_a_minlp_back_end_picks_the_items_and_the_default_nlp_solves_the_nodes(monkeypatch):
    """``solver="bonmin"`` under auto (or method minlp) hands bonmin and its options to
    the MINLP search; the nodes (relaxation, chosen items) take the default NLP back-end."""
    from optdesign.formulations.catalogue import minlp as catalogue_minlp

    seen = []

    def spy(ns, solver, options):
        seen.append((ns.solver, solver, options))
        return None, None

    monkeypatch.setattr(catalogue_minlp, "solve_minlp", spy)
    opts = {"bonmin.algorithm": "B-BB"}
    r = solve_catalogue(_small(), starts=1, solver="bonmin", options=opts)
    assert seen == [("ipopt", "bonmin", opts)]
    assert r.formulation == "catalogue-minlp" and r.details.catalogue.method == "minlp"
    r = solve_catalogue(_small(), method="minlp", starts=1)
    assert seen[-1] == ("ipopt", "bonmin", None) and r.status == "failed"


# A catalogue search on local workers (issue 25): each node's starts run on processes
# forked once for the search, and every node keeps its serial answer, so any number of
# workers gives the same nodes, values, records and optimum as one.


needs_fork = pytest.mark.skipif(not forks_workers(), reason="local workers are forked (Linux)")


def _slow_first(k: int) -> tuple[int, int]:
    time.sleep(0.3 if k == 0 else 0.0)
    return k * k, os.getpid()


@pytest.fixture(scope="module")
def bnb_problem():
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    return problem_from_dict(data)


@needs_fork
def test_kept_workers_give_the_serial_prefix_call_after_call():
    with InheritedWorkers(_slow_first, 2) as workers:
        pids = set()
        for _ in range(3):
            # item 0 is slow, so items 1.. finish first; the answer is still 0..3
            out = workers.map(list(range(8)), lambda done: sum(v >= 4 for v, _ in done) >= 2)
            assert [v for v, _ in out] == [0, 1, 4, 9]
            pids |= {pid for _, pid in out}
            assert not workers.pool.busy  # the items past the answer were waited for
        assert os.getpid() not in pids and len(pids) == 2  # the same two processes
        assert [v for v, _ in workers.map([5, 6])] == [25, 36]
    assert workers.pool is None


def test_one_worker_maps_here():
    with InheritedWorkers(_slow_first, 1) as workers:
        assert workers.pool is None
        assert workers.map([2, 3], lambda done: True) == [(4, os.getpid())]


@needs_fork
def test_a_search_on_two_workers_is_the_search_on_one(bnb_problem):
    # 4 starts, the file's agree of 3: a node stopped on agreement has run a 4th start on
    # the other worker, whose result is dropped
    one = solve_catalogue(bnb_problem, method="bnb", starts=4)
    two = solve_catalogue(bnb_problem, method="bnb", starts=4, workers=2)
    assert one.success and two.success
    assert two.objective == one.objective  # bit for bit: the same starts, the same order
    assert two.design == one.design
    a, b = one.details.catalogue, two.details.catalogue
    assert (b.nlp_solves, b.nodes, b.pruned, b.infeasible) == (
        a.nlp_solves,
        a.nodes,
        a.pruned,
        a.infeasible,
    )
    assert two.multistart.objectives == one.multistart.objectives
    assert a.infeasible_boxes == b.infeasible_boxes


def test_a_search_reads_the_proofs_it_is_given(bnb_problem):
    """A front's searches share one memo of infeasible boxes: a search given the proofs
    of an earlier one skips the boxes they cover (no NLP), with the same answer."""
    from optdesign.formulations.catalogue.bnb import InfeasibleBoxes
    from optdesign.formulations.catalogue.discrete import discrete_variables

    dvars = discrete_variables(bnb_problem)
    memo = InfeasibleBoxes(
        {v.name: (v.lower, v.upper) for v in dvars}, {v.name: v.values for v in dvars}
    )
    first = solve_catalogue(bnb_problem, method="bnb", starts=3, memo=memo)
    assert len(memo) > 0 and first.details.catalogue.implied_infeasible == 0
    again = solve_catalogue(bnb_problem, method="bnb", starts=3, memo=memo)
    assert again.details.catalogue.implied_infeasible > 0
    assert again.details.catalogue.nlp_solves < first.details.catalogue.nlp_solves
    assert again.objective == first.objective and again.design == first.design


def test_a_box_without_an_item_is_infeasible_without_a_solve_and_names_its_solver():
    import optdesign as od
    from optdesign.formulations.catalogue.search import NodeSolver

    ns = NodeSolver(od.load(ROOT / "problems" / "fin_actuator.toml"))
    # the catalogue's screws are d0 x lead pairs: it has no 14 mm screw of 2 mm lead
    none = ns.solve({"d0": (14.0, 14.0), "p": (2.0, 2.0)})
    assert (none.status, none.message) == ("infeasible", "no catalogue item in this box")
    assert none.solver == "ipopt" and ns.n_solves == 0


def test_a_node_solver_of_another_back_end_does_not_take_the_files_ipopt_options():
    """``[solver] ipopt = {...}`` are Ipopt's: a catalogue search on another NLP back-end
    (here CasADi's sqpmethod, which has no ``mu_strategy``) is built without them."""
    import copy

    from optdesign.formulations.catalogue.search import NodeSolver

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data = copy.deepcopy(data)
    data.setdefault("solver", {})["ipopt"] = {"mu_strategy": "monotone"}
    problem = problem_from_dict(data)
    assert NodeSolver(problem, solver="sqpmethod").solver == "sqpmethod"
    assert NodeSolver(problem).backend.name == "ipopt"


def test_a_node_solver_leaves_its_free_rows_unbounded():
    """The diagnosis of an infeasible catalogue problem solves nodes with one
    requirement's rows dropped (``free_rows``): both their bounds go."""
    import copy

    from optdesign.formulations.catalogue.search import NodeSolver

    data = tomllib.loads((ROOT / "problems" / "fin_actuator.toml").read_text())
    data = copy.deepcopy(data)
    data["requirements"]["nut_travel_max"] = "50 mm"  # an upper limit no design meets
    problem = problem_from_dict(data)
    items = {"d0": (25.0, 25.0), "p": (5.0, 5.0), "d": (6, 6)}
    assert not NodeSolver(problem, starts=1).solve(items).success
    rows = [i for i, n in enumerate(NodeSolver(problem).nlp.g_names) if n.startswith("nut_travel")]
    freed = NodeSolver(problem, starts=1, free_rows=tuple(rows)).solve(items)
    assert freed.success
    # its design meets every requirement but the dropped one, which it violates
    from optdesign.formulations.verify import verify_design

    x = np.array([freed.design[v.name] for v in problem.free])
    ok, violated, _ = verify_design(problem, x)
    assert not ok and {v.name.split("[")[0] for v in violated} == {"nut_travel"}


def test_a_node_multistart_stops_once_agree_starts_agree(bnb_problem):
    """As the problem's own multistart (``[solver] agree``, 3 by default): a node's
    starts stop once that many agree on the best value; the answer is the same as with
    every start (``agree=0``), with fewer NLP solves."""
    from optdesign.formulations.catalogue import search as catalogue

    nodes: list = []
    solve = catalogue.NodeSolver.solve

    def recorded(self, *a, **k):
        r = solve(self, *a, **k)
        nodes.append(r.multistart)
        return r

    catalogue.NodeSolver.solve = recorded
    try:
        every = solve_catalogue(bnb_problem, method="bnb", starts=4, agree=0)
        assert not any(m.stopped_early for m in nodes if m is not None and m.n_starts > 1)
        nodes.clear()
        agreed = solve_catalogue(bnb_problem, method="bnb", starts=4)
    finally:
        catalogue.NodeSolver.solve = solve
    assert bnb_problem.spec.solver.agree == 3
    assert agreed.objective == pytest.approx(every.objective, rel=1e-9)
    assert agreed.design == every.design
    assert agreed.details.catalogue.nlp_solves < every.details.catalogue.nlp_solves
    # the nodes stopped on agreement (not at a floor): three starts of the four planned
    stopped = [m for m in nodes if m is not None and m.stopped_early and m.n_at_best >= 3]
    assert stopped and all((m.n_starts, m.n_planned) == (3, 4) for m in stopped)


def test_a_search_that_finds_no_combination_says_whether_the_relaxation_was_feasible(
    bnb_problem, monkeypatch
):
    """No catalogue design from the search: "failed" (more starts may find one) when the
    continuous relaxation has a feasible design, "infeasible" only when it has none."""
    from optdesign.formulations.catalogue import search as catalogue

    stats = {"nodes": 1, "pruned": 0, "infeasible": 0, "leaves": 0, "seeded": 0}
    monkeypatch.setattr(catalogue, "branch_and_bound", lambda *a, **k: (None, stats))
    result = solve_catalogue(bnb_problem, method="bnb", starts=2)
    assert result.status == "failed" and not result.design
    assert result.message == (
        "no catalogue combination gave a feasible design although the continuous "
        "relaxation is feasible (more starts may find one)"
    )
    assert result.details.catalogue.relaxation_status == "optimal"


def test_a_single_search_reports_the_boxes_it_proved_infeasible(bnb_problem):
    """A search without a front's memo still records its own proofs (the optimum's
    neighbouring items read them, and ``details.catalogue.infeasible_boxes`` lists them)."""
    result = solve_catalogue(bnb_problem, method="bnb", starts=3)
    boxes = result.details.catalogue.infeasible_boxes
    assert boxes and all(isinstance(box, dict) and isinstance(eps, dict) for box, eps in boxes)
    assert all(set(box) <= {"p", "d"} for box, _ in boxes)


def test_a_failed_relaxation_is_said_so_beside_the_items_found(monkeypatch):
    """Enumeration solves every combination from its own starts, so a design can come
    out although the relaxation's starts failed: the note says the relaxation failed, and
    no bound is claimed."""
    import copy
    import math

    from optdesign.formulations.catalogue import search as catalogue
    from optdesign.solvers.result import Result

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data = copy.deepcopy(data)
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "6 mm", "8 mm"]}
    problem = problem_from_dict(data)
    solve = catalogue.NodeSolver.solve

    def root_fails(self, bounds, *a, **k):
        if not bounds:
            return Result(
                status="failed",
                objective=math.nan,
                design={},
                solver="ipopt",
                formulation="nlp",
                wall_time_s=0.0,
            )
        return solve(self, bounds, *a, **k)

    monkeypatch.setattr(catalogue.NodeSolver, "solve", root_fails)
    result = solve_catalogue(problem, method="enumerate", starts=2)
    assert result.success and result.bound is None
    note = next(n for n in result.notes if n.startswith("catalogue items chosen"))
    assert "; continuous relaxation: failed; enumerate," in note and "nan" not in note


PROBLEMS = ROOT / "problems"


# --- the catalogue relaxation takes the most favourable items of a box ---------------------
def _strongest_nuts() -> dict[tuple[float, float], dict[str, float]]:
    """(d0, p) -> the strongest nut of the catalogue's CSV (highest Ca, then C0a, then
    rigidity), read with the csv module; rigidity converted from N/um to N/mm."""
    path = ROOT / "optdesign" / "data" / "ball_screws.csv"
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(line for line in fh if not line.startswith("#")))
    best: dict[tuple[float, float], dict[str, float]] = {}
    for r in rows:
        item = {
            "d1": float(r["d1"]),
            "Ca": float(r["Ca"]),
            "C0a": float(r["C0a"]),
            "K_nut": 1000.0 * float(r["rigidity_N_per_um"]),
        }
        key = (float(r["d0"]), float(r["p"]))
        old = best.get(key)
        rank = (item["Ca"], item["C0a"], item["K_nut"])
        if old is None or rank > (old["Ca"], old["C0a"], old["K_nut"]):
            best[key] = item
    return best


# --- branch and bound: what may be pruned --------------------------------------------------
def test_prune_tolerance_is_relative_one_in_a_million():
    from optdesign.formulations.catalogue.search import PRUNE_TOL, cannot_improve

    assert PRUNE_TOL == pytest.approx(1e-6)
    incumbent = 2.0
    # a node whose bound is 0.1 % below the incumbent can still hold a better item
    assert not cannot_improve(incumbent * (1 - 1e-3), incumbent)
    assert not cannot_improve(incumbent * (1 - 1e-5), incumbent)
    assert cannot_improve(incumbent * (1 - 1e-7), incumbent)
    assert cannot_improve(incumbent * 1.01, incumbent)
    # negative objectives: the tolerance is relative to the magnitude
    assert not cannot_improve(-2.0 * (1 + 1e-4), -2.0)
    assert cannot_improve(-2.0 * (1 + 1e-7), -2.0)


def test_catalogue_relaxation_takes_the_most_favourable_items_of_the_box():
    problem = od.load(PROBLEMS / "fin_actuator.toml")
    box = {"d0": (16.0, 20.0), "p": (2.0, 5.0)}
    values = problem.parameter_values(box)
    items = [v for (d0, p), v in _strongest_nuts().items() if 16 <= d0 <= 20 and 2 <= p <= 5]
    assert len(items) >= 3  # several items: the choice of the value matters
    for key in ("d1", "Ca", "C0a", "K_nut"):
        column = [item[key] for item in items]
        assert max(column) > min(column), key
        assert values[f"screw_{key}"] == pytest.approx(max(column), rel=1e-12), key
    # a box holding one item gives that item's own values
    one = problem.parameter_values({"d0": (20.0, 20.0), "p": (5.0, 5.0)})
    item = _strongest_nuts()[(20.0, 5.0)]
    for key in ("d1", "Ca", "C0a", "K_nut"):
        assert one[f"screw_{key}"] == pytest.approx(item[key], rel=1e-12), key
    # the table-fit ratio of the pins: the smallest of the box's items (the smaller
    # clearance is the favourable one for a backlash bound)
    from optdesign.fits import clearance

    box_d = {"d": (5.0, 8.0)}
    pins = [v for v in problem.by_name["d"].values if 5.0 <= v <= 8.0]
    assert len(pins) >= 2
    fit = problem.spec.requirements.fit
    for which in ("max", "min"):
        ratios = [
            float(clearance(fit, D, which, values="table"))
            / float(clearance(fit, D, which, values="smooth"))
            for D in pins
        ]
        assert max(ratios) > min(ratios)
        got = problem.parameter_values(box_d)[f"fit_ratio_{which}"]
        assert got == pytest.approx(min(ratios), rel=1e-12), which


def _catalogue(leads, pins):
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": [f"{p} mm" for p in leads]}
    data["variables"]["d"] = {"values": [f"{d} mm" for d in pins]}
    return problem_from_dict(data)


@pytest.fixture(scope="module")
def enumerated_4x5():
    """4 leads x 5 pins and the enumeration of its 20 item pairs (two starts a node)."""
    problem = _catalogue((4, 5, 6, 8), (4, 5, 6, 8, 10))
    return problem, catalogue.solve_catalogue(problem, method="enumerate", starts=2)


# --- catalogue search -----------------------------------------------------------------
def test_relaxation_bound_without_a_bound_is_nan():
    assert math.isnan(relaxation_bound(SimpleNamespace(bound=None)))
    assert relaxation_bound(SimpleNamespace(bound=np.float64(0.25))) == 0.25


def test_is_on_catalogue_takes_only_the_items_themselves():
    problem = load(ROOT / "problems" / "fin_actuator.toml")
    variables = discrete_variables(problem)
    assert variables
    design = {v.name: float(v.values[0]) for v in variables}
    assert is_on_catalogue(problem, design)
    first = variables[0]
    nearly = dict(design, **{first.name: float(first.values[0]) * (1 + 1e-10)})
    assert not is_on_catalogue(problem, nearly)  # 1e-10 off an item is off the catalogue
    between = dict(design, **{first.name: float(first.values[0]) + 0.5})
    assert not is_on_catalogue(problem, between)


@pytest.mark.slow  # its fixture enumerates a 4 x 5 catalogue: 9-17 s
def test_branch_and_bound_counts_every_node_it_solves(monkeypatch, enumerated_4x5):
    """4 leads x 5 pins: branch and bound equals enumeration, and its counts are those of
    the node solves it made (counted here by a wrapper around the node solver), with
    sqpmethod trying the nodes' starts first and with Ipopt alone."""
    problem, enum = enumerated_4x5
    solves: list[bool] = []
    original = catalogue.NodeSolver.solve

    def counted(self, box, *args, **kwargs):
        result = original(self, box, *args, **kwargs)
        solves.append(bool(result.success))
        return result

    monkeypatch.setattr(catalogue.NodeSolver, "solve", counted)
    alone = catalogue.solve_catalogue(problem, method="bnb", starts=2, first_solver=False)
    info = alone.details.catalogue
    # the relaxation, 7 boxes of 20 item pairs, and the box whose warm bound (one start)
    # would prune it, solved again with the full multistart before it is pruned; every
    # box of several pairs on every other grid angle, the one leaf on the whole grid
    assert info.nodes == len(solves) == 9 and info.first_starts == 0
    assert info.infeasible == solves.count(False) == 2
    # the one leaf (p = 6, d = 6) prunes the one box left open when it was found
    assert (info.leaves, info.pruned) == (1, 1)
    solves.clear()
    bnb = catalogue.solve_catalogue(problem, method="bnb", starts=2)
    info = bnb.details.catalogue
    # with sqpmethod first the values differ in their last digits and the search takes
    # another path to the same answer (two nodes fewer, one more pruned); its phase 1
    # certifies the two infeasible boxes (two starts each)
    assert info.nodes == len(solves) == 7 and (info.leaves, info.pruned) == (1, 2)
    assert info.infeasible == solves.count(False) == 2
    assert info.first_certified == 4 and info.first_starts > info.first_failed == 4
    assert 0 < info.thinned_solves < info.nlp_solves
    assert info.relaxation_angles == 31 < len(problem.phi) == 61
    assert len(enum.details.catalogue.enumerated) == 20
    for found in (alone, bnb):
        assert found.objective == pytest.approx(enum.objective, rel=1e-9)
        assert found.details.catalogue.items == enum.details.catalogue.items == {"p": 6, "d": 6}


def test_the_catalogue_formulation_takes_the_callers_settings():
    """od.solve(..., "catalogue", objective=, starts=, options=) reaches the search."""
    problem = _catalogue((5, 6), (5, 6, 8))
    ripple = od.solve(problem, "catalogue", objective="ripple", starts=2, ranges=False)
    direct = catalogue.solve_catalogue(problem, objective="ripple", starts=2)
    assert ripple.objective == pytest.approx(direct.objective, rel=1e-9)
    assert ripple.details.catalogue.items == {"p": 5, "d": 8}  # not backlash's 6 / 6
    assert ripple.details.catalogue.starts_per_node == 2
    assert ripple.details.catalogue.method == "enumerate"
    # an iteration limit of 1 leaves even the relaxation unsolved: the options arrive
    starved = od.solve(problem, "catalogue", options={"max_iter": 1}, ranges=False, diagnose=False)
    assert starved.status == "infeasible"
    assert "relaxation has no feasible design" in starved.message


def test_a_catalogue_result_keeps_the_callers_seed_and_objective_even_when_infeasible():
    """The seed of a node's multistart is the caller's (the report prints it), and a
    search that finds nothing still names the objective it was asked for."""
    problem = _catalogue((5, 6), (5, 6, 8))
    assert problem.objective_names[0] == "backlash"
    seeded = od.solve(problem, "catalogue", objective="ripple", starts=2, seed=7, ranges=False)
    assert seeded.multistart.seed == 7 and seeded.objective_name == "ripple"
    starved = od.solve(
        problem, "catalogue", objective="ripple", options={"max_iter": 1}, ranges=False,
        diagnose=False,
    )  # fmt: skip
    assert starved.status == "infeasible" and starved.objective_name == "ripple"


@pytest.mark.slow  # the same enumerated 4 x 5 catalogue
def test_first_feasible_finds_a_feasible_catalogue_design_or_none(enumerated_4x5):
    """The diagnosis's depth-first search (reached only when no item combination near the
    relaxation works, so no other fast test calls it): a leaf on the catalogue whose
    design the independent check finds feasible; None when no item pair is feasible."""
    problem, enum = enumerated_4x5
    found = catalogue_bnb.first_feasible(catalogue.NodeSolver(problem, starts=2))
    assert found is not None and found.success
    assert is_on_catalogue(problem, found.design)
    x = np.array([found.design[v.name] for v in problem.free])
    assert verify_design(problem, x)[0]
    # the better child first: the leaf is no worse than the worst of the feasible items
    feasible = {
        (row.items["p"], row.items["d"]): row.objective
        for row in enum.details.catalogue.enumerated
        if row.status == "optimal"
    }
    items = (found.design["p"], found.design["d"])
    assert found.objective == pytest.approx(feasible[items], rel=1e-6)  # that item pair's optimum
    assert found.objective <= max(feasible.values())
    # pins of 4 mm only: too weak for the hinge moment whatever the lead (every pair fails)
    weak = _catalogue((4, 5, 6, 8), (4,))
    assert catalogue_bnb.first_feasible(catalogue.NodeSolver(weak, starts=2)) is None


def test_sqpmethod_nodes_after_failed_ones_solve_as_on_a_fresh_solver():
    """CasADi's sqpmethod starts each QP from qpOASES's last working set, across solves:
    after the failed starts of a box it cannot solve (d in [4, 5] mm), every start of a
    box it solves alone (d in [6, 25] mm) failed too, and the catalogue search with
    ``--solver sqpmethod`` found no design. Each solve now runs on a memory of its own
    (optdesign.solvers.casadi_nlp)."""
    from optdesign.formulations.catalogue.search import NodeSolver

    problem = od.load(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
    ns = NodeSolver(problem, "backlash", 4, 0, "sqpmethod", agree=3)
    failed = ns.solve({"p": (2.0, 10.0), "d": (4.0, 5.0)}, relaxed=True)
    after = ns.solve({"p": (2.0, 10.0), "d": (6.0, 25.0)}, relaxed=True)
    assert not failed.success and after.success
    # the box's least backlash on the thinned grid, as Ipopt and a fresh sqpmethod find it
    assert after.objective == pytest.approx(0.0340646215, rel=1e-8)
