"""Stiffness chain and its reflection to the output, checked against the crank-slider's
equilibrium with springs solved without the rate formulas."""

import warnings

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import fsolve

from optdesign.errors import InputError
from optdesign.models import crank_slider as cs
from optdesign.models import screw, screw_sizing
from optdesign.models import stiffness as stf

PAPER = dict(R=90.0, l=80.0, n=50.0)  # seed 000's crank-slider (mm)


def _equilibrium_rotation(M, phi, K_ax, K_rod, R, l, n):
    """Output rotation under a hinge moment M (N*mm) of the crank-slider whose nut is held
    by an axial spring K_ax (N/mm) at its unloaded position and whose rod is a spring K_rod
    (N/mm) of free length l: stationary point of E(x, dphi) - M dphi, from the geometry
    alone (no rates, no virtual-work forces)."""
    m0 = cs.nut_position(R, l, n, phi)

    def grad(v):
        # unknowns in micro-radians and micrometres, residuals in units of M: well scaled
        dphi, x = 1e-6 * v[0], m0 + 1e-3 * v[1]
        a = phi + dphi
        bx, by = R * np.sin(a), R * np.cos(a)
        d = np.hypot(bx - x, by - n)
        stretch = K_rod * (d - l)
        dd_dx = (x - bx) / d
        dd_da = ((bx - x) * R * np.cos(a) - (by - n) * R * np.sin(a)) / d
        return [(stretch * dd_da - M) / M, (K_ax * (x - m0) + stretch * dd_dx) / M]

    with warnings.catch_warnings():  # fsolve stalls at rounding level; the residual is checked
        warnings.simplefilter("ignore", RuntimeWarning)
        sol = fsolve(grad, [0.0, 0.0], xtol=1e-10)
    assert np.max(np.abs(grad(sol))) < 1e-6  # d - l cancels to ~1e-14 mm
    return 1e-6 * sol[0]


@pytest.mark.parametrize("phi_deg", [-30.0, -18.3, 0.0, 15.0, 30.0])
def test_output_stiffness_matches_the_crank_slider_with_springs(phi_deg):
    phi = np.radians(phi_deg)
    # screw chain: shaft (fixed-supported, nut 300 mm out), nut (HIWIN R20-5T4-FSI,
    # 270 N/um), support bearing 400 N/um, screw torsion over 300 mm through the lead
    p = 5.0
    K_torsion = stf.torsion_to_axial(stf.shaft_torsional_stiffness(17.32, 300.0), p)
    K_ax = screw.series_stiffness(
        screw_sizing.shaft_stiffness(17.32, 300.0, "fixed-supported"), 270e3, 400e3, K_torsion
    )
    K_rod = 1.5e5  # rod and its two pins, N/mm
    rates = (cs.nut_velocity(phi=phi, **PAPER), cs.rod_length_rate(phi=phi, **PAPER))
    K_out = stf.output_stiffness([(K_ax, rates[0]), (K_rod, rates[1])])
    M = 500.0  # N*mm: small (the deflection is 1e-6 of the geometry), +-M cancels the rest
    dphi = (
        _equilibrium_rotation(M, phi, K_ax, K_rod, **PAPER)
        - _equilibrium_rotation(-M, phi, K_ax, K_rod, **PAPER)
    ) / 2
    assert 2 * M / (2 * dphi) == pytest.approx(K_out, rel=1e-6)
    # one member much stiffer than the other: K_out tends to the softer one's K r^2
    for K_a, K_r in ((K_ax, 1e8), (1e8, K_rod)):
        d = (
            _equilibrium_rotation(M, phi, K_a, K_r, **PAPER)
            - _equilibrium_rotation(-M, phi, K_a, K_r, **PAPER)
        ) / 2
        assert M / d == pytest.approx(
            stf.output_stiffness([(K_a, rates[0]), (K_r, rates[1])]), rel=1e-5
        )


def test_torsion_and_axial_conversions():
    # G J / L: 79 231 MPa x pi 20^4 / 32 / 500 mm = 2.4892e6 N*mm/rad
    Kt = stf.shaft_torsional_stiffness(20.0, 500.0)
    assert stf.G_STEEL == pytest.approx(2.06e5 / 2.6)
    assert Kt == pytest.approx(2.06e5 / 2.6 * np.pi * 20.0**4 / 32 / 500.0, rel=1e-12)
    # through a 5 mm lead: (2 pi / 5)^2 = 1.5791 per mm^2
    assert stf.torsion_to_axial(Kt, 5.0) == pytest.approx(Kt * 1.579137, rel=1e-6)
    assert stf.axial_to_torsion(stf.torsion_to_axial(Kt, 5.0), 5.0) == pytest.approx(Kt)
    # seed 001 eq. 7 (models.screw.axial_stiffness) is the lossless form times eta
    lam, phi_f = screw.lead_angle(5.0, 20.0), screw.friction_angle(0.003)
    eta = screw.efficiency_forward(lam, phi_f)
    assert screw.axial_stiffness(Kt, 20.0, 5.0, lam, phi_f) == pytest.approx(
        eta * stf.torsion_to_axial(Kt, 5.0), rel=1e-12
    )
    with pytest.raises(InputError, match="terms"):
        stf.output_stiffness([])


@settings(max_examples=80, deadline=None)
@given(
    K=st.lists(st.floats(1e3, 1e7), min_size=1, max_size=4),
    r=st.lists(st.floats(5.0, 200.0), min_size=4, max_size=4),
)
def test_output_stiffness_below_every_member_and_series_consistent(K, r):
    terms = list(zip(K, r[: len(K)], strict=True))
    K_out = stf.output_stiffness(terms)
    assert all(K_out <= stf.reflected_stiffness(k, rate) * (1 + 1e-12) for k, rate in terms)
    # members with the same rate: series stiffness of the members, reflected once
    same = stf.output_stiffness([(k, r[0]) for k in K])
    assert same == pytest.approx(stf.reflected_stiffness(screw.series_stiffness(*K), r[0]))


def test_casadi_matches_numpy_on_a_grid():
    phi = ca.SX.sym("phi")
    R, l, n = ca.SX.sym("R"), ca.SX.sym("l"), ca.SX.sym("n")
    K_out = stf.output_stiffness(
        [(2e5, cs.nut_velocity(R, l, n, phi)), (1e5, cs.rod_length_rate(R, l, n, phi))]
    )
    f = ca.Function("K", [R, l, n, phi], [K_out, ca.gradient(K_out, R)])
    grid = np.radians(np.linspace(-30, 30, 7))
    num = stf.output_stiffness(
        [(2e5, cs.nut_velocity(phi=grid, **PAPER)), (1e5, cs.rod_length_rate(phi=grid, **PAPER))]
    )
    for g, v in zip(grid, num, strict=True):
        val, dR = (float(x) for x in f(90.0, 80.0, 50.0, g))
        assert val == pytest.approx(v, rel=1e-12)
        h = 1e-4
        fd = (
            stf.output_stiffness(
                [
                    (2e5, cs.nut_velocity(90.0 + h, 80.0, 50.0, g)),
                    (1e5, cs.rod_length_rate(90.0 + h, 80.0, 50.0, g)),
                ]
            )
            - stf.output_stiffness(
                [
                    (2e5, cs.nut_velocity(90.0 - h, 80.0, 50.0, g)),
                    (1e5, cs.rod_length_rate(90.0 - h, 80.0, 50.0, g)),
                ]
            )
        ) / (2 * h)
        assert dR == pytest.approx(fd, rel=1e-5)


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
