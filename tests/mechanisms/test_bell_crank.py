"""The bell crank of examples/bell_crank.py (four pins) against a hand derivation: its
positions solved here by root finding, its ratio by finite differences of them, its loads
by the statics of the horn and the crank, its clearance sensitivities by perturbing a
rod's length with the nut held; and the mechanism contract's declarations (pins, rows'
display units) that docs/mechanisms.md promises."""

from __future__ import annotations

import copy
import itertools
import math
import runpy
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from scipy.optimize import brentq

import optdesign as od
from optdesign import math as m
from optdesign.user_code import UserCodeError

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "bell_crank.py"
MODULE = runpy.run_path(str(EXAMPLE), run_name="bell_crank_example")
BellCrank = MODULE["BellCrank"]
DESIGN = {
    "R": 60.0,
    "l2": 120.0,
    "r2": 50.0,
    "r1": 40.0,
    "l1": 150.0,
    "k_x": 110.0,
    "k_y": 120.0,
    "e": 80.0,
    "gamma": math.pi / 2,
    "phi0": math.pi / 2,
    "p": 5.0,
    "i_a": 2.0,
}
M_H = 300e3  # N*mm


def cross(u, v):
    return u[0] * v[1] - u[1] * v[0]


def chain(phi, **changes):
    """H, K, P2, P1, N solved by root finding: the crank angle psi from |P2 - H| = l2 on
    the branch where P2 lies right of K -> H, then the nut from |P1 - N| = l1."""
    d = {**DESIGN, **changes}
    a = d["phi0"] + phi
    H = np.array([d["R"] * math.sin(a), d["R"] * math.cos(a)])
    K = np.array([d["k_x"], d["k_y"]])

    def P2_of(psi):
        return K + d["r2"] * np.array([math.cos(psi), math.sin(psi)])

    def gap(psi):
        return np.linalg.norm(P2_of(psi) - H) - d["l2"]

    grid = np.linspace(0.0, 2 * math.pi, 721) + 1e-3  # no root on a node
    roots = [
        brentq(gap, lo, hi, xtol=1e-15)
        for lo, hi in itertools.pairwise(grid)
        if gap(lo) * gap(hi) < 0
    ]
    psi = next(r for r in roots if cross(H - K, P2_of(r) - K) < 0)
    P2 = P2_of(psi)
    P1 = K + d["r1"] * np.array([math.cos(psi + d["gamma"]), math.sin(psi + d["gamma"])])
    N = np.array([P1[0] - math.sqrt(d["l1"] ** 2 - (P1[1] - d["e"]) ** 2), d["e"]])
    return H, K, P2, P1, N


def hand(phi):
    """(dx/dphi, nut force, pushrod force F1, rod force F2, S1, S2) of the hand derivation."""
    h = 1e-5
    rate = (chain(phi + h)[4][0] - chain(phi - h)[4][0]) / (2 * h)
    H, K, P2, P1, N = chain(phi)
    u2, u1 = (P2 - H) / DESIGN["l2"], (P1 - N) / DESIGN["l1"]
    F2 = M_H / abs(cross(H, u2))  # the horn: the rod's moment about O carries M_h
    F1 = F2 * abs(cross(P2 - K, u2)) / abs(cross(P1 - K, u1))  # the crank's moments about K
    F = F1 * abs(u1[0])  # the nut takes the pushrod's axial component

    def turn_with_nut_held(name):  # d(phi)/d(length) at the nut's position of phi
        x0 = chain(phi)[4][0]
        delta = 1e-4

        def angle(length):
            def gap(f):
                return chain(f, **{name: length})[4][0] - x0

            return brentq(gap, phi - 0.05, phi + 0.05, xtol=1e-15)

        angles = [angle(DESIGN[name] + s) for s in (delta, -delta)]
        return abs(angles[0] - angles[1]) / (2 * delta)

    return rate, F, F1, F2, turn_with_nut_held("l1"), turn_with_nut_held("l2")


PHIS = (-0.4, 0.0, 0.3)


def test_positions_and_ratio_against_root_finding_and_finite_differences():
    mech = BellCrank(DESIGN)
    for phi in PHIS:
        for mine, theirs in zip(mech.points(phi), chain(phi), strict=True):
            assert np.allclose(np.asarray(mine, dtype=float), theirs, atol=1e-9)
        rate = hand(phi)[0]
        # the ratio by automatic differentiation of nut_position = finite differences
        ratio = 2 * math.pi * DESIGN["i_a"] * rate / DESIGN["p"]
        assert float(mech.ratio(np.array([phi]))[0]) == pytest.approx(ratio, rel=1e-8)
    # the neutral layout: dx/dphi = R r1 / r2 (rod, crank arms and pushrod at right angles)
    assert hand(0.0)[0] == pytest.approx(60.0 * 40.0 / 50.0, rel=1e-9)
    # the angle as a CasADi symbol: one expression in phi, equal at every angle
    phi_s = ca.SX.sym("phi")
    ratio_of = ca.Function("ratio", [phi_s], [mech.ratio(phi_s)])
    for phi in PHIS:
        expected = 2 * math.pi * DESIGN["i_a"] * hand(phi)[0] / DESIGN["p"]
        assert float(ratio_of(phi)) == pytest.approx(expected, rel=1e-8)


def test_loads_and_sensitivities_against_statics_and_perturbed_rods():
    mech = BellCrank(DESIGN)
    pin = od.PinJoint(10.0, 15.0, "H7/g6")
    for phi in PHIS:
        _, F, F1, F2, S1, S2 = hand(phi)
        grid = np.array([phi])
        assert abs(float(mech.nut_force(grid, M_H)[0])) == pytest.approx(F, rel=1e-7)
        pins = [j for j in mech.joints(grid, M_H, pin) if j.pin is not None]
        assert len(pins) == 4
        forces = [abs(float(np.asarray(j.force)[0])) for j in pins]
        assert forces == pytest.approx([F1, F1, F2, F2], rel=1e-7)
        sens = [abs(float(np.asarray(j.sensitivity)[0])) for j in pins]
        assert sens == pytest.approx([S1, S1, S2, S2], rel=1e-6)
        # the backlash: each pin's clearance (fit and flattening under its own force)
        # times its sensitivity, summed
        worst = math.degrees(2 * S1 * pin.clearance(F1) + 2 * S2 * pin.clearance(F2))
        backlash = mech.backlash(grid, mech.joints(grid, M_H, pin)).worst_case
        assert float(np.asarray(backlash)[0]) == pytest.approx(worst, rel=1e-6)
        # one pin size for four pins: the pin requirements see the largest force
        assert float(mech.pin_force(grid, M_H)[0]) == pytest.approx(max(F1, F2), rel=1e-7)
    # the pushrod and the rod carry different forces (r2/r1 = 1.25 at neutral): no
    # single-pin chain would do
    _, _, F1, F2, _, _ = hand(0.0)
    assert F1 / F2 == pytest.approx(50.0 / 40.0, rel=1e-9)


def test_bell_crank_solves_to_the_hand_backlash_and_traces_a_front(tmp_path):
    result, front = MODULE["main"](tmp_path, workers=1)
    assert result.status == "optimal" and result.verified
    design = result.design
    problem = od.load(MODULE["PROBLEM"])
    saved = dict(DESIGN)
    try:
        DESIGN.update({k: v for k, v in design.items() if k in DESIGN})
        pin = od.PinJoint(design["d"], 1.5 * design["d"], "H7/g6")
        phis = np.linspace(-math.radians(25), math.radians(25), 21)
        worst = 0.0
        for phi in phis:
            _, _, F1, F2, S1, S2 = hand(phi)
            worst = max(
                worst, math.degrees(2 * S1 * pin.clearance(F1) + 2 * S2 * pin.clearance(F2))
            )
    finally:
        DESIGN.clear()
        DESIGN.update(saved)
    assert result.objective == pytest.approx(worst, rel=1e-6)
    # the transmission angle's row is in rad, shown in degrees (display_unit converts)
    from optdesign.display.limits import block_infos

    info = block_infos(problem)["transmission_angle"]
    assert info.display(math.radians(50.0)) == pytest.approx(50.0) and info.display_unit == "deg"
    assert len(front.points) == 6 and front.F[-1, 1] == pytest.approx(result.objective, rel=1e-6)


def test_a_mechanism_whose_pins_are_undeclared_is_told_when_registered():
    class Lever(od.Mechanism):
        name = "t23_undeclared"
        variables = {"R": od.VariableInfo("length", "lever")}  # noqa: RUF012

        def nut_position(self, phi):
            return self.R * m.sin(phi)

    with pytest.raises(UserCodeError) as caught:
        od.register_mechanism(Lever)
    text = str(caught.value)
    assert "mechanism 't23_undeclared'" in text and "its pins are undeclared" in text
    assert "pin_joints" in text and "joints(self, phi, M_h, pin)" in text
    assert "t23_undeclared" not in od.registered_mechanisms()

    class Twice(Lever):
        name = "t23_twice"
        pin_joints = ("pin (nut)", "pin (nut)")

    with pytest.raises(UserCodeError, match="pin_joints must be a tuple of distinct names"):
        od.register_mechanism(Twice)

    # each of the three conditions refuses on its own: a list of good names, a blank name
    for bad in (["pin (nut)"], ("pin (nut)", "  ")):

        class Odd(Lever):
            name = "t23_odd"
            pin_joints = bad

        with pytest.raises(UserCodeError, match="pin_joints must be a tuple of distinct"):
            od.register_mechanism(Odd)

    class TwoInLine(Lever):
        name = "t23_two_in_line"
        pin_joints = ("pin (nut)", "pin (lever)")

    od.register_mechanism(TwoInLine, replace=True)
    mech = TwoInLine(R=50.0, p=5.0)
    phi = np.array([0.0, 0.5])
    pins = [j for j in mech.joints(phi, M_H, od.PinJoint(8.0, 12.0)) if j.pin is not None]
    assert [j.name for j in pins] == ["pin (nut)", "pin (lever)"]
    # each on the screw's line: the nut force, 1/(dx/dphi) = 1/(R cos phi)
    assert np.allclose(pins[1].force, M_H / (50.0 * np.cos(phi)))
    assert np.allclose(pins[1].sensitivity, 1.0 / (50.0 * np.cos(phi)))

    class NoPins(Lever):
        name = "t23_no_pins"
        pin_joints = ()

    od.register_mechanism(NoPins, replace=True)
    assert [j.name for j in NoPins(R=50.0, p=5.0).joints(phi, M_H, od.PinJoint(8.0, 12.0))] == [
        "A screw bearings",
        "B screw/nut",
        "O output shaft",
    ]


def test_rows_display_unit_converts_and_refuses_another_dimension():
    rows = od.Rows("mu", 1.0, 0.5, 2.0, "rad", display_unit="deg")
    assert rows.display(math.pi / 2) == pytest.approx(90.0)
    assert od.Rows("f", 1.0, unit="N*mm", display_unit="N*m").display(2500.0) == pytest.approx(2.5)
    assert od.Rows("f", 1.0, unit="mm").display is None  # shown in its unit
    with pytest.raises(od.InputError) as caught:
        od.Rows("mu", 1.0, unit="", display_unit="deg")
    assert caught.value.field == "Rows('mu').display_unit"
    assert "'deg' is an angle and no unit a plain number" in str(caught.value)


def test_bell_crank_problem_copies_are_independent():
    # the example's problem dict is read, not changed, by od.load
    before = copy.deepcopy(MODULE["PROBLEM"])
    od.load(MODULE["PROBLEM"])
    assert before == MODULE["PROBLEM"]


def _toml(data: dict) -> str:
    """The example's problem dict as a problem file (inline tables one level down)."""

    def value(v):
        if isinstance(v, dict):
            return "{" + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + "}"
        return f'"{v}"' if isinstance(v, str) else repr(v)

    lines = [f"{k} = {value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for k, table in data.items():
        if isinstance(table, dict):
            lines += ["", f"[{k}]", *(f"{n} = {value(v)}" for n, v in table.items())]
    return "\n".join(lines) + "\n"


@pytest.mark.slow  # two command-line runs in fresh processes (~20 s)
def test_the_bell_crank_by_entry_point_from_the_command_line_in_another_folder(tmp_path):
    import os
    import subprocess
    import sys

    problem = tmp_path / "bell_crank.toml"
    problem.write_text(_toml(MODULE["PROBLEM"]))
    dist = tmp_path / "bellcrank-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: bellcrank\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text(
        "[optdesign.mechanisms]\nbell_crank = bell_crank:BellCrank\n"
    )
    path = os.pathsep.join([str(tmp_path), str(EXAMPLE.parent), os.environ.get("PYTHONPATH", "")])
    env = {**os.environ, "PYTHONPATH": path}

    def run(*argv):
        return subprocess.run(
            [sys.executable, "-m", "optdesign", *argv],
            capture_output=True,
            text=True,
            timeout=300,
            env=env,
            cwd=tmp_path,
        )

    solve = run("solve", str(problem), "--out", "solved", "--workers", "1")
    assert solve.returncode == 0, solve.stderr
    assert "status    optimal" in solve.stdout
    assert "feasible  verified by the NumPy model" in solve.stdout
    assert (tmp_path / "solved" / "report.html").is_file()
    bench = run("bench", "--problem", str(problem), "--solvers", "slsqp-exact", "--workers", "1")
    assert bench.returncode == 0, bench.stderr
    assert "Suite `user`: 1 instances, 1 runs" in bench.stdout


def test_the_default_assembly_margin_gives_float_angles_and_names_the_first_nan_one():
    """A mechanism that does not write assembly_margin gets the default: positive where
    its nut position is finite. Its nut_position always sees float angles, even from a
    list of ints."""
    from optdesign.errors import AssemblyError

    seen = []

    class Arc(od.Mechanism):
        name = "t32_arc"
        variables = {"R": od.VariableInfo("length", "lever")}  # noqa: RUF012
        pin_joints = ("pin (nut)",)

        def nut_position(self, phi):
            seen.append(np.asarray(phi).dtype)
            return self.R * np.sqrt(1.0 - np.asarray(phi) ** 2)  # no nut past 1 rad

    mech = Arc(R=50.0, p=5.0)
    with np.errstate(invalid="ignore"):
        assert np.asarray(mech.assembly_margin([0, 2])).tolist() == [1.0, -1.0]
    assert seen[-1] == np.float64
    with pytest.raises(AssemblyError) as caught:
        mech.check_assembly(np.array([0.0, 0.5, 1.2, 1.5]))
    assert caught.value.angle_deg == pytest.approx(math.degrees(1.2))
