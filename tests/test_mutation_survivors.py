"""Tests written from the survivors of the mutation run over the store, the units and the
catalogue search (issue 21, `benchmarks/mutation/run.sh`): each pins a behaviour that a
one-token change left unnoticed - the field and the reason of a refusal, a lock file's
holder, a store changed in place through another hard link, the catalogue's tolerance."""

from __future__ import annotations

import math
import os
import tomllib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import optdesign as od
from optdesign import units
from optdesign.errors import InputError
from optdesign.formulations.discrete import discrete_variables
from optdesign.problem import problem_from_dict
from optdesign.problem.load import load
from optdesign.safe_io import UnsafeFileError
from optdesign.storage import _lock_holder, open_store
from optdesign.studies import catalogue
from optdesign.studies.catalogue import is_on_catalogue, relaxation_bound
from optdesign.studies.runner import run_tasks
from optdesign.studies.verify import verify_design

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = '(e.g. "N*mm", "rad/s"; "" for a plain number)'


def _refusal(call, *args) -> str:
    with pytest.raises(InputError) as caught:
        call(*args)
    return str(caught.value)


# --- units: every refusal names its field and says why ----------------------------------
@pytest.mark.parametrize(
    ("unit", "message"),
    [
        (5, 'f.unit: a unit is a string such as "N*mm", got 5'),
        ("m" * 101, "f.unit: too long for a unit (101 characters)"),
        # 100 characters is not too long: the grammar reads it (and finds no such unit)
        ("m" * 100, f"f.unit: cannot read '{'m' * 100}' as a unit: unknown unit '{'m' * 100}'"),
        ("N*foo", f"f.unit: cannot read 'N*foo' as a unit: unknown unit 'foo' {EXAMPLES}"),
        ("N**", "f.unit: cannot read 'N**' as a unit: a power must be a whole number"),
    ],
)
def test_parse_unit_refusals_name_the_field_and_the_reason(unit, message):
    assert _refusal(units.parse_unit, unit, "f.unit").startswith(message)


@pytest.mark.parametrize(
    ("value", "unit", "message"),
    [
        (
            "5 N*m",
            "N*mm/rad",
            "c.upper: '5 N*m' is a moment, expected a moment per angle ('N*mm/rad')",
        ),
        ("5 N*m", "", "c.upper: '5 N*m' is a moment, expected a plain number"),
        (
            "5 xyz",
            "N",
            "c.upper: cannot read '5 xyz' as a quantity: unknown unit 'xyz' (write a number "
            'and a unit, e.g. "500 N*m"; no arithmetic)',
        ),
        ("1e308 kN", "N", "c.upper: '1e308 kN' is out of range"),
        (float("nan"), "N", "c.upper: nan is not a finite number"),
        (5, "N*foo", f"c.upper: cannot read 'N*foo' as a unit: unknown unit 'foo' {EXAMPLES}"),
    ],
)
def test_convert_refusals_name_the_field_and_the_reason(value, unit, message):
    assert _refusal(units.convert, value, unit, "c.upper") == message


def test_convert_reads_strings_and_pint_quantities_in_the_target_unit():
    registry = units.registry()
    assert units.convert("2 kN", "N", "c") == 2000.0
    assert units.convert(registry.Quantity(3.0, "deg"), "rad", "c") == pytest.approx(
        math.radians(3.0), rel=1e-15
    )
    assert units.convert(7, "N", "c") == 7.0  # a bare number: already in the unit


def test_convert_refuses_pint_quantities_that_are_not_one_finite_number():
    registry = units.registry()
    vector = registry.Quantity(np.array([1.0, 2.0]), "N")
    assert _refusal(units.convert, vector, "N", "c.upper") == (
        f"c.upper: expected a scalar quantity, got {vector!r}"
    )
    infinite = registry.Quantity(float("inf"), "N")
    assert _refusal(units.convert, infinite, "N", "c.upper") == (
        f"c.upper: {infinite!r} is not a finite number"
    )


def test_an_object_with_units_that_is_not_pints_is_no_quantity():
    class LooksLikeAQuantity:
        units = "N"
        magnitude = 1.0

    value = LooksLikeAQuantity()
    assert _refusal(units.convert, value, "N", "c.upper") == (
        f"c.upper: expected a number or a quantity string, got {value!r}"
    )


@pytest.mark.parametrize(
    ("unit", "to", "message"),
    [
        (
            "N*mm",
            "N*m/deg",
            "d.unit: 'N*m/deg' is a moment per angle and 'N*mm' a moment: a unit of the "
            "same dimension is needed",
        ),
        (
            "",
            "N",
            "d.unit: 'N' is a force and no unit a plain number: a unit of the same dimension is needed",
        ),
        (
            "N",
            "",
            "d.unit: no unit is a plain number and 'N' a force: a unit of the same dimension is needed",
        ),
        ("N", "N*foo", f"d.unit: cannot read 'N*foo' as a unit: unknown unit 'foo' {EXAMPLES}"),
        ("N*foo", "N", f"d.unit: cannot read 'N*foo' as a unit: unknown unit 'foo' {EXAMPLES}"),
    ],
)
def test_unit_factor_refusals_name_the_field(unit, to, message):
    assert _refusal(units.unit_factor, unit, to, "d.unit") == message


def test_unit_factor_values():
    assert units.unit_factor("kN", "N", "d") == 1000.0
    assert units.unit_factor("deg", "rad", "d") == pytest.approx(math.pi / 180, rel=1e-15)


def test_parse_quantity_names_the_quantity():
    assert _refusal(units.parse_quantity, "5 foo").startswith(
        "quantity: cannot read '5 foo' as a quantity: unknown unit 'foo'"
    )


# --- store: the lock's holder, a store with another hard link ---------------------------
@pytest.mark.parametrize(
    ("content", "holder"),
    [
        (b"12345\n", "pid 12345"),
        (b"not a pid", "pid unknown"),
        (b"\xff\xfe", "pid unknown"),  # not UTF-8
        (b"1" * 65, "pid unknown"),  # more than a pid: not read
        (b"1" * 64, "pid " + "1" * 64),
    ],
)
def test_lock_holder_reads_only_a_pid(tmp_path, content, holder):
    lock = tmp_path / "lock"
    lock.write_bytes(content)
    assert _lock_holder(lock) == holder


def test_lock_holder_of_a_missing_lock_is_unknown(tmp_path):
    assert _lock_holder(tmp_path / "lock") == "pid unknown"


def _double(task, deps):
    return {"value": 2 * task["n"]}


def test_a_torn_store_with_another_hard_link_is_not_repaired_in_place(tmp_path):
    store = tmp_path / "s.jsonl"
    run_tasks([{"id": f"t{i}", "n": i} for i in range(3)], _double, store, key="k")
    torn = store.read_bytes()[:-3]
    store.write_bytes(torn)
    other = tmp_path / "elsewhere.jsonl"
    os.link(store, other)
    with pytest.raises(UnsafeFileError) as caught:
        open_store(store, "k", resume=True)
    assert str(caught.value).startswith(
        f"the store {store} has 2 hard links (changing it would change another file too)"
    )
    assert other.read_bytes() == torn  # the file the other link names is untouched


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


@pytest.mark.slow  # its fixture enumerates a 4 x 5 catalogue: 9-17 s
def test_branch_and_bound_counts_every_node_it_solves(monkeypatch, enumerated_4x5):
    """4 leads x 5 pins: branch and bound equals enumeration, and its counts are those of
    the node solves it made (counted here by a wrapper around the node solver)."""
    problem, enum = enumerated_4x5
    solves: list[bool] = []
    original = catalogue.NodeSolver.solve

    def counted(self, box, *args, **kwargs):
        result = original(self, box, *args, **kwargs)
        solves.append(bool(result.success))
        return result

    monkeypatch.setattr(catalogue.NodeSolver, "solve", counted)
    bnb = catalogue.solve_catalogue(problem, method="bnb", starts=2)
    info = bnb.details.catalogue
    # the relaxation, 7 boxes of 20 item pairs, and the box whose warm bound (one start)
    # would prune it, solved again with the full multistart before it is pruned
    assert info.nodes == len(solves) == 9
    assert info.infeasible == solves.count(False) == 2
    # the one leaf (p = 6, d = 6) prunes the one box left open when it was found
    assert (info.leaves, info.pruned) == (1, 1)
    assert len(enum.details.catalogue.enumerated) == 20
    assert bnb.objective == pytest.approx(enum.objective, rel=1e-9)
    assert bnb.details.catalogue.items == enum.details.catalogue.items == {"p": 6, "d": 6}


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
    found = catalogue.first_feasible(catalogue.NodeSolver(problem, starts=2))
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
    assert catalogue.first_feasible(catalogue.NodeSolver(weak, starts=2)) is None


# --- survivors of the sampled mutation run of issue 21 (docs/testing.md) -----------------
def test_a_gp_objective_with_a_negative_term_is_not_a_gp():
    """A user objective that is a signomial (12 mm - p): the GP diagnosis refuses it,
    names the term, and cvxpy agrees; the problem's own objective stays a GP."""
    import copy

    from formulations.test_gp import CS_FIXED

    from optdesign.formulations.gp import build_gp

    problem = problem_from_dict(copy.deepcopy(CS_FIXED))
    problem.add_objective("lead_margin", lambda q: 12.0 - q.design["p"], unit="mm")
    gp = build_gp(problem, "lead_margin")
    check = {c.name: c for c in gp.checks}["lead_margin"]
    assert not gp.is_gp and check in gp.failures() and check.what == "objective"
    assert check.reason == "lead_margin[] has a negative term: -p + 12 (a signomial)"
    assert check.cvxpy_is_dgp is False
    assert build_gp(problem, "backlash").is_gp


def test_three_objective_weights_are_the_smallest_triangle_holding_the_points():
    """A 3-objective weighted sum: the weights lie on a triangular grid of side s, the
    smallest with s (s + 1) / 2 >= points, and sum to 1."""
    from optdesign.studies.pareto.methods import _weight_grid

    for points, side in ((3, 2), (6, 3), (10, 4), (11, 5), (15, 5)):
        grid = _weight_grid(3, points)
        assert len(grid) == side * (side + 1) // 2
        assert all(min(w) >= 0 and math.isclose(sum(w), 1.0) for w in grid)
        assert len({tuple(round(x, 12) for x in w) for w in grid}) == len(grid)
    assert _weight_grid(2, 5) == [(w, 1 - w) for w in np.linspace(0.0, 1.0, 5)]


def test_an_objective_without_a_problem_or_a_declaration_is_shown_bare():
    """An objective value shown with no problem (a record read alone) or under a name the
    problem does not declare: the number as it is, with no unit."""
    from optdesign.reports.display_units import Shown, objective_shown

    assert objective_shown(None, "backlash", 0.5) == Shown(0.5, "")
    assert objective_shown(None, "backlash", 0.5).text() == "0.5"
    problem = load(Path(__file__).resolve().parents[1] / "problems" / "cs_min_backlash.toml")
    assert objective_shown(problem, "not_an_objective", 2.0) == Shown(2.0, "")
    shown = objective_shown(problem, "CVaR_0.9(backlash)", 0.03)  # a statistic of it
    assert shown.unit == "deg" and shown.value == pytest.approx(0.03)


def test_an_angle_is_shown_in_the_unit_the_file_wrote_it_in():
    from optdesign.reports.display_units import shown

    as_rad = shown(0.5, "rad", "rad")
    assert (as_rad.value, as_rad.unit) == (0.5, "rad")
    as_deg = shown(0.5, "rad")
    assert as_deg.unit == "deg" and as_deg.value == pytest.approx(math.degrees(0.5), rel=1e-15)


def test_the_dn_row_names_the_diameter_of_its_rule():
    from optdesign.problem.drive_requirements import drive_blocks

    def dn_text(rule, limit=None):
        data = tomllib.loads((ROOT / "problems" / "fin_actuator.toml").read_text())
        data["requirements"]["dn_rule"] = rule
        if limit is not None:
            data["requirements"]["dn_max"] = limit
        problem = problem_from_dict(data)
        q = problem.quantities(problem.design_dict(problem.midpoint()))
        return next(b for b in drive_blocks(q, problem.phi_labels) if b.name == "dn").description

    assert dn_text("ball-centre").startswith("d_m x screw speed (DN value; rule ball-centre")
    assert dn_text("HIWIN") == (
        "d0 x screw speed (DN value; rule HIWIN: ground limit 90,000 on the nominal diameter)"
    )
    # a limit given as a number names no grade
    assert dn_text("HIWIN", 70000) == (
        "d0 x screw speed (DN value; rule HIWIN: limit 70,000 on the nominal diameter)"
    )


def test_the_table_fit_ratio_of_a_catalogue_node_is_iso_286_over_the_formula():
    """H7/g6 at 6 mm in ISO 286-2's tables: hole +12/0 um, shaft -4/-12 um, so 24 um
    largest and 4 um smallest clearance; the node's parameter is that over the smooth
    (IT formula) clearance, the smallest ratio over the node's pins."""
    from optdesign.fits import clearance
    from optdesign.problem.drive import _fit_ratios

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    problem = problem_from_dict(data)
    at6 = _fit_ratios(problem, {"d": (6.0, 6.0)})
    assert at6["fit_ratio_max"] == pytest.approx(0.024 / clearance("H7/g6", 6.0, "max", "smooth"))
    assert at6["fit_ratio_min"] == pytest.approx(0.004 / clearance("H7/g6", 6.0, "min", "smooth"))
    assert at6["fit_ratio_max"] < 0.95  # the table is tighter than the formula here
    wide = _fit_ratios(problem, {"d": (5.0, 8.0)})
    ratios = [
        clearance("H7/g6", D, "max", "table") / clearance("H7/g6", D, "max", "smooth")
        for D in (5.0, 6.0, 8.0)
    ]
    assert wide["fit_ratio_max"] == pytest.approx(min(ratios))


@pytest.mark.parametrize("nu", [0.0, 0.5, -0.1, 0.7])
def test_a_pin_poisson_ratio_outside_its_range_is_refused_with_the_value(nu):
    from optdesign.mechanisms.joints import PinJoint

    with pytest.raises(InputError) as caught:
        PinJoint(8.0, 12.0, nu=nu)
    assert caught.value.field == "pin.nu"
    assert caught.value.reason == f"Poisson ratio must lie in (0, 0.5), got {nu!r}"


def test_a_symbolic_poisson_ratio_is_not_range_checked_and_reaches_the_clearance():
    """The joint model takes symbolic material data (a CasADi symbol): only a number is
    checked against (0, 0.5); the symbol is kept for the contact clearance."""
    import casadi as ca

    from optdesign.mechanisms.joints import PinJoint

    nu = ca.SX.sym("nu")
    pin = PinJoint(8.0, 12.0, nu=nu)
    assert pin.nu is nu
    with pytest.raises(InputError):
        PinJoint(8.0, 12.0, nu=0.5)


def test_only_palmgrens_contact_is_restricted_to_steel():
    from optdesign.mechanisms.joints import PinJoint

    titanium = 1.1e5  # MPa
    for contact in ("duan2017", "conforming"):
        assert PinJoint(8.0, 12.0, E=titanium, contact=contact).E == titanium
    with pytest.raises(InputError, match="Palmgren's approach is an empirical law of steel"):
        PinJoint(8.0, 12.0, E=titanium, contact="palmgren")
    assert PinJoint(8.0, 12.0, E=2.1e5, contact="palmgren").contact == "palmgren"
    # the steel band 1.9e5-2.2e5 MPa, both ends included
    for steel in (1.9e5, 2.2e5):
        assert PinJoint(8.0, 12.0, E=steel, contact="palmgren").E == steel
    for not_steel in (1.89e5, 2.21e5):
        with pytest.raises(InputError, match=r"^materials\.pin\.E: Palmgren's approach"):
            PinJoint(8.0, 12.0, E=not_steel, contact="palmgren")


# --- survivors of the second sample (docs/testing.md, "The second sample") ------------------
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


def test_a_ratio_ripple_limit_is_not_a_gp_and_the_diagnosis_says_why():
    """ripple_max bounds (max - min)/(max + min) over the grid, a difference of
    posynomials over a sum: the GP diagnosis names it as a constraint that is not DGP."""
    import copy

    from formulations.test_gp import CS_FIXED

    from optdesign.formulations.gp import build_gp

    data = copy.deepcopy(CS_FIXED)
    data["requirements"]["ripple_max"] = 0.2
    data["variables"]["R"] = {"lower": 60, "upper": 120}  # the ratio's shape depends on R
    gp = build_gp(problem_from_dict(data))
    check = {c.name: c for c in gp.checks}["ripple_max"]
    assert (check.what, check.ok, check.cvxpy_is_dgp) == ("constraint", False, False)
    assert check.reason == (
        "ripple = (max - min)/(max + min) over the grid is a ratio of a difference of posynomials"
    )
    assert not gp.is_gp and check in gp.failures()


def test_an_objective_the_gp_cannot_trace_is_a_failed_check_not_an_unknown_one():
    import copy

    from formulations.test_gp import CS_FIXED

    from optdesign import math as m
    from optdesign.formulations.gp import build_gp

    problem = problem_from_dict(copy.deepcopy(CS_FIXED))
    problem.add_objective("wavy", lambda q: m.sin(q.design["p"]), unit="")
    check = next(c for c in build_gp(problem, "wavy").checks if c.what == "objective")
    assert check.name == "wavy" and check.ok is False and check.reason


def test_the_default_clearance_chain_reads_each_fixed_clearance_under_its_key():
    """A mechanism with the default chain (screw bearings A, screw/nut B, output shaft O):
    the file's clearances reach the backlash, c / (dx/dphi) rad each on the screw's line;
    for the yoke x = R sin(phi), dx/dphi = R cos(phi)."""
    from test_api import yoke_data

    from optdesign import math as m

    class ChainYoke(od.Mechanism):
        name = "t21_chain_yoke"
        variables = {"R": od.VariableInfo("length", "crank radius")}  # noqa: RUF012
        pin_joints = ("crank pin",)

        def nut_position(self, phi):
            return self.R * m.sin(phi)

    od.register_mechanism(ChainYoke, replace=True)
    data = yoke_data("t21_chain_yoke")
    data["clearances"] = {"A": "0.02 mm", "B": "0.01 mm", "O": "0.005 deg"}
    problem = od.load(data)
    R = 80.0
    backlash = problem.quantities({"R": R, "p": 5.0, "i_a": 2.0}).backlash
    phi = np.asarray(problem.phi)
    expected = np.degrees(0.03 / (R * np.cos(phi))) + 0.005
    assert np.asarray(backlash.worst_case, dtype=float).ravel() == pytest.approx(expected, rel=1e-9)
    assert sorted(backlash.per_joint) == ["A screw bearings", "B screw/nut", "O output shaft"]


def test_three_objective_tasks_are_indexed_row_by_row():
    """The index of a three-objective front's tasks is their row-major order (each row's
    head, then its points): the front lists its points, and seeds their retry starts,
    by it."""
    from optdesign.studies.pareto.chains import three_objective_tasks
    from optdesign.studies.pareto.records import PointRecord

    names = ["size", "backlash", "ripple"]
    anchors = {
        k: PointRecord(
            id=f"anchor-{k}",
            kind="anchor",
            status="optimal",
            verified=True,
            target=k,
            objectives=values,
        )
        for k, values in (
            ("size", {"size": 1.0, "backlash": 3.0, "ripple": 3.0}),
            ("backlash", {"size": 3.0, "backlash": 1.0, "ripple": 2.0}),
            ("ripple", {"size": 2.0, "backlash": 2.0, "ripple": 1.0}),
        )
    }
    tasks = three_objective_tasks(anchors, names, 9, "t", {})
    assert [t["index"] for t in tasks] == list(range(len(tasks))) and len(tasks) == 12
    assert [t["id"] for t in tasks[:5]] == [
        "t-000-head",
        "t-000-000",
        "t-000-001",
        "t-000-002",
        "t-001-head",
    ]


def test_a_failed_tie_break_of_the_far_anchor_names_what_its_point_violates(tmp_path):
    """The two-chain sweep checks anchor B's tie-break before the last point: a failed
    one raises NoFeasibleAnchor naming, in the file's units, what its best point violates
    (the problem reaches the check)."""
    import json

    from optdesign.studies.diagnosis import violated_text
    from optdesign.studies.pareto.chains import NoFeasibleAnchor, TwoChains

    fork = load(ROOT / "problems" / "fork_min_backlash.toml")
    od.pareto(fork, ["size", "backlash"], 3, out=tmp_path, starts=1)
    lines = (tmp_path / "epsilon.jsonl").read_text().splitlines()[1:]
    done = {r["id"]: r for r in map(json.loads, lines)}
    chains = TwoChains(["size", "backlash"], 3, "epsilon", {"problem": fork}, "arc", None)
    first = {k: done[k] for k in ("anchor-size", "anchor-backlash-ms")}
    assert chains({"id": "anchor-backlash-ms"}, {}, first)  # the frame and point 0
    failed = dict(done["anchor-backlash"], status="failed", verified=False)
    # its best point: the anchor's design with every free variable at its lower bound
    failed["design"] = {**failed["design"], **{v.name: v.lower for v in fork.free}}
    failed["x"] = [v.lower for v in fork.free]
    shown = violated_text(fork, np.array(failed["x"]))
    assert shown  # that point violates something
    with pytest.raises(NoFeasibleAnchor) as caught:
        chains({"id": "anchor-backlash"}, {}, {**first, "anchor-backlash": failed})
    assert "anchor backlash: no feasible design found (status failed)" in str(caught.value)
    assert f"at the best point found: {shown}" in str(caught.value)


def test_a_design_independent_ripple_limit_is_checked_by_the_gp_against_its_value():
    """With the linkage fixed the ripple does not depend on the design: the GP checks
    ripple_max against the value itself (the NumPy model's at any design) - met at 0.3,
    named as the infeasible requirement at 0.2."""
    import copy

    from formulations.test_gp import CS_FIXED

    from optdesign.formulations.gp import build_gp

    ripple = None
    for limit, lead in ((0.3, None), (0.2, None), (0.2, 5.0)):
        data = copy.deepcopy(CS_FIXED)
        data["requirements"]["ripple_max"] = limit
        if lead is not None:  # the ratio then depends on no free variable at all
            data["variables"]["p"] = lead
        problem = problem_from_dict(data)
        if ripple is None:
            q = problem.quantities(problem.design_dict(problem.midpoint()))
            ratio = np.asarray(q.ratio, dtype=float).ravel()
            ripple = (ratio.max() - ratio.min()) / (ratio.max() + ratio.min())
            assert ripple == pytest.approx(0.238162, abs=1e-6)
        gp = build_gp(problem)
        assert gp.is_gp and "ripple_max" not in {c.name for c in gp.checks}
        expected = [] if limit > ripple else [f"ripple = {ripple:.6g} > ripple_max = 0.2"]
        assert gp.infeasible == expected
        # the ripple as the objective: a constant, the GP a feasibility check
        check = next(c for c in build_gp(problem, "ripple").checks if c.what == "objective")
        assert (check.ok, check.reason) == (True, f"constant {ripple:.6g} (design-independent)")


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


def test_an_anchor_message_without_the_problem_lists_the_records_violations():
    """Without the problem the message of a failed anchor falls back on the record's own
    list of violated rows, whatever design it holds."""
    from optdesign.studies.pareto.chains import anchor_message
    from optdesign.studies.pareto.records import PointRecord

    rec = PointRecord(
        id="anchor-size", kind="anchor", status="failed", verified=False, target="size", design={"R": 50.0},
        violated=["nut_travel", "mean_ratio"],
    )  # fmt: skip
    assert anchor_message("size", rec) == (
        "anchor size: no feasible design found (status failed); violated: nut_travel, mean_ratio"
    )
    rec.violated = []
    assert anchor_message("size", rec).endswith("violated: none reported")


def test_an_nlp_of_one_objective_named_by_a_string_holds_that_objective():
    from optdesign.formulations.nlp import build_nlp

    fork = load(ROOT / "problems" / "fork_min_backlash.toml")
    assert list(build_nlp(fork, "size").objective_values) == ["size"]
    assert list(build_nlp(fork, ["size", "backlash"]).objective_values) == ["size", "backlash"]


@pytest.mark.parametrize(
    ("where", "value", "message"),
    [
        (("requirements", "hinge_moment"), "1e308 kN*m", "'1e308 kN*m' is out of range"),
        (
            ("variables", "d"),
            {"catalogue": "HIWIN"},
            "the HIWIN screw catalogue gives d0 and p only",
        ),
    ],
)
def test_fin_actuator_inputs_refused_naming_their_field(where, value, message):
    """A hinge moment that overflows in internal units, a catalogue screw asked for a
    variable it does not give: each refused naming the field."""
    from optdesign.errors import OptDesignError

    data = tomllib.loads((ROOT / "problems" / "fin_actuator.toml").read_text())
    data[where[0]][where[1]] = value
    with pytest.raises(OptDesignError) as caught:
        od.load(data)
    assert f"{where[0]}.{where[1]}: {message}" in str(caught.value)


def test_common_hypervolumes_use_one_reference_point_for_every_front():
    """Two fronts measured against the reference point of both together: each front's
    common hypervolume is its hypervolume against that point (the larger front's is
    larger), not against its own."""
    from optdesign.studies.pareto.front import Front, FrontPoint, common_hypervolumes
    from optdesign.studies.pareto.metrics import hypervolume, reference_point

    def front(F):
        points = [
            FrontPoint(
                id=f"p{k}",
                kind="eps",
                status="optimal",
                verified=True,
                target="a",
                objectives={"a": a, "b": b},
            )
            for k, (a, b) in enumerate(F)
        ]
        return Front(["a", "b"], "m", points)

    small, large = front([[1.0, 2.0], [2.0, 1.0]]), front([[0.5, 3.0], [3.0, 0.5], [1.0, 1.0]])
    common_hypervolumes([small, large])
    ref = reference_point(np.vstack([small.F, large.F]))
    for f in (small, large):
        assert f.metrics["common_reference_point"] == pytest.approx(ref.tolist())
        assert f.metrics["hypervolume_common"] == pytest.approx(hypervolume(f.F, ref))
    assert small.metrics["hypervolume_common"] != pytest.approx(hypervolume(small.F))
    assert large.metrics["hypervolume_common"] > small.metrics["hypervolume_common"]


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


def test_a_store_left_open_never_keeps_the_process_alive(tmp_path):
    """A store writer's fsync thread is a daemon: a program that exits (or dies) with a
    store still open ends all the same, its records on disk."""
    import subprocess
    import sys
    import textwrap

    store = tmp_path / "s.jsonl"
    store.write_text("")
    code = textwrap.dedent(
        f"""
        from optdesign.storage.store import StoreWriter
        w = StoreWriter({str(store)!r})
        w.write({{"id": "a", "value": 1}})
        """
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert store.read_text() == '{"id": "a", "value": 1}\n'


def test_an_off_catalogue_screw_takes_the_nearest_items_data():
    """A (d0, p) pair the catalogue lacks (an off-catalogue point of a relaxation) reads
    the nearest row by relative distance in both: d0 = 21 mm, p = 5 mm is the
    R20-05 row, marked as not an item."""
    from optdesign.problem.drive import _nearest, catalogue_items

    fin = load(ROOT / "problems" / "fin_actuator.toml")
    items = catalogue_items(fin.spec.screw.catalogue, fin.spec.screw.nut)
    row, on = _nearest(items, 21.0, 5.0)
    assert (row.d0, row.p, on) == (20.0, 5.0, False)
    row, on = _nearest(items, 25.0, 10.0)
    assert (row.d0, row.p, on) == (25.0, 10.0, True)


def test_every_search_of_a_catalogue_front_takes_the_fronts_seed(monkeypatch, tmp_path):
    from optdesign.studies.pareto import catalogue_front

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["6 mm", "8 mm"]}
    problem = problem_from_dict(data)
    assert problem.spec.solver.seed != 5
    seeds = []
    search = catalogue_front.solve_catalogue

    def spy(*args, **kwargs):
        seeds.append(kwargs.get("seed"))
        return search(*args, **kwargs)

    monkeypatch.setattr(catalogue_front, "solve_catalogue", spy)
    od.pareto(problem, ["backlash", "motor_torque"], 3, out=tmp_path, starts=1, seed=5)
    assert seeds and set(seeds) == {5}


def test_a_keyed_pin_joint_adds_its_fixed_clearance_to_the_pins():
    """docs/mechanisms.md: a joint's ``key`` names its fixed clearance in the problem's
    ``[clearances]`` table; on a sized pin joint the value adds to the pin's own."""
    from optdesign.mechanisms.joints import Joint, PinJoint, with_fixed_clearances

    pin = Joint("P lever pin", "P", sensitivity=0.01, force=100.0, pin=PinJoint(8.0, 12.0))
    slide = Joint("A slide", "A", sensitivity=0.01)
    unkeyed = Joint("Q other pin", "", sensitivity=0.01, force=100.0, pin=PinJoint(8.0, 12.0))
    out = with_fixed_clearances([pin, slide, unkeyed], {"P": 0.004, "A": 0.002})
    assert [j.name for j in out] == ["P lever pin", "A slide", "Q other pin"]
    assert [j.clearance for j in out] == [0.004, 0.002, 0.0]
    assert out[0].pin is pin.pin  # the pin itself is kept: its fit adds on top
    # a joint with neither a pin nor a fixed clearance is dropped from the chain
    assert with_fixed_clearances([slide], {}) == []


def test_a_joint_a_plug_in_declares_wrongly_is_refused_naming_it():
    """A mechanism's clearance chain (docs/mechanisms.md): each joint needs a sensitivity
    unless it is angular, a pin joint the force it carries, and no clearance is negative."""
    from optdesign.mechanisms.joints import Joint, PinJoint

    cases = [
        (dict(name="C slide", key="C"), "joint C slide", "needs a sensitivity (rad/mm)"),
        (
            dict(name="D pin", sensitivity=0.01, pin=PinJoint(8.0, 12.0)),
            "joint D pin",
            "a pin joint needs the force it carries",
        ),
        (dict(name="A", sensitivity=0.01, clearance=-0.001), "joint A.clearance", "must be >= 0"),
    ]
    for kwargs, field, reason in cases:
        with pytest.raises(InputError) as caught:
            Joint(**kwargs)
        assert (caught.value.field, caught.value.reason) == (field, reason)
    assert Joint(name="O shaft", angular=True).sensitivity is None  # an angle needs none


def test_a_robust_nlp_takes_the_callers_risk_measure_over_the_files():
    """``build_robust_nlp(..., risk=...)`` (od.solve's robust formulation with a risk of
    the caller's): the caller's measure is minimised, the file's only by default."""
    from optdesign.formulations.robust import build_robust_nlp
    from optdesign.problem import load_problem

    problem = load_problem(ROOT / "problems" / "cs_min_backlash_robust.toml")  # risk = "cvar"
    assert build_robust_nlp(problem).default_target == "CVaR_0.9(backlash)"
    assert build_robust_nlp(problem, risk="mean_std").default_target == "mean+2std(backlash)"
    # and the caller's k of mean + k std, and alpha of CVaR, over the file's (2 and 0.9)
    assert build_robust_nlp(problem, risk="mean_std", k=3.0).default_target == (
        "mean+3std(backlash)"
    )
    assert build_robust_nlp(problem, alpha=0.8).default_target == "CVaR_0.8(backlash)"


def test_an_epsilon_bound_on_a_quantity_the_formulation_lacks_is_refused_naming_them():
    from optdesign.errors import ProblemError
    from optdesign.problem import load_problem
    from optdesign.studies.nlp_solve import formulation_for

    problem = load_problem(ROOT / "problems" / "cs_min_backlash.toml")
    nlp = formulation_for(problem, ("backlash", "ripple"))
    with pytest.raises(ProblemError) as caught:
        nlp.bounds(eps={"size": 1.0})
    assert str(caught.value) == (
        "epsilon bound on 'size': not an objective of this formulation (backlash, ripple)"
    )


def test_a_robust_nlp_of_no_sample_is_refused_naming_the_field():
    from types import SimpleNamespace

    from optdesign.errors import ProblemError
    from optdesign.formulations.robust import build_robust_nlp
    from optdesign.problem import load_problem

    problem = load_problem(ROOT / "problems" / "cs_min_backlash_robust.toml")
    with pytest.raises(ProblemError) as caught:
        build_robust_nlp(problem, samples=SimpleNamespace(n=0))
    assert str(caught.value) == "tolerances.samples: need at least one sample"


def test_a_robust_ripple_names_every_samples_envelope_variables():
    """A spread objective (the ratio ripple) under scatter: two envelope variables per
    sample, each named, as many names as auxiliary variables."""
    from optdesign.formulations.robust import build_robust_nlp, draw_samples
    from optdesign.problem import load_problem

    problem = load_problem(ROOT / "problems" / "cs_min_backlash_robust.toml")
    samples = draw_samples(problem, 3, 0)
    nlp = build_robust_nlp(problem, "ripple", samples=samples)
    assert nlp.z.shape[0] == nlp.n_design + len(nlp.aux_names)
    for s in range(3):
        assert {f"ripple_lo[s{s}]", f"ripple_hi[s{s}]"} <= set(nlp.aux_names)


def test_a_mechanism_without_its_kinematics_or_pins_says_what_to_write():
    import optdesign as od
    from optdesign.errors import InputError

    class Bare(od.Mechanism):
        name = "t32_bare"
        variables = {"R": od.VariableInfo("length", "lever")}  # noqa: RUF012

    bare = Bare(R=50.0, p=5.0)
    with pytest.raises(NotImplementedError, match=r"^Bare must define nut_position\(phi\)$"):
        bare.nut_position(0.1)
    with pytest.raises(InputError) as caught:
        bare.joints(np.zeros(3), 1.0e5, None)
    assert caught.value.field == "pin_joints"
    assert caught.value.reason.endswith("declares no pins: set pin_joints or write joints()")


def test_a_tie_in_distance_from_the_items_branches_on_the_first_declared_variable():
    from types import SimpleNamespace

    from optdesign.studies.catalogue_bnb import on_items

    a = SimpleNamespace(name="a", values=(1.0, 2.0))
    b = SimpleNamespace(name="b", values=(10.0, 20.0))
    box = {"a": (1.0, 2.0), "b": (10.0, 20.0)}
    res = SimpleNamespace(design={"a": 1.5, "b": 15.0})  # both halfway: the same distance
    worst, items = on_items([a, b], box, res)
    assert worst is a and items == {"a": 1.0, "b": 10.0}
    on = SimpleNamespace(design={"a": 2.0, "b": 10.0})
    assert on_items([a, b], box, on)[0] is None


def test_the_conforming_contact_pressure_uses_the_pin_radius():
    """The conforming solution's peak pressure scales as E* dR / R (R the pin's radius,
    dR the radial clearance): checked against the model's dimensionless pressure."""
    from optdesign.mechanisms.joints import PinJoint
    from optdesign.models import pin_contact as pc

    pin = PinJoint(8.0, 12.0, contact="conforming")
    F = 2000.0
    dR = 0.5 * float(pin.fit_clearance())
    E_s = pc.effective_modulus_similar(pin.E, pin.nu)
    P_star = pc.load_parameter(F, pin.L, dR, pin.E, pin.nu)
    expected = E_s * dR / 4.0 * pc.max_pressure_star(P_star)  # R = d / 2 = 4 mm
    assert float(pin.contact_pressure(F)) == pytest.approx(expected, rel=1e-12)
    wider = PinJoint(16.0, 12.0, contact="conforming", extra=0.0)
    assert float(wider.contact_pressure(F)) < float(pin.contact_pressure(F))
