"""The drive inside problems (issue 14): efficiency from the lead, back-drivability, the
lock's load, screw speed, DN, critical speed, static safety, life and output stiffness.

Expected values come from hand formulas written out here (lead angle, virtual work with
the crank-slider's position equation differentiated by central differences, the HIWIN
catalogue file read with the csv module, Miner's cubic mean) or from physics.md's printed
check - never from the function under test.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from optdesign.problem import load_problem, problem_from_dict
from optdesign.studies.nlp_solve import solve_nlp

ROOT = Path(__file__).resolve().parents[2]
FIN = ROOT / "problems" / "fin_actuator.toml"
CATALOGUE_CSV = ROOT / "optdesign" / "data" / "ball_screws.csv"
HINGE = 500e3  # N*mm


def _x(R, l, n, phi0, phi):
    """Crank-slider nut abscissa, seed 000 eq. 2, written out (mm)."""
    a = phi + phi0
    return R * np.sin(a) - np.sqrt(l**2 - (R * np.cos(a) - n) ** 2)


def _dx(R, l, n, phi0, phi, h=1e-6):
    return (_x(R, l, n, phi0, phi + h) - _x(R, l, n, phi0, phi - h)) / (2 * h)


def _data(screw=None, variables=None, objective="ripple", **req):
    data = {
        "name": "drive",
        "mechanism": "crank_slider",
        "variables": {
            "R": {"lower": "30 mm", "upper": "120 mm"},
            "l": {"lower": "40 mm", "upper": "200 mm"},
            "n": {"lower": "0 mm", "upper": "150 mm"},
            "p": {"lower": "2 mm", "upper": "10 mm"},
            "phi0": {"lower": "-0.6 rad", "upper": "0.6 rad"},
            "i_a": 2,
            **(variables or {}),
        },
        "requirements": {
            "deflection": {"min": "-30 deg", "max": "30 deg", "points": 31},
            "hinge_moment": "500 N*m",
            "mean_ratio": {"min": 200, "max": 260},
            "nut_travel_max": "110 mm",
            "transmission_angle": {"min": "40 deg", "max": "140 deg"},
            "rod_inclination_max": "30 deg",
            **req,
        },
        "objective": {"minimize": objective},
    }
    if screw is not None:
        data["screw"] = screw
    return data


def _quantities(problem, **design):
    x = np.array([design[v.name] for v in problem.free])
    return problem.quantities(problem.design_dict(x))


DESIGN = dict(R=80.0, l=120.0, n=60.0, phi0=0.1, p=5.0)


def test_efficiency_from_the_lead_reaches_motor_torque():
    """physics.md's check p = 5, d_m = 20, mu = 0.003: eta = 0.9634, eta' = 0.9621."""
    screw = {"kind": "ball", "friction": 0.003, "gear_efficiency": 0.95}
    problem = problem_from_dict(_data(screw, {"d0": "20 mm"}))
    q = _quantities(problem, **DESIGN)
    assert float(q.efficiency) == pytest.approx(0.9634, abs=5e-5)
    assert float(q.efficiency_back) == pytest.approx(0.9621, abs=5e-5)
    # lead angle by hand: tan(lam) / tan(lam + atan(mu))
    lam = math.atan(5.0 / (math.pi * 20.0))
    eta = math.tan(lam) / math.tan(lam + math.atan(0.003))
    assert float(q.drive_efficiency) == pytest.approx(eta * 0.95, rel=1e-12)
    # motor torque by virtual work: F = M / (dx/dphi), T = F p / (2 pi i_a eta eta_g)
    phi = np.radians(np.linspace(-30, 30, 31))
    F = HINGE / _dx(80.0, 120.0, 60.0, 0.1, phi)
    T = F * 5.0 / (2 * math.pi * 2 * eta * 0.95)
    assert np.asarray(q.motor_torque, dtype=float).ravel() == pytest.approx(T, rel=1e-7)
    # the same problem without [screw] uses eta_screw = 1: 1/(eta eta_g) times less torque
    plain = problem_from_dict(_data())
    T1 = np.asarray(_quantities(plain, **DESIGN).motor_torque, dtype=float).ravel()
    assert T1 == pytest.approx(T * eta * 0.95, rel=1e-7)


@pytest.mark.parametrize(("kind", "mu"), [("ball", 0.003), ("trapezoidal", 0.1)])
def test_a_screw_without_friction_takes_its_kinds_documented_default(kind, mu):
    """docs/drive.md: no ``friction`` means 0.003 for a ball screw, 0.1 for a sliding one."""
    plain = problem_from_dict(_data({"kind": kind}, {"d0": "20 mm"}))
    given = problem_from_dict(_data({"kind": kind, "friction": mu}, {"d0": "20 mm"}))
    eta = float(_quantities(plain, **DESIGN).efficiency)
    assert eta == pytest.approx(float(_quantities(given, **DESIGN).efficiency), rel=1e-12)
    if kind == "ball":  # the lead-angle formula by hand, p = 5, d_m = 20
        lam = math.atan(5.0 / (math.pi * 20.0))
        assert eta == pytest.approx(math.tan(lam) / math.tan(lam + math.atan(mu)), rel=1e-12)
    else:  # a sliding screw at mu 0.1 is far below a ball screw
        assert eta < 0.5


def _self_locking_lead(d_m: float, mu: float) -> float:
    """Largest lead of a self-locking Tr thread (alpha = 15 deg): lam = phi', where
    tan(phi') = mu / cos(alpha_n) and tan(alpha_n) = tan(alpha) cos(lam)."""

    def gap(lam):
        alpha_n = math.atan(math.tan(math.radians(15.0)) * math.cos(lam))
        return lam - math.atan(mu / math.cos(alpha_n))

    lam = brentq(gap, 1e-6, 0.5, xtol=1e-15)
    return math.pi * d_m * math.tan(lam)


@pytest.mark.parametrize("rule", ["forbidden", "required"])
def test_back_drive_requirement_on_a_sliding_screw(rule):
    # the least motor torque wants the longest lead (efficiency grows with it up to
    # ~45 deg): with back-driving forbidden the lead stops where the thread self-locks
    screw = {"kind": "trapezoidal", "friction": 0.1}
    # a long stroke allowed, so that only the efficiency limits the lead
    variables = {"d0": "20 mm", "R": {"lower": "30 mm", "upper": "300 mm"}}
    variables["l"] = {"lower": "40 mm", "upper": "500 mm"}
    data = _data(screw, variables, "motor_torque", back_drive=rule, nut_travel_max="400 mm")
    problem = problem_from_dict(data)
    res = solve_nlp(problem, starts=4, seed=2)
    assert res.status == "optimal" and res.verified
    p_lock = _self_locking_lead(20.0, 0.1)  # 6.55 mm
    assert 6.4 < p_lock < 6.7
    if rule == "forbidden":
        assert res.design["p"] == pytest.approx(p_lock, rel=1e-6)
        assert "back_drive" in {r.name.split("[")[0] for r in res.active}
    else:
        assert res.design["p"] > p_lock + 1.0
    q = _quantities(problem, **{v.name: res.design[v.name] for v in problem.free})
    assert (float(q.efficiency_back) <= 1e-9) == (rule == "forbidden")
    from optdesign.problem.drive_requirements import drive_blocks

    block = next(b for b in drive_blocks(q, problem.phi_labels) if b.name == "back_drive")
    wanted = "back-drivable" if rule == "required" else "self-locking"
    assert block.description == f"back-driving efficiency ({wanted})"


def test_lock_load_uses_the_model_back_efficiency():
    from optdesign.mechanisms import CrankSlider
    from optdesign.models.lock import PinLock, motor_shaft_lock_load

    screw = {"kind": "ball", "friction": 0.005, "gear_back_efficiency": 0.9}
    lock = {"kind": "pin", "radius": "20 mm"}
    problem = problem_from_dict(_data(screw, {"d0": "16 mm"}, lock=lock))
    q = _quantities(problem, **DESIGN)
    lam = math.atan(5.0 / (math.pi * 16.0))
    eta_back = math.tan(lam - math.atan(0.005)) / math.tan(lam)
    mech = CrankSlider(R=80.0, l=120.0, n=60.0, p=5.0, i_a=2, phi0=0.1)
    load = motor_shaft_lock_load(mech, problem.phi, HINGE, eta_back, 0.9)
    expected = PinLock(20.0).force(load.moment)
    assert np.asarray(q.lock_force, dtype=float).ravel() == pytest.approx(
        np.asarray(expected, dtype=float).ravel(), rel=1e-9
    )
    # by hand at the stroke's largest moment: T_back = F p eta' eta_g' / (2 pi i_a),
    # pin lock f_a = 0.35 T / r
    phi = np.radians(np.linspace(-30, 30, 31))
    T = HINGE / np.abs(_dx(80.0, 120.0, 60.0, 0.1, phi)) * 5.0 * eta_back * 0.9 / (4 * math.pi)
    assert float(np.max(q.lock_force)) == pytest.approx(0.35 * T.max() / 20.0, rel=1e-7)


def _catalogue_row(d0: float, p: float) -> dict[str, float]:
    """The strongest nut of HIWIN (d0, p), read from the shipped CSV with the csv module."""
    with CATALOGUE_CSV.open() as f:
        lines = [line for line in f if not line.startswith("#")]
        rows = [r for r in csv.DictReader(lines) if float(r["d0"]) == d0 and float(r["p"]) == p]
    best = max(rows, key=lambda r: (float(r["Ca"]), float(r["C0a"])))
    return {k: float(v) for k, v in best.items() if k in ("d1", "Ca", "C0a")}


FIN_DESIGN = dict(R=100.0, l=150.0, n=90.0, phi0=0.2, d0=25.0, p=5.0, d=6.0)


@pytest.fixture(scope="module")
def fin():
    problem = load_problem(FIN)
    return problem, _quantities(problem, **FIN_DESIGN)


def test_screw_speed_dn_critical_speed_and_static_safety_by_hand(fin):
    problem, q = fin
    phi = np.radians(np.linspace(-30, 30, 61))
    v = np.abs(_dx(100.0, 150.0, 90.0, 0.2, phi))  # mm/rad
    rate = math.radians(120.0)  # rad/s
    n = v * rate / 5.0 * 60.0  # 1/min
    assert np.asarray(q.screw_speed, dtype=float).ravel() == pytest.approx(n, rel=1e-7)
    ev = problem.evaluate(np.array([FIN_DESIGN[v.name] for v in problem.free]))
    c = ev.constraints
    assert np.max(c["dn"].values) == pytest.approx(25.0 * n.max(), rel=1e-7)
    assert c["dn"].upper == 70_000.0  # dn_rule = "ball-centre": 70 000 (HIWIN's: 90 000)
    row = _catalogue_row(25.0, 5.0)
    # HIWIN critical speed n_kmax = 0.8 x 2.71e8 f_n d1 / L^2, fixed-supported f_n = 0.692
    # (F 3.27-3.28; the conservative factors' choice, below the common 15.1)
    N1 = 0.8 * 2.71e8 * 0.692 * row["d1"] / 300.0**2
    assert np.max(c["critical_speed"].values) == pytest.approx(n.max() / N1, rel=1e-7)
    F = HINGE / v
    assert np.max(c["static_safety"].values) == pytest.approx(1.5 * F.max() / row["C0a"], rel=1e-7)


def test_buckling_limits_the_nut_force_to_the_buckling_load(fin):
    """The screw_buckling rows are nut force / buckling load, at most 1: with the screw
    ten times longer the same design buckles, and the check names it."""
    import tomllib

    problem, _ = fin
    x = np.array([FIN_DESIGN[v.name] for v in problem.free])
    row = problem.evaluate(x).constraints["screw_buckling"]
    assert (row.lower, row.upper) == (None, 1.0) and np.max(row.values) < 1.0
    data = tomllib.loads(FIN.read_text())
    data["screw"]["length"] = "3000 mm"
    long_screw = problem_from_dict(data)
    row = long_screw.evaluate(x).constraints["screw_buckling"]
    assert np.max(row.values) > 1.0 and row.upper == 1.0
    from optdesign.studies.verify import verify_design

    ok, violated, _ = verify_design(long_screw, x)
    assert not ok and "screw_buckling" in {v.name.split("[")[0] for v in violated}


def test_the_drive_requirements_carry_their_units_for_the_reports(fin):
    """What a report shows beside each drive requirement's value and limit."""
    from optdesign.reports.limits import block_infos

    problem, _ = fin
    units = {name: info.unit for name, info in block_infos(problem).items()}
    assert units["life"] == "h"
    assert units["screw_buckling"] == units["static_safety"] == ""
    assert block_infos(problem)["life"].description.startswith("rated life L10 over")


def test_a_screw_diameter_of_zero_is_no_catalogue_item():
    """Off the catalogue the nearest screw's data stand in (and the membership block
    fails); a diameter or lead that is not positive has no nearest screw: NaN."""
    from optdesign.problem.drive import _lookup, catalogue_items

    items = catalogue_items("HIWIN", None)
    vals, on = _lookup(items, np.array([25.0, 26.0, 0.0]), np.array([5.0, 5.0, 5.0]), ["d1"])
    assert on.tolist() == [1.0, 0.0, 0.0]
    assert vals["d1"][0] == vals["d1"][1] == pytest.approx(22.32)  # 26 x 5 -> the 25 x 5
    assert np.isnan(vals["d1"][2])


def test_life_over_the_duty_cycle_by_miners_rule(fin):
    _, q = fin
    row = _catalogue_row(25.0, 5.0)
    steps = [(0.0, 150e3, 0.6), (15.0, 300e3, 0.3), (-25.0, 450e3, 0.1)]
    rate = math.radians(120.0)
    loads, speeds, times = [], [], []
    for deg, M, t in steps:
        v = abs(_dx(100.0, 150.0, 90.0, 0.2, math.radians(deg)))
        loads.append(M / v)
        speeds.append(v * rate / 5.0 * 60.0)
        times.append(t)
    # ISO 3408-5: cubic mean load weighted by revolutions, mean speed by time; f_w = 1.2
    revs = sum(n * t for n, t in zip(speeds, times, strict=True))
    F_m = (sum(F**3 * n * t for F, n, t in zip(loads, speeds, times, strict=True)) / revs) ** (
        1 / 3
    )
    n_m = revs / sum(times)
    hours = (row["Ca"] / (1.2 * F_m)) ** 3 * 1e6 / (60 * n_m)
    assert float(np.asarray(q.life_hours).ravel()[0]) == pytest.approx(hours, rel=1e-7)


def test_population_evaluation_equals_one_design_at_a_time(fin):
    """The NumPy path on a population (global searches) gives each design's own values,
    the catalogue lookups and duty-cycle terms included."""
    problem, _ = fin
    rng = np.random.default_rng(5)
    X = np.array([[FIN_DESIGN[v.name] for v in problem.free]] * 4, dtype=float)
    X[:, 0] += rng.uniform(-10, 10, 4)  # R
    X[:, 4] = [16.0, 20.0, 25.0, 25.0]  # d0
    X[:, 5] = [5.0, 5.0, 5.0, 10.0]  # p
    pop = problem.evaluate(X)
    for k in range(4):
        one = problem.evaluate(X[k])
        assert pop.violation[k] == pytest.approx(one.violation, rel=1e-12)
        for name in ("life", "stiffness", "static_safety"):
            assert np.ravel(pop.constraints[name].values[k]) == pytest.approx(
                np.ravel(one.constraints[name].values), rel=1e-12
            )


def _hinge_rotation(q, M, phi, K_ax):
    """Output rotation under an extra hinge moment M with the nut on an axial spring K_ax:
    the nut moves F/K_ax with F = M/(dx/dphi) at the loaded angle, and the angle follows
    from the position equation solved for that nut position (no rates used)."""
    R, l, n, phi0 = 100.0, 150.0, 90.0, 0.2

    def rotation(sign):
        def residual(dphi):
            dx = _x(R, l, n, phi0, phi + dphi) - _x(R, l, n, phi0, phi)
            return K_ax * dx * _dx(R, l, n, phi0, phi + dphi) - sign * M

        return brentq(residual, -1e-2, 1e-2, xtol=1e-16)

    return (rotation(+1) - rotation(-1)) / 2


def test_output_stiffness_of_the_screw_side_against_the_assembled_linkage(fin):
    """Without pins, the output compliance is the screw side's through (dx/dphi)^2: check
    it against the equilibrium of the linkage with the nut on a spring."""
    _ = fin
    data = _data(
        {"kind": "ball", "bearing_stiffness": "400 N/um", "nut_stiffness": "270 N/um"},
        {"d0": "25 mm"},
        "hinge_compliance",
    )
    plain = problem_from_dict(data)
    qq = _quantities(plain, R=100.0, l=150.0, n=90.0, phi0=0.2, p=5.0)
    K_ax = 1 / (1 / 400e3 + 1 / 270e3)
    phi = np.radians(np.linspace(-30, 30, 31))
    for k in (0, 12, 30):
        M = 2000.0  # N*mm: a small moment, the response stays linear
        rot = _hinge_rotation(qq, M, phi[k], K_ax)
        K_out = float(np.asarray(qq.output_stiffness, dtype=float).ravel()[k])
        assert M / rot == pytest.approx(K_out, rel=1e-5)


def test_fin_actuator_stiffness_chain_includes_every_member(fin):
    problem, q = fin
    # removing the pins' contact leaves a stiffer output; removing the screw side too
    # leaves the pins alone: the chain is a series sum
    total = np.asarray(q.output_compliance, dtype=float).ravel()
    from optdesign.problem import drive

    screw_side = np.asarray(drive.axial_compliance(q), dtype=float).ravel()
    s = np.abs(np.asarray(q.mechanism.sensitivity_axial(q.phi), dtype=float).ravel())
    pins = total - screw_side * s**2
    assert np.all(pins > 0) and np.all(screw_side * s**2 > 0)
    # the requirement 600 kN*m/rad is compared with 1/compliance in N*mm/rad
    ev = problem.evaluate(np.array([FIN_DESIGN[v.name] for v in problem.free]))
    assert np.ravel(ev.constraints["stiffness"].values) == pytest.approx(total * 600e6, rel=1e-12)


@pytest.mark.slow
def test_fin_actuator_optimum_confirmed_by_a_global_search():
    """The shipped whole-actuator problem: catalogue search (branch and bound over Ipopt
    relaxations) against differential evolution over the catalogue indices and the
    continuous variables on the NumPy path (no CasADi, no Ipopt)."""
    from independent_global import differential_evolution_optimum

    import optdesign as od

    problem = load_problem(FIN)
    res = od.solve(problem)
    assert res.status == "optimal" and res.verified
    assert res.objective == pytest.approx(0.0348393, rel=1e-5)
    assert {k: res.design[k] for k in ("d0", "p", "d")} == {"d0": 25.0, "p": 5.0, "d": 6.0}
    names = {r.name.split("[")[0] for r in res.active}
    assert {"mean_ratio", "lock_force"} <= names
    for seed in (11, 12):
        de = differential_evolution_optimum(problem, seed=seed, popsize=20, maxiter=600)
        assert de["violation"] <= 1e-6
        assert de["objective"] >= res.objective * (1 - 1e-6)
        assert de["objective"] == pytest.approx(res.objective, rel=1e-4)


@pytest.mark.slow
def test_catalogue_front_backlash_against_motor_torque():
    """A front over catalogue designs (every point a catalogue item with its fit from the
    ISO 286-2 table): the backlash end is the catalogue optimum, the points trade."""
    import tomllib

    import optdesign as od

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
    data["variables"]["p"] = {"values": ["5 mm", "6 mm"]}
    data["variables"]["d"] = {"values": ["5 mm", "6 mm", "8 mm"]}
    problem = problem_from_dict(data)
    front = od.pareto(problem, ["backlash", "motor_torque"], points=3, starts=2)
    frame = front.to_frame()
    assert len(frame) == 3
    backlash = frame["backlash [deg]"].to_numpy()
    torque = frame["motor_torque [N*m]"].to_numpy()
    assert backlash.min() == pytest.approx(0.0340646, rel=1e-5)  # test_catalogue's optimum
    order = np.argsort(backlash)
    assert np.all(np.diff(torque[order]) < 0)  # more backlash buys less torque
    for _, row in frame.iterrows():
        assert row["p [mm]"] in (5.0, 6.0) and row["d [mm]"] in (5.0, 6.0, 8.0)


def test_conforming_pin_contact_in_a_problem():
    """pin_contact = "conforming": the optimum's backlash recomputed with the exact
    (numerical) conforming solution instead of the explicit fit, inside its validity."""
    import tomllib

    from optdesign.models import pin_contact as pc

    data = tomllib.loads((ROOT / "problems" / "cs_min_backlash.toml").read_text())
    data["requirements"]["pin_contact"] = "conforming"
    problem = problem_from_dict(data)
    res = solve_nlp(problem, starts=4, seed=1)
    assert res.status == "optimal" and res.verified
    d = res.design
    q = _quantities(problem, **{v.name: d[v.name] for v in problem.free})
    E, nu = problem.spec.materials.pin.E, problem.spec.materials.pin.nu
    L = d["pin_length_ratio"] * d["d"]
    worst = np.asarray(q.backlash.worst_case, dtype=float).ravel()
    k = int(np.argmax(worst))
    total = 0.0  # rad
    for joint in q.joints:
        if joint.angular:
            total += float(np.ravel(joint.clearance + 0.0 * q.phi)[k])
            continue
        s = abs(float(np.ravel(joint.sensitivity)[k]))
        c = float(np.ravel(joint.clearance + 0.0 * q.phi)[k])
        if joint.pin is not None:
            F = abs(float(np.ravel(joint.force)[k]))
            fit = float(joint.pin.fit_clearance())
            dR = fit / 2
            P_star = F / L / (E / (2 * (1 - nu**2)) * dR)
            assert 0.05 < P_star < 100 and bool(pc.in_fit_range(F, L, dR, E, nu))
            c += fit + dR * pc.persson_exact(P_star).d
        total += s * c
    assert np.degrees(total) == pytest.approx(res.objective, rel=2e-3)
    # the conforming approach (contact part, net-force mode excluded) is below the two
    # flattened surfaces of eq. 11 here: the optimum is lower than duan2017's 0.0362197
    assert res.objective < 0.0362197


@pytest.mark.parametrize(
    "field, value",
    [
        ("critical_speed", True),
        ("dn_max", "ground"),
        ("static_safety_min", 2.0),
        ("stiffness_min", "100 kN*m/rad"),
    ],
)
def test_screw_requirements_without_a_screw_are_refused(field, value):
    from optdesign.errors import ProblemError

    data = _data(None, None, **{field: value, "deflection_rate": "60 deg/s"})
    with pytest.raises(ProblemError, match=rf"requirements\.{field}: needs a \[screw\]") as e:
        problem = problem_from_dict(data)
        problem.evaluate(np.array([80.0, 120.0, 60.0, 5.0, 0.1]))
    assert str(e.value).endswith("needs a [screw] section (its size, catalogue and mounting)")


def test_screw_side_compliance_by_hand(fin):
    """Bearings, nut, and the shaft between the fixed bearing and the nut (tension and
    torsion through the lead) in series: 1/K_b + 1/K_nut + x/(A E) + x (p/2pi)^2/(G J),
    x = nut_offset + the nut's travel from its position at -30 deg (fin_actuator); the
    nut by HIWIN F 3.35 at the hinge moment's nut force, 0.8 K (F / (0.28 Ca))^(1/3)."""
    from optdesign.problem import drive

    _, q = fin
    with CATALOGUE_CSV.open() as f:
        rows = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]
    row = max(
        (r for r in rows if float(r["d0"]) == 25.0 and float(r["p"]) == 5.0),
        key=lambda r: (float(r["Ca"]), float(r["C0a"])),
    )
    d1, K_table = float(row["d1"]), float(row["rigidity_N_per_um"]) * 1e3
    E, G = 2.06e5, 2.06e5 / 2.6
    phi = np.radians(np.linspace(-30, 30, 61))
    F = HINGE / np.abs(_dx(100.0, 150.0, 90.0, 0.2, phi))
    K_nut = 0.8 * K_table * (F / (0.28 * float(row["Ca"]))) ** (1 / 3)
    xs = _x(100.0, 150.0, 90.0, 0.2, phi)
    x = 40.0 + np.abs(xs - xs[0])
    A, J = math.pi * d1**2 / 4, math.pi * d1**4 / 32
    expected = 1 / 400e3 + 1 / K_nut + x / (A * E) + x * (5.0 / (2 * math.pi)) ** 2 / (G * J)
    got = np.asarray(drive.axial_compliance(q), dtype=float).ravel()
    assert got == pytest.approx(expected, rel=1e-9)
    # the output: the screw side through (dx/dphi)^2, each pin through its own
    # sensitivity over its contact stiffness, taken here as a central difference of the
    # loaded pin's clearance in its force
    total = expected / _dx(100.0, 150.0, 90.0, 0.2, phi) ** 2
    for joint in q.joints:
        if joint.pin is None:
            continue
        F = np.abs(np.asarray(joint.force, dtype=float).ravel())
        h = 1e-3 * F
        slope = (
            np.asarray(joint.pin.clearance(F + h), dtype=float)
            - np.asarray(joint.pin.clearance(F - h), dtype=float)
        ) / (2 * h)
        total = total + np.asarray(joint.sensitivity, dtype=float).ravel() ** 2 * slope
    assert np.asarray(q.output_compliance, dtype=float).ravel() == pytest.approx(total, rel=1e-6)


def test_a_pair_the_catalogue_lacks_is_not_a_screw(fin):
    """d0 = 14 mm and p = 5 mm are both catalogue values, but HIWIN sells no 14 x 5."""
    problem, _ = fin
    on = problem.evaluate(np.array([FIN_DESIGN[v.name] for v in problem.free]))
    design = dict(FIN_DESIGN, d0=14.0)
    off = problem.evaluate(np.array([design[v.name] for v in problem.free]))
    assert float(np.ravel(on.constraints["screw_catalogue_membership"].values)[0]) == 1.0
    assert float(np.ravel(off.constraints["screw_catalogue_membership"].values)[0]) == 0.0
    assert off.violation >= 1.0


def test_efficiency_min_requirement():
    screw = {"kind": "trapezoidal", "friction": 0.1, "gear_efficiency": 0.9}
    problem = problem_from_dict(_data(screw, {"d0": "20 mm"}, efficiency_min=0.5))
    ev = problem.evaluate(np.array([DESIGN[v.name] for v in problem.free]))
    block = ev.constraints["efficiency"]
    # Tr thread by hand at p = 5, d 20: lam = atan(5/(20 pi)), phi' = atan(0.1/cos alpha_n)
    lam = math.atan(5.0 / (math.pi * 20.0))
    alpha_n = math.atan(math.tan(math.radians(15.0)) * math.cos(lam))
    eta = math.tan(lam) / math.tan(lam + math.atan(0.1 / math.cos(alpha_n)))
    assert float(np.ravel(block.values)[0]) == pytest.approx(eta * 0.9, rel=1e-9)
    assert block.lower == 0.5 and block.upper is None
    # a plain number, described as the reports show it
    x = np.array([DESIGN[v.name] for v in problem.free])
    (stated,) = [
        b for b in problem.expressions(problem.design_dict(x)).constraints if b.name == "efficiency"
    ]
    assert (stated.unit, stated.description) == ("", "forward efficiency of screw and gear")
    # 0.9 x 0.431 = 0.388 < 0.5: the design violates the requirement by that much
    assert ev.violation >= 0.5 - eta * 0.9 - 1e-12


def test_catalogue_screw_values_the_catalogue_does_not_list_are_refused_when_read():
    """optdesign.problem.consistency: d0 = { values = [...] } of a HIWIN screw with a
    diameter the catalogue lacks (13 mm) found no item for it and ended as "failed ...
    more starts" with NaN rows; it is refused when the problem is read, naming the
    variable, the values and the catalogue's."""
    from optdesign.errors import ProblemError

    screw = {"kind": "ball", "catalogue": "HIWIN"}
    d0 = {"d0": {"values": ["13 mm", "16 mm", "22 mm"]}}
    with pytest.raises(ProblemError) as err:
        problem_from_dict(_data(screw, {**d0, "p": {"catalogue": "HIWIN"}}))
    assert str(err.value).startswith(
        "variables.d0: catalogue 'HIWIN' lists no d0 of 13, 22 mm (its d0 values: 8, 14, 15, "
        "16, 20, 25, 32, 38, 40 mm)"
    )
    p = {"p": {"values": ["5 mm", "6 mm"]}}
    with pytest.raises(ProblemError, match=r"^variables\.p: catalogue 'HIWIN' lists no p of 6 mm"):
        problem_from_dict(_data(screw, {"d0": {"catalogue": "HIWIN"}, **p}))
    # values it lists are a catalogue screw
    ok = problem_from_dict(
        _data(screw, {"d0": {"values": ["16 mm", "25 mm"]}, "p": {"catalogue": "HIWIN"}})
    )
    assert ok.by_name["d0"].values == (16.0, 25.0)
