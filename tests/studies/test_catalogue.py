"""Catalogue variables (issue 4): branch and bound vs enumeration, relaxation bound."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from optdesign.errors import ProblemError
from optdesign.problem import load_problem, problem_from_dict
from optdesign.studies.catalogue import is_on_catalogue, relaxation_bound, solve_catalogue

ROOT = Path(__file__).resolve().parents[2]
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
    assert relaxation_bound(bnb) == pytest.approx(RELAXED, rel=1e-5)
    assert relaxation_bound(bnb) < bnb.objective
    assert bnb.details.catalogue.items == {"p": 6, "d": 6}


def test_catalogue_problem_is_never_solved_as_continuous():
    import optdesign as od
    from optdesign.studies.formulation_registry import choose_formulation

    problem = load_problem(CATALOGUE)
    assert choose_formulation(problem, "auto") == "catalogue"
    with pytest.raises(ProblemError, match="catalogue values"):
        od.solve(problem, "nlp", starts=1)
    with pytest.raises(ProblemError, match=r"variable p: .*catalogue"):
        od.solve(problem, "gp", starts=1)


def test_node_solver_ipopt_options_file_wins_over_node_defaults():
    # Nodes enter Ipopt's restoration phase early (many boxes are infeasible); a problem
    # file's own [solver] ipopt options still decide, and a caller's override both.
    from optdesign.solvers.registry import solver_hints
    from optdesign.studies.catalogue import NodeSolver

    assert solver_hints("ipopt").node_options["expect_infeasible_problem"] == "yes"
    default = NodeSolver(_small_catalogue())
    assert default.backend.options["ipopt"]["expect_infeasible_problem"] == "yes"
    data = tomllib.loads(CATALOGUE.read_text())
    data["solver"] = {"ipopt": {"expect_infeasible_problem": "no"}}
    own = NodeSolver(problem_from_dict(data))
    assert own.backend.options["ipopt"]["expect_infeasible_problem"] == "no"
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
    """Ipopt's own verdict on every start decides the node: 2 starts, no retries; a
    start stopped by its iteration limit, or a single start, still gets the
    RETRY_STARTS retries."""
    from optdesign.studies.catalogue import RETRY_STARTS, NodeSolver

    box = {"p": (5.0, 5.0), "d": (4.0, 4.0)}
    ns = NodeSolver(_weak_pins(), starts=2)
    r = ns.solve(box)
    assert r.status == "infeasible"
    assert r.multistart.outcomes == ["locally infeasible"] * 2
    assert ns.n_solves == r.multistart.n_starts == 2
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
    assert r.status == "infeasible" and four.n_solves == r.multistart.n_starts == 2
    assert r.multistart.n_planned == 4


def test_a_start_that_reaches_the_nodes_floor_settles_it():
    """A floor (the parent's trusted value) no start can go below: the start that reaches
    it ends the multistart; one it cannot reach leaves the full multistart."""
    from optdesign.studies.catalogue import NodeSolver
    from optdesign.studies.catalogue_bnb import trusted

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
    from optdesign.studies.catalogue import NodeSolver
    from optdesign.studies.catalogue_bnb import InfeasibleBoxes

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
    from optdesign.studies.catalogue_bnb import InfeasibleBoxes

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

    from optdesign.solvers.result import MultistartInfo, Result
    from optdesign.studies.catalogue_bnb import PRUNE_TOL, InfeasibleBoxes, _bound_proof

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
    from optdesign.studies import catalogue_bnb

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
    from optdesign.studies.catalogue import solve_catalogue

    problem = od.load(Path(__file__).resolve().parents[2] / "problems" / "cs_min_backlash.toml")
    message = "formulation='catalogue': no variable takes catalogue values"
    for call in (lambda: od.solve(problem, "catalogue"), lambda: solve_catalogue(problem)):
        with pytest.raises(ProblemError) as refused:
            call()
        assert str(refused.value) == message
