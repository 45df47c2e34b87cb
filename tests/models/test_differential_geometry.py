"""Principal curvatures and directions by CasADi AD against analytic surfaces."""

import math

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.models.differential_geometry import Surface, fundamental_forms
from optdesign.models.thread_surface import flank_builder, thread_flank


def cylinder(R):
    return Surface(lambda u, v, p: ca.vertcat(R * ca.cos(v), R * ca.sin(v), u))


def helicoid():
    # r = (u cos v, u sin v, c v), c = p[0]
    return Surface(lambda u, v, p: ca.vertcat(u * ca.cos(v), u * ca.sin(v), p[0] * v), 1)


def test_cylinder():
    R = 3.0
    s = cylinder(R).evaluate(0.3, 0.7)
    # r_u x r_v points inwards, so the circle curves towards n: +1/R.
    assert s.kappa == pytest.approx([1 / R, 0.0], abs=1e-14)
    assert s.first_form == pytest.approx(np.array([[1.0, 0.0], [0.0, R * R]]), abs=1e-14)
    # zero-curvature direction is the axis, the other the circle tangent
    assert abs(s.directions[1] @ np.array([0, 0, 1.0])) == pytest.approx(1.0, abs=1e-14)
    assert abs(s.directions[0] @ np.array([-math.sin(0.7), math.cos(0.7), 0])) == pytest.approx(1.0)


def test_sphere_umbilic():
    R = 2.0
    sph = Surface(
        lambda u, v, p: p[0] * ca.vertcat(ca.cos(u) * ca.cos(v), ca.cos(u) * ca.sin(v), ca.sin(u)),
        1,
    )
    s = sph.evaluate(0.3, 0.7, [R])
    assert np.abs(s.kappa) == pytest.approx([1 / R, 1 / R], rel=1e-13)
    assert s.gaussian_curvature == pytest.approx(1 / R**2, rel=1e-13)


def test_torus():
    R, r, v = 5.0, 1.5, 0.8
    tor = Surface(
        lambda u, v, p: ca.vertcat(
            (R + r * ca.cos(v)) * ca.cos(u), (R + r * ca.cos(v)) * ca.sin(u), r * ca.sin(v)
        )
    )
    s = tor.evaluate(0.4, v)
    expected = sorted([1 / r, math.cos(v) / (R + r * math.cos(v))], reverse=True)
    assert sorted(np.abs(s.kappa), reverse=True) == pytest.approx(expected, rel=1e-13)


@settings(max_examples=30, deadline=None)
@given(st.floats(0.1, 20.0), st.floats(-3.0, 3.0), st.floats(0.05, 5.0))
def test_helicoid(u, v, c):
    s = helicoid().evaluate(u, v, [c])
    k = c / (c * c + u * u)
    assert s.kappa == pytest.approx([k, -k], rel=1e-10)
    assert s.mean_curvature == pytest.approx(0.0, abs=1e-12 * k)
    assert s.gaussian_curvature == pytest.approx(-(c**2) / (c * c + u * u) ** 2, rel=1e-10)
    # principal directions bisect the (orthogonal) coordinate lines
    ru = s.r_u / np.linalg.norm(s.r_u)
    for t in s.directions:
        assert abs(t @ ru) == pytest.approx(math.sqrt(0.5), rel=1e-10)
    assert abs(s.directions[0] @ s.directions[1]) < 1e-12


def test_symbolic_forms_of_helicoid():
    u, v = ca.SX.sym("u"), ca.SX.sym("v")
    c = 0.7
    f = fundamental_forms(ca.vertcat(u * ca.cos(v), u * ca.sin(v), c * v), u, v)
    fn = ca.Function("f", [u, v], [f["E"], f["F"], f["G"], f["L"], f["M"], f["N"], f["kappa1"]])
    E, F, G, L, M, N, k1 = (float(x) for x in fn(2.0, 0.1))
    assert (E, F, G) == pytest.approx((1.0, 0.0, 4.0 + c * c))
    assert (L, N) == pytest.approx((0.0, 0.0), abs=1e-15)
    assert abs(M) == pytest.approx(c / math.sqrt(4.0 + c * c))
    assert k1 == pytest.approx(c / (4.0 + c * c))


def test_thread_flank_with_zero_flank_angle_is_a_helicoid():
    lead, rho = 10.0, 15.0
    s = Surface(flank_builder("screw", 1, 15.0, 2.0, lead, 0.0)).evaluate(rho, 0.3)
    c = lead / (2 * math.pi)
    assert s.kappa == pytest.approx([c / (c * c + rho**2), -c / (c * c + rho**2)], rel=1e-10)


def test_roller_flank_without_lead_is_a_sphere():
    r_r, beta = 5.0, math.radians(45)
    R = r_r / math.sin(beta)
    s = Surface(flank_builder("roller", 1, r_r, 2.0, 1e-9, beta)).evaluate(4.9, 1.0)
    assert np.abs(s.kappa) == pytest.approx([1 / R, 1 / R], rel=1e-7)
    assert np.linalg.norm(s.point[:2]) == pytest.approx(4.9)


def test_screw_flank_without_lead_is_a_cone():
    r_s, beta, rho = 15.0, math.radians(40), 15.3
    s = Surface(flank_builder("screw", 1, r_s, 2.0, 1e-9, beta)).evaluate(rho, 0.2)
    assert sorted(np.abs(s.kappa)) == pytest.approx([0.0, math.sin(beta) / rho], abs=1e-9)


def test_thread_flank_numeric_and_symbolic_agree():
    kw = dict(kind="roller", xi=-1, r0=5.0, pitch=2.0, lead=2.0, beta=math.radians(45))
    num = thread_flank(5.1, 0.4, **kw)
    rho, th = ca.SX.sym("rho"), ca.SX.sym("th")
    sym = ca.Function("f", [rho, th], [thread_flank(rho, th, **kw)])(5.1, 0.4)
    assert np.asarray(sym).ravel() == pytest.approx(num, abs=1e-14)
    # half an axial pitch of tooth at the nominal radius: z = -p/4 at theta = 0
    assert thread_flank(5.0, 0.0, **kw)[2] == pytest.approx(-0.5, abs=1e-14)
