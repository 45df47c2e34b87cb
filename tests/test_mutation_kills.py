"""Tests written for mutants that survived benchmarks/mutation/run.sh (mutmut).

Each pins a behaviour the other tests left free (a default argument, a factor that
was 1 in every case tested); the expected values are written out by hand.
"""

from __future__ import annotations

import math

import pytest
from test_physics_independent import cs_loop  # the loop solved by bisection

from optdesign.models.loads import backdriven_motor_torque, fork_pin_normal_force, motor_torque


def test_load_defaults_are_lossless_and_the_paper_neutral_angle():
    # eta = 1 by default: 1000 N * 5 mm / (2 pi * 2) = 397.8873577 N*mm
    assert motor_torque(1000.0, 5.0, 2.0) == pytest.approx(397.8873577, rel=1e-9)
    assert backdriven_motor_torque(1000.0, 5.0, 2.0) == pytest.approx(397.8873577, rel=1e-9)
    # phi0 = 0 by default: 5e5 N*mm * cos(0.3) / 50 mm = 9553.3648 N
    assert fork_pin_normal_force(5e5, 50.0, 0.3) == pytest.approx(9553.364891, rel=1e-9)


def test_backdriven_torque_multiplies_both_efficiencies():
    # F p eta_s eta_g / (2 pi i_a) = 1000 * 5 * 0.5 * 0.8 / (4 pi) = 159.1549431 N*mm
    assert backdriven_motor_torque(1000.0, 5.0, 2.0, 0.5, 0.8) == pytest.approx(
        2000.0 / (4 * math.pi), rel=1e-12
    )
    assert 2000.0 / (4 * math.pi) == pytest.approx(159.1549431, rel=1e-9)


# --- the fork mechanism: its clearance chain, drawing and bench variables ------------------
def _fork_pin_x(R: float, a: float) -> float:
    # the arm's ray from O at angle a from the normal to the pin's line meets y = R
    return (R / math.cos(a)) * math.sin(a)


def test_fork_joints_are_the_papers_chain_with_phi0():
    # seed 000 Fig. 9: A screw bearings, B screw/nut (axial, 1/(dx/dphi)), O the output
    # shaft (angular), C the pin in the slot (cos a / R, loaded by M cos a / R).
    from optdesign.mechanisms.fork import ShiftingFork

    R, phi0, phi, M = 60.0, 0.2, 0.3, 4e5
    mech = ShiftingFork(R=R, phi0=phi0, p=5.0, i_a=2.0)
    h = 1e-6
    v = (_fork_pin_x(R, phi0 + phi + h) - _fork_pin_x(R, phi0 + phi - h)) / (2 * h)
    joints = mech.joints(phi, M)
    assert [(j.name, j.key, j.angular) for j in joints] == [
        ("A screw bearings", "A", False),
        ("B screw/nut", "B", False),
        ("O output shaft", "O", True),
        ("C pin in slot", "", False),
    ]
    for j in joints[:2]:
        assert float(j.sensitivity) == pytest.approx(1 / v, rel=1e-7)
    a = phi0 + phi  # 0.5 rad: cos a = 0.8775826
    assert float(joints[3].sensitivity) == pytest.approx(0.8775826 / R, rel=1e-6)
    assert float(joints[3].force) == pytest.approx(M * 0.8775826 / R, rel=1e-6)
    assert math.cos(a) == pytest.approx(0.8775826, rel=1e-7)


def test_fork_drawing_and_margin():
    from optdesign.mechanisms.fork import ShiftingFork

    R, phi0, phi = 50.0, 0.1, 0.3
    mech = ShiftingFork(R=R, phi0=phi0, p=5.0, i_a=2.0)
    x = _fork_pin_x(R, phi0 + phi)  # 50 tan 0.4 = 21.1396 mm
    assert x == pytest.approx(21.13966, rel=1e-6)
    end, pin = mech.pin_positions(phi)
    assert [float(v) for v in end] == pytest.approx([x, R])
    assert [float(v) for v in pin] == pytest.approx([x, R])
    sk = mech.sketch(phi)
    assert sk.links == [[(0.0, 0.0), pytest.approx((x, R))]]
    assert sk.pivots == [(0.0, 0.0)] and sk.slider == pytest.approx((x, R))
    # the screw axis drawn from 0.3 R before the nearer end to 0.3 R past the farther one
    assert sk.axis[0] == pytest.approx((-0.3 * R, R)) and sk.axis[1] == pytest.approx(
        (x + 0.3 * R, R)
    )
    sk_neg = mech.sketch(-0.6)  # a = -0.5: the pin left of the axis
    xn = _fork_pin_x(R, -0.5)
    assert sk_neg.axis[0] == pytest.approx((xn - 0.3 * R, R))
    assert sk_neg.axis[1] == pytest.approx((0.3 * R, R))
    # the slot holds the pin while cos a > 0: margin cos(a) R^2
    assert float(mech.assembly_margin(phi)) == pytest.approx(math.cos(0.4) * 2500.0)
    assert float(mech.assembly_margin(1.6)) < 0  # a = 1.7 rad: past perpendicular


def test_fork_bench_template_and_size():
    from optdesign.mechanisms.fork import ShiftingFork

    variables, requirements = ShiftingFork.bench_template()
    assert variables == {"R": {"lower": "30 mm", "upper": "120 mm"}, "p": None}
    assert requirements == {}
    assert ShiftingFork(R=42.0, p=5.0, i_a=2.0).size() == 42.0
    assert ShiftingFork.pin_shear_planes == 1  # one pin in one slot: single shear
    assert ShiftingFork.variables["phi0"].default == 0.0


# --- stiffness and screw: errors name the field --------------------------------------------
def test_stiffness_inputs_are_named():
    from optdesign.errors import InputError
    from optdesign.models import stiffness

    with pytest.raises(InputError, match=r"^d1: must be positive"):
        stiffness.shaft_torsional_stiffness(-1.0, 100.0)
    with pytest.raises(InputError, match=r"^L: must be positive"):
        stiffness.shaft_torsional_stiffness(10.0, 0.0)
    with pytest.raises(InputError, match=r"^p: must be positive"):
        stiffness.torsion_to_axial(1e6, 0.0)
    with pytest.raises(InputError, match=r"^p: must be positive"):
        stiffness.axial_to_torsion(1e5, -5.0)
    with pytest.raises(
        InputError, match=r"^terms: output_stiffness needs at least one \(K, rate\) pair$"
    ):
        stiffness.output_stiffness([])


def test_output_stiffness_of_one_and_two_members_by_hand():
    from optdesign.models.stiffness import output_stiffness

    # one member: K r^2 = 1e5 N/mm * (50 mm/rad)^2 = 2.5e8 N*mm/rad
    assert output_stiffness([(1e5, 50.0)]) == pytest.approx(2.5e8)
    # two in series: 1 / (1/2.5e8 + 1/(2e5 * 25^2 = 1.25e8)) = 8.3333e7
    assert output_stiffness([(1e5, 50.0), (2e5, 25.0)]) == pytest.approx(2.5e8 / 3)


def test_series_stiffness_needs_a_member():
    from optdesign.models.screw import series_stiffness

    with pytest.raises(ValueError, match=r"^series_stiffness needs at least one stiffness$"):
        series_stiffness()
    assert series_stiffness(3.0, 6.0) == pytest.approx(2.0)  # 1/(1/3 + 1/6)


def test_fork_pin_positions_on_a_grid_through_zero():
    import numpy as np

    from optdesign.mechanisms.fork import ShiftingFork

    mech = ShiftingFork(R=40.0, p=5.0, i_a=2.0)
    phi = np.array([-0.2, 0.0, 0.2])
    with np.errstate(all="raise"):  # no 0/0 anywhere on the grid
        end, pin = mech.pin_positions(phi)
    assert np.asarray(pin[1]) == pytest.approx([40.0, 40.0, 40.0])
    assert np.asarray(end[1]) == pytest.approx([40.0, 40.0, 40.0])
    assert np.asarray(pin[0]) == pytest.approx(40.0 * np.tan(phi))


def test_ripple_by_hand_and_the_papers_neutral_angle():
    import numpy as np

    from optdesign.models.crank_slider import arm_angle
    from optdesign.models.ratio import ratio_ripple, ripple_from_bounds

    # (i_max - i_min) / (i_max + i_min): (300 - 100) / 400 = 0.5; (300 - 200) / 500 = 0.2
    assert float(ratio_ripple(np.array([150.0, 100.0, 300.0, 220.0]))) == pytest.approx(0.5)
    assert float(ripple_from_bounds(200.0, 300.0)) == pytest.approx(0.2)
    assert arm_angle(0.3) == 0.3  # phi0 = 0 unless given (the paper's neutral angle)
    assert arm_angle(0.3, 0.1) == pytest.approx(0.4)


# --- screw efficiency: the selector's defaults and wiring ---------------------------------
def test_roller_screw_through_the_selector_is_seed_003s_value():
    # physics.md 6: alpha_s = 10 deg, beta = 45 deg, r_s = 40 mm, r_RP = 10 mm,
    # f_k = 0.055, f_r = 0.01 mm give eta = 0.974796. Lead for a 10 deg helix on
    # d_m = 2 r_s = 80 mm: p = pi * 80 * tan 10 deg = 44.31579 mm.
    from optdesign.models import roller_screw as rs
    from optdesign.models.screw_efficiency import screw_efficiency

    p = math.pi * 80.0 * math.tan(math.radians(10.0))
    assert p == pytest.approx(44.31579, rel=1e-6)
    assert float(screw_efficiency("roller", p, 80.0)) == pytest.approx(0.974796, abs=1e-6)
    back = float(screw_efficiency("roller", p, 80.0, direction="back"))
    lam = math.radians(10.0)
    expected = rs.efficiency_backdrive(lam, math.radians(45.0), 40.0, 10.0, 0.055, 0.01)
    assert back == pytest.approx(float(expected), rel=1e-9)


def test_ball_and_sliding_defaults_by_hand():
    from optdesign.models.screw_efficiency import (
        equivalent_friction_angle,
        is_back_drivable,
        screw_efficiency,
        self_locking_margin,
    )

    # ball screw, mu = 0.003 by default: lam = atan(5 / (20 pi)) = 0.0794101 rad,
    # eta = tan(lam) / tan(lam + atan 0.003) = 0.963440
    lam = math.atan(5.0 / (20.0 * math.pi))
    eta = math.tan(lam) / math.tan(lam + math.atan(0.003))
    assert eta == pytest.approx(0.963440, abs=1e-6)
    assert float(screw_efficiency("ball", 5.0, 20.0)) == pytest.approx(eta, rel=1e-12)
    # trapezoidal = sliding with Tr's 15 deg flank, mu = 0.1 by default; acme 14.5 deg
    for kind, flank in (("trapezoidal", 15.0), ("acme", 14.5), ("sliding", 15.0)):
        alpha_n = math.atan(math.tan(math.radians(flank)) * math.cos(lam))
        phi = math.atan(0.1 / math.cos(alpha_n))
        assert float(equivalent_friction_angle(kind, 5.0, 20.0)) == pytest.approx(phi), kind
        # without the normal section the axial flank angle is used
        phi_axial = math.atan(0.1 / math.cos(math.radians(flank)))
        assert float(
            equivalent_friction_angle(kind, 5.0, 20.0, normal_section=False)
        ) == pytest.approx(phi_axial), kind
        assert float(self_locking_margin(kind, 5.0, 20.0, normal_section=False)) == pytest.approx(
            phi_axial - lam
        ), kind
    # a Tr 20x4 (p = 4, d_m = 18) self-locks at mu = 0.1; a 5/20 ball screw does not
    assert not is_back_drivable("trapezoidal", 4.0, 18.0)
    assert is_back_drivable("ball", 5.0, 20.0)
    # exactly at the locking limit (eta' = 0) the screw is not back-drivable: mu = tan(lam)
    lam_b = math.atan(5.0 / (20.0 * math.pi))
    assert not is_back_drivable("ball", 5.0, 20.0, mu=math.tan(lam_b) * (1 + 1e-12))
    # keyword arguments reach the friction angle: a 45 deg flank raises it
    assert not is_back_drivable("sliding", 5.0, 20.0, 0.07, flank_angle=math.radians(45))
    assert is_back_drivable("sliding", 5.0, 20.0, 0.07)


def test_screw_efficiency_errors_name_the_field():
    import casadi as ca

    from optdesign.errors import InputError
    from optdesign.models.screw_efficiency import (
        equivalent_friction_angle,
        is_back_drivable,
        screw_efficiency,
    )

    with pytest.raises(InputError, match=r"^kind: 'nut' not in \("):
        screw_efficiency("nut", 5.0, 20.0)
    with pytest.raises(InputError, match=r"^direction: 'up' not in \("):
        screw_efficiency("ball", 5.0, 20.0, direction="up")
    with pytest.raises(InputError, match=r"^p: must be positive"):
        screw_efficiency("ball", 0.0, 20.0)
    with pytest.raises(InputError, match=r"^d_m: must be positive"):
        screw_efficiency("ball", 5.0, -1.0)
    with pytest.raises(InputError, match=r"^mu: must be >= 0"):
        equivalent_friction_angle("ball", 5.0, 20.0, -0.01)
    with pytest.raises(InputError, match=r"^mu: must be >= 0"):
        equivalent_friction_angle("sliding", 5.0, 20.0, -0.01)
    with pytest.raises(
        InputError, match=r"^kind: a roller screw has no single friction angle; use screw_eff"
    ):
        equivalent_friction_angle("roller", 5.0, 20.0)
    for args in (
        (ca.SX.sym("p"), 20.0, 0.1),
        (5.0, ca.SX.sym("d"), 0.1),
        (5.0, 20.0, ca.SX.sym("mu")),
    ):
        with pytest.raises(InputError, match=r"^p: is_back_drivable needs numbers"):
            is_back_drivable("sliding", *args)


# --- the crank-slider mechanism, against the loop solved here ------------------------------
CS = {"R": 90.0, "l": 80.0, "n": 50.0, "phi0": 0.2, "p": 5.0, "i_a": 2.0}


def _phi_holding_nut(m_target, n, guess, l=80.0):
    """Output angle at which the loop closes with the nut at m_target (secant)."""
    x0, x1 = guess, guess + 1e-3
    f = lambda p: cs_loop(p, n=n, l=l)[1][0] - m_target  # noqa: E731
    for _ in range(60):
        f0, f1 = f(x0), f(x1)
        if f1 == f0:
            break
        x0, x1 = x1, x1 - f1 * (x1 - x0) / (f1 - f0)
    return x1


def test_crank_slider_geometry_against_the_loop():
    from optdesign.mechanisms.crank_slider import CrankSlider

    mech = CrankSlider(**CS)
    for phi in (-0.3, 0.1, 0.4):
        (Bx, By), (Cx, Cy) = cs_loop(phi)
        B, C = mech.pin_positions(phi)
        assert [float(v) for v in B] == pytest.approx([Bx, By], rel=1e-9)
        assert [float(v) for v in C] == pytest.approx([Cx, Cy], rel=1e-9)
        assert float(mech.rod_run(phi)) == pytest.approx(Bx - Cx, rel=1e-9)
        u = By - 50.0
        assert float(mech.assembly_margin(phi)) == pytest.approx(80.0**2 - u**2, rel=1e-9)
        assert float(mech.rod_inclination(phi)) == pytest.approx(math.atan2(u, Bx - Cx))
        # transmission angle: between B->O and B->C
        bo, bc = (-Bx, -By), (Cx - Bx, Cy - By)
        cos_mu = (bo[0] * bc[0] + bo[1] * bc[1]) / (90.0 * 80.0)
        assert float(mech.transmission_angle(phi)) == pytest.approx(math.acos(cos_mu))
        # d|BC|/dphi with the nut held, by central differences
        h = 1e-6

        def dist(f, C=(Cx, Cy)):
            (bx, by), _ = cs_loop(f)
            return math.hypot(C[0] - bx, C[1] - by)

        rate = (dist(phi + h) - dist(phi - h)) / (2 * h)
        assert float(mech.rod_length_rate(phi)) == pytest.approx(rate, rel=1e-5)
        assert float(mech.sensitivity_rod_length(phi)) == pytest.approx(1 / rate, rel=1e-5)
        assert float(mech.rod_force(phi, 5e5)) == pytest.approx(5e5 / rate, rel=1e-5)
        # the nut slide: C moved across the screw by dn with the nut held
        dn = 1e-4
        dphi = (_phi_holding_nut(Cx, 50.0 + dn, phi) - _phi_holding_nut(Cx, 50.0 - dn, phi)) / (
            2 * dn
        )
        assert float(mech.sensitivity_lateral(phi)) == pytest.approx(abs(dphi), rel=1e-4)
    assert mech.size() == 170.0  # R + l


def test_crank_slider_guarded_path_stays_finite_past_the_toggle():
    import numpy as np

    from optdesign.mechanisms.crank_slider import ASSEMBLY_FLOOR, CrankSlider

    # n = 200 mm: the rod (80 mm) cannot reach the nut line (u = R cos a - n < -80 mm)
    bad = {**CS, "n": 200.0}
    assert CrankSlider(**bad).floor is None and ASSEMBLY_FLOOR == 1e-6
    with np.errstate(invalid="ignore"):
        assert np.isnan(float(CrankSlider(**bad).rod_run(0.0)))
        assert np.isnan(float(CrankSlider(**bad).transmission_angle(0.0)))
        assert np.isnan(float(CrankSlider(**bad).rod_inclination(0.0)))
    guarded = CrankSlider(bad, guarded=True)
    assert guarded.floor == 1e-6
    assert float(guarded.rod_run(0.0)) == pytest.approx(1e-3)  # sqrt of the floor
    u = 90.0 * math.cos(0.2) - 200.0  # a = phi0 + 0 = 0.2 rad
    assert float(guarded.rod_inclination(0.0)) == pytest.approx(math.atan2(u, 1e-3))
    # the nut position R sin a - s with s = 1e-3 mm, and the nut-slide sensitivity
    # |u| / (s |dm/dphi|) stay finite on the guarded path, NaN on the plain one
    assert float(guarded.nut_position(0.0)) == pytest.approx(90.0 * math.sin(0.2) - 1e-3)
    assert np.isfinite(float(guarded.sensitivity_lateral(0.0)))
    with np.errstate(invalid="ignore"):
        assert np.isnan(float(CrankSlider(**bad).nut_position(0.0)))
        assert np.isnan(float(CrankSlider(**bad).sensitivity_lateral(0.0)))


def test_crank_slider_joints_are_the_papers_chain():
    from optdesign.mechanisms.crank_slider import CrankSlider

    mech = CrankSlider(**CS)
    phi, M = 0.1, 5e5
    joints = mech.joints(phi, M)
    assert [(j.name, j.key, j.angular) for j in joints] == [
        ("A screw bearings", "A", False),
        ("B screw/nut", "B", False),
        ("C nut slide", "C", False),
        ("O output shaft", "O", True),
        ("D rod pin (arm)", "", False),
        ("E rod pin (nut)", "", False),
    ]
    axial = float(mech.sensitivity_axial(phi))
    rod = float(mech.sensitivity_rod_length(phi))
    assert [float(j.sensitivity) for j in joints[:3]] == pytest.approx(
        [axial, axial, float(mech.sensitivity_lateral(phi))]
    )
    for j in joints[4:]:
        assert float(j.sensitivity) == pytest.approx(rod)
        assert float(j.force) == pytest.approx(float(mech.rod_force(phi, M)))
    assert float(mech.pin_force(phi, M)) == pytest.approx(float(mech.rod_force(phi, M)))
    assert CrankSlider.pin_shear_planes == 2  # a rod pin in a fork end: double shear


def test_crank_slider_requirement_rows_by_hand():
    from types import SimpleNamespace

    import numpy as np

    from optdesign.mechanisms.crank_slider import CrankSlider

    mech = CrankSlider(**CS)
    phi = np.array([-0.3, 0.1, 0.4])
    loops = [cs_loop(f) for f in phi]
    u = np.array([B[1] - 50.0 for B, _ in loops])
    (margin,) = mech.requirement_rows("assembly_margin_min", 0.05, phi)
    assert margin.name == "assembly_margin"
    assert np.asarray(margin.expr) == pytest.approx((80.0**2 - u**2) / 80.0**2)
    assert (margin.lower, margin.upper) == (0.05, None)
    band = SimpleNamespace(min=math.radians(40), max=math.radians(140))
    (ta,) = mech.requirement_rows("transmission_angle", band, phi)
    assert ta.name == "transmission_angle" and ta.display_unit == "deg"
    mu = np.asarray(mech.transmission_angle(phi))
    assert np.asarray(ta.expr) == pytest.approx(np.cos(mu))
    # cos is decreasing: 40..140 deg <=> cos in [cos 140, cos 40] = [-0.766044, 0.766044]
    assert ta.lower == pytest.approx(-0.7660444) and ta.upper == pytest.approx(0.7660444)
    assert ta.display(np.asarray(ta.expr)) == pytest.approx(np.degrees(mu))
    assert ta.display(np.array([1.0 + 1e-12, -1.0 - 1e-12])) == pytest.approx([0.0, 180.0])
    half = SimpleNamespace(min=None, max=math.radians(120))
    (ta2,) = mech.requirement_rows("transmission_angle", half, phi)
    assert ta2.lower == pytest.approx(-0.5) and ta2.upper is None
    (inc,) = mech.requirement_rows("rod_inclination_max", math.radians(30), phi)
    assert inc.name == "rod_inclination" and inc.display_unit == "deg"
    assert np.asarray(inc.expr) == pytest.approx(u / 80.0)
    assert (inc.lower, inc.upper) == (pytest.approx(-0.5), pytest.approx(0.5))
    assert inc.display(np.array([0.5, 1.0 + 1e-12])) == pytest.approx([30.0, 90.0])
    with pytest.raises(NotImplementedError, match="CrankSlider declares 'nosuch'"):
        mech.requirement_rows("nosuch", 1.0, phi)


def test_crank_slider_drawing_and_bench_family():
    from optdesign.mechanisms.crank_slider import CrankSlider

    mech = CrankSlider(**CS)
    (Bx, By), (Cx, Cy) = cs_loop(0.1)
    sk = mech.sketch(0.1)
    assert sk.links[0][0] == (0.0, 0.0) and sk.links[0][1] == pytest.approx((Bx, By))
    assert sk.links[1][0] == pytest.approx((Bx, By)) and sk.links[1][1] == pytest.approx((Cx, Cy))
    assert sk.pivots == [(0.0, 0.0)] and sk.slider == pytest.approx((Cx, Cy))
    # the screw axis from half a rod before the nearer end to 10 mm past the farther one
    lo, hi = min(0.0, Cx), max(0.0, Cx)
    assert sk.axis[0] == pytest.approx((lo - 40.0, 50.0))
    assert sk.axis[1] == pytest.approx((hi + 10.0, 50.0))
    # the benchmark's crank-slider family (benchmarks/README.md): its boxes and limits
    variables, requirements = CrankSlider.bench_template()
    assert variables == {
        "R": {"lower": "30 mm", "upper": "120 mm"},
        "l": {"lower": "40 mm", "upper": "200 mm"},
        "n": {"lower": "0 mm", "upper": "150 mm"},
        "p": None,
        "phi0": {"lower": "-0.6 rad", "upper": "0.6 rad"},
    }
    assert requirements == {
        "transmission_angle": {"min": "40 deg", "max": "140 deg"},
        "rod_inclination_max": "30 deg",
    }


def test_crank_slider_guarded_transmission_angle_past_the_toggle():
    import numpy as np

    from optdesign.mechanisms.crank_slider import CrankSlider

    # a = 1.2 rad, n = 113.6 mm: u = 90 cos 1.2 - 113.6 = -81.0 mm, |u| > l = 80 mm (no
    # assembly); the guarded path uses s = sqrt(1e-6) = 1e-3 mm and stays finite:
    # cos mu = (s sin a + u cos a) / l = -0.36682
    bad = {"R": 90.0, "l": 80.0, "n": 113.6, "phi0": 0.0, "p": 5.0, "i_a": 2.0}
    a = 1.2
    u = 90.0 * math.cos(a) - 113.6
    cos_mu = (1e-3 * math.sin(a) + u * math.cos(a)) / 80.0
    assert u == pytest.approx(-80.988, abs=1e-3) and cos_mu == pytest.approx(-0.36682, abs=1e-4)
    guarded = CrankSlider(bad, guarded=True)
    assert float(guarded.transmission_angle(a)) == pytest.approx(math.acos(cos_mu))
    band = type("Band", (), {"min": None, "max": None})()
    (row,) = guarded.requirement_rows("transmission_angle", band, np.array([a]))
    assert float(np.asarray(row.expr)[0]) == pytest.approx(cos_mu)
    assert row.lower is None and row.upper is None  # no limit given: none set
    with np.errstate(invalid="ignore"):
        assert np.isnan(float(CrankSlider(**bad).transmission_angle(a)))


def test_crank_slider_rows_describe_themselves():
    # the rows' unit and description are what a report prints next to the values
    from types import SimpleNamespace

    import numpy as np

    from optdesign.mechanisms.crank_slider import CrankSlider

    mech = CrankSlider(**CS)
    phi = np.array([0.0])
    (margin,) = mech.requirement_rows("assembly_margin_min", 0.05, phi)
    band = SimpleNamespace(min=math.radians(40), max=math.radians(140))
    (ta,) = mech.requirement_rows("transmission_angle", band, phi)
    (inc,) = mech.requirement_rows("rod_inclination_max", math.radians(30), phi)
    assert [(r.unit, r.description) for r in (margin, ta, inc)] == [
        ("", "(l^2 - u^2)/l^2: the rod reaches the nut line"),
        ("", "transmission angle"),
        ("", "rod inclination to the screw axis"),
    ]
    # below -1 the display clips to -90 deg instead of NaN
    assert inc.display(np.array([-1.0 - 1e-12])) == pytest.approx([-90.0])


def test_crank_slider_drawing_with_the_nut_right_of_the_axis():
    from optdesign.mechanisms.crank_slider import CrankSlider

    # phi = 1.0 with phi0 = 0.2 (a = 1.2): B = (83.88, 32.61), C = (5.80, 50): the axis
    # runs from 0 - l/2 = -40 mm to 5.80 + 10 mm
    mech = CrankSlider(**CS)
    _, (Cx, _) = cs_loop(1.0)
    assert Cx == pytest.approx(5.80, abs=0.01)
    sk = mech.sketch(1.0)
    assert sk.axis[0] == pytest.approx((-40.0, 50.0))
    assert sk.axis[1] == pytest.approx((Cx + 10.0, 50.0))


def test_back_drivable_exactly_at_the_locking_limit_is_not():
    from optdesign.models.screw_efficiency import is_back_drivable

    # mu = tan(lambda) exactly (the same expression): lambda - phi = 0, eta' = 0: locked
    mu = 5.0 / (math.pi * 20.0)
    assert not is_back_drivable("ball", 5.0, 20.0, mu)
