"""The Watt six-bar plug-in (``six_bar.py``) against its independent model
(``six_bar_reference.py``) at random designs: positions (and both against scipy root
finding), the ratio, the clearance sensitivities (and against literal re-solving with the
nut held), the joints' forces, the backlash, the ripple and the requirements; the
problem loads and matches the reference's constants; the recorded reference optima
(``six_bar_optimum.json``) hold on both models. Recomputing the optima by the reference's
differential evolution is marked slow and runs with ``pytest -m slow`` only."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

import optdesign as od

HERE = Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))

from multimodal_mechanisms import first_passing  # noqa: E402
from multimodal_mechanisms import six_bar as plugin  # noqa: E402
from multimodal_mechanisms import six_bar_reference as ref  # noqa: E402

OPTIMUM = HERE / "six_bar_optimum.json"
PROBLEMS = {obj: od.load(plugin.problem(obj)) for obj in ("backlash", "ripple")}
FREE = [v.name for v in PROBLEMS["backlash"].free]
DRIVE = {"p": 5.0, "i_a": 2.0}
REL = 1e-7
#: Pins of the plug-in's chain: name -> the reference's quantity (sensitivity, force).
PINS = {
    "pushrod pin (nut)": "push",
    "pushrod pin (rocker)": "push",
    "rocker pivot K": "pivot",
    "rod pin (rocker)": "rod",
    "rod pin (horn)": "rod",
}


def random_designs(n, seed=0):
    """Designs drawn uniformly in the bounds that assemble over the stroke away from the
    loops' limits (reaches above the assembly rows' floors, the ratio >= 5: near a dead
    point the reference's finite differences lose their digits)."""
    rng = np.random.default_rng(seed)
    Z = rng.random((2000, ref.NV))

    def passes(chunk: np.ndarray) -> np.ndarray:
        q = ref.analyse(ref._design_of(chunk))
        ok = np.all(q["rod_reach"] > 0.1, axis=1) & np.all(q["push_reach"] > 0.3, axis=1)
        ok &= np.all(q["ratio"] > 5.0, axis=1)
        return ok & np.all(np.isfinite(q["backlash_deg"]), axis=1)

    chosen = np.asarray(first_passing(Z, passes, n, chunk=250), dtype=int)
    assert chosen.size == n, f"only {chosen.size} designs assemble"
    return [
        {**ref.FIXED, **{k: float(v[0]) for k, v in ref._design_of(Z[j]).items()}} for j in chosen
    ]


DESIGNS = random_designs(12)


def mechanism(design):
    return plugin.WattSixBar({**{k: v for k, v in design.items() if k != "d"}, **DRIVE})


def column(design, phi):
    """The reference's analysis of one design, as 1-D arrays over ``phi``."""
    q = ref.analyse(design, phi)
    return {k: (v[0] if isinstance(v, np.ndarray) else v) for k, v in q.items()}


def test_the_problem_loads_and_matches_the_reference_constants():
    p = PROBLEMS["backlash"]
    assert p.mechanism_name == "watt_six_bar" and p.objective_names[0] == "backlash"
    assert FREE == list(ref.NAMES) and len(FREE) >= 6 and "d" in FREE
    assert np.allclose(p.lower(), ref.LOWER) and np.allclose(p.upper(), ref.UPPER)
    fixed = p.fixed_values
    assert {k: fixed[k] for k in ref.FIXED} == pytest.approx(ref.FIXED)
    assert fixed["p"] == ref.LEAD and fixed["i_a"] == ref.GEAR
    assert fixed["pin_length_ratio"] == ref.PIN_LENGTH_RATIO
    assert np.allclose(p.phi, ref.PHI, rtol=0, atol=1e-15)
    req = p.spec.requirements
    assert req.hinge_moment == pytest.approx(ref.M_H)
    assert (req.mean_ratio.min, req.mean_ratio.max) == ref.MEAN_RATIO
    assert req.nut_travel_max == ref.NUT_TRAVEL_MAX
    for name, band in (
        ("transmission_angle", ref.TRANSMISSION_DEG),
        ("rocker_transmission_angle", ref.ROCKER_TRANSMISSION_DEG),
    ):
        value = getattr(req, name)
        assert np.degrees([value.min, value.max]) == pytest.approx(band)
    assert math.degrees(req.pushrod_inclination_max) == pytest.approx(
        ref.PUSHROD_INCLINATION_MAX_DEG
    )
    assert req.pin_bearing_pressure_max == ref.PIN_BEARING_MAX
    assert req.pin_shear_stress_max == ref.PIN_SHEAR_MAX
    assert plugin.WattSixBar.pin_shear_planes == ref.SHEAR_PLANES and req.pin_shear_planes is None
    assert (req.fit, req.fit_clearance, req.pin_contact) == (ref.FIT, "max", "duan2017")
    assert (p.spec.materials.pin.E, p.spec.materials.pin.nu) == (ref.E_PIN, ref.NU_PIN)
    cl = p.spec.clearances
    assert (cl.A, cl.B, cl.O) == pytest.approx(
        (ref.CLEARANCE_A, ref.CLEARANCE_B, ref.CLEARANCE_O), rel=1e-12
    )
    assert req.backlash_max is None
    ripple = PROBLEMS["ripple"]
    assert ripple.objective_names[0] == "ripple"
    assert math.degrees(ripple.spec.requirements.backlash_max) == pytest.approx(
        ref.RIPPLE_PROBLEM_BACKLASH_MAX_DEG
    )
    with pytest.raises(ValueError, match="use 'backlash' or 'ripple'"):
        plugin.problem("size")


def test_positions_against_the_reference_and_root_finding():
    phi = ref.PHI
    for design in DESIGNS[:6]:
        mine = mechanism(design).points(phi)
        theirs = ref.positions(ref._as_columns(design), phi)[:5]
        for a, b in zip(mine, theirs, strict=True):
            assert np.allclose(
                np.asarray(a, dtype=float), np.asarray(b, dtype=float)[:, 0], atol=1e-9
            )
        for k in (0, 13):
            solved = ref.positions_by_root_finding(design, phi[k])
            for a, b in zip(mine, solved, strict=True):
                assert np.allclose([a[0][k], a[1][k]], b, atol=1e-8)


def test_ratio_sensitivities_and_forces_against_the_reference():
    phi = ref.PHI
    for design in DESIGNS:
        mech = mechanism(design)
        q = column(design, phi)
        assert mech.ratio(phi) == pytest.approx(q["ratio"], rel=REL)
        # the closed-form nut velocity is the automatic derivative of the nut position
        auto = od.Mechanism.nut_velocity(mech, phi)
        assert mech.nut_velocity(phi) == pytest.approx(auto, rel=1e-10)
        assert np.abs(mech.nut_force(phi, ref.M_H)) == pytest.approx(q["F_nut"], rel=REL)
        assert np.abs(mech.sensitivity_axial(phi)) == pytest.approx(q["S_axial"], rel=REL)
        pin = od.PinJoint(design["d"], 1.5 * design["d"])
        pins = {j.name: j for j in mech.joints(phi, ref.M_H, pin) if j.pin is not None}
        assert set(pins) == set(PINS)
        for name, kind in PINS.items():
            assert np.abs(pins[name].sensitivity) == pytest.approx(q[f"S_{kind}"], rel=REL)
            assert np.abs(pins[name].force) == pytest.approx(q[f"F_{kind}"], rel=REL)
        assert mech.pin_force(phi, ref.M_H) == pytest.approx(q["F_pin"], rel=REL)
        fixed = {j.key for j in mech.joints(phi, ref.M_H, pin) if j.key}
        assert fixed == {"A", "B", "O"}


def test_sensitivities_against_literal_re_solving_with_the_nut_held():
    design = DESIGNS[0]
    for phi in (ref.PHI[2], ref.PHI[15]):
        q = column(design, np.array([phi]))
        for name, key in (("l1", "S_push"), ("l2", "S_rod")):
            assert ref.turn_with_nut_held(design, phi, name) == pytest.approx(q[key][0], rel=1e-6)
        pivot = math.hypot(
            ref.turn_with_nut_held(design, phi, "k_x"), ref.turn_with_nut_held(design, phi, "k_y")
        )
        assert pivot == pytest.approx(q["S_pivot"][0], rel=1e-6)


def test_the_pivot_force_is_the_rocker_s_force_balance_and_the_nut_force_its_virtual_work():
    """Two statics of the reference checked against each other: the nut force from the
    pushrod's axial component equals M_h / (dx/dphi) (virtual work), and the pivot's
    sensitivity (perturbed pivot) equals its reaction per unit hinge moment (statics)."""
    for design in DESIGNS:
        q = column(design, ref.PHI)
        assert q["F_nut"] == pytest.approx(ref.M_H / np.abs(q["rate"]), rel=1e-8)
        assert q["S_pivot"] == pytest.approx(q["F_pivot"] / ref.M_H, rel=1e-8)
        assert q["S_push"] == pytest.approx(q["F_push"] / ref.M_H, rel=1e-8)
        assert q["S_rod"] == pytest.approx(q["F_rod"] / ref.M_H, rel=1e-8)


@pytest.mark.parametrize("objective", ["backlash", "ripple"])
def test_backlash_ripple_and_requirements_against_the_reference(objective):
    p = PROBLEMS[objective]
    X = np.array([[design[k] for k in FREE] for design in DESIGNS])
    ev = p.evaluate(X)
    for j, design in enumerate(DESIGNS):
        theirs = ref.evaluate(design, objective)
        assert ev.objectives["backlash"][j] == pytest.approx(theirs["backlash"], rel=REL)
        assert ev.objectives["ripple"][j] == pytest.approx(theirs["ripple"], rel=REL)
        rows = theirs["constraints"]
        mine = {k: np.asarray(b.values)[j] for k, b in ev.constraints.items()}
        assert mine["ratio_positive"] == pytest.approx(rows["ratio_positive"][0], rel=REL)
        assert mine["mean_ratio"] == pytest.approx(rows["mean_ratio"][0], rel=REL)
        assert mine["nut_travel"] == pytest.approx(rows["nut_travel"][0], rel=REL)
        assert mine["rod_reach"] == pytest.approx(rows["rod_reach"][0], rel=1e-9, abs=1e-12)
        assert mine["push_reach"] == pytest.approx(rows["push_reach"][0], rel=1e-9)
        for name in ("pin_bearing_pressure", "pin_shear_stress"):
            assert mine[name] == pytest.approx(rows[name][0], rel=REL)
        for name in ("transmission_angle", "rocker_transmission_angle"):
            degrees = plugin.degrees_of_cosine(mine[name])
            assert degrees == pytest.approx(rows[name][0], abs=1e-7)
        inclination = np.abs(plugin.degrees_of_sine(mine["pushrod_inclination_max"]))
        assert inclination == pytest.approx(rows["pushrod_inclination"][0], abs=1e-7)
        if objective == "ripple":
            assert mine["backlash"] == pytest.approx(rows["backlash"][0], rel=REL)
        # both models agree whether the design meets every requirement (none of these
        # random designs sits on a boundary to 1e-6)
        assert (ev.violation[j] <= 1e-9) == (theirs["violation"] <= 1e-9)


def test_the_symbolic_model_equals_the_numeric_one():
    design = DESIGNS[1]
    mech = mechanism(design)
    phi_s = ca.SX.sym("phi")
    ratio = ca.Function("ratio", [phi_s], [mech.ratio(phi_s)])
    for phi in (-0.3, 0.1, 0.4):
        assert float(ratio(phi)) == pytest.approx(float(mech.ratio(np.array([phi]))[0]), rel=1e-12)
    guarded = plugin.WattSixBar(
        {**{k: v for k, v in design.items() if k != "d"}, **DRIVE}, guarded=True
    )
    assert guarded.nut_position(0.2) == pytest.approx(mech.nut_position(0.2), rel=1e-12)


def test_sketch_size_and_the_benchmark_template():
    design = DESIGNS[2]
    mech = mechanism(design)
    sketch = mech.sketch(0.1)
    assert isinstance(sketch, od.Sketch) and len(sketch.links) == 4
    assert sketch.pivots[1] == pytest.approx((design["k_x"], design["k_y"]))
    assert sketch.slider == pytest.approx(tuple(float(c) for c in mech.points(0.1)[4]))
    assert mech.size() == pytest.approx(
        sum(design[k] for k in ("R", "l2", "r2", "r1", "l1")), rel=1e-15
    )
    from optdesign.studies.bench.instances import instance_dict

    for family in plugin.WattSixBar.bench_families:
        od.load(instance_dict(family, 0))


def _recorded():
    return json.loads(OPTIMUM.read_text())


@pytest.mark.parametrize("objective", ["backlash", "ripple"])
def test_the_recorded_optimum_holds_on_both_models(objective):
    record = _recorded()[objective]
    design = record["design"]
    theirs = ref.evaluate(design, objective)
    assert theirs["objective"] == pytest.approx(record["value"], rel=1e-9)
    assert theirs["violation"] <= ref.FEASIBLE
    p = PROBLEMS[objective]
    ev = p.evaluate(np.array([design[k] for k in FREE]))
    assert ev.objectives[objective] == pytest.approx(record["value"], rel=REL)
    assert ev.violation <= 1e-6
    for trap in record.get("local_optima", []):  # the traps are worse, and feasible
        value = ref.evaluate(trap["design"], objective)
        assert value["violation"] <= ref.FEASIBLE
        assert value["objective"] == pytest.approx(trap["value"], rel=1e-9)
        assert value["objective"] > record["value"] * (1 + 1e-3)


@pytest.mark.slow  # one differential-evolution run and its polish (about a minute)
@pytest.mark.parametrize("objective", ["backlash", "ripple"])
def test_the_reference_search_finds_the_recorded_optimum_again(objective, request):
    """The run of the recorded search that reached the optimum reaches it again (the
    whole search, 24 runs on each of three seeds, is the record's ``command``). Skipped
    unless ``-m slow`` is given, so that the plain run of this file stays fast."""
    if "slow" not in (request.config.getoption("markexpr") or ""):
        pytest.skip("a differential-evolution run: run with -m slow")
    record = _recorded()[objective]
    check = record["check_run"]
    found = ref.reference_search(objective, seed=check["seed"], only=[check["run"]])
    assert found["violation"] <= ref.FEASIBLE
    assert found["value"] == pytest.approx(record["value"], rel=1e-6)
    for search in record["searches"]:  # every recorded search agreed on it
        assert search["value"] == pytest.approx(record["value"], rel=1e-6)
