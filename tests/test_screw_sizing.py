"""Ball-screw sizing (physics.md 8): the catalogue examples and the constraint forms."""

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.models import screw, screw_sizing


def test_buckling_catalogue_example():
    # d1 = 12.5, la = 820, fixed-supported -> 3630 N (10 x 12.5^4 / 820^2 x 1e4 = 3630.9)
    assert screw_sizing.buckling_load(12.5, 820.0, "fixed-supported") == pytest.approx(
        3630.0, abs=1.0
    )
    # The exact Euler constant is 0.2 % lower (eta_2 = 10 rounds 9.98).
    euler = screw_sizing.buckling_load(12.5, 820.0, "fixed-supported", form="euler")
    assert euler == pytest.approx(3623.7, abs=0.1)
    # Mounting factors scale as 1.3 : 10 : 20.
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
    # lambda_2 = 15.1: 15.1 x 12.5 / 1000^2 x 1e7 = 1887.5 min^-1
    assert screw_sizing.critical_speed(12.5, 1000.0) == pytest.approx(1887.5)
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
