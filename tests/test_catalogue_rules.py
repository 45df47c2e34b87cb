"""Drive numbers by the catalogue's own rules (issue 26): the nut's load-dependent
stiffness (HIWIN F 3.34-3.35), the mounting factors of buckling and critical speed
(HIWIN F 3.25-3.28 against the common rounded ones), the DN rules and the design value
of the efficiency for sizing.

Expected values are written out here from the catalogue's printed formulas and constants
(HIWIN BS-08-2-EN-1704-K, sections 3.7.4-3.7.7) and the catalogue file read with the csv
module - never from the function under test.
"""

from __future__ import annotations

import csv
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from optdesign.errors import InputError
from optdesign.models import screw_sizing as sizing
from optdesign.problem import drive, load_problem, problem_from_dict

ROOT = Path(__file__).resolve().parents[1]
FIN = ROOT / "problems" / "fin_actuator.toml"
CATALOGUE_CSV = ROOT / "optdesign" / "data" / "ball_screws.csv"
HINGE = 500e3  # N*mm
#: The shipped fin_actuator optimum (docs/drive.md section 6).
OPT = dict(R=105.571, l=59.7942, n=102.087, phi0=math.radians(13.132), d0=25.0, p=5.0, d=6.0)


def _x(R, l, n, phi0, phi):
    """Crank-slider nut abscissa, seed 000 eq. 2, written out (mm)."""
    a = phi + phi0
    return R * np.sin(a) - np.sqrt(l**2 - (R * np.cos(a) - n) ** 2)


def _dx(R, l, n, phi0, phi, h=1e-6):
    return (_x(R, l, n, phi0, phi + h) - _x(R, l, n, phi0, phi - h)) / (2 * h)


def _row(d0: float, p: float) -> dict[str, float]:
    """The strongest nut of HIWIN (d0, p), read from the shipped CSV with the csv module."""
    with CATALOGUE_CSV.open() as f:
        lines = [line for line in f if not line.startswith("#")]
        rows = [r for r in csv.DictReader(lines) if float(r["d0"]) == d0 and float(r["p"]) == p]
    best = max(rows, key=lambda r: (float(r["Ca"]), float(r["C0a"])))
    out = {k: float(best[k]) for k in ("d1", "Ca", "C0a")}
    out["K"] = float(best["rigidity_N_per_um"]) * 1e3  # N/mm
    return out


def _fin(**changes):
    data = tomllib.loads(FIN.read_text())
    for section, values in changes.items():
        data[section].update(values)
    return problem_from_dict(data)


def _quantities(problem, design=OPT):
    x = np.array([design[v.name] for v in problem.free])
    return problem.quantities(problem.design_dict(x))


def _flat(v):
    return np.asarray(v, dtype=float).ravel()


# --- nut stiffness ---------------------------------------------------------------------------
def test_nut_stiffness_formulas_of_the_catalogue():
    """F 3.35: 0.8 K at the reference load 0.28 Ca, growing as the cube root of the load;
    F 3.34: 0.8 K at the catalogue's preload of 0.1 Ca."""
    K, Ca = 480e3, 17730.0  # R25-5T6-FSI: 480 N/um, Ca 17 730 N
    assert sizing.nut_stiffness_at_load(K, Ca, 0.28 * Ca) == pytest.approx(384e3, rel=1e-12)
    # at the load the table is calculated for (30 % of Ca) the rule gives 0.8186 K
    assert sizing.nut_stiffness_at_load(K, Ca, -0.3 * Ca) / K == pytest.approx(
        0.8 * (0.3 / 0.28) ** (1 / 3), rel=1e-12
    )
    assert sizing.nut_stiffness_at_load(K, Ca, 0.28 * Ca / 8) == pytest.approx(192e3)
    assert sizing.nut_stiffness_preloaded(K, Ca, 0.1 * Ca) == pytest.approx(384e3)
    assert sizing.nut_stiffness_preloaded(K, Ca, 0.0125 * Ca) == pytest.approx(192e3)
    with pytest.raises(InputError, match="Ca"):
        sizing.nut_stiffness_at_load(K, 0.0, 1000.0)


def test_fin_optimum_output_stiffness_with_the_load_dependent_nut_by_hand():
    """Acceptance: at the shipped optimum the output stiffness with the nut by HIWIN
    F 3.35 at the hinge moment's nut force equals the chain written out by hand - the
    nut 0.8 K (F / 0.28 Ca)^(1/3) at each angle, the bearings, the shaft in tension and
    torsion, the screw side through (dx/dphi)^2 and each pin through its sensitivity."""
    problem = load_problem(FIN)
    q = _quantities(problem)
    row = _row(25.0, 5.0)
    R, l, n, phi0 = OPT["R"], OPT["l"], OPT["n"], OPT["phi0"]
    phi = np.radians(np.linspace(-30, 30, 61))
    v = np.abs(_dx(R, l, n, phi0, phi))
    F = HINGE / v  # N, virtual work
    K_nut = 0.8 * row["K"] * (F / (0.28 * row["Ca"])) ** (1 / 3)
    assert _flat(drive.nut_stiffness(q)) == pytest.approx(K_nut, rel=1e-6)
    xs = _x(R, l, n, phi0, phi)
    x = 40.0 + np.abs(xs - xs[0])
    E, G = 2.06e5, 2.06e5 / 2.6
    A, J = math.pi * row["d1"] ** 2 / 4, math.pi * row["d1"] ** 4 / 32
    axial = 1 / 400e3 + 1 / K_nut + x / (A * E) + x * (5.0 / (2 * math.pi)) ** 2 / (G * J)
    total = axial / v**2
    for joint in q.joints:
        if joint.pin is None:
            continue
        Fj = np.abs(_flat(joint.force))
        h = 1e-3 * Fj
        slope = (_flat(joint.pin.clearance(Fj + h)) - _flat(joint.pin.clearance(Fj - h))) / (2 * h)
        total = total + _flat(joint.sensitivity) ** 2 * slope
    assert _flat(q.output_compliance) == pytest.approx(total, rel=1e-6)
    # the figure of the docs and the issue: 1.106 MN*m/rad at least (1.172 with the table)
    assert (1 / total).min() * 1e-9 == pytest.approx(1.10556, abs=2e-5)
    table = _quantities(_fin(screw={"nut_stiffness_rule": "table"}))
    assert (1 / _flat(table.output_compliance)).min() * 1e-9 == pytest.approx(1.17203, abs=2e-5)


def test_nut_stiffness_at_the_duty_cycles_mean_load():
    """``stiffness_load = "duty-mean"``: one nut stiffness at ISO 3408-5's cubic mean load
    of the duty cycle (weighted by revolutions), written out here."""
    q = _quantities(_fin(requirements={"stiffness_load": "duty-mean"}))
    row = _row(25.0, 5.0)
    R, l, n, phi0 = OPT["R"], OPT["l"], OPT["n"], OPT["phi0"]
    steps = [(0.0, 150e3, 0.6), (15.0, 300e3, 0.3), (-25.0, 450e3, 0.1)]
    loads, revs = [], []
    for deg, M, t in steps:
        v = abs(_dx(R, l, n, phi0, math.radians(deg)))
        loads.append(M / v)
        revs.append(v * t)  # the speed is proportional to |dx/dphi|
    F_m = (sum(F**3 * r for F, r in zip(loads, revs, strict=True)) / sum(revs)) ** (1 / 3)
    K = 0.8 * row["K"] * (F_m / (0.28 * row["Ca"])) ** (1 / 3)
    assert _flat(drive.nut_stiffness(q)) == pytest.approx([K], rel=1e-6)
    assert (1 / _flat(q.output_compliance)).min() * 1e-9 == pytest.approx(1.03614, abs=2e-5)


def test_preloaded_nut_and_the_choices_refused():
    problem = _fin(screw={"nut_stiffness_rule": "preload", "nut_preload": 0.05})
    q = _quantities(problem)
    assert _flat(drive.nut_stiffness(q)) == pytest.approx([0.8 * 480e3 * 0.5 ** (1 / 3)])
    from optdesign.reports.limits import block_infos

    text = block_infos(problem)["stiffness"].description
    assert "HIWIN F 3.34 at a preload of 0.05 Ca" in text
    text = block_infos(_fin(screw={"nut_stiffness_rule": "table"}))["stiffness"].description
    assert "(nut: the catalogue's table value)" in text
    from optdesign.errors import OptDesignError

    with pytest.raises(OptDesignError, match="nut_preload"):
        _fin(screw={"nut_stiffness_rule": "preload"})
    with pytest.raises(OptDesignError, match="nut_preload"):
        _fin(screw={"nut_preload": 0.05})
    with pytest.raises(OptDesignError, match="nut_preload"):
        _fin(screw={"nut_stiffness_rule": "preload", "nut_preload": 0.2})
    data = tomllib.loads(FIN.read_text())
    data["screw"].pop("catalogue")
    data["screw"]["nut_stiffness_rule"] = "load"
    with pytest.raises(OptDesignError, match="nut_stiffness_rule"):
        problem_from_dict(data)


# --- mounting factors --------------------------------------------------------------------------
@pytest.mark.parametrize(
    "mounting, fk, fn",
    [
        ("fixed-fixed", 1.0, 1.0),
        ("fixed-supported", 0.5, 0.692),
        ("supported-supported", 0.25, 0.446),
        ("fixed-free", 0.0625, 0.147),
    ],
)
def test_hiwin_buckling_and_critical_speed_by_mounting(mounting, fk, fn):
    """HIWIN F 3.25-3.28 with its printed constants and factors f_k, f_n: F_kmax =
    0.5 x 4.072e5 f_k dk^4 / ls^2 and n_kmax = 0.8 x 2.71e8 f_n dk / ls^2."""
    dk, ls = 22.32, 300.0
    P = 0.5 * 4.072e5 * fk * dk**4 / ls**2
    N = 0.8 * 2.71e8 * fn * dk / ls**2
    assert sizing.buckling_load(dk, ls, mounting, rule="HIWIN") == pytest.approx(P, rel=1e-12)
    assert sizing.critical_speed(dk, ls, mounting, rule="HIWIN") == pytest.approx(N, rel=1e-12)
    # the default (conservative) never exceeds HIWIN's nor the common rounded factors
    for rule in ("HIWIN", "common"):
        assert sizing.buckling_load(dk, ls, mounting) <= sizing.buckling_load(
            dk, ls, mounting, rule=rule
        )
        assert sizing.critical_speed(dk, ls, mounting) <= sizing.critical_speed(
            dk, ls, mounting, rule
        )
    # the common factors agree with HIWIN's within 1.8 %, except fixed-free
    common_b = sizing.buckling_load(dk, ls, mounting, rule="common") / P
    common_n = sizing.critical_speed(dk, ls, mounting, "common") / N
    if mounting == "fixed-free":
        assert common_b == pytest.approx(1.3 / 1.2725, rel=1e-12)  # +2.2 %, unsafe side
        assert common_n == pytest.approx(3.4 / 3.18696, rel=1e-12)  # +6.7 %
        assert sizing.BUCKLING_FACTOR[mounting] == pytest.approx(1.2725)
        assert sizing.CRITICAL_SPEED_FACTOR[mounting] == pytest.approx(3.18696)
    else:
        assert abs(common_b - 1) < 0.018 and abs(common_n - 1) < 0.018
    with pytest.raises(InputError, match="rule"):
        sizing.critical_speed(dk, ls, mounting, "THK")


def test_mounting_rule_reaches_the_problem_and_its_summary_text():
    """The fin_actuator's critical speed and buckling rows use the rule of
    ``mounting_factors``; the requirement's text names the rule and its factor."""
    row = _row(25.0, 5.0)
    R, l, n, phi0 = OPT["R"], OPT["l"], OPT["n"], OPT["phi0"]
    phi = np.radians(np.linspace(-30, 30, 61))
    v = np.abs(_dx(R, l, n, phi0, phi))
    speed = v * math.radians(120.0) / 5.0 * 60.0
    for rule, lam in (("conservative", 0.8 * 27.1 * 0.692), ("common", 15.1)):
        problem = _fin(screw={"mounting_factors": rule})
        ev = problem.evaluate(np.array([OPT[x.name] for x in problem.free]))
        N1 = lam * row["d1"] / 300.0**2 * 1e7
        assert np.max(ev.constraints["critical_speed"].values) == pytest.approx(
            speed.max() / N1, rel=1e-6
        )
    from optdesign.reports.limits import block_infos

    infos = block_infos(problem)  # what the summary prints beside a binding requirement
    assert "common factor lambda_2 = 15.1" in infos["critical_speed"].description
    assert "common factor eta_2 = 10" in infos["screw_buckling"].description
    infos = block_infos(load_problem(FIN))
    assert "conservative factor lambda_2 = 15" in infos["critical_speed"].description
    assert "HIWIN F 3.35 at the hinge moment's nut force" in infos["stiffness"].description
    assert "1.3-1.8 normal" in infos["life"].description


# --- DN rules ------------------------------------------------------------------------------------
def test_dn_rules_name_the_diameter_and_the_limit():
    assert sizing.dn_rule("HIWIN", "ground") == ("nominal", 90_000.0)
    assert sizing.dn_rule("HIWIN", "rolled") == ("nominal", 70_000.0)
    assert sizing.dn_rule("ball-centre", "ground") == ("ball-centre", 70_000.0)
    assert sizing.dn_rule("ball-centre", "high-speed") == ("ball-centre", 70_000.0)
    with pytest.raises(InputError, match="dn_rule"):
        sizing.dn_rule("NSK", "ground")
    # the default is the conservative rule: 70 000 for the fin_actuator's ground screw
    problem = load_problem(FIN)
    ev = problem.evaluate(np.array([OPT[x.name] for x in problem.free]))
    assert ev.constraints["dn"].upper == 70_000.0
    R, l, n, phi0 = OPT["R"], OPT["l"], OPT["n"], OPT["phi0"]
    v = np.abs(_dx(R, l, n, phi0, np.radians(np.linspace(-30, 30, 61))))
    dn = 25.0 * (v * math.radians(120.0) / 5.0 * 60.0).max()
    assert np.max(ev.constraints["dn"].values) == pytest.approx(dn, rel=1e-6)
    assert dn / 70_000.0 == pytest.approx(0.9904, abs=1e-4)  # 99 % of the limit
    hiwin = _fin(requirements={"dn_rule": "HIWIN"})
    assert hiwin.evaluate(np.array([OPT[x.name] for x in hiwin.free])).constraints[
        "dn"
    ].upper == pytest.approx(90_000.0)


@pytest.mark.slow  # a catalogue solve of fin_actuator: 9.5 s with the oldest releases
def test_dn_rule_is_stated_in_the_summary_where_it_binds():
    import optdesign as od

    data = tomllib.loads(FIN.read_text())
    data["requirements"]["dn_max"] = 69000.0
    result = od.solve(data)
    text = result.summary()
    limits = text[text.index("what limits the optimum") :]
    assert "rule ball-centre" in limits and "on the ball-centre diameter" in limits
    # the --json document carries the same text with the binding requirement
    import json

    from optdesign.reports.result_json import result_json

    doc = json.loads(result_json(result))
    texts = [d.get("description", "") for d in _dicts(doc) if d.get("name") == "dn"]
    assert any("rule ball-centre" in t and "ball-centre diameter" in t for t in texts)


def _dicts(node):
    """Every dict inside a JSON document."""
    if isinstance(node, dict):
        yield node
        for v in node.values():
            yield from _dicts(v)
    elif isinstance(node, list):
        for v in node:
            yield from _dicts(v)


# --- efficiency for sizing -----------------------------------------------------------------------
def test_design_efficiency_sizes_the_motor_torque_with_the_catalogue_value():
    """``efficiency_design = "HIWIN"``: the motor torque with eta = 0.85 (HIWIN F 3.15,
    lower end of 0.85-0.95), back-driving from friction (the heavier load on the lock)."""
    friction = _quantities(load_problem(FIN))
    design = _quantities(_fin(screw={"efficiency_design": "HIWIN"}))
    R, l, n, phi0 = OPT["R"], OPT["l"], OPT["n"], OPT["phi0"]
    v = np.abs(_dx(R, l, n, phi0, np.radians(np.linspace(-30, 30, 61))))
    torque = HINGE / v * 5.0 / (2 * math.pi * 2 * 0.85 * 0.96)  # N*mm
    assert _flat(design.motor_torque) == pytest.approx(torque, rel=1e-6)
    # the friction model gives eta = 0.92688 at this lead: the design value is 9 % higher
    ratio = _flat(design.motor_torque).max() / _flat(friction.motor_torque).max()
    assert ratio == pytest.approx(0.92688 / 0.85, rel=1e-4)
    assert _flat(design.lock_force) == pytest.approx(_flat(friction.lock_force), rel=1e-12)
    # the summary's efficiency fact says where the value comes from
    from optdesign.reports.facts import design_facts

    problem = _fin(screw={"efficiency_design": "HIWIN"})
    facts = {
        f.name: f
        for f in design_facts(
            problem, problem.design_dict(np.array([OPT[x.name] for x in problem.free]))
        )
    }
    assert "HIWIN's design value 0.85" in facts["drive_efficiency"].description
    assert facts["drive_efficiency"].value.value == pytest.approx(100 * 0.85 * 0.96)
    data = tomllib.loads(FIN.read_text())
    data["screw"].update(kind="trapezoidal", efficiency_design="HIWIN")
    from optdesign.errors import OptDesignError

    with pytest.raises(OptDesignError, match="efficiency_design"):
        problem_from_dict(data)


@pytest.mark.parametrize("value", ["69000 mm/min", "fast", ""])
def test_dn_max_that_is_neither_a_number_nor_a_grade_is_refused_in_one_message(value):
    from optdesign.errors import OptDesignError

    data = tomllib.loads(FIN.read_text())
    data["requirements"]["dn_max"] = value
    with pytest.raises(OptDesignError) as caught:
        problem_from_dict(data)
    text = str(caught.value)
    assert "requirements.dn_max: a number (d x n in mm x 1/min, e.g. 70000) or a grade " in text
    assert f"got {value!r}" in text and "literal" not in text and "float" not in text
