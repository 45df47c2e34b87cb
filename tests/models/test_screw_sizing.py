"""Ball-screw sizing (physics.md 8): the catalogue examples and the constraint forms."""

import math
import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.models import screw, screw_sizing
from optdesign.models import screw_sizing as sizing
from optdesign.problem import load_problem, problem_from_dict


def test_buckling_catalogue_example():
    # d1 = 12.5, la = 820, fixed-supported -> 3630 N (10 x 12.5^4 / 820^2 x 1e4 = 3630.9)
    assert screw_sizing.buckling_load(12.5, 820.0, "fixed-supported") == pytest.approx(
        3630.0, abs=1.0
    )
    # The exact Euler constant is 0.2 % lower (eta_2 = 10 rounds 9.98).
    euler = screw_sizing.buckling_load(12.5, 820.0, "fixed-supported", form="euler")
    assert euler == pytest.approx(3623.7, abs=0.1)
    # Mounting factors scale as 1.2725 : 10 : 20 (the default, conservative rule).
    ff = screw_sizing.buckling_load(12.5, 820.0, "fixed-fixed")
    assert ff / screw_sizing.buckling_load(12.5, 820.0, "fixed-supported") == pytest.approx(2.0)


def test_life_catalogue_example():
    # C = 4400 N, Fm = 250 N, 2118 min^-1, f_w = 1.2 -> 24 824 h published; the formula
    # gives 24 826.6 h (the catalogue rounds intermediate values): 1e-4 relative.
    L = screw_sizing.rated_life_hours(4400.0, 250.0, 2118.0, 1.2)
    assert L == pytest.approx(24824.0, rel=2e-4)
    assert screw_sizing.rated_life_revolutions(4400.0, 250.0, 1.2) == pytest.approx(
        (4400 / 300) ** 3 * 1e6
    )


def test_mean_load_of_a_duty_cycle():
    # Cubic mean: equal revolutions at 100, 200, 300 N -> (36e6/3)^(1/3) = 228.94 N
    assert screw_sizing.mean_load([100.0, 200.0, 300.0], [1.0, 1.0, 1.0]) == pytest.approx(
        228.943, abs=1e-3
    )
    # A constant load is its own mean whatever the revolutions.
    assert screw_sizing.mean_load([250.0, 250.0], [3.0, 7.0]) == pytest.approx(250.0)
    with pytest.raises(InputError, match="revolutions"):
        screw_sizing.mean_load([1.0, 2.0], [1.0])


def test_yield_speed_and_stiffness():
    assert screw_sizing.yield_load(12.5) == pytest.approx(147.0 * np.pi * 12.5**2 / 4)
    # common lambda_2 = 15.1: 15.1 x 12.5 / 1000^2 x 1e7 = 1887.5 min^-1; the default
    # (conservative) takes HIWIN's 0.8 x 2.71e8 x 0.692 (F 3.27-3.28): 1875.32 min^-1
    assert screw_sizing.critical_speed(12.5, 1000.0, rule="common") == pytest.approx(1887.5)
    assert screw_sizing.critical_speed(12.5, 1000.0) == pytest.approx(1875.32)
    A = np.pi * 12.5**2 / 4
    k1 = screw_sizing.shaft_stiffness(12.5, 500.0, "fixed-free")
    assert k1 == pytest.approx(A * 2.06e5 / 500.0)
    assert screw_sizing.shaft_stiffness(12.5, 500.0, "fixed-fixed") == pytest.approx(4 * k1)
    K = screw_sizing.axial_stiffness_chain(k1, 300.0, 500.0, 1000.0)
    assert 1 / K == pytest.approx(1 / k1 + 1 / 300 + 1 / 500 + 1 / 1000)
    with pytest.raises(InputError, match="mounting"):
        screw_sizing.critical_speed(12.5, 1000.0, "glued")


def test_efficiency_check_uses_models_screw():
    lam = screw.lead_angle(5.0, 20.0)
    phi_f = screw.friction_angle(0.003)
    assert np.degrees(lam) == pytest.approx(4.550, abs=5e-4)
    assert screw.efficiency_forward(lam, phi_f) == pytest.approx(0.9634, abs=5e-5)
    assert screw.efficiency_backdrive(lam, phi_f) == pytest.approx(0.9621, abs=5e-5)


def test_margins_casadi_match_numpy():
    d1, la = ca.SX.sym("d1"), ca.SX.sym("la")
    g = ca.vertcat(
        screw_sizing.buckling_margin(3000.0, d1, la),
        screw_sizing.yield_margin(3000.0, d1),
        screw_sizing.critical_speed_margin(1500.0, d1, la),
        screw_sizing.life_margin(2e4, 4400.0, 250.0, 2118.0),
    )
    f = ca.Function("g", [d1, la], [g])
    num = [
        screw_sizing.buckling_margin(3000.0, 12.5, 820.0),
        screw_sizing.yield_margin(3000.0, 12.5),
        screw_sizing.critical_speed_margin(1500.0, 12.5, 820.0),
        screw_sizing.life_margin(2e4, 4400.0, 250.0, 2118.0),
    ]
    assert np.asarray(f(12.5, 820.0)).ravel() == pytest.approx(num, rel=1e-12)
    # 3000 N against 3630.9 N: positive margin; 4000 N would buckle.
    assert num[0] > 0 > screw_sizing.buckling_margin(4000.0, 12.5, 820.0)


@settings(max_examples=50, deadline=None)
@given(d1=st.floats(5, 80), la=st.floats(100, 3000), k=st.floats(1.01, 3))
def test_buckling_falls_with_length(d1, la, k):
    for mounting in screw_sizing.BUCKLING_FACTOR:
        assert screw_sizing.buckling_load(d1, k * la, mounting) < screw_sizing.buckling_load(
            d1, la, mounting
        )


def test_life_default_is_the_iso_nominal_life():
    # ISO 3408-5 has no load factor: f_w = 1.0 by default, 1.2 only when asked for
    assert screw_sizing.rated_life_revolutions(4400.0, 250.0) == pytest.approx(
        (4400 / 250) ** 3 * 1e6
    )
    ratio = screw_sizing.rated_life_hours(4400.0, 250.0, 2118.0) / screw_sizing.rated_life_hours(
        4400.0, 250.0, 2118.0, f_w=1.2
    )
    assert ratio == pytest.approx(1.728)


def test_buckling_fixed_free_factor_is_on_the_unsafe_side():
    # Euler with safety 0.5 and E = 2.06e5: eta_2 = 0.5 x 0.25 x pi^3 E / 64 x 1e-4 = 1.2475
    euler = screw_sizing.buckling_load(20.0, 1000.0, "fixed-free", form="euler")
    assert euler * 1000.0**2 / 20.0**4 / 1e4 == pytest.approx(1.24752, abs=1e-5)
    cat = screw_sizing.buckling_load(20.0, 1000.0, "fixed-free", rule="common")
    assert cat / euler == pytest.approx(1.0421, abs=1e-4)  # the common 1.3: +4.2 %
    # HIWIN's fixed-free factor (the default's) is 0.5 x 40.72 x 0.0625 = 1.2725: +2.0 %
    hiwin = screw_sizing.buckling_load(20.0, 1000.0, "fixed-free")
    assert hiwin / euler == pytest.approx(1.2725 / 1.24752, rel=1e-5)
    # HIWIN's constant 4.072e5 is pi^3 E / 16 with E = 2.1e5 MPa (to 0.06 %)
    assert 4.072e5 == pytest.approx(np.pi**3 * 2.1e5 / 16, rel=1e-3)


def test_duty_cycle_life_against_miners_rule():
    # Three steps (N, min^-1, s). Independent check: Miner's rule, each step's share of
    # the revolutions used up against its own constant-load life.
    F, n, t = (
        np.array([1500.0, 4000.0, 800.0]),
        np.array([1000.0, 200.0, 3000.0]),
        np.array([30.0, 50.0, 20.0]),
    )
    Ca = 12_520.0  # HIWIN R25-5T4-FSI, BS-08-2-EN-1704-K Table 6.6
    L_h = screw_sizing.duty_cycle_life_hours(Ca, F, n, t, f_w=1.1)
    life_rev = (Ca / (1.1 * F)) ** 3 * 1e6
    rev_per_hour = 60.0 * n * t / t.sum()
    assert 1.0 / np.sum(rev_per_hour / life_rev) == pytest.approx(L_h, rel=1e-12)
    # one step: the constant-load life at that step's speed
    assert screw_sizing.duty_cycle_life_hours(Ca, [1500.0], [1000.0], [1.0]) == pytest.approx(
        (Ca / 1500.0) ** 3 * 1e6 / 60_000.0
    )
    with pytest.raises(InputError, match="times"):
        screw_sizing.duty_cycle_life_hours(Ca, F, n, t[:2])


def test_static_safety_and_dn():
    # R20-5T3-FSI: C0 = 17 670 N (HIWIN Table 6.6); 5 kN peak -> f_s = 3.534
    assert screw_sizing.static_safety_factor(17_670.0, -5000.0) == pytest.approx(3.534)
    assert screw_sizing.static_safety_margin(5000.0, 17_670.0, 3.0) == pytest.approx(
        1 - 15_000 / 17_670
    )
    # DN: 20 mm at 3000 min^-1 = 60 000 < 70 000 (rolled), margin 1/7
    assert screw_sizing.dn_value(20.0, 3000.0) == 60_000.0
    assert screw_sizing.dn_margin(20.0, 3000.0) == pytest.approx(1 / 7)
    assert screw_sizing.dn_margin(20.0, 4000.0, screw_sizing.DN_LIMIT["ground"]) == pytest.approx(
        1 - 80 / 90
    )


def test_shaft_mass_inertia_and_reflected_inertia_against_si_forms():
    # 20 mm x 1 m steel: rho pi d^2 L / 4 in SI = 7850 x pi x 0.02^2 / 4 = 2.4662 kg
    mass = screw_sizing.shaft_mass(20.0, 1000.0)
    assert mass == pytest.approx(7850 * np.pi * 0.02**2 / 4, rel=1e-12)
    assert mass == pytest.approx(2.4662, abs=1e-4)
    J = screw_sizing.shaft_inertia(20.0, 1000.0)  # kg*mm^2
    assert J * 1e-6 == pytest.approx(mass * (20.0 / 2000) ** 2 / 2, rel=1e-12)  # HIWIN F 3.19
    # reflected to the motor, HIWIN F 3.19 in SI with N1/N2 = 1/i_a:
    JM, JG1, JG2, m_l, P, i_a = 2e-5, 1e-5, 4e-5, 12.0, 5.0, 2.5
    si = JG1 + JG2 / i_a**2 + J * 1e-6 / i_a**2 + m_l * (P / (2000 * np.pi)) ** 2 / i_a**2
    mine = screw_sizing.reflected_inertia(J, m_l, P, i_a, J_driven=JG2 * 1e6, J_driving=JG1 * 1e6)
    assert (mine * 1e-6 + JM) == pytest.approx(si + JM, rel=1e-12)


def test_shaft_stiffness_by_mounting_and_nut_position():
    AE = np.pi * 12.5**2 / 4 * 2.06e5
    L = 800.0
    for x in (100.0, 400.0, 650.0):
        # fixed-fixed: the two shaft parts x and L - x act in parallel
        ff = screw_sizing.shaft_stiffness(12.5, L, "fixed-fixed", x=x)
        assert ff == pytest.approx(AE / x + AE / (L - x), rel=1e-12)
        # one axial bearing (fixed-free, fixed-supported): only the part x carries load
        assert screw_sizing.shaft_stiffness(12.5, L, "fixed-supported", x=x) == pytest.approx(
            AE / x
        )
    assert screw_sizing.shaft_stiffness(12.5, L, "fixed-fixed") == pytest.approx(4 * AE / L)
    assert screw_sizing.shaft_stiffness(12.5, L, "fixed-supported") == pytest.approx(AE / L)
    with pytest.raises(InputError, match=r"^x"):
        screw_sizing.shaft_stiffness(12.5, L, "fixed-fixed", x=L)
    with pytest.raises(InputError, match="mounting"):
        screw_sizing.shaft_stiffness(12.5, L, "supported-supported")


@settings(max_examples=60, deadline=None)
@given(x=st.floats(0.02, 0.98))
def test_fixed_fixed_stiffness_is_least_at_mid_span(x):
    L = 1000.0
    k = screw_sizing.shaft_stiffness(16.0, L, "fixed-fixed", x=x * L)
    assert k >= screw_sizing.shaft_stiffness(16.0, L, "fixed-fixed") * (1 - 1e-12)
    assert k > screw_sizing.shaft_stiffness(16.0, L, "fixed-supported", x=x * L)


ROOT = Path(__file__).resolve().parents[2]


FIN = ROOT / "problems" / "fin_actuator.toml"


#: The shipped fin_actuator optimum (docs/drive.md section 6).
OPT = dict(R=105.571, l=59.7942, n=102.087, phi0=math.radians(13.132), d0=25.0, p=5.0, d=6.0)


def _x(R, l, n, phi0, phi):
    """Crank-slider nut abscissa, seed 000 eq. 2, written out (mm)."""
    a = phi + phi0
    return R * np.sin(a) - np.sqrt(l**2 - (R * np.cos(a) - n) ** 2)


def _dx(R, l, n, phi0, phi, h=1e-6):
    return (_x(R, l, n, phi0, phi + h) - _x(R, l, n, phi0, phi - h)) / (2 * h)


def _fin(**changes):
    data = tomllib.loads(FIN.read_text())
    for section, values in changes.items():
        data[section].update(values)
    return problem_from_dict(data)


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
