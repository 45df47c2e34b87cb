"""The catalogue front (studies/pareto/catalogue_front.py): its end points are its
anchors' designs, not solved again, and they are the optima of their own limits."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import pytest

import optdesign as od
from optdesign.problem import problem_from_dict
from optdesign.studies.catalogue import solve_catalogue

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def small_front(tmp_path_factory):
    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "6 mm", "8 mm"]}
    problem = problem_from_dict(data)
    out = tmp_path_factory.mktemp("front")
    front = od.pareto(problem, ["backlash", "motor_torque"], points=3, starts=2, out=out)
    lines = (out / "epsilon-catalogue.jsonl").read_text().splitlines()[1:]
    records = {r["id"]: r for r in map(json.loads, lines)}
    return problem, front, records


def test_the_ends_of_a_catalogue_front_are_its_anchors(small_front):
    _, front, records = small_front
    first, last = records["epsilon-catalogue-0000"], records["epsilon-catalogue-0002"]
    for end, anchor, limit in (
        (first, records["anchor-backlash"], "backlash_max"),
        (last, records["anchor-motor_torque"], "backlash_max"),
    ):
        assert end["design"] == anchor["design"] and end["objectives"] == anchor["objectives"]
        assert end["n_solves"] == 0 and end["target"] == "motor_torque"
        # the limit holds to the solver's feasibility tolerance
        assert anchor["objectives"]["backlash"] <= end["eps"]["backlash"] * (1 + 1e-6)
        assert limit in end["active"] and "motor_torque_max" not in end["active"]
    assert records["epsilon-catalogue-0001"]["n_solves"] > 0
    assert len(front.points) >= 2


def test_the_inner_point_is_solved_at_the_limit_midway_between_the_anchors(small_front):
    _, _, records = small_front
    middle = records["epsilon-catalogue-0001"]
    # the limits evenly spaced in backlash between the two anchors' values
    lo = records["anchor-backlash"]["objectives"]["backlash"] * (1 + 1e-7) + 1e-12
    hi = records["anchor-motor_torque"]["objectives"]["backlash"]
    assert middle["eps"]["backlash"] == pytest.approx(0.5 * (lo + hi), rel=1e-12)
    assert middle["objectives"]["backlash"] <= middle["eps"]["backlash"] * (1 + 1e-6)


def test_each_end_is_the_optimum_of_its_own_limit(small_front):
    """Solved again as a catalogue search of its own (min motor torque s.t. its backlash
    limit), each end point's torque is the search's, to the anchors' slack."""
    problem, _, records = small_front
    for pid in ("epsilon-catalogue-0000", "epsilon-catalogue-0002"):
        end = records[pid]
        again = solve_catalogue(problem, starts=2, objective="motor_torque", eps=end["eps"])
        assert again.success
        assert end["objectives"]["motor_torque"] == pytest.approx(again.objective, rel=1e-6)


@pytest.mark.slow  # two catalogue anchors searched twice: 8-24 s
def test_an_anchors_first_stage_leaves_the_ties_to_its_tie_break():
    """fin_actuator's motor torque does not depend on the pin: its catalogue optimum ties
    over the pins the requirements allow. The anchor's first stage only needs the value
    (its tie-break decides the design): searched with ``ties=False`` it gets the same
    value with fewer NLP solves, at one of the tied designs."""
    problem = od.load(ROOT / "problems" / "fin_actuator.toml")
    decided = solve_catalogue(problem, objective="motor_torque")
    value_only = solve_catalogue(problem, objective="motor_torque", ties=False)
    assert decided.success and value_only.success
    assert value_only.objective == pytest.approx(decided.objective, rel=1e-6)
    assert value_only.details.catalogue.nlp_solves < decided.details.catalogue.nlp_solves
    # the items decide the tie only in the first search: the smallest pin that works
    assert decided.design["d"] <= value_only.design["d"]
    assert decided.design["d0"] == value_only.design["d0"]
