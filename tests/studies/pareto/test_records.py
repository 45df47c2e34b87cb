"""A front's stored records (studies/pareto/records.py), pinned function by function.

The JSON form of a record and of its warm start (key order, sparse vectors, None for
non-finite numbers), the record a solve's result becomes (the epsilon bounds checked
again, the rows it names) and the trust of a stored record: every field's type check
and every check of a design on both sides of its tolerance, each refusal's message.
The crank-slider design used is feasible (checked here on the NumPy path); the bounds
and catalogue checks at their edges run on a stand-in problem whose independent check
always passes, so only the check under test can refuse.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import optdesign as od
from optdesign.formulations.verify import verify_design
from optdesign.problem import load_problem
from optdesign.solvers.result import ConstraintReport, Result
from optdesign.storage import StoreError
from optdesign.studies.pareto import (
    PointRecord,
    records,
)
from optdesign.studies.pareto.records import (
    BOUNDS_RTOL,
    RECHECK_RTOL,
    AnchorStarts,
    RawSolution,
    json_vector,
    record_from_result,
    record_problem,
    vector,
)

PROBLEMS = Path(__file__).resolve().parents[3] / "problems"
#: A feasible design of cs_min_backlash (R, l, n, p, phi0, d), inside every requirement.
X_OK = [100.0, 60.0, 100.0, 5.0, 0.2, 7.0]


@pytest.fixture(scope="module")
def cs():
    return load_problem(PROBLEMS / "cs_min_backlash.toml")


@pytest.fixture(scope="module")
def good(cs):
    """A stored record of the feasible design, as a front writes it."""
    ok, violated, objectives = verify_design(cs, np.array(X_OK))
    assert ok and not violated
    design = {**cs.fixed_values, **dict(zip([v.name for v in cs.free], X_OK, strict=True))}
    return PointRecord(
        id="eps-0001",
        kind="eps",
        target="size",
        status="optimal",
        verified=True,
        x=list(X_OK),
        design=design,
        objectives={k: float(v) for k, v in objectives.items()},
        eps={"backlash": 0.05},
    ).to_dict()


# --- JSON forms ---------------------------------------------------------------------------
def test_a_warm_start_round_trips_with_its_four_keys_and_its_fingerprint_as_text():
    raw = RawSolution(np.array([1.0, 2.0]), np.zeros(4), np.array([0.0, -3.5, 0.0]), "nlp-a")
    d = raw.to_dict()
    assert d == {
        "z": [1.0, 2.0],
        "lam_x": {"size": 4, "index": [], "value": []},
        "lam_g": {"size": 3, "index": [1], "value": [-3.5]},
        "nlp": "nlp-a",
    }
    back = RawSolution.from_dict({**d, "nlp": 17})
    assert back.nlp == "17"
    assert back.z.tolist() == [1.0, 2.0]
    assert back.lam_x.tolist() == [0.0] * 4
    assert back.lam_g.tolist() == [0.0, -3.5, 0.0]


def test_json_vector_is_sparse_only_when_fewer_than_half_the_entries_are_nonzero():
    assert json_vector([0.0, 1.0, 0.0, 2.0]) == [0.0, 1.0, 0.0, 2.0]  # 2 of 4: dense
    assert json_vector([0.0, 1.0, 0.0, 0.0]) == {"size": 4, "index": [1], "value": [1.0]}
    assert json_vector(np.array([[0.0, 0.0], [0.0, math.inf]])) == {
        "size": 4,
        "index": [3],
        "value": [None],
    }
    assert json_vector([math.nan, 1.0]) == [None, 1.0]
    assert json_vector([]) == []


def test_vector_reads_both_forms_with_none_as_nan():
    a = vector({"size": 5, "index": [0, 3], "value": [2.5, None]})
    assert a[[0, 1, 2, 4]].tolist() == [2.5, 0.0, 0.0, 0.0] and math.isnan(a[3])
    b = vector([1.0, None, -2.0])
    assert b[0] == 1.0 and math.isnan(b[1]) and b[2] == -2.0
    assert b.dtype == float and a.dtype == float


def test_a_records_json_keeps_the_stores_key_order_and_its_nested_records():
    rec = PointRecord(
        id="anchor-size",
        kind="anchor",
        target="size",
        status="optimal",
        verified=True,
        objectives={"size": 160.0, "ripple": math.nan},
        raw=RawSolution(np.array([1.0]), np.array([0.5]), np.array([0.0, 0.0, 2.0]), "f"),
        multistart=AnchorStarts(n_starts=3, n_planned=5, n_at_best=2, agree=2, stopped_early=True),
        slope=-1.5,
    )
    d = rec.to_dict()
    assert list(d) == [
        *PointRecord.KEYS,
        "fallback",
        "order",
        "n_solves",
        "slope",
        "warm",
        "retried",
        "raw",
        "multistart",
    ]
    assert d["objectives"] == {"size": 160.0, "ripple": None}
    assert d["raw"] == {
        "z": [1.0],
        "lam_x": [0.5],
        "lam_g": {"size": 3, "index": [2], "value": [2.0]},
        "nlp": "f",
    }
    assert d["multistart"] == {
        "n_starts": 3,
        "n_planned": 5,
        "n_at_best": 2,
        "agree": 2,
        "stopped_early": True,
        "optima": 0,
        "counted": 0,
        "p_better": None,
        "stop": "",
    }
    back = PointRecord.from_dict(d)
    assert back.multistart == rec.multistart
    assert back.raw.nlp == "f" and back.raw.lam_g.tolist() == [0.0, 0.0, 2.0]
    assert back.slope == -1.5 and back.objectives["size"] == 160.0
    assert math.isnan(back.objectives["ripple"])
    bare = PointRecord(id="p", kind="eps", target="a", status="failed").to_dict()
    assert bare["raw"] is None and bare["multistart"] is None


def test_a_record_read_back_takes_none_as_nan_in_every_table_and_ignores_other_keys():
    d = PointRecord(id="p", kind="eps", target="a", status="failed").to_dict()
    d.update(
        design={"R": None, "l": 2.0},
        objectives={"size": None},
        eps={"backlash": None},
        weights={"size": None},
        future_field=1,
    )
    rec = PointRecord.from_dict(d)
    for table in (rec.design, rec.objectives, rec.eps, rec.weights):
        assert all(math.isnan(v) for k, v in table.items() if k != "l")
    assert rec.design["l"] == 2.0
    del d["eps"], d["weights"]
    rec = PointRecord.from_dict(d)
    assert rec.eps == {} and rec.weights == {} and rec.raw is None and rec.multistart is None


# --- a solve's result as a record --------------------------------------------------------
def _result(cs, **more) -> Result:
    return Result(
        status="optimal",
        objective=160.0,
        formulation="nlp",
        solver="ipopt",
        design=dict(zip([v.name for v in cs.free], X_OK, strict=True)),
        **more,
    )


def test_a_result_becomes_a_checked_record_with_its_sorted_active_rows_and_warm_start(cs):
    rows = [
        ConstraintReport(name=n, value=0.0, lower=0.0, upper=None, amount=0.0)
        for n in ("b[2]", "a_envelope[1]", "b[10]", "a2", "a[1]", "ab[0]")
    ]
    raw = {"z": [1, 2], "lam_x": [0, 0], "lam_g": [0.5]}
    rec = record_from_result(
        cs,
        _result(cs, active=rows, raw=raw),
        "eps",
        "size",
        {"backlash": 0.05, "ripple": math.inf},
        "eps-0003",
        "fp",
    )
    assert rec.status == "optimal" and rec.verified is True and rec.success
    assert (rec.id, rec.kind, rec.target) == ("eps-0003", "eps", "size")
    assert rec.x == X_OK
    assert rec.design == {
        **cs.fixed_values,
        **dict(zip("R l n p phi0 d".split(), X_OK, strict=True)),
    }
    assert rec.objectives["size"] == pytest.approx(160.0)
    assert rec.eps == {"backlash": 0.05}  # the infinite bound is no bound
    # sorted by the row's base name (a before a2, unlike the plain text order), then
    # the whole name; envelopes left out
    assert rec.active == ["a[1]", "a2", "ab[0]", "b[10]", "b[2]"]
    assert rec.raw.nlp == "fp"
    assert rec.raw.z.tolist() == [1.0, 2.0] and rec.raw.z.dtype == float
    assert rec.raw.lam_x.tolist() == [0.0, 0.0] and rec.raw.lam_g.tolist() == [0.5]
    assert rec.fallback == ""
    # no fingerprint: no warm start kept (it could not be matched to a formulation)
    assert record_from_result(cs, _result(cs, raw=raw), "eps", "size", {}).raw is None
    assert record_from_result(cs, _result(cs), "eps", "size", {}, "e", "fp").raw is None


def test_a_result_above_its_epsilon_bound_is_recorded_infeasible(cs):
    backlash = verify_design(cs, np.array(X_OK))[2]["backlash"]
    at = record_from_result(cs, _result(cs), "eps", "size", {"backlash": backlash})
    assert at.status == "optimal" and at.verified is True
    # just inside the relative tolerance (1e-6 of max(1, bound)) and just outside it
    inside = record_from_result(cs, _result(cs), "eps", "size", {"backlash": backlash - 9e-7})
    assert inside.status == "optimal" and inside.verified is True
    above = record_from_result(cs, _result(cs), "eps", "size", {"backlash": backlash - 2e-6})
    assert above.status == "infeasible" and above.verified is False and not above.success
    assert above.eps == {"backlash": backlash - 2e-6}


def test_a_result_keeps_why_it_fell_back_and_loses_a_success_the_check_refuses(cs):
    from optdesign.solvers.details import Details

    result = _result(cs, details=Details(fallback="slsqp failed: ipopt"))
    assert record_from_result(cs, result, "eps", "size", {}).fallback == "slsqp failed: ipopt"
    bad = _result(cs)
    bad.design["d"] = 4.5  # the pins too thin: a requirement violated
    rec = record_from_result(cs, bad, "eps", "size", {})
    assert rec.status == "infeasible" and rec.verified is False and not rec.success
    assert rec.violated and rec.x == [*X_OK[:5], 4.5]


def test_a_result_without_a_design_keeps_its_status_and_no_x(cs):
    failed = Result(status="failed", objective=math.nan, formulation="nlp", solver="ipopt")
    rec = record_from_result(cs, failed, "anchor", "size", {"backlash": 0.01}, "a")
    assert rec.status == "failed" and rec.x is None and rec.design == {}
    assert rec.eps == {"backlash": 0.01}


# --- trusting a stored record: its shape ---------------------------------------------------
@pytest.mark.parametrize(
    "change, why",
    [
        ({"kind": None}, "has no text field 'kind'"),
        ({"status": 3}, "has no text field 'status'"),
        ({"target": ["a"]}, "has no text field 'target'"),
        ({"message": 1}, "field 'message' is not text"),
        ({"solver": None}, "field 'solver' is not text"),
        ({"fallback": 0}, "field 'fallback' is not text"),
        ({"retried": False}, "field 'retried' is not text"),
        ({"verified": "yes"}, "field 'verified' is not true, false or null"),
        ({"verified": 1.5}, "field 'verified' is not true, false or null"),
        ({"design": [1.0]}, "field 'design' is not a table of numbers"),
        ({"objectives": {"size": "1"}}, "field 'objectives' is not a table of numbers"),
        ({"eps": {"size": True}}, "field 'eps' is not a table of numbers"),
        ({"weights": "w"}, "field 'weights' is not a table of numbers"),
        ({"active": "a"}, "field 'active' is not a list of names"),
        ({"order": [None]}, "field 'order' is not a list of names"),
        ({"x": {"R": 1.0}}, "field 'x' is not a list of numbers"),
        ({"x": [1.0, "2"]}, "field 'x' is not a list of numbers"),
        ({"x": [True]}, "field 'x' is not a list of numbers"),
        ({"wall_time_s": None}, "field 'wall_time_s' has a value of the wrong type (None)"),
        ({"n_solves": -1}, "field 'n_solves' has a value of the wrong type (-1)"),
        ({"n_solves": True}, "field 'n_solves' has a value of the wrong type (True)"),
        ({"n_solves": 2.0}, "field 'n_solves' has a value of the wrong type (2.0)"),
        ({"iterations": 1.0}, "field 'iterations' has a value of the wrong type (1.0)"),
        ({"iterations": False}, "field 'iterations' has a value of the wrong type (False)"),
        ({"slope": "1"}, "field 'slope' has a value of the wrong type ('1')"),
        ({"warm": 3}, "field 'warm' has a value of the wrong type (3)"),
        (
            {"iterations": "x" * 60},
            "field 'iterations' has a value of the wrong type ('" + "x" * 39 + ")",
        ),
        ({"raw": [1.0]}, "field 'raw' is not a solution with its multipliers"),
        ({"multistart": {"n_starts": 1}}, "field 'multistart' is not a multistart record"),
    ],
)
def test_a_stored_record_of_the_wrong_shape_names_the_field(cs, change, why):
    record = PointRecord(id="p", kind="eps", target="size", status="failed").to_dict()
    assert record_problem(cs, record) is None
    assert record_problem(cs, {**record, **change}) == why


def test_a_stored_record_may_leave_out_every_optional_field(cs):
    record = {"id": "p", "kind": "eps", "status": "failed", "target": "size"}
    assert record_problem(cs, record) is None
    ok = {
        "verified": None,
        "x": [1.0, None, 2],
        "design": {"R": None, "l": 3},
        "n_solves": 0,
        "iterations": None,
        "slope": None,
        "warm": None,
        "wall_time_s": 2,
        "multistart": None,
        "raw": None,
    }
    assert record_problem(cs, {**record, **ok}) is None
    assert record_problem(cs, {**record, "iterations": 7, "slope": 0, "warm": "w"}) is None


def _raw(**vectors):
    base = {"z": [1.0], "lam_x": [0.0], "lam_g": [], "nlp": "f"}
    return {**base, **vectors}


@pytest.mark.parametrize(
    "raw, ok",
    [
        (_raw(), True),
        (_raw(z={"size": 3, "index": [0, 2], "value": [1.0, None]}), True),
        (_raw(lam_g={"size": 2, "index": [], "value": []}), True),
        (_raw(nlp=None), False),
        (_raw(z=None), False),
        (_raw(lam_x=["a"]), False),
        (_raw(lam_g={"size": 2.0, "index": [], "value": []}), False),
        (_raw(z={"size": 3, "index": (0,), "value": [1.0]}), False),
        (_raw(z={"size": 3, "index": [0], "value": (1.0,)}), False),
        (_raw(z={"size": 3, "index": [0, 1], "value": [1.0]}), False),
        (_raw(z={"size": 3, "index": [3], "value": [1.0]}), False),
        (_raw(z={"size": 3, "index": [-1], "value": [1.0]}), False),
        (_raw(z={"size": 3, "index": [1.0], "value": [1.0]}), False),
        (_raw(z={"size": 3, "index": [2], "value": ["1"]}), False),
    ],
)
def test_a_stored_warm_start_must_be_vectors_with_a_fingerprint(cs, raw, ok):
    record = PointRecord(id="p", kind="eps", target="size", status="failed").to_dict()
    why = record_problem(cs, {**record, "raw": raw})
    assert why == (None if ok else "field 'raw' is not a solution with its multipliers")


def test_a_stored_warm_start_of_this_formulation_must_have_its_size_and_be_finite(cs):
    nlp = SimpleNamespace(fingerprint="f", lbz=np.zeros(2))
    record = PointRecord(id="p", kind="eps", target="size", status="failed").to_dict()

    def why(**vectors):
        return record_problem(cs, {**record, "raw": _raw(**vectors)}, nlp)

    assert why(z=[1.0, 2.0], lam_x=[0.0, 0.0]) is None
    assert why(z=[1.0], lam_x=[0.0, 0.0]) == "holds a warm start of the wrong size"
    assert why(z=[1.0, 2.0], lam_x=[0.0]) == "holds a warm start of the wrong size"
    assert why(z=[1.0, None], lam_x=[0.0, 0.0]) == "holds a warm start that is not finite"
    # another formulation's warm start is never used, so never checked against this one
    assert why(z=[1.0], lam_x=[0.0], nlp="g") is None
    assert record_problem(cs, {**record, "raw": _raw(z=[1.0])}) is None  # no formulation


# --- trusting a stored record: its design ---------------------------------------------------
def test_a_stored_solution_is_trusted_only_with_its_independent_check(cs, good):
    assert record_problem(cs, good) is None
    assert record_problem(cs, {**good, "status": "feasible"}) is None
    assert record_problem(cs, {**good, "verified": None}) == (
        "has status 'optimal' without the independent check"
    )
    # refused by the check or not a solution: shown as failed, never read as a design
    assert record_problem(cs, {**good, "verified": False, "design": {}}) is None
    assert record_problem(cs, {**good, "status": "infeasible", "design": {}}) is None


def test_a_stored_solution_needs_every_free_variable(cs, good):
    design = {k: v for k, v in good["design"].items() if k not in ("l", "d")}
    assert record_problem(cs, {**good, "design": design}) == "has no value of l in its design"


def test_a_stored_fixed_variable_must_be_the_problems_to_twelve_digits(cs, good):
    def with_i_a(value):
        return {**good, "design": {**good["design"], "i_a": value}}

    assert record_problem(cs, with_i_a(2.0 * (1 + 1e-13))) is None
    assert record_problem(cs, with_i_a(2.0000000001)) == (
        "has the fixed variable i_a = 2.0000000001, the problem 2.0"
    )
    design = {k: v for k, v in good["design"].items() if k != "pin_length_ratio"}
    assert record_problem(cs, {**good, "design": design}) is None  # absent: the problem's


def test_a_stored_x_must_be_its_design(cs, good):
    assert record_problem(cs, {**good, "x": None}) is None
    assert record_problem(cs, {**good, "x": [*X_OK[:5], X_OK[5] * (1 + 1e-13)]}) is None
    assert record_problem(cs, {**good, "x": [*X_OK[:5], X_OK[5] * (1 + 1e-11)]}) == (
        "has an 'x' that is not its design"
    )
    assert record_problem(cs, {**good, "x": X_OK[:5]}) == "has an 'x' that is not its design"
    near_zero = {**good, "design": {**good["design"], "n": 0.0}, "x": X_OK}
    near_zero["x"] = [100.0, 60.0, 1e-30, 5.0, 0.2, 7.0]
    # no absolute tolerance: a design variable at 0 stored as 1e-30 in x is not its design
    assert record_problem(cs, near_zero) == "has an 'x' that is not its design"


def test_a_stored_objective_must_be_finite_and_equal_its_recomputation(cs, good):
    objectives = good["objectives"]
    size = objectives["size"]

    def with_size(value):
        return {**good, "objectives": {**objectives, "size": value}}

    assert record_problem(cs, with_size(None)) == "has objective size = nan"
    assert record_problem(cs, with_size(size * (1 + 0.5 * RECHECK_RTOL))) is None
    assert record_problem(cs, with_size(size * (1 - 0.5 * RECHECK_RTOL))) is None
    wrong = size * (1 + 2 * RECHECK_RTOL)
    assert record_problem(cs, with_size(wrong)) == (
        f"has objective size = {wrong:.10g}, but its design gives {size:.10g}"
    )
    lower = size * (1 - 2 * RECHECK_RTOL)
    assert record_problem(cs, with_size(lower)) == (
        f"has objective size = {lower:.10g}, but its design gives {size:.10g}"
    )
    less = {k: v for k, v in objectives.items() if k != "backlash"}
    assert record_problem(cs, {**good, "objectives": less}) == (
        "has no value of objective backlash"
    )


def test_a_stored_design_that_violates_a_requirement_names_it(cs, good):
    design = {**good["design"], "d": 4.5}
    x = [*X_OK[:5], 4.5]
    ok, violated, _ = verify_design(cs, np.array(x))
    assert not ok
    assert record_problem(cs, {**good, "design": design, "x": x}) == (
        f"has a design that violates {violated[0].describe()}"
    )


def test_a_stored_point_must_meet_its_epsilon_bounds(cs, good):
    backlash = good["objectives"]["backlash"]
    assert record_problem(cs, {**good, "eps": {"backlash": backlash - 9e-7}}) is None
    bound = backlash - 2e-6
    assert record_problem(cs, {**good, "eps": {"backlash": bound}}) == (
        f"has objective backlash above its epsilon bound {bound:.10g}"
    )
    # a bound on a name that is no objective of the problem is not checked
    assert record_problem(cs, {**good, "eps": {"no_such": -1.0}}) is None


class _Var:
    def __init__(self, name, values=()):
        self.name, self.unit, self.values, self.discrete = name, "mm", values, bool(values)


class _Stand:
    """A problem of two free variables, a in [0, 10] and c of catalogue values in
    [1, 5] (bounds tolerances 1e-8 and 4e-9), and one fixed variable."""

    def __init__(self):
        self.free = [_Var("a"), _Var("c", (1.0, 2.5, 5.0))]
        self.fixed_values = {"k": 3.0}

    def lower(self):
        return np.array([0.0, 1.0])

    def upper(self):
        return np.array([10.0, 5.0])


@pytest.fixture
def stand(monkeypatch):
    """The stand-in problem, its independent check passing at any design."""
    monkeypatch.setattr(records, "verify_design", lambda problem, x: (True, [], {"f": 1.0}))
    return _Stand()


def _solution(**design):
    return PointRecord(
        id="p",
        kind="eps",
        target="f",
        status="optimal",
        verified=True,
        design=design,
        objectives={"f": 1.0},
    ).to_dict()


def test_a_stored_design_may_lie_outside_its_bounds_by_their_tolerance_only(stand):
    tol_a = BOUNDS_RTOL * 10.0  # span 10
    tol_c = BOUNDS_RTOL * 4.0  # span 4
    assert record_problem(stand, _solution(a=10.0 + 0.9 * tol_a, c=2.5)) is None
    assert record_problem(stand, _solution(a=-0.9 * tol_a, c=2.5)) is None
    assert record_problem(stand, _solution(a=10.0 + 1.1 * tol_a, c=2.5)) == (
        "has a = 10.00000001 mm, outside its bounds [0, 10]"
    )
    assert record_problem(stand, _solution(a=-1.1 * tol_a, c=2.5)) == (
        "has a = -1.1e-08 mm, outside its bounds [0, 10]"
    )
    assert record_problem(stand, _solution(a=1.0, c=5.0 + 0.9 * tol_c)) is None
    assert record_problem(stand, _solution(a=1.0, c=5.0 + 1.1 * tol_c)) == (
        "has c = 5.000000004 mm, outside its bounds [1, 5]"
    )
    assert record_problem(stand, _solution(a=None, c=2.5)) == (
        "has a = nan mm, outside its bounds [0, 10]"
    )


def test_a_narrow_variables_bounds_tolerance_is_relative_to_one():
    stand = _Stand()
    stand.free = [_Var("a")]
    stand.lower = lambda: np.array([0.0])
    stand.upper = lambda: np.array([1e-3])
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(records, "verify_design", lambda problem, x: (True, [], {"f": 1.0}))
        assert record_problem(stand, _solution(a=1e-3 + 0.9e-9)) is None
        assert record_problem(stand, _solution(a=1e-3 + 1.1e-9)) == (
            "has a = 0.0010000011 mm, outside its bounds [0, 0.001]"
        )


def test_a_stored_catalogue_variable_must_be_on_an_item(stand):
    tol_c = BOUNDS_RTOL * 4.0
    assert record_problem(stand, _solution(a=1.0, c=2.5 + 0.9 * tol_c)) is None
    assert record_problem(stand, _solution(a=1.0, c=2.5 - 0.9 * tol_c)) is None
    assert record_problem(stand, _solution(a=1.0, c=2.5 + 1.1 * tol_c)) == (
        "has c = 2.500000004 mm, not one of its catalogue values"
    )
    assert record_problem(stand, _solution(a=1.0, c=3.0)) == (
        "has c = 3 mm, not one of its catalogue values"
    )
    # a continuous variable between two of the catalogue's values is fine
    assert record_problem(stand, _solution(a=2.5 + 0.5, c=1.0)) is None


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


def _resume_weighted(problem, out, points=3, starts=1):
    return od.pareto(
        problem,
        ["backlash", "size"],
        points,
        method="weighted_sum",
        starts=starts,
        out=out,
        resume=True,
    )


@pytest.mark.parametrize("status", [None, "failed"])
def test_a_stored_record_whose_verified_flag_is_not_a_boolean_refuses_the_resume(
    weighted_run, tmp_path, status
):
    """A record's ``verified`` is true, false or null; anything else refuses the resume,
    a failed record's too (a failed record is otherwise not checked further)."""
    problem, finished, _ = weighted_run
    out = shutil.copytree(finished, tmp_path / "out")
    store = out / "weighted_sum.jsonl"
    lines = [json.loads(x) for x in store.read_text().splitlines()]
    k = next(k for k, r in enumerate(lines) if k and r.get("verified") is True)
    lines[k]["verified"] = "yes"
    if status is not None:
        lines[k]["status"] = status
    store.write_text("".join(json.dumps(x) + "\n" for x in lines))
    with pytest.raises(StoreError, match=f"line {k + 1}: record") as caught:
        _resume_weighted(problem, out)
    assert "field 'verified' is not true, false or null" in str(caught.value)


@pytest.fixture(scope="module")
def cs_min_backlash():
    return od.load(ROOT / "problems" / "cs_min_backlash.toml")


# --- stored records -----------------------------------------------------------------------
def test_a_stored_anchor_whose_multistart_is_not_a_multistart_record_is_not_trusted(
    cs_min_backlash,
):
    """A stored record's ``multistart`` is null or the anchor's multistart record (every
    field); anything else is named as the reason the record cannot be trusted."""
    record = PointRecord(
        id="anchor-backlash-ms",
        kind="anchor-multistart",
        target="backlash",
        status="failed",
        multistart=AnchorStarts(
            n_starts=2, n_planned=2, n_at_best=0, agree=None, stopped_early=False
        ),
    ).to_dict()
    assert record_problem(cs_min_backlash, record) is None
    for broken in ({"n_starts": 2}, [2, 2, 0, None, False], "2 starts"):
        why = record_problem(cs_min_backlash, {**record, "multistart": broken})
        assert why == "field 'multistart' is not a multistart record"


def test_a_stored_record_whose_lists_are_not_lists_of_names_is_not_trusted(cs_min_backlash):
    """A stored record's ``active``, ``violated`` and ``order`` are lists of names; a
    number among them is named as the reason the record cannot be trusted."""
    record = PointRecord(
        id="epsilon-0001", kind="eps", target="size", status="failed", active=["backlash"]
    ).to_dict()
    assert record_problem(cs_min_backlash, record) is None
    for name in ("active", "violated", "order"):
        why = record_problem(cs_min_backlash, {**record, name: ["backlash", 5]})
        assert why == f"field {name!r} is not a list of names"


def test_a_failed_points_record_keeps_the_names_of_its_first_twenty_violated_rows(
    cs_min_backlash,
):
    """A front's record names at most 20 violated rows (the first ones, in the
    solver's order): a point violating a whole grid does not fill the store."""
    import math

    from optdesign.solvers.result import ConstraintReport, Result
    from optdesign.studies.pareto.records import record_from_result

    rows = [
        ConstraintReport(name=f"deflection[{i}]", value=1.0, lower=None, upper=0.5, amount=0.5)
        for i in range(25)
    ]
    result = Result(
        status="infeasible", solver="ipopt", objective=math.nan, formulation="nlp", violated=rows
    )
    rec = record_from_result(cs_min_backlash, result, "eps", "size", {"backlash": 0.01}, "e-1")
    assert rec.violated == [f"deflection[{i}]" for i in range(20)]
    assert not rec.success


def test_a_sparse_vector_round_trips_exactly_through_the_store():
    """Warm starts are stored as sparse vectors when most entries are zero (inactive
    multipliers): the nonzero entries with their indices - a 1.0 (a scaled variable at
    its upper bound) among them - and every value comes back bit for bit."""
    from optdesign.studies.pareto.records import json_vector, vector

    v = np.zeros(10)
    v[3], v[6] = 1.0, -2.5
    stored = json_vector(v)
    assert stored == {"size": 10, "index": [3, 6], "value": [1.0, -2.5]}
    assert vector(stored).tolist() == v.tolist()
    dense = np.array([1.0, 0.0, 1e-300, np.inf])
    assert json_vector(dense) == [1.0, 0.0, 1e-300, None]
    assert vector(json_vector(dense))[:3].tolist() == [1.0, 0.0, 1e-300]
