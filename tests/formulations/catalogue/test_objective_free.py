"""optdesign/formulations/catalogue/objective_free.py: a catalogue variable whose item
data only the requirements read (the motor under a backlash objective) is split last, at
the first item the node's design meets. Checked against an enumeration over the items
(the same value and the same items, ties decided by value then items), with the
objective reading the motor (its mass, its peak torque) as well as not, where the rule
must not apply."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest
from problem.test_motor_catalogue_variable import _csv  # the shipped rows as a CSV

import optdesign as od
from optdesign.formulations.catalogue.objective_free import (
    first_item_met,
    objective_free_variables,
    split_last_variables,
)
from optdesign.formulations.catalogue.search import NodeSolver, solve_catalogue
from optdesign.problem.parameters import without_impossible_items

ROOT = Path(__file__).resolve().parents[3]

#: The shipped SGM7J-02A ... -08A rows with masses made up for the test, the 04A the
#: heaviest: under motor_mass the lightest motor that can give the step is not the first.
MASSES_KG = {"SGM7J-02A": 1.1, "SGM7J-04A": 2.9, "SGM7J-06A": 1.9, "SGM7J-08A": 2.6}


def _small(
    tmp_path: Path, objective: str, rise_time: str = "72 ms", motor_first: bool = False
) -> od.DesignProblem:
    """cs_min_backlash with its pins from the ISO 2338 catalogue (8, 10, 12 mm), a motor
    from a four-motor CSV (the 02A excluded in closed form), the fin's load and a step:
    9 combinations. ``motor_first``: the file declares the motor before the pins, so a
    tie goes to the smaller motor first."""
    from hostile_corpus import dumps

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash.toml").read_text())
    data["variables"]["d"] = {"catalogue": "ISO 2338", "lower": "8 mm", "upper": "12 mm"}
    if motor_first:
        data["variables"] = {"motor": {"catalogue": "motors.csv"}, **data["variables"]}
    data["motor"] = {"catalogue": "motors.csv"}
    data["load"] = {"inertia": "0.5 kg*m^2", "hinge_spring": "-500 N*m/rad",
                    "damping": "5 N*m*s/rad", "nut_mass": "0.6 kg"}  # fmt: skip
    data["motion"] = {"step": "3 deg", "rise_time": rise_time, "damping_ratio": 0.7,
                      "rate": "120 deg/s"}  # fmt: skip
    data["objective"] = {"minimize": objective}
    (tmp_path / "motors.csv").write_text(_csv(MASSES_KG))
    path = tmp_path / f"{objective}.toml"
    path.write_text(dumps(data))
    return od.load(path)


def _catalogue_motor() -> od.DesignProblem:
    data = tomllib.loads((ROOT / "problems" / "fin_actuator_motor.toml").read_text())
    data["motor"] = {k: v for k, v in data["motor"].items() if k != "designation"}
    data["motor"]["catalogue"] = "Yaskawa Sigma-7"
    return od.load(copy.deepcopy(data))


def test_only_a_variable_neither_the_objective_nor_a_row_reads_by_value_is_split_last():
    """Backlash reads the pins, not the screw's or the motor's data; the screw's d0 and p
    move the design through their values, the motor's number moves nothing but its data.
    The motor's peak torque reads the motor's rotor inertia: not split last then."""
    problem, _ = without_impossible_items(_catalogue_motor())
    backlash = NodeSolver(problem, starts=1)
    assert objective_free_variables(backlash) == {"d0", "p", "motor"}
    assert split_last_variables(backlash) == {"motor"}
    peak = NodeSolver(problem, objective="motor_peak_torque", starts=1)
    assert "motor" not in objective_free_variables(peak)
    assert split_last_variables(peak) == frozenset()


def test_the_first_motor_the_named_optimum_meets_is_its_own_motor():
    """At the named SGM7J-06A's optimum (screw 25 x 5, pins 10 mm), the motors are
    checked in order: the 04A (motor 5) cannot give the step's peak torque at that
    design, the 06A (motor 6) can; a backlash above the design's own fails every one."""
    named = tomllib.loads((ROOT / "problems" / "fin_actuator_motor.toml").read_text())
    best = od.solve(od.load(named), ranges=False, sensitivities=False)
    problem, _ = without_impossible_items(_catalogue_motor())
    ns = NodeSolver(problem, starts=1)
    x = np.array([best.design.get(n, 0.0) for n in ns.names])
    box = {v.name: (v.lower, v.upper) for v in problem.free if v.discrete}
    items = {"d0": 25.0, "p": 5.0, "d": 10.0}
    assert first_item_met(ns, box, x, best.objective, "motor", items) == 6.0
    assert first_item_met(ns, box, x, 0.99 * best.objective, "motor", items) is None
    above = {**box, "motor": (7.0, 14.0)}
    assert first_item_met(ns, above, x, best.objective, "motor", items) == 7.0


@pytest.mark.parametrize(
    ("objective", "rise_time", "motor_first", "items"),
    [
        # every motor that can give the step ties on the backlash: the first one (04A)
        ("backlash", "72 ms", False, {"d": 10.0, "motor": 2.0}),
        # a faster step: the 04A still can, at a larger backlash (0.0370046 deg against
        # the 06A's and 08A's 0.0369799): the first motor is not the answer
        ("backlash", "68 ms", False, {"d": 10.0, "motor": 3.0}),
        ("backlash", "68 ms", True, {"motor": 3.0, "d": 10.0}),
        # the objective reads the motor (its mass): the lightest that can, the 06A
        ("motor_mass", "72 ms", False, {"d": 8.0, "motor": 3.0}),
    ],
)
def test_branch_and_bound_finds_the_enumerations_combination(
    tmp_path, objective, rise_time, motor_first, items
):
    """The search's value and items equal the enumeration's over the combinations,
    whether the objective ignores the motor (split last) or reads its mass (not), with
    the motor declared after the pins or before them (the order that decides a tie)."""
    problem = _small(tmp_path, objective, rise_time, motor_first)
    ns = NodeSolver(problem, starts=1)
    assert ("motor" in split_last_variables(ns)) == (objective == "backlash")
    enum = solve_catalogue(problem, method="enumerate")
    bnb = solve_catalogue(problem, method="bnb")
    assert enum.status == bnb.status == "optimal"
    assert enum.details.catalogue.items == items
    assert list(bnb.details.catalogue.items.items()) == list(items.items())
    assert bnb.objective == pytest.approx(enum.objective, rel=1e-7)


def test_the_catalogue_motor_is_the_enumerations_motor_for_less_than_twice_the_named_solves():
    """fin_actuator_motor with the motor from the 14-motor catalogue: motor 6 (SGM7J-06A)
    at the named motor's backlash (motors 1-4 excluded in closed form, 5 infeasible, 6-14
    tie: benchmarks/motor/cost.py enumerates them), in fewer than twice the NLP solves of
    the named motor's search (68 before the motor was split last, 27 since)."""
    named = tomllib.loads((ROOT / "problems" / "fin_actuator_motor.toml").read_text())
    one = od.solve(od.load(named), ranges=False, sensitivities=False)
    chosen = od.solve(_catalogue_motor(), ranges=False, sensitivities=False)
    assert chosen.status == "optimal" and chosen.design["motor"] == 6.0
    assert chosen.objective == pytest.approx(0.0377566355, rel=1e-9)
    assert chosen.objective == pytest.approx(one.objective, rel=1e-9)
    assert chosen.details.catalogue.nlp_solves < 2 * one.details.catalogue.nlp_solves


def test_an_implicit_epigraph_reads_the_motor_through_its_rows():
    """fin_actuator_loop's bandwidth_period is a root of the loop, bounded by implicit
    rows rather than an expression: the motor's rotor inertia enters those rows, so the
    motor is read by the objective and split as the others are; under the backlash the
    same problem's motor is split last."""
    data = tomllib.loads((ROOT / "problems" / "fin_actuator_loop.toml").read_text())
    data["motor"] = {k: v for k, v in data["motor"].items() if k != "designation"}
    data["motor"]["catalogue"] = "Yaskawa Sigma-7"
    problem, _ = without_impossible_items(od.load(data))
    bandwidth = NodeSolver(problem, objective="bandwidth_period", starts=1)
    assert objective_free_variables(bandwidth) == frozenset()
    assert split_last_variables(NodeSolver(problem, starts=1)) == {"motor"}
