"""optdesign/mechanisms/joints.py as a whole: each joint's clearance, stiffness and
pressure against the models it composes (and against finite differences of its own
clearance), the refusals at both sides of every bound, and the chain's bookkeeping
(fixed clearances by key, sampled fits, backlash in degrees)."""

import math
import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from independent_physics import cs_loop  # the crank-slider loop solved by bisection

import optdesign as od
from optdesign.errors import InputError
from optdesign.fits import clearance as iso_clearance
from optdesign.mechanisms.joints import (
    Joint,
    PinJoint,
    backlash_of,
    with_fixed_clearances,
    with_sampled_fits,
)
from optdesign.models import pin_contact
from optdesign.models.fit_formulas import Fit
from optdesign.models.hertz_line import pin_flattening, pin_flattening_first_order
from optdesign.models.lug_flexibility import Lug

D, L, F = 10.0, 12.0, 3000.0
LUG = Lug(cheek_thickness=5.0)


def _pin(**kw):
    return PinJoint(kw.pop("d", D), kw.pop("L", L), **kw)


# --- PinJoint: refusals at both sides of each bound -------------------------------------


@pytest.mark.parametrize("nu", [0.0, 0.5, -0.1, 0.7])
def test_a_poisson_ratio_outside_the_open_interval_is_refused_by_field(nu):
    with pytest.raises(InputError) as err:
        _pin(nu=nu)
    assert err.value.field == "pin.nu"
    assert "(0, 0.5)" in str(err.value)


@pytest.mark.parametrize("nu", [1e-6, 0.25, 0.499999])
def test_a_poisson_ratio_inside_the_open_interval_is_accepted(nu):
    assert _pin(nu=nu).nu == nu


@pytest.mark.parametrize(
    "field,kw", [("pin.d", {"d": 0.0}), ("pin.L", {"L": -1.0}), ("pin.E", {"E": 0.0})]
)
def test_non_positive_sizes_are_refused_by_field(field, kw):
    with pytest.raises(InputError) as err:
        _pin(**kw)
    assert err.value.field == field


def test_an_unknown_contact_model_is_refused_listing_the_models():
    with pytest.raises(InputError) as err:
        _pin(contact="hertz")
    assert err.value.field == "pin.contact"
    assert "'hertz'" in str(err.value) and "palmgren" in str(err.value)


@pytest.mark.parametrize(
    "E,ok", [(1.9e5, True), (2.2e5, True), (1.8999e5, False), (2.2001e5, False)]
)
def test_palmgrens_steel_band_is_closed_at_both_ends(E, ok):
    if ok:
        assert _pin(contact="palmgren", E=E).E == E
    else:
        with pytest.raises(InputError) as err:
            _pin(contact="palmgren", E=E)
        assert err.value.field == "materials.pin.E"
        assert f"{E:g} MPa" in str(err.value)


def test_only_palmgren_checks_the_modulus_band():
    for contact in ("duan2017", "conforming"):
        assert _pin(contact=contact, E=7.0e4).E == 7.0e4


def test_huth_needs_a_lug_and_names_the_lug_section():
    with pytest.raises(InputError) as err:
        _pin(contact="huth")
    assert err.value.field == "materials.lug"
    assert "cheek_thickness" in str(err.value)
    with pytest.raises(InputError) as err:
        _pin().lug_compliance()
    assert err.value.field == "materials.lug"


def test_a_symbolic_modulus_and_poisson_ratio_are_not_range_checked():
    E, nu = ca.SX.sym("E"), ca.SX.sym("nu")
    pin = PinJoint(D, L, E=E, nu=nu, contact="palmgren")
    assert pin.E is E and pin.nu is nu


def test_the_placeholder_is_one_unit_pin_made_once():
    a, b = PinJoint.placeholder(), PinJoint.placeholder()
    assert a is b
    assert (a.d, a.L, a.fit, a.contact) == (1.0, 1.0, "H7/g6", "duan2017")


# --- PinJoint: the fit's clearance --------------------------------------------------------


@pytest.mark.parametrize("fit", ["H7/g6", "H8/f7", "H11/c11"])
def test_the_fit_clearance_is_iso_286s_smooth_or_table_value(fit):
    smooth = Fit.parse(fit, values="smooth")
    for which in ("max", "min"):
        assert _pin(fit=fit, which=which).fit_clearance() == pytest.approx(
            float(smooth.clearance(D, which)), rel=1e-12
        )
        assert _pin(fit=fit, values="table").fit_clearance(which) == pytest.approx(
            float(iso_clearance(fit, D, which, values="table")), rel=1e-12
        )
    lo, hi = _pin(fit=fit).fit_band()
    assert 0.0 <= lo < hi
    assert hi == pytest.approx(float(smooth.clearance(D, "max")))


def test_the_table_ratio_scales_the_smooth_clearance_of_its_own_side():
    pin = _pin(ratio_max=1.5, ratio_min=0.5)
    smooth = Fit.parse("H7/g6", values="smooth")
    assert pin.fit_clearance("max") == pytest.approx(1.5 * float(smooth.clearance(D, "max")))
    assert pin.fit_clearance("min") == pytest.approx(0.5 * float(smooth.clearance(D, "min")))
    # A symbolic diameter with table values takes the smooth formula times the ratio.
    d = ca.SX.sym("d")
    sym = PinJoint(d, L, values="table", ratio_max=1.25)
    value = float(ca.Function("c", [d], [sym.fit_clearance()])(D))
    assert value == pytest.approx(1.25 * float(smooth.clearance(D, "max")), rel=1e-12)


def test_a_table_only_fit_takes_its_clearance_from_the_ratio_parameter():
    d = ca.SX.sym("d")
    pin = PinJoint(d, L, fit="H7/s6", values="table", ratio_max=0.021, ratio_min=-0.004)
    assert float(ca.Function("c", [d], [pin.fit_clearance("max")])(D)) == pytest.approx(0.021)
    assert float(ca.Function("c", [d], [pin.fit_clearance("min")])(D)) == pytest.approx(-0.004)


# --- PinJoint: clearance, stiffness, pressure per contact model ---------------------------


def test_the_duan2017_clearance_adds_each_flattened_surface_and_the_extra():
    base = _pin().fit_clearance()
    flat = pin_flattening(D, F, L, 2.1e5, 0.3)
    assert _pin().clearance(F) == pytest.approx(base + 2 * flat, rel=1e-12)
    assert _pin(surfaces=1, extra=0.004).clearance(F) == pytest.approx(
        0.004 + base + flat, rel=1e-12
    )
    first = pin_flattening_first_order(D, F, L, 2.1e5, 0.3)
    assert first != pytest.approx(flat, rel=1e-6)
    assert _pin(first_order=True).clearance(F) == pytest.approx(base + 2 * first, rel=1e-12)


def test_the_other_contact_models_add_their_own_approach():
    base = _pin().fit_clearance()
    conforming = pin_contact.approach(F, L, 0.5 * D, 0.5 * base, 2.1e5, 0.3)
    assert _pin(contact="conforming", extra=0.001).clearance(F) == pytest.approx(
        0.001 + base + conforming, rel=1e-12
    )
    assert _pin(contact="palmgren").clearance(F) == pytest.approx(
        base + pin_contact.palmgren_approach(F, L), rel=1e-12
    )
    huth = _pin(contact="huth", lug=LUG)
    assert huth.clearance(F) == pytest.approx(base + LUG.compliance(D, L, 2.1e5) * F, rel=1e-12)
    # The four differ: a model swapped for another is seen.
    values = [
        _pin(contact=c, lug=LUG).clearance(F)
        for c in ("duan2017", "conforming", "palmgren", "huth")
    ]
    assert len({round(v, 9) for v in values}) == 4


@pytest.mark.parametrize("contact", ["duan2017", "conforming", "palmgren", "huth"])
@pytest.mark.parametrize("surfaces", [1, 2])
def test_the_contact_stiffness_is_the_inverse_slope_of_the_clearance(contact, surfaces):
    """Independent check: central differences of the joint's own clearance in F."""
    pin = _pin(contact=contact, lug=LUG, surfaces=surfaces)
    for force in (500.0, 3000.0, 12000.0):
        h = 1e-3 * force
        slope = (pin.clearance(force + h) - pin.clearance(force - h)) / (2 * h)
        assert float(pin.contact_stiffness(force)) == pytest.approx(1.0 / slope, rel=1e-5)


def test_huths_stiffness_is_constant_over_a_grid_of_forces():
    forces = np.array([0.0, 100.0, 5000.0])
    k = _pin(contact="huth", lug=LUG).contact_stiffness(forces)
    assert np.shape(k) == (3,)
    assert np.allclose(k, 1.0 / LUG.compliance(D, L, 2.1e5))


def test_the_contact_pressure_is_hertzs_peak_or_the_conforming_solutions():
    b = math.sqrt(4.0 * D * (F / L) * (1 - 0.3**2) / (math.pi * 2.1e5))
    hertz = 2.0 * F / (math.pi * b * L)
    for contact in ("duan2017", "palmgren", "huth"):
        assert _pin(contact=contact, lug=LUG).contact_pressure(F) == pytest.approx(hertz, rel=1e-12)
    c = _pin().fit_clearance()
    assert _pin(contact="conforming").contact_pressure(F) == pytest.approx(
        pin_contact.max_pressure(F, L, 0.5 * D, 0.5 * c, 2.1e5, 0.3), rel=1e-12
    )


# --- Joint ------------------------------------------------------------------------------


def test_a_joint_refuses_a_negative_clearance_naming_itself():
    with pytest.raises(InputError) as err:
        Joint("A", sensitivity=1.0, clearance=-1e-9)
    assert err.value.field == "joint A.clearance"
    assert Joint("A", sensitivity=1.0, clearance=0.0).clearance == 0.0


def test_a_joint_needs_a_sensitivity_unless_angular_and_a_force_with_a_pin():
    with pytest.raises(InputError, match="sensitivity") as err:
        Joint("B")
    assert err.value.field == "joint B"
    assert Joint("shaft", angular=True, clearance=1e-3).sensitivity is None
    with pytest.raises(InputError, match="force") as err:
        Joint("C", sensitivity=1.0, pin=_pin())
    assert err.value.field == "joint C"


def test_a_joints_rotation_is_its_sensitivity_times_its_clearance_under_the_load_magnitude():
    phi = np.linspace(-0.5, 0.5, 5)
    S = np.array([-0.2, -0.1, 0.05, 0.1, 0.2])
    force = np.array([-3000.0, -1000.0, 0.0, 1000.0, 3000.0])
    pin = _pin()
    joint = Joint("D", sensitivity=S, force=force, pin=pin, clearance=0.002)
    expected_c = 0.002 + np.array([pin.clearance(abs(f)) for f in force])
    assert np.allclose(joint.total_clearance(), expected_c, rtol=1e-12)
    assert np.allclose(joint.rotation(phi), np.abs(S) * expected_c, rtol=1e-12)
    # Without a pin, only the fixed clearance.
    plain = Joint("A", sensitivity=S, clearance=0.01)
    assert np.allclose(plain.rotation(phi), np.abs(S) * 0.01)


def test_an_angular_joint_rotates_by_its_clearance_at_every_angle():
    phi = np.linspace(-0.5, 0.5, 7)
    rot = Joint("shaft", angular=True, clearance=2e-3, sensitivity=5.0).rotation(phi)
    assert np.shape(rot) == (7,)
    assert np.allclose(rot, 2e-3)


def test_the_backlash_is_each_joints_rotation_in_degrees_summed_and_root_summed():
    phi = np.array([0.0, 0.1])
    joints = [
        Joint("A", sensitivity=np.array([0.1, 0.2]), clearance=0.01),
        Joint("B", sensitivity=np.array([0.3, -0.4]), clearance=0.02),
        Joint("shaft", angular=True, clearance=1e-3),
    ]
    b = backlash_of(joints, phi)
    deg = 180.0 / math.pi
    a = np.array([0.001, 0.002]) * deg
    bb = np.array([0.006, 0.008]) * deg
    s = np.array([1e-3, 1e-3]) * deg
    assert list(b.per_joint) == ["A", "B", "shaft"]
    assert np.allclose(b.per_joint["B"], bb)
    assert np.allclose(b.worst_case, a + bb + s)
    assert np.allclose(b.rss, np.sqrt(a**2 + bb**2 + s**2))


def test_two_joints_of_one_name_are_refused_instead_of_one_lost_from_the_backlash():
    """A pin joining three links has two running clearances; named both after the pin,
    the per-joint table kept one and the sums lost the other (issue 35)."""
    eye = Joint("knee pin", sensitivity=np.array([0.1, 0.2]), clearance=0.01)
    with pytest.raises(
        InputError,
        match=r"joints: two joints of the clearance chain are "
        r"named 'knee pin': .* one joint per eye that turns on it",
    ):
        backlash_of([eye, Joint("A", sensitivity=1.0), eye], np.array([0.0, 0.1]))


# --- the chain a problem sees -------------------------------------------------------------


def test_fixed_clearances_are_set_by_key_added_to_keyed_pins_and_empty_joints_dropped():
    pin = _pin()
    chain = [
        Joint("A joint", key="A", sensitivity=1.0),
        Joint("B joint", key="B", sensitivity=1.0),
        Joint("keyed pin", key="C", sensitivity=1.0, force=1.0, pin=pin, clearance=0.001),
        Joint("sized pin", sensitivity=1.0, force=1.0, pin=pin),
        Joint("unkeyed", sensitivity=1.0, clearance=0.5),
    ]
    out = with_fixed_clearances(chain, {"A": 0.01, "B": 0.0, "C": 0.002, "": 9.0})
    assert [j.name for j in out] == ["A joint", "keyed pin", "sized pin"]
    assert out[0].clearance == 0.01
    assert out[1].clearance == pytest.approx(0.003)
    assert out[2] is chain[3]
    # The inputs are left as they were.
    assert chain[0].clearance == 0.0 and chain[2].clearance == 0.001


def test_sampled_fits_put_each_pin_at_its_own_fraction_of_its_band():
    pins = [_pin(fit="H7/g6", extra=0.001), _pin(fit="H8/f7", d=20.0)]
    chain = [
        Joint("p1", sensitivity=1.0, force=0.0, pin=pins[0]),
        Joint("A", sensitivity=1.0, clearance=0.01),
        Joint("p2", sensitivity=1.0, force=0.0, pin=pins[1]),
    ]
    out = with_sampled_fits(chain, [0.25, 0.75])
    assert out[1] is chain[1]
    for joint, pin, u in ((out[0], pins[0], 0.25), (out[2], pins[1], 0.75)):
        lo, hi = pin.fit_band()
        assert joint.pin.which == "min"
        assert joint.pin.fit_clearance() + joint.pin.extra == pytest.approx(
            pin.extra + lo + u * (hi - lo), rel=1e-12
        )


def test_each_of_three_pins_takes_its_own_draw_in_order():
    pins = [_pin(d=d) for d in (8.0, 10.0, 12.0)]
    chain = [Joint(f"p{i}", sensitivity=1.0, force=0.0, pin=pin) for i, pin in enumerate(pins)]
    out = with_sampled_fits(chain, [0.1, 0.5, 0.9])
    for joint, pin, u in zip(out, pins, (0.1, 0.5, 0.9), strict=True):
        lo, hi = pin.fit_band()
        assert joint.pin.extra == pytest.approx(u * (hi - lo), rel=1e-12)


def test_a_wrong_count_of_fit_draws_is_refused_naming_both_counts():
    """Fewer draws than pins was an IndexError before the count was checked first."""
    pin = _pin()
    chain = [Joint(f"p{i}", sensitivity=1.0, force=0.0, pin=pin) for i in (1, 2)]
    chain.insert(1, Joint("A", sensitivity=1.0, clearance=0.01))
    with pytest.raises(InputError) as err:
        with_sampled_fits(chain, [0.5])
    assert err.value.field == "tolerances.fit"
    assert "1 fit draws for 2 pin joints" in str(err.value)
    with pytest.raises(InputError, match="3 fit draws for 2 pin joints"):
        with_sampled_fits(chain, [0.5, 0.5, 0.5])


# Clearance chains against brute-force re-assembly, and errors that name the field.


@pytest.mark.parametrize("nu", [0.0, 0.5, -0.1, 0.7])
def test_poisson_ratio_out_of_range(nu):
    with pytest.raises(InputError, match=r"pin\.nu"):
        PinJoint(10, 15, nu=nu)


ROOT = Path(__file__).resolve().parents[2]


PROBLEMS = ROOT / "problems"


#: Fixed clearances, all different, so that a joint reading another's value shows.
CLEARANCES = {"A": "0.011 mm", "B": "0.037 mm", "C": "0.023 mm", "O": "0.0013 deg"}


def _problem(stem: str, **sections) -> od.DesignProblem:
    data = tomllib.loads((PROBLEMS / f"{stem}.toml").read_text())
    data.update(sections)
    return od.load(data)


def _fd(f, x: float, h: float = 1e-6) -> float:
    return (f(x + h) - f(x - h)) / (2 * h)


# --- the clearance chain: each fixed clearance reaches its own joint -----------------------
def _crank_slider_nut(d):
    return lambda phi: cs_loop(phi, d["R"], d["l"], d["n"], d["phi0"])[1][0]


def _fork_nut(d):
    # the pin on the line y = R at angle phi0 + phi from the normal: x = R tan(phi0 + phi)
    return lambda phi: d["R"] * math.tan(d["phi0"] + phi)


def _pivot_nut(d):
    def length(phi):
        a = d["phi0"] + phi
        return math.hypot(d["R"] * math.sin(a) - d["a_T"], d["R"] * math.cos(a) - d["b_T"])

    return length


@pytest.mark.parametrize(
    ("stem", "nut", "design"),
    [
        ("cs_min_backlash", _crank_slider_nut, {"R": 90.0, "l": 80.0, "n": 50.0, "phi0": 0.2}),
        ("fork_min_backlash", _fork_nut, {"R": 70.0, "phi0": 0.0}),
        ("pivot_min_backlash", _pivot_nut, {"R": 90.0, "a_T": -220.0, "b_T": 40.0, "phi0": 0.1}),
    ],
)
def test_each_fixed_clearance_reaches_its_own_joint(stem, nut, design):
    problem = _problem(stem)
    keys = set(problem.mechanism.fixed_clearances)
    problem = _problem(stem, clearances={k: CLEARANCES[k] for k in keys})
    x = problem.midpoint()
    values = problem.design_dict(x)
    values.update({k: v for k, v in design.items() if k in values})
    q = problem.quantities(values)
    per_joint = q.backlash.per_joint
    k_grid = [0, 17, len(problem.phi) - 1]
    f = nut({**{"phi0": 0.0}, **design})
    for k in k_grid:
        phi = float(problem.phi[k])
        s_axial = 1.0 / abs(_fd(f, phi))  # rad/mm: output rotation per axial clearance
        for name, key in (("A screw bearings", "A"), ("B screw/nut", "B")):
            mm = float(CLEARANCES[key].split()[0])
            assert float(np.ravel(per_joint[name])[k]) == pytest.approx(
                math.degrees(s_axial * mm), rel=1e-6
            ), (name, phi)
        assert float(np.ravel(per_joint["O output shaft"])[k]) == pytest.approx(0.0013, rel=1e-12)
    if "C" in keys:  # the crank-slider's nut slide: move the screw's line by dn
        d = design

        def phi_at(n_shift, m_target, guess):
            from scipy.optimize import brentq

            def g(phi):
                return cs_loop(phi, d["R"], d["l"], d["n"] + n_shift, d["phi0"])[1][0] - m_target

            return brentq(g, guess - 0.05, guess + 0.05, xtol=1e-14)

        for k in k_grid:
            phi = float(problem.phi[k])
            m0 = f(phi)
            h = 1e-4
            s_lat = abs(phi_at(h, m0, phi) - phi_at(-h, m0, phi)) / (2 * h)
            assert float(np.ravel(per_joint["C nut slide"])[k]) == pytest.approx(
                math.degrees(s_lat * 0.023), rel=1e-5
            )


@pytest.mark.parametrize("nu", [0.0, 0.5, -0.1, 0.7])
def test_a_pin_poisson_ratio_outside_its_range_is_refused_with_the_value(nu):
    from optdesign.mechanisms.joints import PinJoint

    with pytest.raises(InputError) as caught:
        PinJoint(8.0, 12.0, nu=nu)
    assert caught.value.field == "pin.nu"
    assert caught.value.reason == f"Poisson ratio must lie in (0, 0.5), got {nu!r}"


def test_a_symbolic_poisson_ratio_is_not_range_checked_and_reaches_the_clearance():
    """The joint model takes symbolic material data (a CasADi symbol): only a number is
    checked against (0, 0.5); the symbol is kept for the contact clearance."""
    import casadi as ca

    from optdesign.mechanisms.joints import PinJoint

    nu = ca.SX.sym("nu")
    pin = PinJoint(8.0, 12.0, nu=nu)
    assert pin.nu is nu
    with pytest.raises(InputError):
        PinJoint(8.0, 12.0, nu=0.5)


def test_only_palmgrens_contact_is_restricted_to_steel():
    from optdesign.mechanisms.joints import PinJoint

    titanium = 1.1e5  # MPa
    for contact in ("duan2017", "conforming"):
        assert PinJoint(8.0, 12.0, E=titanium, contact=contact).E == titanium
    with pytest.raises(InputError, match="Palmgren's approach is an empirical law of steel"):
        PinJoint(8.0, 12.0, E=titanium, contact="palmgren")
    assert PinJoint(8.0, 12.0, E=2.1e5, contact="palmgren").contact == "palmgren"
    # the steel band 1.9e5-2.2e5 MPa, both ends included
    for steel in (1.9e5, 2.2e5):
        assert PinJoint(8.0, 12.0, E=steel, contact="palmgren").E == steel
    for not_steel in (1.89e5, 2.21e5):
        with pytest.raises(InputError, match=r"^materials\.pin\.E: Palmgren's approach"):
            PinJoint(8.0, 12.0, E=not_steel, contact="palmgren")


def test_a_keyed_pin_joint_adds_its_fixed_clearance_to_the_pins():
    """docs/mechanisms.md: a joint's ``key`` names its fixed clearance in the problem's
    ``[clearances]`` table; on a sized pin joint the value adds to the pin's own."""
    from optdesign.mechanisms.joints import Joint, PinJoint, with_fixed_clearances

    pin = Joint("P lever pin", "P", sensitivity=0.01, force=100.0, pin=PinJoint(8.0, 12.0))
    slide = Joint("A slide", "A", sensitivity=0.01)
    unkeyed = Joint("Q other pin", "", sensitivity=0.01, force=100.0, pin=PinJoint(8.0, 12.0))
    out = with_fixed_clearances([pin, slide, unkeyed], {"P": 0.004, "A": 0.002})
    assert [j.name for j in out] == ["P lever pin", "A slide", "Q other pin"]
    assert [j.clearance for j in out] == [0.004, 0.002, 0.0]
    assert out[0].pin is pin.pin  # the pin itself is kept: its fit adds on top
    # a joint with neither a pin nor a fixed clearance is dropped from the chain
    assert with_fixed_clearances([slide], {}) == []


def test_a_joint_a_plug_in_declares_wrongly_is_refused_naming_it():
    """A mechanism's clearance chain (docs/mechanisms.md): each joint needs a sensitivity
    unless it is angular, a pin joint the force it carries, and no clearance is negative."""
    from optdesign.mechanisms.joints import Joint, PinJoint

    cases = [
        (dict(name="C slide", key="C"), "joint C slide", "needs a sensitivity (rad/mm)"),
        (
            dict(name="D pin", sensitivity=0.01, pin=PinJoint(8.0, 12.0)),
            "joint D pin",
            "a pin joint needs the force it carries",
        ),
        (dict(name="A", sensitivity=0.01, clearance=-0.001), "joint A.clearance", "must be >= 0"),
    ]
    for kwargs, field, reason in cases:
        with pytest.raises(InputError) as caught:
            Joint(**kwargs)
        assert (caught.value.field, caught.value.reason) == (field, reason)
    assert Joint(name="O shaft", angular=True).sensitivity is None  # an angle needs none


def test_the_conforming_contact_pressure_uses_the_pin_radius():
    """The conforming solution's peak pressure scales as E* dR / R (R the pin's radius,
    dR the radial clearance): checked against the model's dimensionless pressure."""
    from optdesign.mechanisms.joints import PinJoint
    from optdesign.models import pin_contact as pc

    pin = PinJoint(8.0, 12.0, contact="conforming")
    F = 2000.0
    dR = 0.5 * float(pin.fit_clearance())
    E_s = pc.effective_modulus_similar(pin.E, pin.nu)
    P_star = pc.load_parameter(F, pin.L, dR, pin.E, pin.nu)
    expected = E_s * dR / 4.0 * pc.max_pressure_star(P_star)  # R = d / 2 = 4 mm
    assert float(pin.contact_pressure(F)) == pytest.approx(expected, rel=1e-12)
    wider = PinJoint(16.0, 12.0, contact="conforming", extra=0.0)
    assert float(wider.contact_pressure(F)) < float(pin.contact_pressure(F))
