"""The pivoting (trunnion-mounted) screw, checked against computations that do not use its
formulas: finite differences, a loop closure solved numerically, statics by cross
products, and property tests."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

import optdesign as od
from optdesign.mechanisms import Mechanism, PinJoint, PivotingScrew

DESIGN = {"R": 90.0, "a_T": -220.0, "b_T": 40.0, "phi0": 0.1, "p": 5.0, "i_a": 2.0}
PHI = np.radians(np.linspace(-30.0, 30.0, 13))


def _length(R, a_T, b_T, phi0, phi):
    """Actuator length by plain vector geometry (not the model)."""
    B = np.array([R * np.sin(phi0 + phi), R * np.cos(phi0 + phi)])
    return float(np.hypot(*(B - np.array([a_T, b_T]))))


def _angle_at_length(d, L, guess):
    """Output angle where the actuator has length L (loop closure solved numerically)."""
    return brentq(
        lambda phi: _length(d["R"], d["a_T"], d["b_T"], d["phi0"], phi) - L,
        guess - 0.2,
        guess + 0.2,
        xtol=1e-15,
    )


def test_nut_velocity_three_ways():
    mech = PivotingScrew(**DESIGN)
    h = 1e-6
    fd = (mech.nut_position(PHI + h) - mech.nut_position(PHI - h)) / (2 * h)
    np.testing.assert_allclose(mech.nut_velocity(PHI), fd, rtol=1e-7)
    # the framework's automatic derivative (CasADi AD of nut_position) agrees
    np.testing.assert_allclose(
        Mechanism.nut_velocity(mech, PHI), mech.nut_velocity(PHI), rtol=1e-12
    )
    # the length itself is the distance pivot-pin
    assert mech.nut_position(PHI[3]) == pytest.approx(_length(90, -220, 40, 0.1, PHI[3]), rel=1e-14)


@pytest.mark.parametrize("k", [0, 4, 8, 12])
def test_loop_closure_gives_the_inverse_rate(k):
    # dphi/dL of the assembled linkage (lengthen the actuator, re-solve for phi) is the
    # output rotation per unit clearance along the actuator, 1/(dL/dphi)
    mech = PivotingScrew(**DESIGN)
    phi = PHI[k]
    L = mech.nut_position(phi)
    delta = 1e-5
    fd = (_angle_at_length(DESIGN, L + delta, phi) - _angle_at_length(DESIGN, L - delta, phi)) / (
        2 * delta
    )
    assert fd == pytest.approx(float(mech.sensitivity_axial(phi)), rel=1e-7)
    joints = mech.joints(np.array([phi]), 500e3, PinJoint(8.0, 12.0))
    pins = [j for j in joints if j.pin is not None]
    assert [j.name for j in pins] == ["horn pin", "trunnion"]
    for j in pins:
        assert float(np.asarray(j.sensitivity).ravel()[0]) == pytest.approx(fd, rel=1e-7)


def test_statics_by_cross_product():
    # the actuator force F along T->B produces the hinge moment about O: |B x F| = M_h
    mech = PivotingScrew(**DESIGN)
    M_h = 500e3
    F = mech.nut_force(PHI, M_h)
    for k, phi in enumerate(PHI):
        B = np.array([90 * np.sin(0.1 + phi), 90 * np.cos(0.1 + phi)])
        u = (B - np.array([-220.0, 40.0])) / _length(90, -220, 40, 0.1, phi)
        moment = abs(B[0] * u[1] - B[1] * u[0]) * F[k]
        assert moment == pytest.approx(M_h, rel=1e-12)


def test_transmission_angle_from_the_pin_positions():
    mech = PivotingScrew(**DESIGN)
    c = mech.transmission_angle_cos(PHI)
    for k, phi in enumerate(PHI):
        B = np.array([90 * np.sin(0.1 + phi), 90 * np.cos(0.1 + phi)])
        v1, v2 = -B, np.array([-220.0, 40.0]) - B
        expected = v1 @ v2 / (np.linalg.norm(v1) * np.linalg.norm(v2))
        assert c[k] == pytest.approx(expected, rel=1e-12)


def test_ratio_by_finite_step_tends_to_the_exact_ratio():
    mech = PivotingScrew(**DESIGN)
    errs = [np.max(np.abs(mech.ratio_finite_step(PHI, s) - mech.ratio(PHI))) for s in (1e-2, 1e-3)]
    assert errs[1] < errs[0] / 8  # first order in the step


@settings(max_examples=60, deadline=None)
@given(
    R=st.floats(30, 120),
    a_T=st.floats(-300, -40),
    b_T=st.floats(-100, 150),
    phi0=st.floats(-0.6, 0.6),
)
def test_casadi_and_numpy_paths_agree(R, a_T, b_T, phi0):
    x = ca.SX.sym("x", 4)
    sym = PivotingScrew(R=x[0], a_T=x[1], b_T=x[2], phi0=x[3], p=5.0, i_a=2.0)
    f = ca.Function("f", [x], [sym.ratio(PHI), sym.nut_force(PHI, 5e5)])
    num = PivotingScrew(R=R, a_T=a_T, b_T=b_T, phi0=phi0, p=5.0, i_a=2.0)
    ratio, force = f([R, a_T, b_T, phi0])
    np.testing.assert_allclose(np.asarray(ratio).ravel(), num.ratio(PHI), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(np.asarray(force).ravel(), num.nut_force(PHI, 5e5), rtol=1e-10)


def test_requirement_rows_by_hand():
    """The pivoting screw's own requirements: the transmission angle at the horn pin
    (cos, band flipped, shown in degrees) and the dead length (length minus stroke, mm),
    from the plain vector geometry."""
    from types import SimpleNamespace

    mech = PivotingScrew(**DESIGN)
    band = SimpleNamespace(min=np.radians(40.0), max=np.radians(140.0))
    (ta,) = mech.requirement_rows("transmission_angle", band, PHI)
    assert (ta.name, ta.unit, ta.display_unit) == ("transmission_angle", "", "deg")
    assert ta.description == "transmission angle (horn to actuator)"
    assert ta.lower == pytest.approx(np.cos(np.radians(140.0)))
    assert ta.upper == pytest.approx(np.cos(np.radians(40.0)))
    # shown in degrees, a cosine rounded past +-1 as 0 and 180 deg (never NaN)
    assert ta.display(np.cos(np.radians(40.0))) == pytest.approx(40.0)
    assert ta.display(1.0 + 1e-12) == 0.0 and ta.display(-1.0 - 1e-12) == 180.0
    (dead,) = mech.requirement_rows("dead_length", 60.0, PHI)
    assert (dead.name, dead.unit, dead.lower, dead.upper) == ("dead_length", "mm", 60.0, None)
    assert dead.description == "actuator length minus stroke"
    lengths = np.array(
        [_length(DESIGN["R"], DESIGN["a_T"], DESIGN["b_T"], DESIGN["phi0"], f) for f in PHI]
    )
    stroke = abs(lengths[-1] - lengths[0])
    assert np.asarray(dead.expr, dtype=float).ravel() == pytest.approx(lengths - stroke, rel=1e-12)


def test_the_sketch_draws_the_horn_and_the_actuator_from_the_geometry():
    phi = 0.2
    sk = PivotingScrew(**DESIGN).sketch(phi)
    a = DESIGN["phi0"] + phi
    B = (DESIGN["R"] * np.sin(a), DESIGN["R"] * np.cos(a))
    T = (DESIGN["a_T"], DESIGN["b_T"])
    assert np.allclose(sk.links[0], [(0.0, 0.0), B]) and np.allclose(sk.links[1], [T, B])
    assert np.allclose(sk.pivots, [(0.0, 0.0), T]) and np.allclose(sk.slider, B)
    assert np.allclose(sk.axis, [T, B])


def test_both_pins_sit_on_the_actuator_and_carry_its_force():
    """The chain: A, B axial and O angular, then the horn pin and the trunnion, each with
    the actuator's sensitivity 1/(dL/dphi) and force M_h/(dL/dphi) (the statics above)."""
    mech = PivotingScrew(**DESIGN)
    pin = PinJoint(8.0, 10.0)
    chain = mech.joints(PHI, 2.0e5, pin)
    assert [(j.name, j.key, j.angular, j.pin is pin) for j in chain] == [
        ("A screw bearings", "A", False, False),
        ("B screw/nut", "B", False, False),
        ("O output shaft", "O", True, False),
        ("horn pin", "", False, True),
        ("trunnion", "", False, True),
    ]
    rate = np.asarray(mech.nut_velocity(PHI), dtype=float)
    for j in (chain[0], chain[1], chain[3], chain[4]):
        assert np.allclose(j.sensitivity, 1.0 / rate, rtol=1e-12)
    for j in chain[3:]:
        assert np.allclose(j.force, 2.0e5 / rate, rtol=1e-12)
    assert np.allclose(mech.pin_force(PHI, 2.0e5), 2.0e5 / rate, rtol=1e-12)


def test_the_size_is_the_horn_plus_the_pivot_distance():
    mech = PivotingScrew(**DESIGN)
    assert float(mech.size()) == pytest.approx(90.0 + np.hypot(220.0, 40.0), rel=1e-12)


def test_a_one_sided_transmission_band_leaves_the_other_bound_open():
    from types import SimpleNamespace

    mech = PivotingScrew(**DESIGN)
    (lower_only,) = mech.requirement_rows(
        "transmission_angle", SimpleNamespace(min=np.radians(50.0), max=None), PHI
    )
    assert lower_only.lower is None
    assert lower_only.upper == pytest.approx(np.cos(np.radians(50.0)))
    (upper_only,) = mech.requirement_rows(
        "transmission_angle", SimpleNamespace(min=None, max=np.radians(120.0)), PHI
    )
    assert upper_only.upper is None
    assert upper_only.lower == pytest.approx(np.cos(np.radians(120.0)))
    with pytest.raises(NotImplementedError, match="'stiffness'"):
        mech.requirement_rows("stiffness", 1.0, PHI)


def test_the_requirements_declared_ranges_and_the_benchmarks_template():
    req = PivotingScrew.requirements
    assert (req["transmission_angle"].kind, req["transmission_angle"].valid) == (
        "band",
        (0.0, np.pi),
    )
    assert (req["dead_length"].kind, req["dead_length"].dimension) == ("value", "length")
    assert req["dead_length"].valid == (0.0, np.inf)
    variables, requirements = PivotingScrew.bench_template()
    assert variables == {
        "R": {"lower": "30 mm", "upper": "120 mm"},
        "a_T": {"lower": "-300 mm", "upper": "-40 mm"},
        "b_T": {"lower": "-100 mm", "upper": "150 mm"},
        "p": None,
        "phi0": {"lower": "-0.6 rad", "upper": "0.6 rad"},
    }
    assert list(variables) == ["R", "a_T", "b_T", "p", "phi0"]
    assert requirements == {
        "transmission_angle": {"min": "40 deg", "max": "140 deg"},
        "dead_length": "60 mm",
    }
    assert PivotingScrew.pin_shear_planes == 2
    assert PivotingScrew.bench_families == {"pivot_backlash": ("backlash",)}


ROOT = Path(__file__).resolve().parents[2]


PROBLEMS = ROOT / "problems"


def _problem(stem: str, **sections) -> od.DesignProblem:
    data = tomllib.loads((PROBLEMS / f"{stem}.toml").read_text())
    data.update(sections)
    return od.load(data)


def _pivot_nut(d):
    def length(phi):
        a = d["phi0"] + phi
        return math.hypot(d["R"] * math.sin(a) - d["a_T"], d["R"] * math.cos(a) - d["b_T"])

    return length


# --- the pivoting screw's dead length ------------------------------------------------------
def test_pivot_dead_length_is_length_minus_the_whole_stroke():
    problem = _problem("pivot_min_backlash")
    d = {"R": 90.0, "a_T": -220.0, "b_T": 40.0, "phi0": 0.1}
    values = problem.design_dict(problem.midpoint())
    values.update(d)
    ex = problem.expressions(values)
    block = next(b for b in ex.constraints if b.name == "dead_length")
    L = _pivot_nut(d)
    lengths = np.array([L(float(phi)) for phi in problem.phi])
    stroke = L(math.radians(30.0)) - L(math.radians(-30.0))
    assert stroke == pytest.approx(lengths[-1] - lengths[0], rel=1e-12)
    assert stroke > 5.0  # far from one grid step's travel (about stroke / 60)
    np.testing.assert_allclose(np.ravel(block.expr), lengths - stroke, rtol=1e-12)
    assert block.lower == pytest.approx(60.0) and block.upper is None
