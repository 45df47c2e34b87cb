"""Behaviour of the drive (problem/drive.py) and its requirement blocks
(problem/drive_requirements.py), pinned function by function: every block's bounds, unit,
description and value, every branch of the screw data, the parameters of the solver path
and the nut stiffness rules, and the messages of what a problem lacks.

Expected values come from the shipped HIWIN CSV read with the csv module, from the
crank-slider's position equation differentiated by central differences and from hand
formulas (HIWIN F 3.4, 3.8, 3.25-3.35, ISO 3408-5 L10) - never from the function under test.
"""

from __future__ import annotations

import copy
import csv
import math
import tomllib
from types import SimpleNamespace

import numpy as np
import pytest
from problem.test_drive import CATALOGUE_CSV, FIN, FIN_DESIGN, HINGE, _dx, _x

from optdesign.errors import ProblemError
from optdesign.problem import drive, problem_from_dict

BASE = tomllib.loads(FIN.read_text())
PHI = np.radians(np.linspace(-30, 30, 61))
V = np.abs(_dx(100.0, 150.0, 90.0, 0.2, PHI))  # mm/rad of the fin design
F_NUT = HINGE / V  # N
SPEED = V * math.radians(120.0) / 5.0 * 60.0  # 1/min


def _rows() -> list[dict[str, str]]:
    with CATALOGUE_CSV.open() as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def _best(d0: float, p: float, nut: str | None = None) -> dict[str, float]:
    """The strongest nut of (d0, p): highest Ca, then C0a, then rigidity."""
    rows = [
        r
        for r in _rows()
        if float(r["d0"]) == d0
        and float(r["p"]) == p
        and (nut is None or r["designation"].endswith(nut))
    ]
    best = max(rows, key=lambda r: (float(r["Ca"]), float(r["C0a"]), float(r["rigidity_N_per_um"])))
    return {
        "d1": float(best["d1"]),
        "Ca": float(best["Ca"]),
        "C0a": float(best["C0a"]),
        "K_nut": float(best["rigidity_N_per_um"]) * 1e3,
        "id": best["id"],
    }


def _fin(screw=None, drop_screw=(), drop_req=(), **req):
    """fin_actuator with ``screw`` keys changed, some keys dropped, requirements changed."""
    data = copy.deepcopy(BASE)
    for key in drop_screw:
        data["screw"].pop(key, None)
    data["screw"].update(screw or {})
    for key in drop_req:
        data["requirements"].pop(key, None)
    data["requirements"].update(req)
    return problem_from_dict(data)


def _x_of(problem, **design):
    d = dict(FIN_DESIGN, **design)
    return np.array([d[v.name] for v in problem.free])


def _blocks(problem, **design):
    ex = problem.expressions(problem.design_dict(_x_of(problem, **design)))
    return {b.name: b for b in ex.constraints}


def _values(block) -> np.ndarray:
    return np.asarray(block.expr, dtype=float).ravel()


@pytest.fixture(scope="module")
def fin_blocks():
    problem = _fin()
    return problem, _blocks(problem)


# --- drive_requirements: the blocks of fin_actuator ----------------------------------------
DRIVE_NAMES = [
    "back_drive",
    "screw_catalogue_membership",
    "screw_buckling",
    "screw_yield",
    "critical_speed",
    "dn",
    "static_safety",
    "life",
    "stiffness",
]


def test_fin_actuator_has_the_drive_blocks_in_order_with_their_bounds_units_and_labels(
    fin_blocks,
):
    problem, blocks = fin_blocks
    names = [n for n in blocks if n in [*DRIVE_NAMES, "efficiency"]]
    assert names == DRIVE_NAMES
    expected = {
        "back_drive": (0.0, None, ""),
        "screw_catalogue_membership": (1.0, None, ""),
        "screw_buckling": (None, 1.0, ""),
        "screw_yield": (None, 1.0, ""),
        "critical_speed": (None, 1.0, ""),
        "dn": (None, 70_000.0, "mm/min"),
        "static_safety": (None, 1.0, ""),
        "life": (200.0, None, "h"),
        "stiffness": (None, 1.0, ""),
    }
    for name, (lo, hi, unit) in expected.items():
        b = blocks[name]
        assert (b.lower, b.upper, b.unit) == (lo, hi, unit), name
    one_value = {"back_drive", "screw_catalogue_membership", "life"}
    for name in DRIVE_NAMES:
        labels = blocks[name].labels
        assert labels == ([""] if name in one_value else problem.phi_labels), name
    assert len(problem.phi_labels) == 61


def test_fin_actuator_drive_block_descriptions(fin_blocks):
    _, blocks = fin_blocks
    assert {n: blocks[n].description for n in DRIVE_NAMES} == {
        "back_drive": "back-driving efficiency (back-drivable)",
        "screw_catalogue_membership": "(d0, p) is a screw of the catalogue",
        "screw_buckling": "nut force / buckling load (fixed-supported, conservative factor "
        "eta_2 = 10)",
        "screw_yield": "nut force / permissible shaft load",
        "critical_speed": "screw speed / critical speed (fixed-supported, conservative factor "
        "lambda_2 = 15)",
        "dn": "d_m x screw speed (DN value; rule ball-centre: ground limit 70,000 on the "
        "ball-centre diameter)",
        "static_safety": "f_s x nut force / static rating C0a",
        "life": "rated life L10 over the duty cycle (f_w = 1.2; HIWIN f_p: 1.1-1.2 without "
        "impact, 1.3-1.8 normal, 2-3 impact and vibration)",
        "stiffness": "required stiffness / stiffness at the output (nut: HIWIN F 3.35 at the "
        "hinge moment's nut force)",
    }


def test_fin_actuator_drive_block_values_by_hand(fin_blocks):
    problem, blocks = fin_blocks
    row = _best(25.0, 5.0)
    d1 = row["d1"]
    # buckling, conservative fixed-supported eta_2 = min(0.5 x 40.72 x 0.5, 10) = 10
    P1 = 10.0 * d1**4 / 300.0**2 * 1e4
    assert _values(blocks["screw_buckling"]) == pytest.approx(F_NUT / P1, rel=1e-7)
    assert _values(blocks["screw_yield"]) == pytest.approx(
        F_NUT / (147.0 * math.pi * d1**2 / 4.0), rel=1e-7
    )
    # critical speed, conservative lambda_2 = min(0.8 x 27.1 x 0.692, 15.1)
    N1 = 0.8 * 27.1 * 0.692 * d1 / 300.0**2 * 1e7
    assert _values(blocks["critical_speed"]) == pytest.approx(SPEED / N1, rel=1e-7)
    assert _values(blocks["dn"]) == pytest.approx(25.0 * SPEED, rel=1e-7)
    assert _values(blocks["static_safety"]) == pytest.approx(1.5 * F_NUT / row["C0a"], rel=1e-7)
    assert _values(blocks["screw_catalogue_membership"]) == pytest.approx([1.0])
    x = _x_of(problem)
    q = problem.quantities(problem.design_dict(x))
    assert _values(blocks["life"]) == pytest.approx(float(np.ravel(q.life_hours)[0]), rel=1e-12)
    stiffness = 600e3 * 1e3  # N*mm/rad
    assert _values(blocks["stiffness"]) == pytest.approx(
        np.asarray(q.output_compliance, dtype=float).ravel() * stiffness, rel=1e-12
    )
    assert _values(blocks["back_drive"]) == pytest.approx(
        np.ravel(np.asarray(q.efficiency_back, dtype=float)), rel=1e-12
    )


@pytest.mark.parametrize(
    ("factors", "mounting", "eta", "lam"),
    [
        ("HIWIN", "fixed-supported", "10.18", "15"),
        ("common", "fixed-supported", "10", "15.1"),
        ("HIWIN", "fixed-free", "1.272", "3.187"),
        ("conservative", "fixed-fixed", "20", "21.68"),
    ],
)
def test_buckling_and_critical_speed_name_the_mounting_and_the_rule_factor(
    factors, mounting, eta, lam
):
    problem = _fin({"mounting_factors": factors, "mounting": mounting})
    blocks = _blocks(problem)
    assert blocks["screw_buckling"].description == (
        f"nut force / buckling load ({mounting}, {factors} factor eta_2 = {eta})"
    )
    assert blocks["critical_speed"].description == (
        f"screw speed / critical speed ({mounting}, {factors} factor lambda_2 = {lam})"
    )
    d1 = _best(25.0, 5.0)["d1"]
    hiwin_fk = {"fixed-free": 0.0625, "fixed-supported": 0.5, "fixed-fixed": 1.0}[mounting]
    common = {"fixed-free": 1.3, "fixed-supported": 10.0, "fixed-fixed": 20.0}[mounting]
    eta2 = {
        "HIWIN": 0.5 * 40.72 * hiwin_fk,
        "common": common,
        "conservative": min(0.5 * 40.72 * hiwin_fk, common),
    }[factors]
    P1 = eta2 * d1**4 / 300.0**2 * 1e4
    assert _values(blocks["screw_buckling"]) == pytest.approx(F_NUT / P1, rel=1e-7)


@pytest.mark.parametrize(
    ("rule", "dn_max", "limit", "text"),
    [
        (
            "HIWIN",
            "ground",
            90_000.0,
            "d0 x screw speed (DN value; rule HIWIN: ground limit 90,000 on the nominal diameter)",
        ),
        (
            "HIWIN",
            "rolled",
            70_000.0,
            "d0 x screw speed (DN value; rule HIWIN: rolled limit 70,000 on the nominal diameter)",
        ),
        (
            "ball-centre",
            85_000,
            85_000.0,
            "d_m x screw speed (DN value; rule ball-centre: "
            "limit 85,000 on the ball-centre diameter)",
        ),
        (
            "HIWIN",
            123_456.7,
            123_456.7,
            "d0 x screw speed (DN value; rule HIWIN: limit 123,457 on the nominal diameter)",
        ),
    ],
)
def test_dn_block_by_rule_and_grade(rule, dn_max, limit, text):
    blocks = _blocks(_fin(dn_rule=rule, dn_max=dn_max))
    b = blocks["dn"]
    assert (b.lower, b.upper, b.unit, b.description) == (None, limit, "mm/min", text)
    assert _values(b) == pytest.approx(25.0 * SPEED, rel=1e-7)


def test_dn_on_the_ball_centre_uses_the_mean_diameter_not_d0():
    """A continuous screw's d_m equals d0; the solver path's item data too: the two
    diameters differ only through a hand-made ScrewData."""
    q = SimpleNamespace()
    data = drive.ScrewData(d0=20.0, p=5.0, d_m=21.0, d1=17.0, Ca=1e4, C0a=1e4, K_nut=1e5)
    problem = _fin(dn_rule="ball-centre", dn_max=70_000)
    real = problem.quantities(problem.design_dict(_x_of(problem)))
    q.problem, q.screw, q.nut_force = problem, data, real.nut_force
    q.screw_speed = np.full(61, 100.0)
    q.drive_efficiency, q.efficiency_back = 0.9, 0.5
    q.life_hours, q.output_compliance = 1.0, 1.0
    from optdesign.problem.drive_requirements import drive_blocks

    blocks = {b.name: b for b in drive_blocks(q, ["a"])}
    assert _values(blocks["dn"]) == pytest.approx(np.full(61, 2100.0))
    assert blocks["dn"].labels == ["a"]
    problem = _fin(dn_rule="HIWIN", dn_max=70_000)
    q.problem = problem
    blocks = {b.name: b for b in drive_blocks(q, ["a"])}
    assert _values(blocks["dn"]) == pytest.approx(np.full(61, 2000.0))


def test_back_drive_forbidden_is_an_upper_bound_named_self_locking():
    b = _blocks(_fin(back_drive="forbidden"))["back_drive"]
    assert (b.lower, b.upper, b.labels, b.unit) == (None, 0.0, [""], "")
    assert b.description == "back-driving efficiency (self-locking)"


def test_efficiency_min_block_on_fin_actuator():
    problem = _fin(efficiency_min=0.9)
    blocks = _blocks(problem)
    b = blocks["efficiency"]
    assert list(blocks).index("efficiency") == list(blocks).index("back_drive") - 1
    assert (b.lower, b.upper, b.labels, b.unit) == (0.9, None, [""], "")
    assert b.description == "forward efficiency of screw and gear"
    q = problem.quantities(problem.design_dict(_x_of(problem)))
    assert _values(b) == pytest.approx(np.ravel(np.asarray(q.drive_efficiency, dtype=float)))


def test_checks_switched_off_or_without_length_leave_their_blocks_out():
    assert "screw_buckling" not in _blocks(_fin({"check_buckling": False}))
    assert "screw_yield" not in _blocks(_fin({"check_yield": False}))
    blocks = _blocks(_fin(drop_screw=["length"], critical_speed=False))
    assert "screw_buckling" not in blocks and "screw_yield" in blocks
    assert "critical_speed" not in blocks


def test_critical_speed_without_a_screw_length_names_what_it_needs():
    problem = _fin(drop_screw=["length"])
    with pytest.raises(ProblemError) as e:
        _blocks(problem)
    assert str(e.value) == (
        "requirements.critical_speed: needs screw.length (the distance between the supports)"
    )


@pytest.mark.parametrize(
    ("nut", "expected"),
    [
        ({"nut_stiffness_rule": "table"}, "the catalogue's table value"),
        (
            {"nut_stiffness_rule": "preload", "nut_preload": 0.05},
            "HIWIN F 3.34 at a preload of 0.05 Ca",
        ),
        ({"nut_stiffness_rule": "load"}, "HIWIN F 3.35 at the hinge moment's nut force"),
        ({"nut_stiffness_rule": None}, "HIWIN F 3.35 at the hinge moment's nut force"),
    ],
)
def test_stiffness_description_names_the_nut_rule(nut, expected):
    screw = {k: v for k, v in nut.items() if v is not None}
    drop = ["nut_stiffness_rule"] if nut["nut_stiffness_rule"] is None else []
    b = _blocks(_fin(screw, drop_screw=drop))["stiffness"]
    assert b.description == f"required stiffness / stiffness at the output (nut: {expected})"


def test_stiffness_description_for_the_duty_cycles_mean_load():
    b = _blocks(_fin(stiffness_load="duty-mean"))["stiffness"]
    assert b.description == (
        "required stiffness / stiffness at the output (nut: HIWIN F 3.35 at the duty cycle's "
        "mean load)"
    )


def test_back_drive_and_life_without_a_screw_section_are_refused_naming_the_field():
    from problem.test_drive import _data

    with pytest.raises(ProblemError) as e:
        problem = problem_from_dict(_data(None, None, back_drive="required"))
        problem.evaluate(np.array([80.0, 120.0, 60.0, 5.0, 0.1]))
    assert str(e.value) == (
        "requirements.back_drive: needs a [screw] section (its type, friction and size)"
    )
    steps = [{"deflection": "0 deg", "hinge_moment": "100 N*m", "time": 1.0}]
    data = _data(None, None, life_min="10 h", duty_cycle=steps, deflection_rate="60 deg/s")
    with pytest.raises(ProblemError) as e:
        problem = problem_from_dict(data)
        problem.evaluate(np.array([80.0, 120.0, 60.0, 5.0, 0.1]))
    assert str(e.value) == (
        "requirements.life_min: needs a [screw] section (its size, catalogue and mounting)"
    )


# --- drive: the catalogue ------------------------------------------------------------------
@pytest.mark.parametrize("nut", [None, "FSI", "FSC"])
def test_catalogue_items_are_the_strongest_nut_of_each_pair(nut):
    items = drive.catalogue_items("HIWIN", nut)
    pairs = {
        (float(r["d0"]), float(r["p"]))
        for r in _rows()
        if nut is None or r["designation"].endswith(nut)
    }
    assert set(items) == pairs
    for (d0, p), item in items.items():
        best = _best(d0, p, nut)
        assert item.id == best["id"], (d0, p)
        assert nut is None or item.nut == nut


def test_catalogue_values_are_sorted_and_unique_and_other_names_refused():
    assert drive.catalogue_values("HIWIN", "d0") == (
        8.0,
        14.0,
        15.0,
        16.0,
        20.0,
        25.0,
        32.0,
        38.0,
        40.0,
    )
    assert drive.catalogue_values("HIWIN", "p") == (2.0, 2.5, 5.0, 10.0, 16.0, 20.0)
    assert drive.catalogue_values("HIWIN", "p", "FSI") == (2.0, 2.5, 5.0, 10.0)
    assert drive.catalogue_values("HIWIN", "d0", nut="FSC")[0] == 14.0
    with pytest.raises(ProblemError) as e:
        drive.catalogue_values("HIWIN", "R")
    assert str(e.value) == "variables.R: the HIWIN screw catalogue gives d0 and p only"
    with pytest.raises(ProblemError) as e:
        drive.catalogue_items("THK", None)
    assert str(e.value) == "screw.catalogue: unknown catalogue 'THK' (known: HIWIN)"


def test_row_values_and_the_load_factor_of_hiwin_f335():
    row = drive.catalogue_items("HIWIN", None)[(25.0, 5.0)]
    best = _best(25.0, 5.0)
    assert drive._row_value(row, "d1") == best["d1"]
    assert drive._row_value(row, "K_nut") == best["K_nut"]
    assert drive._row_value(row, "K_load") == pytest.approx(
        0.8 * best["K_nut"] / (0.28 * best["Ca"]) ** (1 / 3), rel=1e-12
    )
    assert np.isnan(drive._row_value(None, "Ca"))
    no_mass = copy.copy(row)
    object.__setattr__(no_mass, "nut_mass", None)
    assert np.isnan(drive._row_value(no_mass, "nut_mass"))


@pytest.mark.parametrize(
    ("d0", "p", "near", "exact"),
    [
        (25.0 + 2e-10, 5.0 - 2e-10, (25.0, 5.0), True),
        (25.0, 5.001, (25.0, 5.0), False),
        (26.0, 5.0, (25.0, 5.0), False),
        (29.0, 5.0, (32.0, 5.0), False),  # log(32/29) < log(29/25); linear: 3 < 4 too
        (22.0, 5.0, (20.0, 5.0), False),  # log(22/20) = 0.095 < log(25/22) = 0.128
        (22.5, 5.0, (25.0, 5.0), False),  # log(25/22.5) = 0.105 < log(22.5/20) = 0.118
        (25.0, 7.4, (25.0, 10.0), False),  # log(10/7.4) = 0.301 < log(7.4/5) = 0.392
        (25.0, 3.1, (25.0, 2.0), False),  # log(3.1/2) = 0.438 < log(5/3.1) = 0.478
        (14.0, 5.0, (16.0, 5.0), False),  # 14 x 5 unsold: the 16 x 5 beats the 14 x 10
    ],
)
def test_nearest_item_by_log_distance(d0, p, near, exact):
    items = drive.catalogue_items("HIWIN", None)
    item, is_item = drive._nearest(items, d0, p)
    assert (item.d0, item.p) == near and is_item is exact


def test_lookup_scalar_and_array_and_no_screw_where_sizes_are_not_positive():
    items = drive.catalogue_items("HIWIN", None)
    vals, on = drive._lookup(items, 25.0, 5.0, ["d1", "Ca"])
    assert type(on) is float and on == 1.0
    assert type(vals["d1"]) is float and vals["d1"] == _best(25.0, 5.0)["d1"]
    assert vals["Ca"] == _best(25.0, 5.0)["Ca"]
    d0 = np.array([[25.0], [np.nan], [25.0], [-25.0], [20.0], [np.inf]])
    p = np.array([[5.0], [5.0], [0.0], [5.0], [-5.0], [5.0]])
    vals, on = drive._lookup(items, d0, p, ["C0a"])
    assert on.shape == (6, 1) and on.ravel().tolist() == [1.0, 0, 0, 0, 0, 0]
    assert vals["C0a"][0, 0] == _best(25.0, 5.0)["C0a"]
    assert np.isnan(vals["C0a"][1:]).all()
    # small positive sizes have a nearest screw; a valid design after invalid ones counts
    d0 = np.array([0.0, 0.5, 8.0, np.nan, 32.0])
    p = np.array([5.0, 2.5, 0.5, 5.0, 10.0])
    vals, on = drive._lookup(items, d0, p, ["d1"])
    assert on.tolist() == [0.0, 0.0, 0.0, 0.0, 1.0]
    assert np.isnan(vals["d1"][[0, 3]]).all()
    assert vals["d1"][[1, 2]].tolist() == [_best(8.0, 2.5)["d1"]] * 2
    assert vals["d1"][4] == _best(32.0, 10.0)["d1"]
    # broadcast: one lead against two diameters
    vals, on = drive._lookup(items, np.array([20.0, 25.0]), 5.0, ["d1"])
    assert vals["d1"].tolist() == [_best(20.0, 5.0)["d1"], _best(25.0, 5.0)["d1"]]
    assert on.tolist() == [1.0, 1.0]


# --- drive: parameters of the solver path --------------------------------------------------
def _fit_ratio(fit: str, diameters, which: str) -> float:
    """The smallest table/smooth clearance ratio over ``diameters`` (the models' clearances)."""
    from optdesign.models.fit_formulas import Fit

    f = Fit.parse(fit, "fit", values="table")
    return min(
        float(f.clearance(D, which, values="table")) / float(f.clearance(D, which, values="smooth"))
        for D in diameters
    )


def test_fit_values_is_the_files_choice_else_table_for_a_catalogue_pin():
    assert drive.fit_values(_fin()) == "table"
    assert drive.fit_values(_fin(fit_values="smooth")) == "smooth"
    continuous = copy.deepcopy(BASE)
    continuous["variables"]["d"] = {"lower": "4 mm", "upper": "16 mm"}
    assert drive.fit_values(problem_from_dict(continuous)) == "smooth"
    continuous["requirements"]["fit_values"] = "table"
    with pytest.raises(ProblemError) as e:
        problem_from_dict(continuous).parameters()
    assert str(e.value) == (
        "requirements.fit_values: table values need pin diameters from a catalogue "
        '(d = { catalogue = "ISO 2338", ... }) or a fixed d; use "smooth" for a continuous d'
    )
    fixed = copy.deepcopy(BASE)
    fixed["variables"]["d"] = "6 mm"
    assert drive.fit_values(problem_from_dict(fixed)) == "smooth"
    fixed["requirements"]["fit_values"] = "table"
    problem = problem_from_dict(fixed)
    assert drive.fit_values(problem) == "table"
    # a fixed pin has its one item: the table clearance at 6 mm, H7 +12/0 um, g6 -4/-12 um
    values = problem.parameter_values({"d0": (25.0, 25.0), "p": (5.0, 5.0)})
    assert values["fit_ratio_max"] == pytest.approx(_fit_ratio("H7/g6", [6.0], "max"))
    assert values["fit_ratio_min"] == pytest.approx(_fit_ratio("H7/g6", [6.0], "min"))


def test_parameter_defaults_of_fin_actuator_and_without_a_table_fit():
    names = ["screw_d1", "screw_Ca", "screw_C0a", "screw_K_nut", "screw_K_load"]
    assert _fin().parameters() == {"fit_ratio_max": 1.0, "fit_ratio_min": 1.0} | dict.fromkeys(
        names, 1.0
    )
    assert _fin(fit_values="smooth").parameters() == dict.fromkeys(names, 1.0)


def test_a_fit_without_smooth_formula_takes_the_smallest_table_clearance():
    """H7/g4 exists only as table values (IT4): the parameter is the clearance itself (mm),
    the smallest over the node's pins."""
    from optdesign.models.fit_formulas import Fit

    problem = _fin(fit="H7/g4")
    f = Fit.parse("H7/g4", "fit", values="table")
    pins = problem.by_name["d"].values
    everywhere = {
        w: min(float(f.clearance(D, w, values="table")) for D in pins) for w in ("max", "min")
    }
    defaults = problem.parameters()
    assert defaults["fit_ratio_max"] == pytest.approx(everywhere["max"], rel=1e-12)
    assert defaults["fit_ratio_min"] == pytest.approx(everywhere["min"], rel=1e-12)
    at_8 = problem.parameter_values({"d": (8.0, 8.0), "d0": (25.0, 25.0), "p": (5.0, 5.0)})
    assert at_8["fit_ratio_max"] == pytest.approx(float(f.clearance(8.0, "max", values="table")))
    assert at_8["fit_ratio_min"] == pytest.approx(float(f.clearance(8.0, "min", values="table")))


def test_parameter_values_at_a_leaf_and_over_a_node():
    problem = _fin()
    leaf = problem.parameter_values({"d0": (25.0, 25.0), "p": (5.0, 5.0), "d": (6.0, 6.0)})
    row = _best(25.0, 5.0)
    assert leaf == pytest.approx(
        {
            "fit_ratio_max": _fit_ratio("H7/g6", [6.0], "max"),
            "fit_ratio_min": _fit_ratio("H7/g6", [6.0], "min"),
            "screw_d1": row["d1"],
            "screw_Ca": row["Ca"],
            "screw_C0a": row["C0a"],
            "screw_K_nut": row["K_nut"],
            "screw_K_load": 0.8 * row["K_nut"] / (0.28 * row["Ca"]) ** (1 / 3),
        },
        rel=1e-12,
    )
    # a node: the most favourable values of its items, each field on its own
    node = problem.parameter_values({"d0": (16.0, 20.0), "p": (2.0, 5.0), "d": (5.0, 10.0)})
    rows = [_best(d0, p) for d0, p in [(16.0, 2.0), (16.0, 5.0), (20.0, 2.0), (20.0, 5.0)]]
    for field in ("d1", "Ca", "C0a", "K_nut"):
        assert node[f"screw_{field}"] == max(r[field] for r in rows), field
    k_load = [0.8 * r["K_nut"] / (0.28 * r["Ca"]) ** (1 / 3) for r in rows]
    assert node["screw_K_load"] == pytest.approx(max(k_load), rel=1e-12)
    pins = [D for D in problem.by_name["d"].values if 5.0 <= D <= 10.0]
    assert len(pins) >= 3
    assert node["fit_ratio_max"] == pytest.approx(_fit_ratio("H7/g6", pins, "max"))
    assert node["fit_ratio_min"] == pytest.approx(_fit_ratio("H7/g6", pins, "min"))


def test_box_edges_count_within_the_tolerance_and_free_variables_span_their_bounds():
    problem = _fin()
    row = _best(25.0, 5.0)
    near = problem.parameter_values(
        {"d0": (25.0 + 5e-10, 25.0 + 5e-10), "p": (5.0 - 5e-10, 5.0 - 5e-10), "d": (6.0, 6.0)}
    )
    assert near["screw_d1"] == row["d1"]
    assert problem.parameter_values({"d0": (25.0 + 5e-9, 26.0), "p": (5.0, 5.0)}).keys() == {
        "fit_ratio_max",
        "fit_ratio_min",
    }
    # the pins: a relative tolerance of 1e-9 x the upper end
    pin = problem.parameter_values(
        {"d": (6.0 + 3e-9, 6.0 + 3e-9), "d0": (25.0, 25.0), "p": (5.0, 5.0)}
    )
    assert pin["fit_ratio_max"] == pytest.approx(_fit_ratio("H7/g6", [6.0], "max"))
    empty = problem.parameter_values(
        {"d": (6.0 + 3e-8, 6.0 + 3e-8), "d0": (25.0, 25.0), "p": (5.0, 5.0)}
    )
    assert (empty["fit_ratio_max"], empty["fit_ratio_min"]) == (1.0, 1.0)
    # d0 and p absent from the box: their bounds (12-25 mm, 2-10 mm)
    whole = problem.parameter_values({"d": (6.0, 6.0)})
    rows = [
        _best(d0, p) for d0, p in drive.catalogue_items("HIWIN", None) if 12 <= d0 <= 25 and p <= 10
    ]
    assert whole["screw_Ca"] == max(r["Ca"] for r in rows)
    assert whole["screw_d1"] == max(r["d1"] for r in rows)
    # a fixed lead: its value, not a range
    fixed = copy.deepcopy(BASE)
    fixed["variables"]["p"] = "5 mm"
    fixed = problem_from_dict(fixed)
    values = fixed.parameter_values({"d": (6.0, 6.0)})
    five = [_best(d0, 5.0) for d0 in (16.0, 20.0, 25.0)]
    assert values["screw_C0a"] == max(r["C0a"] for r in five)
    assert values["screw_d1"] == max(r["d1"] for r in five)


def test_box_has_item():
    problem = _fin()
    assert drive.box_has_item(problem, {"d0": (25.0, 25.0), "p": (5.0, 5.0)})
    assert not drive.box_has_item(problem, {"d0": (14.0, 14.0), "p": (5.0, 5.0)})
    assert not drive.box_has_item(problem, {"d0": (13.0, 13.9), "p": (2.0, 10.0)})
    # 25 x 2 and 25 x 5 exist, no lead between: the box's lead ends are its own
    assert not drive.box_has_item(problem, {"d0": (25.0, 25.0), "p": (3.0, 4.0)})
    from problem.test_drive import _data

    continuous = problem_from_dict(_data({"kind": "ball"}, {"d0": "20 mm"}))
    assert drive.box_has_item(continuous, {"d0": (13.0, 13.9)})
    assert drive.box_has_item(problem_from_dict(_data(None, None)), {})
    assert continuous.parameters() == {}
    assert problem_from_dict(_data(None, None)).parameters() == {}


# --- drive: screw data, efficiency, speed, life --------------------------------------------
def _q(problem, **design):
    return problem.quantities(problem.design_dict(_x_of(problem, **design)))


def test_screw_data_on_the_solver_path_reads_the_parameters():
    problem = _fin()
    design = problem.design_dict(_x_of(problem))
    values = {"screw_d1": 1.5, "screw_Ca": 2.5, "screw_C0a": 3.5, "screw_K_nut": 4.5}
    values["screw_K_load"] = 5.5
    q = problem.quantities({**design, **problem.parameter_design(values)})
    assert q.screw == drive.ScrewData(
        25.0, 5.0, 25.0, d1=1.5, Ca=2.5, C0a=3.5, K_nut=4.5, K_load=5.5, on_catalogue=None
    )


def test_screw_data_of_a_catalogue_design_on_the_numpy_path():
    row = _best(25.0, 5.0)
    data = _q(_fin()).screw
    assert (data.d0, data.p, data.d_m) == (25.0, 5.0, 25.0)
    assert (data.d1, data.Ca, data.C0a, data.K_nut) == (
        row["d1"],
        row["Ca"],
        row["C0a"],
        row["K_nut"],
    )
    assert data.K_load == pytest.approx(0.8 * row["K_nut"] / (0.28 * row["Ca"]) ** (1 / 3))
    assert data.on_catalogue == 1.0
    fsc = _q(_fin({"nut": "FSC"})).screw
    assert fsc.Ca == _best(25.0, 5.0, "FSC")["Ca"] != row["Ca"]


def test_screw_data_of_a_continuous_screw_and_of_the_legacy_root_diameter():
    from problem.test_drive import DESIGN, _data

    def data_of(d):
        problem = problem_from_dict(d)
        x = np.array([DESIGN[v.name] for v in problem.free])
        return problem.quantities(problem.design_dict(x)).screw

    got = data_of(_data({"kind": "ball"}, {"d0": "20 mm"}))
    assert got == drive.ScrewData(20.0, 5.0, 20.0, pytest.approx(0.83 * 20.0), K_nut=None)
    got = data_of(_data({"root_ratio": 0.8, "nut_stiffness": "200 N/um"}, {"d0": "20 mm"}))
    assert (got.d1, got.K_nut, got.Ca, got.C0a) == (pytest.approx(16.0), 200e3, None, None)
    assert data_of(_data(None, {"d0": "20 mm"})).d1 == pytest.approx(16.6)
    legacy = _data(None, None)
    legacy["requirements"]["screw"] = {"root_diameter": "12.5 mm"}
    assert data_of(legacy) == drive.ScrewData(None, 5.0, None, 12.5)
    assert data_of(_data(None, None)) is None


def _ball(p, d_m, mu):
    lam, rho = math.atan(p / (math.pi * d_m)), math.atan(mu)
    return math.tan(lam) / math.tan(lam + rho), math.tan(lam - rho) / math.tan(lam)


def test_efficiencies_of_the_friction_model_and_of_hiwins_design_value():
    fwd, back = drive.efficiencies(_q(_fin()))
    want = _ball(5.0, 25.0, 0.005)
    assert float(np.ravel(fwd)[0]) == pytest.approx(want[0], rel=1e-9)
    assert float(np.ravel(back)[0]) == pytest.approx(want[1], rel=1e-9)
    fwd, back = drive.efficiencies(_q(_fin({"efficiency_design": "HIWIN"})))
    assert float(np.ravel(fwd)[0]) == pytest.approx(0.85, abs=1e-15)
    assert float(np.ravel(back)[0]) == pytest.approx(want[1], rel=1e-9)
    assert drive.gear_efficiencies(_fin().spec) == (0.96, 0.94)


def test_efficiencies_without_a_screw_section_are_the_requirements_constants():
    from problem.test_drive import DESIGN, _data

    def of(**req):
        problem = problem_from_dict(_data(None, None, **req))
        x = np.array([DESIGN[v.name] for v in problem.free])
        q = problem.quantities(problem.design_dict(x))
        return drive.efficiencies(q), drive.gear_efficiencies(problem.spec)

    assert of(eta_screw=0.9, eta_gear=0.8) == ((0.9, 1.0), (0.8, 1.0))
    lock = {"kind": "pin", "radius": "20 mm", "eta_screw_back": 0.7, "eta_gear_back": 0.6}
    assert of(eta_screw=0.9, eta_gear=0.8, lock=lock) == ((0.9, 0.7), (0.8, 0.6))


def test_screw_speed_at_one_angle():
    q = _q(_fin())
    phi = math.radians(10.0)
    v = abs(float(_dx(100.0, 150.0, 90.0, 0.2, phi)))
    got = float(np.ravel(drive.screw_speed(q, phi))[0])
    assert got == pytest.approx(v * math.radians(120.0) / 5.0 * 60.0, rel=1e-7)
    grid = np.asarray(drive.screw_speed(q), dtype=float).ravel()
    assert grid == pytest.approx(SPEED, rel=1e-7)


STEPS = [(5.0, 100e3, 2.0), (-20.0, 400e3, 1.0), (25.0, 250e3, 1.0)]


def _duty_by_hand():
    """ISO 3408-5: F_m = (sum F^3 n t / sum n t)^(1/3), n_m = sum n t / sum t."""
    v = [abs(float(_dx(100.0, 150.0, 90.0, 0.2, math.radians(a)))) for a, _, _ in STEPS]
    F = [M / vk for vk, (_, M, _) in zip(v, STEPS, strict=True)]
    n = [vk * math.radians(120.0) / 5.0 * 60.0 for vk in v]
    t = [s[2] for s in STEPS]
    revs = sum(nk * tk for nk, tk in zip(n, t, strict=True))
    work = sum(Fk**3 * nk * tk for Fk, nk, tk in zip(F, n, t, strict=True))
    return (work / revs) ** (1 / 3), revs / sum(t)


def _duty(**extra):
    cycle = [
        {"deflection": f"{a} deg", "hinge_moment": f"{M / 1e3} N*m", "time": t} for a, M, t in STEPS
    ]
    return _fin(duty_cycle=cycle, **extra)


def test_duty_cycle_means_and_life_by_hand():
    q = _q(_duty())
    F_m, n_m = drive.duty_cycle_means(q)
    want_F, want_n = _duty_by_hand()
    assert float(np.ravel(F_m)[0]) == pytest.approx(want_F, rel=1e-7)
    assert float(np.ravel(n_m)[0]) == pytest.approx(want_n, rel=1e-7)
    Ca = _best(25.0, 5.0)["Ca"]
    life = (Ca / (1.2 * want_F)) ** 3 * 1e6 / (60.0 * want_n)
    assert float(np.ravel(drive.life_hours(q))[0]) == pytest.approx(life, rel=1e-7)


def test_duty_cycle_means_of_a_population_are_one_per_design():
    problem = _duty()
    x = _x_of(problem)
    X = np.vstack([x, x])
    X[1, [v.name for v in problem.free].index("R")] = 90.0
    q = problem.quantities(problem.design_dict(X))
    F_m, _ = drive.duty_cycle_means(q)
    assert np.shape(F_m) == (2, 1)
    assert float(F_m[0, 0]) == pytest.approx(_duty_by_hand()[0], rel=1e-7)
    assert float(F_m[1, 0]) != pytest.approx(float(F_m[0, 0]), rel=1e-3)


# --- drive: stiffness -----------------------------------------------------------------------
def _shaft(x, d1, p=5.0):
    """Tension and torsion of the shaft over a length x (mm/N)."""
    E, G = 2.06e5, 2.06e5 / 2.6
    return x / (math.pi * d1**2 / 4 * E) + x * (p / (2 * math.pi)) ** 2 / (G * math.pi * d1**4 / 32)


def test_nut_stiffness_rule_defaults():
    assert drive.nut_stiffness_rule(_fin().spec) == "load"
    assert drive.nut_stiffness_rule(_fin(drop_screw=["nut_stiffness_rule"]).spec) == "load"
    assert drive.nut_stiffness_rule(_fin({"nut_stiffness_rule": "table"}).spec) == "table"
    from problem.test_drive import _data

    continuous = problem_from_dict(_data({"nut_stiffness": "200 N/um"}, {"d0": "20 mm"}))
    assert drive.nut_stiffness_rule(continuous.spec) == "table"


@pytest.mark.parametrize(
    ("rule", "factor"),
    [("table", 1.0), ("preload", 0.8 * (0.05 / 0.1) ** (1 / 3)), ("preload-0.02", None)],
)
def test_nut_stiffness_by_table_and_preload(rule, factor):
    K = _best(25.0, 5.0)["K_nut"]
    if rule == "preload-0.02":
        screw = {"nut_stiffness_rule": "preload", "nut_preload": 0.02}
        factor = 0.8 * (0.02 / 0.1) ** (1 / 3)
    elif rule == "preload":
        screw = {"nut_stiffness_rule": "preload", "nut_preload": 0.05}
    else:
        screw = {"nut_stiffness_rule": "table"}
    q = _q(_fin(screw))
    assert float(np.ravel(drive.nut_stiffness(q))[0]) == pytest.approx(factor * K, rel=1e-12)
    # bearings, nut and shaft in series; the nut is one value, the shaft varies
    xs = _x(100.0, 150.0, 90.0, 0.2, PHI)
    expected = 1 / 400e3 + 1 / (factor * K) + _shaft(40.0 + np.abs(xs - xs[0]), 22.32)
    got = np.asarray(drive.axial_compliance(q), dtype=float).ravel()
    assert got == pytest.approx(expected, rel=1e-9)


def test_nut_stiffness_at_the_duty_cycles_mean_load():
    q = _q(_duty(stiffness_load="duty-mean"))
    row = _best(25.0, 5.0)
    F_m = _duty_by_hand()[0]
    assert float(np.ravel(drive.nut_load(q))[0]) == pytest.approx(F_m, rel=1e-7)
    K = 0.8 * row["K_nut"] * (F_m / (0.28 * row["Ca"])) ** (1 / 3)
    assert float(np.ravel(drive.nut_stiffness(q))[0]) == pytest.approx(K, rel=1e-7)
    hinge = _q(_duty())
    assert np.asarray(drive.nut_load(hinge), dtype=float).ravel() == pytest.approx(F_NUT, rel=1e-7)


def test_axial_compliance_keeps_only_the_members_the_file_gives():
    from problem.test_drive import DESIGN, _data

    def compliance(screw):
        problem = problem_from_dict(_data(screw, {"d0": "20 mm"}))
        x = np.array([DESIGN[v.name] for v in problem.free])
        q = problem.quantities(problem.design_dict(x))
        return q, np.asarray(drive.axial_compliance(q), dtype=float).ravel()

    q, c = compliance({"nut_stiffness": "200 N/um"})
    assert c == pytest.approx([1 / 200e3], rel=1e-12)
    assert drive.nut_stiffness(q) == 200e3
    q, c = compliance({"bearing_stiffness": "300 N/um"})
    assert c == pytest.approx([1 / 300e3], rel=1e-12)
    assert drive.nut_stiffness(q) is None
    q, c = compliance({"nut_offset": "30 mm", "root_ratio": 0.8})
    xs = _x(80.0, 120.0, 60.0, 0.1, PHI[::2])
    expected = _shaft(30.0 + np.abs(xs - xs[0]), 16.0)
    assert c == pytest.approx(expected, rel=1e-9)
    # the output: through the screw's rate (dx/dphi)^2, no pin in this problem
    total = np.asarray(drive.output_compliance(q), dtype=float).ravel()
    assert total == pytest.approx(expected / _dx(80.0, 120.0, 60.0, 0.1, PHI[::2]) ** 2, rel=1e-6)


def test_a_continuous_screw_and_the_solver_path_have_no_membership_block():
    from problem.test_drive import DESIGN, _data

    screw = {"length": "400 mm", "nut_stiffness": "200 N/um"}
    problem = problem_from_dict(
        _data(screw, {"d0": "20 mm"}, deflection_rate="60 deg/s", dn_max=50_000)
    )
    x = np.array([DESIGN[v.name] for v in problem.free])
    blocks = {b.name: b for b in problem.expressions(problem.design_dict(x)).constraints}
    drive_names = [n for n in blocks if n.startswith("screw_") or n in ("dn", "stiffness")]
    assert drive_names == ["screw_buckling", "screw_yield", "dn"]
    fin = _fin()
    design = fin.design_dict(_x_of(fin))
    params = fin.parameter_values({"d0": (25.0, 25.0), "p": (5.0, 5.0), "d": (6.0, 6.0)})
    ex = fin.expressions({**design, **fin.parameter_design(params)})
    names = [b.name for b in ex.constraints]
    assert "screw_catalogue_membership" not in names
    assert [n for n in DRIVE_NAMES if n in names] == [
        n for n in DRIVE_NAMES if n != "screw_catalogue_membership"
    ]


def test_a_fit_whose_smooth_clearance_is_zero_keeps_the_ratio_one():
    """H7/h6's least clearance is 0 by the formula and by the table: no ratio, 1."""
    values = _fin(fit="H7/h6").parameter_values(
        {"d": (6.0, 6.0), "d0": (25.0, 25.0), "p": (5.0, 5.0)}
    )
    assert values["fit_ratio_min"] == 1.0
    assert values["fit_ratio_max"] == pytest.approx(_fit_ratio("H7/h6", [6.0], "max"))


@pytest.mark.parametrize(
    ("nut", "text"), [({"nut_stiffness": "200 N/um"}, "as given"), ({}, "rigid")]
)
def test_stiffness_description_of_a_continuous_screws_nut(nut, text):
    from problem.test_drive import DESIGN, _data

    screw = {"length": "400 mm", "check_buckling": False, **nut}
    problem = problem_from_dict(_data(screw, {"d0": "20 mm"}, stiffness_min="10 kN*m/rad"))
    x = np.array([DESIGN[v.name] for v in problem.free])
    blocks = {b.name: b for b in problem.expressions(problem.design_dict(x)).constraints}
    assert blocks["stiffness"].description == (
        f"required stiffness / stiffness at the output (nut: {text})"
    )
