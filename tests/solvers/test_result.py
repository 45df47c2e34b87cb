"""One solved-point record, one success rule, typed details written as result files have
always had them (optdesign/solvers/solved_point.py, result.py, details.py;
studies/pareto/records.py, front.py)."""

import itertools
import json
import math

import pytest

from optdesign.formulations.catalogue.details import CatalogueCombination, CatalogueDetails
from optdesign.formulations.gp.details import GPDetails
from optdesign.formulations.robust.details import NominalOptimum, RobustDetails
from optdesign.solvers.details import Details, GPTiming
from optdesign.solvers.result import ConstraintReport, Result
from optdesign.solvers.solved_point import SHARED_FIELDS, SolvedPoint, is_success, shared_fields
from optdesign.studies.pareto.front import FrontPoint, make_front
from optdesign.studies.pareto.records import PointRecord
from optdesign.studies.sweep import SweepPoint


@pytest.mark.parametrize(
    ("status", "verified", "expected"),
    [
        ("optimal", True, True),
        ("feasible", None, True),  # not checked (yet): the solver's word
        ("optimal", False, False),  # refused by the independent check
        ("infeasible", True, False),
        ("max_iterations", None, False),
    ],
)
def test_result_record_and_front_point_share_one_success_rule(status, verified, expected):
    result = Result(
        status=status,
        objective=1.0,
        design={"x": 1.0},
        solver="ipopt",
        formulation="nlp",
        wall_time_s=0.0,
        verified=verified,
    )
    rec = PointRecord(id="p", kind="eps", status=status, verified=verified, target="a")
    point = FrontPoint.from_record(rec, "epsilon")
    assert is_success(status, verified) is expected
    assert (result.success, rec.success, point.success) == (expected, expected, expected)


#: ``Result.to_dict()`` keys, in order, as the code wrote them before the records shared
#: a base (main at 4e796a2): the complete internal record of a solve.
RESULT_KEYS = (
    "status objective design solver formulation wall_time_s termination "
    "solution_status message objective_name objectives iterations n_evals violated "
    "active max_violation verified bound certificate globality multistart ranges diagnosis "
    "sensitivities item_steps problem mechanism notes extra"
).split()

#: A front store's JSON line (``PointRecord.to_dict()``), keys in order, as main wrote it.
RECORD_KEYS = (
    "id kind status verified target message x design objectives eps weights active "
    "violated wall_time_s iterations solver fallback order n_solves slope warm "
    "retried raw multistart"
).split()

STATUSES = ["optimal", "feasible", "infeasible", "failed", "max_iterations", "time_limit", ""]


def test_a_result_a_record_and_a_front_point_are_one_solved_point_with_one_success_rule():
    assert SHARED_FIELDS == (
        "status",
        "verified",
        "message",
        "design",
        "objectives",
        "wall_time_s",
        "iterations",
        "solver",
    )
    for cls in (Result, PointRecord, FrontPoint):
        assert issubclass(cls, SolvedPoint)
        assert "success" not in vars(cls)  # no record writes a rule of its own
    for status, verified in itertools.product(STATUSES, (True, False, None)):
        points = [
            SolvedPoint(status=status, verified=verified),
            Result(status=status, verified=verified, objective=1.0, formulation="nlp"),
            PointRecord(id="p", kind="eps", status=status, verified=verified, target="a"),
            FrontPoint(id="p", kind="eps", status=status, verified=verified, target="a"),
        ]
        expected = status in ("optimal", "feasible") and verified is not False
        assert [p.success for p in points] == [expected] * 4, (status, verified)
        assert is_success(status, verified) is expected
    for status in STATUSES:  # a sweep's point stores the checked status, no flag
        point = SweepPoint(index=0, values=(1.0,), status=status, objective=1.0, design={})
        assert point.success is (status in ("optimal", "feasible")), status


def test_solved_points_are_built_by_keyword_so_an_old_positional_call_fails_loudly():
    # Result's old positional order (status, objective, design, ...) would now fill other
    # fields silently; a keyword-only record refuses it.
    with pytest.raises(TypeError, match="positional"):
        Result("optimal", 1.0, {"x": 1.0}, "ipopt", "nlp", 0.0)
    with pytest.raises(TypeError, match="positional"):
        PointRecord("p", "eps", "optimal", True, "a")


def test_a_record_copies_the_shared_part_of_a_result_once_and_keeps_the_file_keys():
    result = Result(
        status="feasible",
        verified=True,
        message="Solve_Succeeded",
        design={"x": 1.5, "y": 2.0},
        objectives={"a": 0.25, "b": 4.0},
        wall_time_s=0.75,
        iterations=17,
        solver="ipopt",
        objective=0.25,
        formulation="nlp-direct",
        active=[ConstraintReport("a_max", 0.25, None, 0.25)],
    )
    rec = PointRecord(**shared_fields(result), id="eps-0001", kind="eps", target="a")
    assert {k: getattr(rec, k) for k in SHARED_FIELDS} == {
        "status": "feasible",
        "verified": True,
        "message": "Solve_Succeeded",
        "design": {"x": 1.5, "y": 2.0},
        "objectives": {"a": 0.25, "b": 4.0},
        "wall_time_s": 0.75,
        "iterations": 17,
        "solver": "ipopt",
    }
    rec.design["x"] = 9.0  # a copy: the record never changes the result it came from
    assert result.design["x"] == 1.5
    assert list(result.to_dict()) == RESULT_KEYS
    assert list(json.loads(result.to_json())) == RESULT_KEYS
    assert list(rec.to_dict()) == RECORD_KEYS
    point = FrontPoint.from_record(rec, "epsilon")
    assert list(point.to_dict())[:3] == ["objectives", "design", "status"]


def test_a_stored_record_of_an_older_run_loads_and_is_written_back_unchanged():
    # A front store's line as main wrote it, and one without the optional "solver" and
    # "verified" keys (as hand-made or earlier stores may lack them).
    line = (
        '{"id": "anchor-a", "kind": "anchor", "status": "optimal", "verified": true, '
        '"target": "a", "message": "", "x": [1.5], "design": {"x": 1.5}, '
        '"objectives": {"a": 0.25}, "eps": {}, "weights": {}, "active": ["a_max"], '
        '"violated": [], "wall_time_s": 0.5, "iterations": 12, "solver": "ipopt", '
        '"fallback": "", "order": ["a", "b"], "n_solves": 3, "slope": null, '
        '"warm": null, "retried": "", "raw": null, "multistart": null}'
    )
    stored = json.loads(line)
    rec = PointRecord.from_dict(stored)
    assert json.dumps(rec.to_dict()) == line
    assert rec.success and rec.iterations == 12 and rec.order == ["a", "b"]
    short = {k: v for k, v in stored.items() if k not in ("solver", "verified")}
    old = PointRecord.from_dict(short)
    assert (old.solver, old.verified, old.success) == ("", None, True)
    assert list(old.to_dict()) == RECORD_KEYS


def test_front_point_is_its_record_and_writes_front_json_keys():
    rec = PointRecord(
        id="eps-0001",
        kind="eps",
        status="optimal",
        verified=True,
        target="a",
        objectives={"a": 1.0, "b": 2.0},
        design={"x": 3.0},
        weights={"a": 0.5},
        n_solves=3,
        retried="jumped",
    )
    point = FrontPoint.from_record(rec, "weighted_sum")
    assert point.eps == {"a": 0.5}  # the weights when there are no epsilon bounds
    assert list(point.to_dict()) == [
        "objectives",
        "design",
        "status",
        "active",
        "method",
        "verified",
        "eps",
        "id",
        "rejected",
        "n_solves",
        "wall_time_s",
        "message",
        "retried",
    ]
    assert point.to_dict()["n_solves"] == 3
    assert isinstance(point, PointRecord) and point.kind == "eps" and point.raw is None
    failed = FrontPoint.from_record(
        PointRecord(id="eps-0002", kind="eps", status="optimal", verified=False, target="a"),
        "weighted_sum",
    )
    front = make_front([point, failed], ["a", "b"], "weighted_sum")
    assert [p.id for p in front.points] == ["eps-0001"]
    assert [(p.id, p.rejected) for p in front.rejected] == [("eps-0002", "failed")]
    assert front.metrics["n_failed"] == 1


def test_typed_details_are_written_under_extra_with_the_old_keys():
    details = Details(
        catalogue=CatalogueDetails(
            method="enumerate",
            combinations=2,
            variables={"d": [5.0, 6.0]},
            relaxation_bound=None,
            relaxation_status="infeasible",
            relaxation_design={},
            starts_per_node=2,
            enumerated=[CatalogueCombination({"d": 5.0}, "infeasible", math.nan)],
            nlp_solves=3,
        ),
        gp=GPDetails(timing=GPTiming(trace_s=0.5)),
        robust=RobustDetails(
            "CVaR_0.9(backlash)",
            64,
            7,
            0.1,
            False,
            nominal_optimum=NominalOptimum("optimal", "backlash", 0.02, {"d": 6.0}),
        ),
        fallback="failed: iteration limit",
    )
    result = Result(
        status="infeasible", objective=math.nan, solver="ipopt", formulation="catalogue-enumerate"
    )
    result.details = details
    extra = result.to_dict()["extra"]
    assert extra["gp_timing"] == {"trace_s": 0.5}  # unmeasured timings are left out
    assert extra["risk_label"] == "CVaR_0.9(backlash)" and extra["saa_samples"] == 64
    assert "saa_check" not in extra  # no design, no recomputed statistic
    assert extra["nominal_optimum"] == {"status": "optimal", "backlash": 0.02, "design": {"d": 6.0}}
    assert extra["catalogue"]["enumerated"] == [
        {"items": {"d": 5.0}, "status": "infeasible", "objective": None}
    ]
    assert extra["catalogue"]["relaxation_bound"] is None  # kept: it is always written
    assert "items" not in extra["catalogue"] and "nodes" not in extra["catalogue"]
    assert extra["fallback"] == "failed: iteration limit"
