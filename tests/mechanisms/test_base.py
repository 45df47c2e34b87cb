"""optdesign/mechanisms/base.py as a whole, through a plug-in written as a user would (a
lever, x = R sin(phi) + e): the variable table and its refusals, the derived kinematics
and loads against their closed forms, the default clearance chain, sizes, assembly checks,
the row display units and the automatic derivative on every path."""

import math
from typing import ClassVar

import casadi as ca
import numpy as np
import pytest

import optdesign as od
from optdesign import math as m
from optdesign.errors import AssemblyError, InputError
from optdesign.mechanisms.base import (
    DRIVE_VARIABLES,
    Mechanism,
    Rows,
    VariableInfo,
    as_variable_info,
)
from optdesign.mechanisms.joints import PinJoint


class Lever(Mechanism):
    name = "test_lever"
    variables: ClassVar = {
        "R": ("length", "lever arm"),
        "e": VariableInfo("length", "offset", positive=False, default=0.0),
        "tilt": ("angle", "mount tilt", False, 0.0),
        "k": ("dimensionless", "a factor", True, 1.0),
    }
    pin_joints = ("pin a", "pin b")

    def nut_position(self, phi):
        return self.R * m.sin(phi) + self.e


class Bare(Mechanism):
    """A plug-in that declares nothing but its kinematics."""

    variables: ClassVar = {"R": "length"}

    def nut_position(self, phi):
        return self.R * m.sin(phi)


class CircleLever(Lever):
    """Assembles only where |phi| < 0.5 rad (NaN elsewhere on the NumPy path)."""

    title = "circle lever"

    def nut_position(self, phi):
        return self.R * m.sqrt(0.25 - phi**2)


PHI = np.radians(np.array([-30.0, -10.0, 0.0, 20.0, 30.0]))


def lever(**kw):
    return Lever(**{"R": 40.0, "p": 5.0, **kw})


# --- variables ------------------------------------------------------------------------------


def test_a_variable_of_an_unknown_dimension_is_refused_listing_the_dimensions():
    with pytest.raises(InputError) as err:
        VariableInfo("mass", "m")
    assert err.value.field == "dimension"
    assert "'mass' is not one of length, angle, dimensionless" in str(err.value)


def test_the_short_forms_of_a_variable():
    assert as_variable_info("angle") == VariableInfo("angle", "")
    assert as_variable_info(("length", "arm")) == VariableInfo("length", "arm", True, None)
    full = as_variable_info(("length", "arm", False, 3.0))
    assert (full.positive, full.default) == (False, 3.0)
    info = VariableInfo("length", "x")
    assert as_variable_info(info) is info


def test_every_mechanism_has_the_screw_lead_required_and_the_gear_ratio_at_one():
    assert DRIVE_VARIABLES["p"].default is None
    assert DRIVE_VARIABLES["i_a"].default == 1.0
    assert list(Lever.variable_table()) == ["R", "e", "tilt", "k", "p", "i_a"]


def test_a_mechanism_may_declare_a_drive_variable_of_its_own():
    class OwnLead(Bare):
        variables: ClassVar = {"R": "length", "p": ("length", "own lead", True, 4.0)}

    table = OwnLead.variable_table()
    assert list(table) == ["R", "p", "i_a"]
    assert table["p"].description == "own lead"
    assert OwnLead(R=1.0).p == 4.0


def test_construction_fills_defaults_and_keyword_values_win_over_the_design():
    lev = Lever({"R": 10.0, "p": 2.0, "unused": 1.0}, R=20.0)
    assert lev.values == {"R": 20.0, "e": 0.0, "tilt": 0.0, "k": 1.0, "p": 2.0, "i_a": 1.0}
    assert lev.guarded is False
    assert Lever(R=1.0, p=1.0, guarded=1).guarded is True


def test_an_unknown_keyword_is_refused_naming_it_and_the_known_variables():
    with pytest.raises(InputError) as err:
        lever(zeta=1.0, alpha=2.0)
    assert err.value.field == "alpha"
    assert "not a variable of a test_lever (known: R, e, tilt, k, p, i_a)" in str(err.value)


def test_a_missing_variable_is_refused_with_its_description():
    with pytest.raises(InputError) as err:
        Lever(p=5.0)
    assert err.value.field == "R"
    assert "required by a test_lever (lever arm)" in str(err.value)


@pytest.mark.parametrize("name,value", [("R", 0.0), ("k", -1.0), ("p", -5.0), ("i_a", 0.0)])
def test_a_positive_variable_must_be_positive(name, value):
    with pytest.raises(InputError) as err:
        lever(**{name: value})
    assert err.value.field == name


def test_a_signed_variable_may_be_negative_but_must_be_finite():
    assert lever(e=-3.0, tilt=-0.1).e == -3.0
    for bad in (math.nan, math.inf):
        with pytest.raises(InputError) as err:
            lever(e=bad)
        assert err.value.field == "e"


def test_the_label_is_the_title_else_the_name_else_the_class():
    assert CircleLever.label() == "circle lever"
    assert Lever.label() == "test_lever"
    assert Bare.label() == "Bare"


def test_attributes_read_design_values_and_a_missing_one_names_the_variables():
    lev = lever()
    assert lev.R == 40.0 and lev.i_a == 1.0
    with pytest.raises(
        AttributeError, match=r"Lever has no attribute 'r' \(its variables: R, e, tilt, k, p, i_a\)"
    ):
        _ = lev.r
    assert repr(lev) == "Lever(R=40.0, e=0.0, tilt=0.0, k=1.0, p=5.0, i_a=1.0)"


def test_a_property_that_raises_attribute_error_shows_its_own_error():
    class Buggy(Lever):
        @property
        def arm(self):
            return self.undefined_thing

    with pytest.raises(AttributeError, match="'undefined_thing'"):
        _ = Buggy(R=1.0, p=1.0).arm


# --- kinematics and loads against closed forms ----------------------------------------------


def test_the_derived_kinematics_equal_their_closed_forms():
    lev = lever(e=2.0, i_a=3.0)
    v = 40.0 * np.cos(PHI)
    assert np.allclose(lev.nut_velocity(PHI), v, rtol=1e-12)
    ratio = 2 * np.pi * 3.0 * v / 5.0
    assert np.allclose(lev.ratio(PHI), ratio, rtol=1e-12)
    assert float(lev.ripple(PHI)) == pytest.approx(
        (ratio.max() - ratio.min()) / (ratio.max() + ratio.min()), rel=1e-12
    )
    step = 1e-3
    fd = 2 * np.pi * 3.0 * (40.0 * np.sin(PHI + step) - 40.0 * np.sin(PHI)) / (5.0 * step)
    assert np.allclose(lev.ratio_finite_step(PHI, step), fd, rtol=1e-12)
    assert float(lev.nut_travel(-0.5, 0.25)) == pytest.approx(40.0 * (np.sin(0.25) + np.sin(0.5)))


def test_the_loads_are_virtual_work_and_the_screw_torque():
    lev = lever(i_a=2.0)
    M_h = 5.0e5
    F = M_h / (40.0 * np.cos(PHI))
    assert np.allclose(lev.nut_force(PHI, M_h), F, rtol=1e-12)
    T = lev.motor_torque(PHI, M_h, eta_screw=0.9, eta_gear=0.8)
    assert np.allclose(T, F * 5.0 / (2 * np.pi * 2.0 * 0.9 * 0.8), rtol=1e-12)
    assert np.allclose(lev.sensitivity_axial(PHI), 1 / (40.0 * np.cos(PHI)), rtol=1e-12)


def test_a_guarded_mechanism_never_divides_by_a_zero_rate():
    dead = np.array([np.pi / 2])
    with np.errstate(divide="ignore"):
        assert abs(float(lever().sensitivity_axial(dead)[0])) > 1e12
    guarded = float(lever(guarded=True).sensitivity_axial(dead)[0])
    assert np.isfinite(guarded) and abs(guarded) <= 1.0 / m.RATE_GUARD
    # Away from the dead point the guard changes nothing.
    assert np.allclose(
        lever(guarded=True).sensitivity_axial(PHI), lever().sensitivity_axial(PHI), rtol=0
    )


# --- the default clearance chain and the pin force ----------------------------------------


def test_the_default_chain_is_the_screws_bearings_nut_and_output_shaft():
    chain = lever().joints(PHI, 1e5)
    assert [(j.name, j.key, j.angular) for j in chain] == [
        ("A screw bearings", "A", False),
        ("B screw/nut", "B", False),
        ("O output shaft", "O", True),
    ]
    assert np.allclose(chain[0].sensitivity, 1 / (40.0 * np.cos(PHI)))
    assert chain[2].sensitivity is None


def test_a_sized_pin_adds_one_joint_per_declared_pin_loaded_by_the_nut_force():
    pin = PinJoint(8.0, 10.0)
    chain = lever().joints(PHI, 1e5, pin)
    pins = chain[3:]
    assert [j.name for j in pins] == ["pin a", "pin b"]
    for j in pins:
        assert j.pin is pin and j.key == ""
        assert np.allclose(j.force, 1e5 / (40.0 * np.cos(PHI)))
        assert np.allclose(j.sensitivity, 1 / (40.0 * np.cos(PHI)))
    assert np.allclose(lever().pin_force(PHI, -1e5), 1e5 / (40.0 * np.cos(PHI)))


def test_the_pin_force_is_the_largest_magnitude_over_the_pin_joints():
    class TwoPins(Lever):
        def joints(self, phi, M_h, pin=None):
            from optdesign.mechanisms.joints import Joint

            return [
                Joint("small", sensitivity=1.0, force=np.array([-1.0, 5.0, -7.0]), pin=pin),
                Joint("large", sensitivity=1.0, force=np.array([3.0, -2.0, 6.0]), pin=pin),
                Joint("A", "A", sensitivity=1.0, force=np.array([99.0, 99.0, 99.0])),
            ]

    assert np.allclose(TwoPins(R=1.0, p=1.0).pin_force(PHI[:3], 1.0), [3.0, 5.0, 7.0])


def test_a_mechanism_without_pins_says_so_for_the_chain_and_the_pin_force():
    with pytest.raises(InputError) as err:
        Bare(R=1.0, p=1.0).joints(PHI, 1.0)
    assert err.value.field == "pin_joints"
    assert "a Bare declares no pins" in str(err.value)

    class NoPin(Bare):
        pin_joints = ()

    assert len(NoPin(R=1.0, p=1.0).joints(PHI, 1.0, PinJoint(8.0, 10.0))) == 3
    with pytest.raises(InputError) as err:
        NoPin(R=1.0, p=1.0).pin_force(PHI, 1.0)
    assert err.value.field == "pin"
    assert "has no sized pin joint" in str(err.value)


def test_the_backlash_is_the_chains_in_degrees():
    chain = lever().joints(PHI, 1e5)
    from optdesign.mechanisms.joints import with_fixed_clearances

    chain = with_fixed_clearances(chain, {"A": 0.01, "O": 1e-3})
    b = lever().backlash(PHI, chain)
    expected = np.degrees(0.01 / (40.0 * np.cos(PHI)) + 1e-3)
    assert np.allclose(b.worst_case, expected, rtol=1e-12)


# --- size, requirements, assembly ------------------------------------------------------------


def test_the_size_sums_the_own_length_variables_only():
    assert float(lever(e=-2.0, tilt=0.3, k=7.0, p=9.0).size()) == pytest.approx(38.0)


def test_a_declared_requirement_without_rows_says_which():
    with pytest.raises(NotImplementedError, match="Lever declares 'stiffness' but builds no rows"):
        lever().requirement_rows("stiffness", 1.0, PHI)
    assert lever().assembly_rows(PHI) == []
    assert lever().sketch(0.0) is None
    with pytest.raises(NotImplementedError, match="Bare must define nut_position"):
        Mechanism.nut_position(Bare(R=1.0, p=1.0), 0.0)


def test_the_default_assembly_margin_marks_the_angles_without_a_position():
    circle = CircleLever(R=10.0, p=1.0)
    with np.errstate(invalid="ignore"):
        margin = circle.assembly_margin([-0.6, -0.4, 0.0, 0.49, 0.51])
    assert margin.tolist() == [-1.0, 1.0, 1.0, 1.0, -1.0]
    circle.check_assembly([-0.4, 0.0, 0.4])
    with pytest.raises(AssemblyError) as err:
        circle.check_assembly([0.0, 0.55, 0.6, -0.7])
    assert err.value.angle_deg == pytest.approx(np.degrees(0.55))
    assert err.value.margin == -1.0
    assert "circle lever R=10, e=0, tilt=0, k=1, p=1, i_a=1" in str(err.value)


def test_a_population_is_checked_design_by_design_naming_the_first_angle():
    """A population's margins (designs x angles) against a grid of angles."""
    circle = CircleLever(R=np.array([[10.0], [20.0]]), p=1.0)
    circle.check_assembly([-0.4, 0.0, 0.4])
    with pytest.raises(AssemblyError) as err:
        circle.check_assembly([0.0, 0.3, 0.55])
    assert err.value.angle_deg == pytest.approx(np.degrees(0.55))
    assert "R=<array (2, 1)>" in str(err.value)


def test_a_margin_of_exactly_zero_does_not_assemble():
    class Touching(Lever):
        def assembly_margin(self, phi):
            return np.asarray(phi) * 0.0 + np.where(np.asarray(phi) > 0.1, 0.0, 1.0)

    with pytest.raises(AssemblyError) as err:
        Touching(R=1.0, p=1.0).check_assembly([0.0, 0.2])
    assert err.value.angle_deg == pytest.approx(np.degrees(0.2))


def test_the_design_description_shows_arrays_and_symbols_by_kind():
    lev = Lever(R=np.array([1.0, 2.0, 3.0]), p=ca.SX.sym("p"), e=2.5)
    assert lev.describe() == "test_lever R=<array (3,)>, e=2.5, tilt=0, k=1, p=<symbolic>, i_a=1"


# --- rows shown in another unit ---------------------------------------------------------------


def test_a_row_converts_to_its_display_unit_or_names_itself():
    row = Rows("angle", 0.0, unit="rad", display_unit="deg")
    assert row.display(1.0) == pytest.approx(180.0 / np.pi)
    assert Rows("same", 0.0, unit="mm", display_unit="mm").display is None
    custom = Rows("c", 0.0, unit="", display=lambda v: 2 * v, display_unit="deg")
    assert custom.display(3.0) == 6.0
    with pytest.raises(InputError) as err:
        Rows("bad", 0.0, unit="mm", display_unit="deg")
    assert err.value.field == "Rows('bad').display_unit"


# --- the automatic derivative on every path ------------------------------------------------------


def test_the_automatic_derivative_on_symbolic_numeric_and_population_paths():
    phi = ca.SX.sym("phi")
    R = ca.SX.sym("R")
    sym = Lever(R=R, p=5.0)
    f = ca.Function("v", [phi, R], [sym.nut_velocity(phi)])
    assert float(f(0.3, 40.0)) == pytest.approx(40.0 * np.cos(0.3), rel=1e-12)
    # A numeric grid with a symbolic design: one expression per angle.
    col = ca.Function("c", [R], [sym.nut_velocity(PHI)])(40.0)
    assert np.allclose(np.asarray(col).ravel(), 40.0 * np.cos(PHI), rtol=1e-12)
    # A population broadcast against the grid on the last axis.
    pop = Lever(R=np.array([[10.0], [20.0]]), p=5.0).nut_velocity(PHI)
    assert pop.shape == (2, 5)
    assert np.allclose(pop, np.array([[10.0], [20.0]]) * np.cos(PHI), rtol=1e-12)
    # Integer angles are taken as numbers.
    assert float(lever().nut_velocity(0)) == pytest.approx(40.0)


@pytest.mark.parametrize("name", ["_Lever", "Lever__v2", "_"])
def test_the_automatic_derivative_of_a_class_whose_name_casadi_would_refuse(name):
    """CasADi names take no leading nor doubled underscore: a user's class named so gets
    its derivative all the same (it was refused: "Function name is not valid")."""
    cls = type(name, (Lever,), {})
    assert np.allclose(cls(R=40.0, p=5.0).nut_velocity(PHI), 40.0 * np.cos(PHI), rtol=1e-12)


def test_the_automatic_derivative_refuses_values_it_cannot_see_through():
    lev = lever()
    lev.values["R"] = np.array([object()], dtype=object)  # as the GP diagnosis's tracers
    with pytest.raises(
        TypeError,
        match=r"Lever\.nut_velocity is the automatic derivative of nut_position, which needs "
        r"CasADi or NumPy values; write nut_velocity in closed form to trace it \(GP diagnosis\)",
    ):
        lev.nut_velocity(PHI)


def test_the_default_clearance_chain_reads_each_fixed_clearance_under_its_key():
    """A mechanism with the default chain (screw bearings A, screw/nut B, output shaft O):
    the file's clearances reach the backlash, c / (dx/dphi) rad each on the screw's line;
    for the yoke x = R sin(phi), dx/dphi = R cos(phi)."""
    from test_api import yoke_data

    from optdesign import math as m

    class ChainYoke(od.Mechanism):
        name = "t21_chain_yoke"
        variables = {"R": od.VariableInfo("length", "crank radius")}  # noqa: RUF012
        pin_joints = ("crank pin",)

        def nut_position(self, phi):
            return self.R * m.sin(phi)

    od.register_mechanism(ChainYoke, replace=True)
    data = yoke_data("t21_chain_yoke")
    data["clearances"] = {"A": "0.02 mm", "B": "0.01 mm", "O": "0.005 deg"}
    problem = od.load(data)
    R = 80.0
    backlash = problem.quantities({"R": R, "p": 5.0, "i_a": 2.0}).backlash
    phi = np.asarray(problem.phi)
    expected = np.degrees(0.03 / (R * np.cos(phi))) + 0.005
    assert np.asarray(backlash.worst_case, dtype=float).ravel() == pytest.approx(expected, rel=1e-9)
    assert sorted(backlash.per_joint) == ["A screw bearings", "B screw/nut", "O output shaft"]


def test_a_mechanism_without_its_kinematics_or_pins_says_what_to_write():
    import optdesign as od
    from optdesign.errors import InputError

    class Bare(od.Mechanism):
        name = "t32_bare"
        variables = {"R": od.VariableInfo("length", "lever")}  # noqa: RUF012

    bare = Bare(R=50.0, p=5.0)
    with pytest.raises(NotImplementedError, match=r"^Bare must define nut_position\(phi\)$"):
        bare.nut_position(0.1)
    with pytest.raises(InputError) as caught:
        bare.joints(np.zeros(3), 1.0e5, None)
    assert caught.value.field == "pin_joints"
    assert caught.value.reason.endswith("declares no pins: set pin_joints or write joints()")
