"""Physics checked against computations that do not call the code under test.

Each expected value below comes from one of: the geometry redone with plain NumPy and
differentiated by finite differences, a hand derivation whose numbers are written out, or
the standard's/paper's formula typed in again here. These are the tests that catch a
one-line bug in a model (issue 13: the fork's ratio with phi0 != 0, the motor torque's
2 pi, the pin shear's 4F, a broken three-objective front).
"""

from __future__ import annotations

import itertools
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from optdesign.mechanisms.crank_slider import CrankSlider
from optdesign.mechanisms.fork import ShiftingFork
from optdesign.models import fork as fork_model
from optdesign.models.loads import (
    backdriven_motor_torque,
    fork_pin_normal_force,
    motor_torque,
    pin_bearing_pressure,
    pin_shear_stress,
)
from optdesign.problem import load_problem, problem_from_dict
from optdesign.studies.nlp_solve import solve_nlp

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"


# --- fork geometry, phi0 != 0 ----------------------------------------------------------------
def _fork_pin_x(R: float, a: float) -> float:
    """Nut position from the geometry alone: the arm is the ray from O at angle a from the
    normal to the pin's line (direction (sin a, cos a)); the pin is where it meets y = R."""
    t = R / math.cos(a)  # ray parameter at y = R
    return t * math.sin(a)


def _fd(f, x: float, h: float = 1e-6) -> float:
    return (f(x + h) - f(x - h)) / (2 * h)


@pytest.mark.parametrize("phi0", [0.25, -0.4])
@pytest.mark.parametrize("phi", [-0.3, 0.0, 0.35])
def test_fork_ratio_with_a_neutral_angle_from_finite_differences(phi0, phi):
    R, p, i_a = 70.0, 4.0, 2.0
    v = _fd(lambda f: _fork_pin_x(R, phi0 + f), phi)  # dx/dphi, mm/rad
    # motor angle per output angle: 2 pi i_a / p motor radians per mm of nut travel
    expected = 2 * math.pi * i_a * v / p
    mech = ShiftingFork(R=R, phi0=phi0, p=p, i_a=i_a)
    assert float(mech.ratio(phi)) == pytest.approx(expected, rel=1e-7)
    assert float(fork_model.ratio(R, p, i_a, phi, phi0)) == pytest.approx(expected, rel=1e-7)
    assert float(mech.nut_position(phi)) == pytest.approx(_fork_pin_x(R, phi0 + phi), rel=1e-12)
    # the output rotation per slot-normal clearance: the pin's lever arm is R / cos a
    assert float(mech.sensitivity_slot_normal(phi)) == pytest.approx(
        math.cos(phi0 + phi) / R, rel=1e-12
    )
    # axial sensitivity is the inverse of the finite-difference nut velocity
    assert float(mech.sensitivity_axial(phi)) == pytest.approx(1.0 / v, rel=1e-7)


def test_fork_neutral_angle_written_out():
    # R = 50 mm, phi0 = 20 deg, phi = 10 deg: a = 30 deg, cos^2 a = 3/4,
    # ds/dphi = 50 / 0.75 = 66.667 mm/rad; i = 2 pi * 2 * 66.667 / 5 = 167.552.
    mech = ShiftingFork(R=50.0, phi0=math.radians(20), p=5.0, i_a=2.0)
    assert float(mech.ratio(math.radians(10))) == pytest.approx(167.5516, rel=1e-6)
    # the pin's normal force M cos a / R: 500 N*m -> 5e5 * 0.866025 / 50 = 8660.25 N
    assert float(mech.pin_force(math.radians(10), 5e5)) == pytest.approx(8660.254, rel=1e-6)
    assert float(fork_pin_normal_force(5e5, 50.0, 0.1, 0.2)) == pytest.approx(
        5e5 * 0.9553365 / 50.0, rel=1e-6
    )


def cs_loop(phi, R=90.0, l=80.0, n=50.0, phi0=0.2):
    """Arm pin B and nut pin C = (m, n) of the crank-slider at deflection ``phi``: B at
    angle phi0 + phi from the normal to the screw's line, C on that line at distance n
    from O, on the near side of B, with |BC| = l by bisection on m in [Bx - l, Bx] (no
    closed form taken from the model)."""
    a = phi0 + phi
    Bx, By = R * math.sin(a), R * math.cos(a)
    lo, hi = Bx - l, Bx
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if (mid - Bx) ** 2 + (n - By) ** 2 > l**2:
            lo = mid
        else:
            hi = mid
    return (Bx, By), (0.5 * (lo + hi), n)


def test_crank_slider_ratio_from_finite_differences_of_the_loop():
    # The nut pin C = (m, n) on the screw's line at distance n from O; the arm pin B at
    # angle a = phi0 + phi from the normal to that line; rod |BC| = l. Solve the loop for
    # m (the nut on the near side of B) and differentiate by central differences.
    R, l, n, phi0, p, i_a = 90.0, 80.0, 50.0, 0.3, 5.0, 2.0

    def m_of(phi):
        return cs_loop(phi, R, l, n, phi0)[1][0]

    mech = CrankSlider(R=R, l=l, n=n, phi0=phi0, p=p, i_a=i_a)
    for phi in (-0.2, 0.0, 0.25):
        v = _fd(m_of, phi)
        i_num = abs(2 * math.pi * i_a * v / p)
        # the ratio's sign convention is the mechanism's; the magnitude is geometry
        assert abs(float(mech.ratio(phi))) == pytest.approx(i_num, rel=1e-6), phi


# --- loads ----------------------------------------------------------------------------------
def test_motor_torque_by_hand():
    # T = F p / (2 pi i_a eta): 1000 N * 5 mm / (2 * 3.14159265 * 2 * 0.9) = 442.0970641 N*mm
    assert motor_torque(1000.0, 5.0, 2.0, 0.9) == pytest.approx(442.0970641, rel=1e-9)
    # gear efficiency multiplies the screw's: eta = 0.9 * 0.8
    assert motor_torque(1000.0, 5.0, 2.0, 0.9, 0.8) == pytest.approx(552.6213301, rel=1e-9)
    # back-driven: F p eta' / (2 pi i_a) = 1000 * 5 * 0.5 / (4 pi) = 198.9436789 N*mm
    assert backdriven_motor_torque(1000.0, 5.0, 2.0, 0.5) == pytest.approx(198.9436789, rel=1e-9)


def test_motor_torque_by_virtual_work_through_the_fork():
    # Power balance: T_m * dtheta_m = M_h * dphi with dtheta_m = i * dphi, so T_m = M_h / i,
    # i from the finite-difference ratio of the geometry (no call into the load model).
    R, phi0, p, i_a, M_h = 80.0, 0.15, 5.0, 2.0, 5e5
    mech = ShiftingFork(R=R, phi0=phi0, p=p, i_a=i_a)
    for phi in (-0.4, 0.1, 0.4):
        i = 2 * math.pi * i_a * _fd(lambda f: _fork_pin_x(R, phi0 + f), phi) / p
        assert float(mech.motor_torque(phi, M_h)) == pytest.approx(M_h / i, rel=1e-7)
        # and with a screw efficiency the motor supplies 1/eta times more
        assert float(mech.motor_torque(phi, M_h, 0.8)) == pytest.approx(M_h / i / 0.8, rel=1e-7)


def test_pin_stresses_by_hand():
    # single shear 4F/(pi d^2): 4 * 1000 / (3.14159265 * 100) = 12.7323954 MPa
    assert pin_shear_stress(1000.0, 10.0, 1) == pytest.approx(12.73239545, rel=1e-9)
    # double shear halves it: 6.3661977 MPa (also the default)
    assert pin_shear_stress(1000.0, 10.0, 2) == pytest.approx(6.366197724, rel=1e-9)
    assert pin_shear_stress(1000.0, 10.0) == pytest.approx(6.366197724, rel=1e-9)
    # projected bearing pressure F/(d L): 1000 / (10 * 15) = 6.6667 MPa
    assert pin_bearing_pressure(1000.0, 10.0, 15.0) == pytest.approx(6.6666667, rel=1e-8)


def _fork_data(**requirements) -> dict:
    data = tomllib.loads((PROBLEMS / "fork_min_backlash.toml").read_text())
    data["requirements"].update(requirements)
    return data


def test_fork_pin_sized_by_single_shear():
    # With the shear limit at 150 MPa (and the pressure limit relaxed) the smallest pin
    # that holds wins: at phi = 0 (the largest normal force) with R at its travel limit
    # 55 / tan 30 deg = 95.2627944 mm, F = 5e5 / 95.2627944 = 5248.6393 N and
    # d = sqrt(4 F / (pi tau)) = sqrt(4 * 5248.6393 / (pi * 150)) = 6.6746797 mm.
    problem = problem_from_dict(
        _fork_data(pin_shear_stress_max="150 MPa", pin_bearing_pressure_max="1000 MPa")
    )
    res = solve_nlp(problem, starts=2, seed=1)
    assert res.status == "optimal"
    assert res.design["R"] == pytest.approx(95.2627944, rel=1e-6)
    assert res.design["d"] == pytest.approx(6.6746797, rel=1e-5)
    assert any(a.name.startswith("pin_shear_stress") for a in res.active)


# --- the fork's backlash optimum, derived by hand ------------------------------------------
def test_fork_optimum_backlash_from_the_iso_formula_and_hertz_by_hand():
    """fork_min_backlash at its optimum, every term recomputed from the standards.

    R = 55 / tan 30 deg = 95.2627944 mm (nut travel 110 mm over +-30 deg), F = M/R at
    phi = 0; the bearing pressure F/(1.5 d^2) = 100 MPa fixes d. The clearance is H7/g6
    from the ISO 286-1 formulas (tolerance factor i = 0.45 D^(1/3) + 0.001 D um, IT7 = 16 i,
    IT6 = 10 i, g: es = -2.5 D^0.34 um): c_max = IT7 + IT6 - es. Hertz line contact
    (seed 000 eq. 10-11): b^2 = 4 D (F/L)(1 - nu^2)/(pi E), Delta = D/2 - sqrt(D^2/4 - b^2)
    for each of pin and bore. The backlash is (c_max + 2 Delta) / R at phi = 0.
    """
    R = 55.0 / math.tan(math.radians(30.0))
    F = 5e5 / R
    d = math.sqrt(F / (1.5 * 100.0))
    assert R == pytest.approx(95.2627944, rel=1e-9)
    assert d == pytest.approx(5.9153128, rel=1e-7)
    i_um = 0.45 * d ** (1 / 3) + 0.001 * d
    c_max = (16 * i_um + 10 * i_um + 2.5 * d**0.34) * 1e-3  # mm
    b2 = 4 * d * (F / (1.5 * d)) * (1 - 0.3**2) / (math.pi * 2.1e5)
    delta = d / 2 - math.sqrt(d**2 / 4 - b2)
    expected = math.degrees((c_max + 2 * delta) / R)
    # the same numbers written out: i = 0.819754 um, IT7 + IT6 = 26 i = 21.3136 um,
    # -es = 4.5752 um, c_max = 0.0258888 mm; b^2 = 0.0193058 mm^2, 2 Delta = 0.0065310 mm
    assert c_max == pytest.approx(0.0258888, rel=1e-5)
    assert 2 * delta == pytest.approx(0.0065310, rel=1e-5)
    assert expected == pytest.approx(0.0194989, rel=1e-5)
    res = solve_nlp(load_problem(PROBLEMS / "fork_min_backlash.toml"), starts=2, seed=1)
    assert res.design["d"] == pytest.approx(d, rel=1e-6)
    assert res.objective == pytest.approx(expected, rel=1e-6)


# --- a three-objective front, fast -----------------------------------------------------------
def test_three_objective_front_small(tmp_path):
    """The crank-slider's (ripple, backlash, size) front on a 2 x 2 grid.

    Checked against properties an epsilon-constraint front must have, not its own
    output: three columns; every point meets its epsilons; the ripple and backlash ends
    are the single-objective optima found (and checked against a global search) in
    test_solve (0.0121114, 0.0362197 deg); within a row (same ripple bound) a looser
    backlash bound never gives a larger size; no point is dominated by another.
    """
    from optdesign.studies.pareto import compute_front
    from optdesign.studies.pareto.metrics import non_dominated

    cs = load_problem(PROBLEMS / "cs_min_backlash.toml")
    front = compute_front(
        cs, ["ripple", "backlash", "size"], 3, "epsilon", out=tmp_path, starts=2, workers=1
    )
    F = front.F
    assert F.shape[1] == 3 and len(F) >= 4
    assert all(p.verified for p in front.points)
    for p in front.points:
        for k, e in p.eps.items():
            assert p.objectives[k] <= e * (1 + 1e-6) + 1e-12, (p.eps, p.objectives)
    assert F[:, 0].min() == pytest.approx(0.0121114, rel=1e-4)
    assert F[:, 1].min() == pytest.approx(0.0362197, rel=1e-4)
    # the smallest linkage of the box is on the front
    assert F[:, 2].min() == pytest.approx(front.anchors["size"]["size"], rel=1e-6)
    # rows: points with both a ripple and a backlash bound, grouped by the ripple bound
    rows: dict[float, list] = {}
    for p in front.points:
        if "ripple" in p.eps and "backlash" in p.eps:
            rows.setdefault(round(p.eps["ripple"], 9), []).append(p)
    assert len(rows) == 2 and all(len(r) >= 2 for r in rows.values())
    for row in rows.values():
        row.sort(key=lambda p: p.eps["backlash"])
        sizes = [p.objectives["size"] for p in row]
        assert all(b <= a * (1 + 1e-6) for a, b in itertools.pairwise(sizes)), sizes
    # distinct points only: near-duplicates (same point reached twice) are not dominated
    uniq = np.unique(np.round(F / np.abs(F).max(axis=0), 6), axis=0)
    assert non_dominated(uniq).all()
