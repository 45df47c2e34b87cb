"""Kinematics checked against independent computations: CasADi derivatives vs finite
differences of the position equations, loop closure, virtual work, symmetry."""

import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from independent_physics import _fd, cs_loop
from scipy.optimize import brentq

from optdesign.errors import AssemblyError, InputError
from optdesign.mechanisms import CrankSlider, Joint, PinJoint, ShiftingFork
from optdesign.models import crank_slider as cs_model
from optdesign.models import crank_slider as model


@st.composite
def crank_designs(draw):
    """Random crank-slider designs that assemble over +-30 deg (margin >= 5 % of l^2)."""
    R = draw(st.floats(30, 120))
    l = draw(st.floats(40, 200))
    n = draw(st.floats(0, 150))
    phi0 = draw(st.floats(-0.6, 0.6))
    p = draw(st.floats(2, 10))
    mech = CrankSlider(R=R, l=l, n=n, p=p, i_a=2.0, phi0=phi0)
    phi = np.radians(np.linspace(-30, 30, 61))
    margin = mech.assembly_margin(phi)
    from hypothesis import assume

    assume(np.min(margin) > 0.05 * l**2)
    assume(np.min(np.abs(mech.nut_velocity(phi))) > 1.0)
    return mech


def test_casadi_derivative_matches_central_difference():
    R, l, n, phi0 = 90.0, 80.0, 50.0, 0.1
    phi = ca.SX.sym("phi")
    m_expr = cs_model.nut_position(R, l, n, phi, phi0)
    dm = ca.Function("dm", [phi], [ca.jacobian(m_expr, phi)])
    h = 1e-6
    for p in np.radians(np.linspace(-30, 30, 13)):
        fd = (
            cs_model.nut_position(R, l, n, p + h, phi0)
            - cs_model.nut_position(R, l, n, p - h, phi0)
        ) / (2 * h)
        assert float(dm(p)) == pytest.approx(fd, rel=1e-7)
        # the hand-written derivative used by the ratio agrees with both
        assert cs_model.nut_velocity(R, l, n, p, phi0) == pytest.approx(float(dm(p)), rel=1e-12)


def test_symbolic_and_numeric_paths_agree():
    x = ca.SX.sym("x", 4)  # R, l, n, phi0
    phi = np.radians(np.linspace(-30, 30, 7))
    mech = CrankSlider(R=x[0], l=x[1], n=x[2], p=5.0, i_a=2.0, phi0=x[3])
    f = ca.Function("i", [x], [mech.ratio(phi)])
    val = np.array(f([90, 80, 50, 0.2])).ravel()
    ref = CrankSlider(R=90, l=80, n=50, p=5.0, i_a=2.0, phi0=0.2).ratio(phi)
    np.testing.assert_allclose(val, ref, rtol=1e-13)


@settings(max_examples=60, deadline=None)
@given(crank_designs())
def test_loop_closure_and_virtual_work(mech):
    phi = np.radians(np.linspace(-30, 30, 61))
    (bx, by), (cx, cy) = mech.pin_positions(phi)
    np.testing.assert_allclose(np.hypot(cx - bx, cy - by), mech.l, rtol=1e-12)
    # virtual work: F_a dm = M_h dphi with dm from a central difference of positions
    M_h = 500e3
    h = 1e-6
    dm = mech.nut_position(phi + h) - mech.nut_position(phi - h)
    np.testing.assert_allclose(mech.nut_force(phi, M_h) * dm, M_h * 2 * h, rtol=1e-5)
    # the rod force projected on the screw axis carries the nut force
    s = mech.rod_run(phi)
    np.testing.assert_allclose(
        mech.rod_force(phi, M_h) * s / mech.l, mech.nut_force(phi, M_h), rtol=1e-10
    )


@settings(max_examples=40, deadline=None)
@given(crank_designs())
def test_transmission_angle_from_pin_positions(mech):
    phi = np.radians(np.linspace(-30, 30, 31))
    (bx, by), (cx, cy) = mech.pin_positions(phi)
    bo = np.stack([-bx, -by])
    bc = np.stack([cx - bx, cy - by])
    cosang = np.sum(bo * bc, axis=0) / (np.linalg.norm(bo, axis=0) * np.linalg.norm(bc, axis=0))
    np.testing.assert_allclose(mech.transmission_angle(phi), np.arccos(cosang), atol=1e-9)
    # signed inclination of the rod to the screw axis: atan2(u, s) with u = yB - yC, s = xB - xC
    np.testing.assert_allclose(mech.rod_inclination(phi), np.arctan2(by - cy, bx - cx), atol=1e-12)


def test_fork_symmetric_crank_slider_not():
    phi = np.radians(np.linspace(-30, 30, 61))
    fork = ShiftingFork(R=90, p=5, i_a=2)
    np.testing.assert_allclose(fork.ratio(phi), fork.ratio(-phi), rtol=1e-14)
    mech = CrankSlider(R=90, l=80, n=50, p=5, i_a=2)
    assert np.max(np.abs(mech.ratio(phi) - mech.ratio(-phi))) > 10


def test_fork_derivative_matches_finite_difference():
    fork = ShiftingFork(R=75.0, p=4.0, i_a=2.0)
    phi = np.radians(np.linspace(-30, 30, 13))
    h = 1e-6
    fd = (fork.nut_position(phi + h) - fork.nut_position(phi - h)) / (2 * h)
    np.testing.assert_allclose(fork.nut_velocity(phi), fd, rtol=1e-8)
    # virtual work for the pin: F_n * (pin lever arm) = M_h
    M_h = 500e3
    np.testing.assert_allclose(fork.pin_normal_force(phi, M_h) * 75.0 / np.cos(phi), M_h)


def test_finite_step_ratio_converges_to_derivative():
    mech = CrankSlider(R=90, l=80, n=50, p=5, i_a=2)
    phi = np.radians(np.linspace(-30, 30, 61))
    errs = [np.max(np.abs(mech.ratio_finite_step(phi, h) - mech.ratio(phi))) for h in (1e-2, 1e-3)]
    assert errs[1] < errs[0] / 8  # first-order forward difference: error ~ step


def test_numpy_population_broadcasts():
    R = np.array([[80.0], [90.0], [100.0]])
    mech = CrankSlider(R=R, l=80.0, n=50.0, p=5.0, i_a=2.0)
    phi = np.radians(np.linspace(-30, 30, 61))
    i = mech.ratio(phi)
    assert i.shape == (3, 61)
    np.testing.assert_allclose(i[1], CrankSlider(R=90, l=80, n=50, p=5, i_a=2).ratio(phi))
    assert mech.ripple(phi).shape == (3,)


def _output_angle(R, l, n, phi0, m_target, guess):
    """Solve the loop closure for phi at a fixed nut position (independent of the models'
    derivative formulas)."""

    def f(phi):
        a = phi0 + phi
        return (R * np.sin(a) - m_target) ** 2 + (R * np.cos(a) - n) ** 2 - l**2

    return brentq(f, guess - 0.05, guess + 0.05, xtol=1e-15)


@pytest.mark.parametrize("phi_deg", [-30, -12, 0, 17, 30])
def test_rod_length_sensitivity_by_reassembly(phi_deg):
    R, l, n, phi0 = 90.0, 80.0, 50.0, 0.0
    phi = np.radians(phi_deg)
    mech = CrankSlider(R=R, l=l, n=n, p=5, i_a=2, phi0=phi0)
    m0 = mech.nut_position(phi)
    delta = 1e-4
    phi_plus = _output_angle(R, l + delta, n, phi0, m0, phi)
    phi_minus = _output_angle(R, l - delta, n, phi0, m0, phi)
    fd = (phi_plus - phi_minus) / (2 * delta)
    assert abs(fd) == pytest.approx(abs(mech.sensitivity_rod_length(phi)), rel=1e-6)
    # lateral clearance of the nut slide: move the nut line by dn
    fd_n = (
        _output_angle(R, l, n + delta, phi0, m0, phi)
        - _output_angle(R, l, n - delta, phi0, m0, phi)
    ) / (2 * delta)
    assert abs(fd_n) == pytest.approx(mech.sensitivity_lateral(phi), rel=1e-6, abs=1e-12)


def test_backlash_chain_crank_slider():
    mech = CrankSlider(R=90, l=80, n=50, p=5, i_a=2)
    phi = np.radians(np.linspace(-30, 30, 61))
    pin = PinJoint(10, 15, "H7/g6")
    joints = [j for j in mech.joints(phi, 500e3, pin) if j.pin is not None]
    b = mech.backlash(phi, joints)
    # both rod pins carry the same force and the same clearance: equal shares
    np.testing.assert_allclose(b.per_joint["D rod pin (arm)"], b.per_joint["E rod pin (nut)"])
    np.testing.assert_allclose(b.worst_case, 2 * b.per_joint["D rod pin (arm)"])
    np.testing.assert_allclose(b.rss, np.sqrt(2) * b.per_joint["D rod pin (arm)"])
    # by hand at phi = 0: clearance (fit + 2 Delta) / (d|BC|/dphi), in degrees
    F = mech.rod_force(0.0, 500e3)
    c = pin.clearance(F)
    expected = np.degrees(c / model.rod_length_rate(90, 80, 50, 0.0))
    assert b.per_joint["D rod pin (arm)"][30] == pytest.approx(expected, rel=1e-12)
    # an angular clearance at O adds directly
    b2 = mech.backlash(phi, [Joint("O", "O", angular=True, clearance=np.radians(0.01))])
    np.testing.assert_allclose(b2.worst_case, 0.01)


def test_assembly_error_names_angle_and_margin():
    mech = CrankSlider(R=90, l=45, n=10, p=5, i_a=2)  # rod too short at -30 deg (u = 67.9 > l)
    with pytest.raises(AssemblyError, match=r"deflection -30\.000 deg.*margin") as exc:
        mech.check_assembly(np.radians(np.linspace(-30, 30, 61)))
    assert exc.value.margin < 0
    # the message ends with the design it was checked at (the mechanism's description)
    assert str(exc.value).endswith(f"; {mech.describe()}") and "R=90" in mech.describe()
    CrankSlider(R=90, l=80, n=50, p=5, i_a=2).check_assembly(np.radians(np.linspace(-30, 30, 61)))


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"R": -90}, "R"),
        ({"l": 0}, "l"),
        ({"p": 0}, "p"),
        ({"n": float("nan")}, "n"),
        ({"i_a": -1}, "i_a"),
    ],
)
def test_non_physical_inputs_name_the_field(kwargs, field):
    args = {"R": 90, "l": 80, "n": 50, "p": 5, "i_a": 2} | kwargs
    with pytest.raises(InputError) as exc:
        CrankSlider(**args)
    assert exc.value.field == field


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
