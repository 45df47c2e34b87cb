"""One solved-point record, one success rule, typed details written as result files have
always had them (optdesign/solvers/result.py, details.py; studies/pareto/records.py,
front.py)."""

import math

import pytest

from optdesign.solvers.details import (
    CatalogueCombination,
    CatalogueDetails,
    Details,
    GPDetails,
    GPTiming,
    NominalOptimum,
    RobustDetails,
)
from optdesign.solvers.result import Result, is_success
from optdesign.studies.pareto.front import FrontPoint, make_front
from optdesign.studies.pareto.records import PointRecord


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
    result = Result(status, 1.0, {"x": 1.0}, "ipopt", "nlp", 0.0, verified=verified)
    rec = PointRecord(id="p", kind="eps", status=status, verified=verified, target="a")
    point = FrontPoint.from_record(rec, "epsilon")
    assert is_success(status, verified) is expected
    assert (result.success, rec.success, point.success) == (expected, expected, expected)


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
    result = Result("infeasible", math.nan, {}, "ipopt", "catalogue-enumerate", 0.0)
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
