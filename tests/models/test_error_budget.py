"""Error budget (seed 003 eq. 2-6), mapped through a crank-slider (its Monte Carlo:
tests/reproduce/test_monte_carlo.py)."""

import casadi as ca
import numpy as np
import pytest

from optdesign.errors import InputError
from optdesign.mechanisms import CrankSlider
from optdesign.models import error_budget as eb

MECH = CrankSlider(R=90.0, l=80.0, n=50.0, p=5.0, i_a=2.0)


def budget_sources():
    return [
        eb.lead_error_source(0.003),
        eb.backlash_source(0.005),
        eb.coaxiality_source(0.01, 5.0, 20.0),
        eb.deformation_source(2000.0, 1e5, 0.2),
        eb.encoder_source(np.radians(0.01)),
        eb.random_source("mounting", 0.002),
        eb.random_source("rod pins", 0.004, "rod_length", "uniform"),
    ]


def test_paper_terms():
    # eq. 2: 0.01 mm/rev over 3 turns -> 0.03 mm; eq. 5: 5 mm lead, 0.01 rad -> 7.958 um
    assert eb.lead_error(0.01, 3 * 2 * np.pi) == pytest.approx(0.03)
    assert eb.encoder_error(5.0, 0.01) == pytest.approx(5.0 * 0.01 / (2 * np.pi))
    # eq. 4 at theta = 90 deg: 0.01 x 5 / (20 pi) = 7.958e-4 mm
    assert eb.coaxiality_error(0.01, np.pi / 2, 5.0, 20.0) == pytest.approx(7.9577e-4, rel=1e-4)
    s, r = eb.transmission_error([1.0, 2.0], [3.0, 4.0])
    assert (s, r) == pytest.approx((3.0, 5.0))


def test_output_mapping_through_the_crank_slider():
    phi = 0.3
    v = float(MECH.nut_velocity(phi))
    axial = eb.random_source("x", 1.0)
    assert eb.contribution(axial, 0.01, MECH, phi) == pytest.approx(0.01 / v)
    # Encoder at the motor: p dtheta / (2 pi i_a) at the nut, i.e. dtheta / i(phi) at the output.
    enc = eb.encoder_source(1.0)
    assert eb.contribution(enc, 1e-3, MECH, phi) == pytest.approx(1e-3 / float(MECH.ratio(phi)))
    # Lead error over the screw turns from phi = 0.
    lead = eb.lead_error_source(1.0)
    travel = float(MECH.nut_position(phi) - MECH.nut_position(0.0))
    assert eb.contribution(lead, 0.002, MECH, phi) == pytest.approx(0.002 * travel / 5.0 / v)
    # Budget of eq. 6 built from the same gains.
    b = eb.budget(budget_sources(), MECH, phi)
    g = eb.gains(budget_sources(), MECH, phi)
    sd = [s.sd for s in budget_sources()]
    assert float(b.rss) == pytest.approx(
        np.sqrt(
            sum(
                (abs(gi) * si) ** 2
                for gi, si, s in zip(g, sd, budget_sources(), strict=True)
                if s.kind == "random"
            )
        )
    )
    with pytest.raises(InputError, match="acts_on"):
        eb.contribution(eb.random_source("r", 1.0, "rod_length"), 1.0)


def test_deformation_of_the_stiffness_chain_per_angle():
    # Compliance 1/K under the nut force M_h/(dx/dphi): output M_h / (K (dx/dphi)^2).
    K, M_h = 5e4, 5e5
    src = eb.compliance_source(K, 0.1)
    phi = np.radians(np.array([-30.0, 0.0, 30.0]))
    v = np.asarray(MECH.nut_velocity(phi))
    out = eb.contribution(src, 1.0 / K, MECH, phi, M_h=M_h)
    assert np.asarray(out) == pytest.approx(M_h / (K * v**2))
    assert eb.contribution(src, 1.0 / K, F=1000.0) == pytest.approx(1000.0 / K)
    with pytest.raises(InputError, match="M_h"):
        eb.contribution(src, 1.0 / K, MECH, 0.0)


def test_contribution_casadi_matches_numpy():
    R, l = ca.SX.sym("R"), ca.SX.sym("l")
    sym_mech = CrankSlider(R=R, l=l, n=50.0, p=5.0, i_a=2.0)
    src = eb.lead_error_source(1.0)
    f = ca.Function("c", [R, l], [eb.contribution(src, 0.003, sym_mech, 0.25)])
    assert float(f(90.0, 80.0)) == pytest.approx(
        float(eb.contribution(src, 0.003, MECH, 0.25)), rel=1e-12
    )


def test_source_validation():
    with pytest.raises(InputError, match="distribution"):
        eb.ErrorSource("x", "random", "cauchy", 1.0)
    with pytest.raises(InputError, match="scale"):
        eb.ErrorSource("x", "random", "normal", -1.0)
