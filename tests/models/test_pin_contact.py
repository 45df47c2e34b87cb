"""Conforming pin-in-bore contact (Persson's problem) and Palmgren's line-contact approach."""

import math
import re
import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import optdesign as od
from optdesign.errors import InputError, OptDesignError
from optdesign.mechanisms.joints import PinJoint
from optdesign.models import pin_contact as pc
from optdesign.models.fit_formulas import fit_clearance
from optdesign.problem import problem_from_dict

E, NU = 2.1e5, 0.3


def test_palmgren_paper_pin():
    # seed 000's pin: d = 10 mm, l = 20 mm, F = 20 kN: 3.84e-5 x 20000^0.9 / 20^0.8 = 25.97 um
    delta = pc.palmgren_approach(20e3, 20.0)
    assert 1e3 * delta == pytest.approx(25.97, abs=0.01)
    assert 1e3 * delta == pytest.approx(26, abs=0.5)  # the "~26 um" of the brief
    h = 1.0
    fd = 2 * h / (pc.palmgren_approach(20e3 + h, 20.0) - pc.palmgren_approach(20e3 - h, 20.0))
    assert pc.palmgren_stiffness(20e3, 20.0) == pytest.approx(fd, rel=1e-8)


def test_uniform_mode_compliance_is_lames_solution():
    # uniform pressure p on the pin (solid disc) and in the bore (hole in a large plate),
    # plane strain (Lame): u_disc = -p R (1+nu)(1-2nu)/E, u_hole = +p R (1+nu)/E. Their
    # sum is the opening w_0 = p R / E* with 1/E* = 2 (1 - nu^2)/E: compliance 1.
    R, p = 5.0, 100.0
    w0 = p * R * (1 + NU) / E + p * R * (1 + NU) * (1 - 2 * NU) / E
    assert w0 / (R * p / pc.effective_modulus_similar(E, NU)) == pytest.approx(1.0)
    assert pc.gap_compliance(0) == 1.0 and pc.gap_compliance(1) == 0.0
    # modes n >= 2 tend to the half-plane's 2/n (a flat surface under p cos(n x / R))
    n = np.array([2, 10, 1000])
    assert pc.gap_compliance(n) * n / 2 == pytest.approx(n**2 / (n**2 - 1.0))


def test_exact_solution_tends_to_hertz_for_small_arcs():
    s = pc.persson_exact(0.01)
    eps_h, q_h = np.sqrt(4 * 0.01 / np.pi), np.sqrt(0.01 / np.pi)
    assert s.eps == pytest.approx(eps_h, rel=5e-3)  # 6.5 deg arc
    assert s.q0 == pytest.approx(q_h, rel=5e-3)
    # equilibrium: P* = pi q_1 = 2 int_0^pi q cos(theta) dtheta
    dth = s.theta[1] - s.theta[0]
    assert 2 * np.sum(s.q * np.cos(s.theta)) * dth == pytest.approx(0.01, rel=1e-9)
    # the explicit form is Hertz's in the limit, by construction
    for P in (1e-6, 1e-4):
        assert pc.half_angle_star(P) == pytest.approx(np.sqrt(4 * P / np.pi), rel=2e-3)
        assert pc.max_pressure_star(P) == pytest.approx(np.sqrt(P / np.pi), rel=2e-2)


def test_wide_arcs_wrap_towards_ninety_degrees():
    s = pc.persson_exact(50.0)
    assert np.radians(80) < s.eps < np.pi / 2
    # Hertz is far off there: its "half-angle" exceeds 180 deg
    assert np.sqrt(4 * 50 / np.pi) > np.pi
    assert np.all(s.q >= 0) and s.q[s.theta > s.eps + 0.01].max() == 0.0


@pytest.mark.parametrize("P_star", [0.03, 0.3, 3.0, 30.0])
def test_explicit_approximation_against_the_exact_solution(P_star):
    s = pc.persson_exact(P_star)
    assert pc.half_angle_star(P_star) == pytest.approx(s.eps, rel=0.012)
    assert pc.max_pressure_star(P_star) == pytest.approx(s.q0, rel=0.012)
    assert pc.approach_star(P_star) == pytest.approx(s.d, rel=0.008)


def test_paper_pin_lies_outside_hertz_range():
    # D = 10, L = 20, 20 kN, H7/g6 largest clearance (30.9 um on the diameter)
    dR = fit_clearance(10.0, "H7/g6", "max") / 2
    P_star = pc.load_parameter(20e3, 20.0, dR, E, NU)
    assert P_star == pytest.approx(0.561, abs=0.002)
    eps = pc.contact_half_angle(20e3, 20.0, 5.0, dR, E, NU)
    assert np.degrees(eps) == pytest.approx(41.5, abs=0.5)
    assert np.degrees(pc.hertz_half_angle(20e3, 20.0, 5.0, dR, E, NU)) == pytest.approx(
        48.4, abs=0.1
    )
    assert not pc.in_hertz_range(20e3, 20.0, 5.0, dR, E, NU)
    assert pc.in_fit_range(20e3, 20.0, dR, E, NU)
    # a light load on the same pin is inside: 200 N -> P* = 0.0056, eps = 4.9 deg
    assert pc.in_hertz_range(200.0, 20.0, 5.0, dR, E, NU)
    assert not pc.in_fit_range(1e7, 20.0, dR, E, NU)


@settings(max_examples=80, deadline=None)
@given(
    F=st.floats(10.0, 5e4),
    k=st.floats(1.01, 3.0),
    dR=st.floats(0.002, 0.05),
    R=st.floats(2.0, 20.0),
)
def test_monotone_in_load_and_clearance(F, k, dR, R):
    args = (20.0, R, dR, E, NU)
    for f in (pc.contact_half_angle, pc.max_pressure, pc.approach):
        assert f(k * F, *args) > f(F, *args)
    assert pc.contact_stiffness(k * F, *args) > pc.contact_stiffness(F, *args) > 0
    # a larger clearance: narrower arc, higher pressure
    wider = (20.0, R, k * dR, E, NU)
    assert pc.contact_half_angle(F, *wider) < pc.contact_half_angle(F, *args)
    assert pc.max_pressure(F, *wider) > pc.max_pressure(F, *args)
    assert pc.contact_half_angle(F, *args) < np.pi / 2
    # the conforming pressure is at least Hertz's (the wide arc is not Hertz's ellipse)
    assert pc.max_pressure(F, *args) >= 0.99 * pc.hertz_max_pressure(F, *args)


def test_casadi_matches_numpy_and_stiffness_is_the_derivative():
    F, dR = ca.SX.sym("F"), ca.SX.sym("dR")
    exprs = [
        pc.contact_half_angle(F, 20.0, 5.0, dR, E, NU),
        pc.max_pressure(F, 20.0, 5.0, dR, E, NU),
        pc.approach(F, 20.0, 5.0, dR, E, NU),
    ]
    f = ca.Function("c", [F, dR], [ca.vertcat(*exprs), ca.jacobian(exprs[2], F)])
    for Fv, dRv in ((500.0, 0.01), (2e4, 0.0155)):
        vals, dd = f(Fv, dRv)
        num = [
            pc.contact_half_angle(Fv, 20.0, 5.0, dRv, E, NU),
            pc.max_pressure(Fv, 20.0, 5.0, dRv, E, NU),
            pc.approach(Fv, 20.0, 5.0, dRv, E, NU),
        ]
        assert np.asarray(vals).ravel() == pytest.approx(num, rel=1e-12)
        assert 1.0 / float(dd) == pytest.approx(
            pc.contact_stiffness(Fv, 20.0, 5.0, dRv, E, NU), rel=1e-10
        )


def test_bad_inputs_name_the_field():
    with pytest.raises(InputError, match=r"^dR"):
        pc.contact_half_angle(1e3, 20.0, 5.0, 0.0, E, NU)
    with pytest.raises(InputError, match=r"^P_star"):
        pc.persson_exact(0.0)
    with pytest.raises(InputError, match=r"^l"):
        pc.palmgren_approach(1e3, -1.0)


# The pin contact models side by side (issue 26): Palmgren's empirical approach as a
# selectable model, and the backlash of an optimum under each model (``--contact-models``,
# ``od.solve(..., contact_models=True)``).


ROOT = Path(__file__).resolve().parents[2]


FIN = ROOT / "problems" / "fin_actuator.toml"


def _at_optimum(model: str) -> float:
    data = tomllib.loads(FIN.read_text())
    data["requirements"]["pin_contact"] = model
    problem = problem_from_dict(data)
    design = dict(R=105.571, l=59.7942, n=102.087, phi0=math.radians(13.132), d0=25, p=5, d=6)
    x = np.array([design[v.name] for v in problem.free], dtype=float)
    return float(np.ravel(problem.evaluate(x).objectives["backlash"])[0])


def test_palmgren_joint_against_the_printed_approach():
    """[D17]'s pin (d 10, L 20, 20 kN): Palmgren 3.84e-5 x 20 000^0.9 / 20^0.8 = 25.97 um
    ([P59]), added to the fit's clearance; the stiffness is its tangent F / (0.9 delta)."""
    pin = PinJoint(10.0, 20.0, contact="palmgren")
    added = float(pin.clearance(20000.0) - pin.fit_clearance())
    assert added == pytest.approx(3.84e-5 * 20000.0**0.9 / 20.0**0.8, rel=1e-12)
    assert added * 1e3 == pytest.approx(25.97, abs=0.01)
    h = 1.0
    slope = float(pin.clearance(20000.0 + h) - pin.clearance(20000.0 - h)) / (2 * h)
    assert float(pin.contact_stiffness(20000.0)) == pytest.approx(1 / slope, rel=1e-6)
    # 2.35 times eq. 11's flattening of pin and bore (11.04 um): the bulk compression
    duan = float(PinJoint(10.0, 20.0).clearance(20000.0) - pin.fit_clearance())
    assert added / duan == pytest.approx(2.352, abs=1e-3)
    with pytest.raises(InputError, match=r"materials\.pin\.E"):
        PinJoint(10.0, 20.0, E=7.0e4, contact="palmgren")
    with pytest.raises(InputError, match=r"pin\.contact"):
        PinJoint(10.0, 20.0, contact="tate")


def test_backlash_spread_over_the_contact_models_at_the_fin_optimum(fin_lug_optimum):
    problem, result = fin_lug_optimum
    line = next(n for n in result.notes if n.startswith("backlash by pin contact model"))
    values = {
        name: float(v)
        for name, v in re.findall(r"(duan2017|conforming|palmgren) ([0-9.]+) deg", line)
    }
    assert set(values) == {"duan2017", "conforming", "palmgren"}
    assert "duan2017 0.0348393 deg (the file's)" in line
    # each model's value equals the problem written with that model, evaluated at the
    # optimum the summary states (a file, not the spread's copy)
    for model, value in values.items():
        assert value == pytest.approx(_at_optimum(model), rel=2e-5)
    # the conforming contact is the stiffest reading, Palmgren's (bulk compression) the softest
    assert values["conforming"] < values["duan2017"] < values["palmgren"]
    assert problem.spec.requirements.pin_contact == "duan2017"  # the problem is unchanged
    assert line in result.summary()
    with pytest.raises(OptDesignError, match="contact_models"):
        od.solve(problem, contact_models="yes")
