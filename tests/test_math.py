"""The public math module's guarded functions (issue 35, item 1), and a user's linkage that
does not assemble at some design or angle: its NaN is reported ("cannot assemble at
deflection ..."), never printed as NumPy's RuntimeWarning ("invalid value encountered in
sqrt", "divide by zero"), through loading, declaring constraints, evaluating, checking a
front's objectives and solving.
"""

from __future__ import annotations

import warnings

import casadi as ca
import numpy as np
import pytest

import optdesign as od
from optdesign import math as m
from optdesign.errors import AssemblyError
from optdesign.studies.pareto.run_setup import check_objectives


# --- the guarded functions -------------------------------------------------------------------
def test_sqrt_domain_is_nan_outside_on_numpy_and_guarded_on_casadi_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isnan(m.sqrt_domain(-1.0)) and m.sqrt_domain(4.0) == 2.0
        assert np.array_equal(m.sqrt_domain(np.array([-1.0, 9.0])), [np.nan, 3.0], equal_nan=True)
    x = ca.SX.sym("x")
    f = ca.Function("f", [x], [m.sqrt_domain(x), ca.jacobian(m.sqrt_domain(x), x)])
    value, slope = (float(v) for v in f(-1.0))
    assert value == pytest.approx(1e-6) and slope == 0.0  # finite, no NaN


def test_divide_domain_is_nan_at_a_zero_divisor_on_numpy_and_finite_on_casadi():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isnan(m.divide_domain(1.0, 0.0)) and np.isnan(m.divide_domain(0.0, 0.0))
        assert m.divide_domain(3.0, 2.0) == 1.5 and np.ndim(m.divide_domain(3.0, 2.0)) == 0
        grid = m.divide_domain(np.array([[1.0], [2.0]]), np.array([0.0, 4.0, -1.0]))
        assert np.array_equal(grid, [[np.nan, 0.25, -1.0], [np.nan, 0.5, -2.0]], equal_nan=True)
        assert np.isnan(m.divide_domain(1.0, np.nan))
    b = ca.SX.sym("b")
    f = ca.Function("f", [b], [m.divide_domain(2.0, b), ca.jacobian(m.divide_domain(2.0, b), b)])
    for at, expected in ((0.0, 2e9), (-1e-12, -2e9), (4.0, 0.5)):
        value, slope = (float(v) for v in f(at))
        assert value == pytest.approx(expected) and np.isfinite(slope)
    assert float(m.divide_domain(1.0, ca.DM(0.0))) == pytest.approx(1e9)


# --- a user's linkage that does not assemble everywhere --------------------------------------
class _CrankAndRod(od.Mechanism):
    """A crank R turning about the output axis, a rod l from the crank pin to the nut on a
    screw axis at height e: x = R sin(phi) - sqrt(l^2 - (R cos(phi) - e)^2), which assembles
    only where |R cos(phi) - e| < l."""

    name = "t35_crank_and_rod"
    variables = {  # noqa: RUF012 - a plug-in declares its variables as a plain dict
        "R": od.VariableInfo("length", "crank"),
        "l": od.VariableInfo("length", "rod"),
        "e": od.VariableInfo("length", "screw axis height", positive=False),
    }
    pin_joints = ("crank pin",)

    def reach(self, phi):
        u = self.R * m.cos(phi) - self.e
        return (self.l**2 - u**2) / self.l**2

    def nut_position(self, phi):
        return self.R * m.sin(phi) - self.l * m.sqrt_domain(self.reach(phi))

    def assembly_rows(self, phi):
        return [od.Rows("reach", self.reach(phi), 0.05, None, "", "cos^2 of the rod's angle")]


class _CrankAndRodByAngles(_CrankAndRod):
    """The same linkage through the rod's angle (an arccos, a division by the rod's
    cosine): NaN where it does not assemble, and a zero divisor at the fold."""

    name = "t35_crank_and_rod_by_angles"

    def nut_position(self, phi):
        u = self.R * m.cos(phi) - self.e
        beta = m.arcsin(u / self.l)  # NaN where |u| > l
        return self.R * m.sin(phi) - self.l * m.cos(beta)

    def nut_velocity(self, phi):  # closed form through a guarded division by cos(beta)
        u = self.R * m.cos(phi) - self.e
        cos_beta = m.sqrt_domain(1.0 - (u / self.l) ** 2)
        return self.R * m.cos(phi) - m.divide_domain(u * self.R * m.sin(phi), self.l * cos_beta)


for _cls in (_CrankAndRod, _CrankAndRodByAngles):
    od.register_mechanism(_cls, replace=True)


def _problem(mechanism: str) -> dict:
    """Bounds whose middle (R 75, l 32.5, e 130 mm) does not assemble, and parts of them
    that do."""
    return {
        "name": "t35_does_not_assemble",
        "mechanism": mechanism,
        "variables": {
            "R": {"lower": "30 mm", "upper": "120 mm"},
            "l": {"lower": "5 mm", "upper": "60 mm"},
            "e": {"lower": "20 mm", "upper": "240 mm"},
            "p": {"lower": "2 mm", "upper": "10 mm"},
            "d": {"lower": "4 mm", "upper": "30 mm"},
            "i_a": 2,
            "pin_length_ratio": 1.5,
        },
        "requirements": {
            "deflection": {"min": "-30 deg", "max": "30 deg", "points": 21},
            "hinge_moment": "100 N*m",
            "mean_ratio": {"min": 100, "max": 300},
            "nut_travel_max": "200 mm",
            "pin_bearing_pressure_max": "100 MPa",
            "fit": "H7/g6",
        },
        "objective": {"minimize": "backlash"},
    }


@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("cls", [_CrankAndRod, _CrankAndRodByAngles], ids=lambda c: c.name)
def test_a_user_linkage_that_does_not_assemble_prints_no_runtime_warning(cls):
    problem = od.load(_problem(cls.name))
    middle = problem.quantities(problem.design_dict(problem.midpoint()))
    assert np.isnan(np.asarray(middle.nut_position, dtype=float)).all()  # NaN, silently
    with pytest.raises(AssemblyError, match=r"cannot assemble at deflection -30\.000 deg"):
        middle.mechanism.check_assembly(problem.phi)
    # what runs the mechanism at the middle of the bounds: declarations, a front's check
    problem.add_constraint("nut_force", lambda q: q.nut_force, upper="50 kN", unit="N")
    problem.add_objective("peak_force", lambda q: m.fabs(q.nut_force), unit="N")
    assert check_objectives(problem, ["size", "backlash"]) == ["size", "backlash"]
    # a population, most of it not assembling: NaN and violated, not warned about
    rng = np.random.default_rng(35)
    lo, hi = (np.array([getattr(v, k) for v in problem.free]) for k in ("lower", "upper"))
    ev = problem.evaluate(lo + rng.random((64, len(lo))) * (hi - lo))
    apart = np.isnan(ev.objectives["nut_travel"])
    assert 10 < apart.sum() < 64 and (ev.violation[apart] > 1e300).all()
    result = od.solve(problem, starts=2, ranges=False, sensitivities=False)
    assert result.success and result.verified


@pytest.mark.filterwarnings("error::RuntimeWarning")
def test_a_user_linkage_that_never_assembles_is_reported_not_warned_about():
    data = _problem(_CrankAndRod.name)
    data["variables"]["e"] = "200 mm"  # |R cos(phi) - e| >= 96 mm > l everywhere
    data["variables"]["R"] = {"lower": "30 mm", "upper": "60 mm"}
    problem = od.load(data)
    result = od.solve(problem, starts=1, ranges=False, sensitivities=False)
    assert not result.success and result.verified is not True
    assert any(row.name.startswith("reach") for row in result.violated)
