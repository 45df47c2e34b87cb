"""optdesign/formulations/catalogue/node_bounds.py: which way a catalogue front's node
values may travel from one search to the next (a lower bound from looser limits to
tighter ones, never back; infeasibility from a limited objective's least value; a start
at the same items only)."""

import numpy as np
import pytest

from optdesign.formulations.catalogue.node_bounds import NodeBounds, looser_or_equal
from optdesign.tolerances import OBJECTIVE_TIE_TOL

FULL = {"p": (2.0, 10.0), "d": (4.0, 16.0)}


def test_a_value_under_looser_limits_bounds_a_sub_box_under_tighter_ones_never_the_reverse():
    nodes = NodeBounds(FULL)
    nodes.add({"p": (5.0, 10.0)}, {"backlash": 0.04}, "torque", 2150.0, np.zeros(2))
    sub = {"p": (5.0, 6.0), "d": (6.0, 8.0)}
    assert nodes.lower_bound(sub, {"backlash": 0.038}, "torque") == 2150.0  # tighter
    assert nodes.lower_bound(sub, {"backlash": 0.04}, "torque") == 2150.0  # the same
    # looser, or the limit dropped: the feasible set may have grown, no bound
    assert nodes.lower_bound(sub, {"backlash": 0.041}, "torque") is None
    assert nodes.lower_bound(sub, {}, "torque") is None
    # a wider box, another objective: no bound either
    assert nodes.lower_bound({"p": (2.0, 10.0)}, {"backlash": 0.038}, "torque") is None
    assert nodes.lower_bound(sub, {"backlash": 0.038}, "mass") is None


def test_the_greatest_applicable_value_is_the_bound_and_an_untrusted_one_is_none():
    nodes = NodeBounds(FULL)
    nodes.add({}, {}, "torque", 2100.0, None)  # the root with no limit
    nodes.add({"p": (5.0, 5.0)}, {"backlash": 0.05}, "torque", 2180.0, None)
    nodes.add({"p": (5.0, 5.0)}, {"backlash": 0.03}, "torque", 2300.0, None)  # tighter
    nodes.add({"p": (5.0, 5.0)}, {}, "torque", None, np.ones(2))  # one start: no bound
    leaf = {"p": (5.0, 5.0), "d": (6.0, 6.0)}
    assert nodes.lower_bound(leaf, {"backlash": 0.04}, "torque") == 2180.0
    assert nodes.lower_bound(leaf, {"backlash": 0.02}, "torque") == 2300.0
    assert nodes.lower_bound({"p": (2.0, 4.0)}, {"backlash": 0.04}, "torque") == 2100.0
    assert len(nodes) == 4


def test_a_box_whose_least_value_of_a_limited_objective_exceeds_the_limit_is_infeasible():
    nodes = NodeBounds(FULL)
    nodes.add({"d": (4.0, 8.0)}, {}, "backlash", 0.04, None)
    sub = {"d": (5.0, 6.0)}
    assert nodes.infeasible(sub, {"backlash": 0.039})
    # at the value, or within the tie tolerance below it: the limit may be met
    assert not nodes.infeasible(sub, {"backlash": 0.04})
    assert not nodes.infeasible(sub, {"backlash": 0.04 * (1 - 0.5 * OBJECTIVE_TIE_TOL)})
    assert not nodes.infeasible(sub, {"torque": 1.0})  # no limit on backlash
    assert not nodes.infeasible({"d": (4.0, 10.0)}, {"backlash": 0.039})  # a wider box
    # a value found under a limit the later search does not hold proves nothing there
    nodes = NodeBounds(FULL)
    nodes.add({"d": (4.0, 8.0)}, {"torque": 2000.0}, "backlash", 0.04, None)
    assert not nodes.infeasible(sub, {"backlash": 0.039})
    assert nodes.infeasible(sub, {"backlash": 0.039, "torque": 1999.0})


def test_a_start_is_the_latest_optimum_of_the_same_items_and_objective():
    nodes = NodeBounds(FULL)
    leaf = {"p": (5.0, 5.0), "d": (6.0, 6.0)}
    nodes.add(leaf, {"backlash": 0.04}, "torque", 2190.0, np.array([1.0, 2.0]))
    nodes.add(leaf, {"backlash": 0.039}, "torque", None, np.array([3.0, 4.0]))
    nodes.add(leaf, {}, "backlash", 0.035, np.array([5.0, 6.0]))
    nodes.add(leaf, {"backlash": 0.038}, "torque", None, None)  # infeasible: no optimum
    assert nodes.start(leaf, "torque") == pytest.approx([3.0, 4.0])
    assert nodes.start(leaf, "backlash") == pytest.approx([5.0, 6.0])
    assert nodes.start({"p": (5.0, 5.0)}, "torque") is None  # a box holding it: no start


def test_limits_are_looser_or_equal_when_every_stored_one_is_held_as_tight():
    assert looser_or_equal({}, {"a": 1.0})
    assert looser_or_equal({"a": 2.0}, {"a": 2.0, "b": 1.0})
    assert not looser_or_equal({"a": 2.0}, {"a": 2.5})
    assert not looser_or_equal({"a": 2.0}, {"b": 1.0})


def test_an_optimum_under_looser_limits_is_reused_only_where_it_meets_the_tighter_ones():
    """The feasible set shrank around it: an optimum that meets the tighter limits with
    room is their optimum too (a copy of its result); one at a limit, one found under
    tighter limits, or one of another box or objective is not."""
    from optdesign.solvers.result import Result

    def result(backlash):
        return Result(
            status="optimal",
            objective=2190.0,
            design={"p": 5.0, "d": 6.0},
            objectives={"torque": 2190.0, "backlash": backlash},
            solver="fake",
            formulation="nlp",
        )

    nodes = NodeBounds(FULL)
    leaf = {"p": (5.0, 5.0), "d": (6.0, 6.0)}
    kept = result(0.0379)
    nodes.add(leaf, {"backlash": 0.0403}, "torque", 2190.0, np.zeros(2), kept)
    again = nodes.reuse(leaf, {"backlash": 0.0389}, "torque")
    assert again is not kept and again.objective == 2190.0 and again.design == kept.design
    assert nodes.reuse(leaf, {"backlash": 0.0379}, "torque") is None  # at the limit
    assert nodes.reuse(leaf, {"backlash": 0.041}, "torque") is None  # looser: may move
    assert nodes.reuse({"p": (5.0, 5.0)}, {"backlash": 0.0389}, "torque") is None
    assert nodes.reuse(leaf, {"backlash": 0.0389}, "backlash") is None
    assert nodes.reuse(leaf, {"backlash": 0.0389, "mass": 1.0}, "torque") is None  # unknown


def test_a_full_memo_drops_its_oldest_half(monkeypatch):
    from optdesign.formulations.catalogue import node_bounds

    monkeypatch.setattr(node_bounds, "MAX_ENTRIES", 4)
    nodes = NodeBounds(FULL)
    for k in range(5):
        nodes.add({"p": (float(k), float(k))}, {}, "torque", 100.0 + k, np.full(2, k))
    assert len(nodes) == 3  # 5 > 4: the oldest 2 dropped
    assert nodes.start({"p": (1.0, 1.0)}, "torque") is None
    assert nodes.start({"p": (4.0, 4.0)}, "torque") == pytest.approx([4.0, 4.0])
    assert nodes.lower_bound({"p": (2.0, 2.0)}, {}, "torque") == 102.0
