"""PRSM geometry, thread-contact matching, principal-plane angle omega, studies."""

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.models.hertz_point import curvature_sum_difference
from optdesign.models.prsm import PRSMContact, PRSMGeometry
from optdesign.reproduce.prsm_contact_sweeps import (
    area_vs_load,
    omega_vs_position,
    reference_geometry,
    sweep_pitch,
)


def test_standard_relations():
    g = reference_geometry()
    assert (g.d_r, g.d_n) == (10.0, 50.0)
    assert g.lead_s == g.lead_n == 10.0 and g.lead_r == 2.0
    # roller and nut have equal helix angles: atan(10/(50 pi)) = atan(2/(10 pi))
    assert g.helix_angle("roller") == pytest.approx(g.helix_angle("nut"), rel=1e-15)
    assert g.helix_angle("screw") == pytest.approx(math.atan(10 / (30 * math.pi)))
    assert g.roller_profile_radius == pytest.approx(5 * math.sqrt(2))


@pytest.mark.parametrize(
    "changes, field",
    [
        ({"n_starts": 2}, "n_starts"),
        ({"d_s": -1.0}, "d_s"),
        ({"pitch": 0.0}, "pitch"),
        ({"pitch": 6.0}, "pitch"),
        ({"beta": math.radians(85)}, "beta"),
        ({"roller_arc": 0.5}, "roller_arc"),
    ],
)
def test_validation_names_field(changes, field):
    with pytest.raises(InputError) as ei:
        replace(PRSMGeometry(), **changes)
    assert ei.value.field == field


@pytest.fixture(scope="module")
def solver():
    return PRSMContact(reference_geometry())


@pytest.mark.parametrize("side", ["screw", "nut"])
def test_contact_is_a_tangency(solver, side):
    c = solver.contact(side, 0.7)
    assert c.residual < 1e-10
    assert c.normal_mismatch < 1e-10  # outward normals opposite
    # principal directions lie in the common tangent plane and are orthonormal
    for d in (*c.dirs1, *c.dirs2):
        assert abs(d @ c.normal) < 1e-10
    assert abs(c.dirs1[0] @ c.dirs1[1]) < 1e-10


def test_nut_contact_on_line_of_centres(solver):
    # equal helix angles of roller and nut: contact at the nominal radii, on the centre line
    c = solver.contact("nut", 0.0)
    rho_n, th_n, rho_r, _th_r, _ = c.params
    assert rho_n == pytest.approx(25.0, abs=1e-9)
    assert rho_r == pytest.approx(5.0, abs=1e-9)
    assert th_n == pytest.approx(0.0, abs=1e-10)
    # nut flank: straight generator (kappa ~ 0) and concave circle, about -sin(beta)/r_n
    assert c.rho1[1] == pytest.approx(-math.sin(math.radians(45)) / 25.0, rel=0.01)


def test_screw_contact_is_displaced_by_helix_mismatch(solver):
    # screw and roller helix angles differ: the contact leaves the centre line a little
    c = solver.contact("screw", 0.0)
    assert 0.0 < c.params[1] < 0.1  # rad
    assert abs(c.params[0] - 15.0) < 0.2


def test_relative_curvature_tensor_matches_omega_formula(solver):
    """F(rho) with cos(2 omega) equals the eigenvalue split of the summed curvature tensor."""
    for side in ("screw", "nut"):
        c = solver.contact(side, 1.3)
        e1 = c.dirs1[0]
        e2 = np.cross(c.normal, e1)
        C = np.zeros((2, 2))
        for k, d in zip((*c.rho1, *c.rho2), (*c.dirs1, *c.dirs2), strict=True):
            t = np.array([d @ e1, d @ e2])
            C += k * np.outer(t, t)
        lam = np.linalg.eigvalsh(C)  # 2A, 2B
        s, F = curvature_sum_difference(*c.rho1, *c.rho2, c.omega)
        assert s == pytest.approx(lam.sum(), rel=1e-12)
        assert F == pytest.approx((lam[1] - lam[0]) / lam.sum(), rel=1e-9)


@settings(max_examples=8, deadline=None)
@given(st.floats(1.0, 3.5), st.floats(35.0, 55.0))
def test_omega_constant_along_contact_position(pitch, beta_deg):
    g = reference_geometry(pitch=pitch, beta=math.radians(beta_deg))
    om = omega_vs_position(np.linspace(0, 2 * math.pi, 7), g)
    for side in ("screw", "nut"):
        assert np.ptp(om[side]) < 1e-10


def test_spherical_roller_omega_near_45_and_spreads_with_pitch():
    sp = sweep_pitch([0.5, 1.0, 2.0])
    dev = np.degrees(np.abs(sp.omega["screw"] - math.pi / 4))
    assert np.all(np.diff(dev) > 0) and dev[0] < 1.0
    # roughly linear: doubling the pitch doubles the deviation from 45 deg
    assert dev[2] / dev[1] == pytest.approx(2.0, rel=0.05)


def test_exact_hertz_independent_of_pairing(solver):
    c = solver.contact("screw")
    h = c.hertz(1000.0)
    from optdesign.models.hertz_point import hertz_point_contact

    E_star = 2.06e5 / (2 * 0.91)
    h2 = hertz_point_contact(*c.rho1, *c.rho2[::-1], c.omega + math.pi / 2, 1000.0, E_star)
    assert h2.eccentricity == pytest.approx(h.eccentricity, rel=1e-9)
    # the two omega = 0 pairings coincide when omega < 45 deg
    assert c.omega < math.pi / 4
    assert c.hertz_aligned(1e3).a == c.hertz_aligned(1e3, pairing="nearest").a


def test_area_grows_as_load_to_two_thirds():
    av = area_vs_load([100.0, 800.0])
    for side in ("screw", "nut"):
        for arr in av[side]:
            assert arr[1] / arr[0] == pytest.approx(4.0, rel=1e-10)


def test_reproduce_writes_plots(tmp_path, capsys):
    from optdesign.reproduce import REPRODUCTIONS, run

    assert REPRODUCTIONS["prsm-contact"] == "optdesign.reproduce.prsm_contact"
    assert run("prsm-contact", tmp_path) == 0
    text = capsys.readouterr().out
    assert "d_s = 30 mm" in text and "8.7 %" in text
    assert len(list(tmp_path.glob("*.png"))) == 5
