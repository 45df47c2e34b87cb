"""Screw sizing and motor-shaft lock (issue 7) as requirements and objectives of problems."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.errors import ProblemError
from optdesign.formulations.nlp.solve import solve_nlp
from optdesign.mechanisms import CrankSlider
from optdesign.models.lock import PinLock, motor_shaft_lock_load
from optdesign.models.screw_sizing import buckling_load
from optdesign.problem import problem_from_dict
from problem.test_drive import _data  # the drive's crank-slider problem


def _problem(**req):
    objective = req.pop("_objective", "ripple")
    # requirements.screw (the screw's own requirements), not _data's [screw] section
    screw_requirements = req.pop("screw", None)
    data = _data(objective=objective, **req)
    if screw_requirements is not None:
        data["requirements"]["screw"] = screw_requirements
    return problem_from_dict(data)


def test_lock_force_objective_matches_the_model():
    lock = {"kind": "pin", "radius": "40 mm", "eta_screw_back": 0.9}
    problem = _problem(lock=lock, _objective="lock_force")
    res = solve_nlp(problem, starts=4)
    assert res.status == "optimal" and res.verified
    d = res.design
    mech = CrankSlider(R=d["R"], l=d["l"], n=d["n"], p=d["p"], i_a=d["i_a"], phi0=d["phi0"])
    load = motor_shaft_lock_load(mech, problem.phi, 500e3, 0.9, 1.0, PinLock(40.0))
    assert res.objective == pytest.approx(float(load.force), rel=1e-7)
    # the paper's pin lock: f_a = 0.35 M / R
    assert float(load.force) == pytest.approx(0.35 * float(load.moment_max) / 40.0, rel=1e-12)
    # the least lock force wants the smallest nut force: the mean ratio sits at its top
    assert res.objectives["ripple"] < 0.2
    names = {r.name for r in res.active}
    assert "mean_ratio" in names


def test_screw_buckling_is_imposed_and_named_when_it_cannot_be_met():
    # la = 500 mm: P1 = 10 * 12.5^4 / 500^2 * 1e4 = 9766 N, met by the ripple optimum
    ok = _problem(screw={"root_diameter": "12.5 mm", "buckling_length": "500 mm"})
    res = solve_nlp(ok, starts=3)
    assert res.status == "optimal"
    x = np.array([res.design[v.name] for v in ok.free])
    F = ok.evaluate(x).constraints["screw_buckling"].values
    P1 = buckling_load(12.5, 500.0)
    assert P1 == pytest.approx(9765.625)
    assert np.max(F) <= P1 * (1 + 1e-6)
    # la = 1500 mm: P1 = 1085 N, below any nut force that carries 500 N*m over a 110 mm travel
    bad = _problem(screw={"root_diameter": "12.5 mm", "buckling_length": "1500 mm"})
    res = solve_nlp(bad, starts=3)
    assert not res.success
    assert any(v.name.startswith("screw_buckling") for v in res.violated)


@pytest.mark.parametrize(
    ("lock", "message"),
    [
        ({"kind": "friction_plate", "r1": "30 mm"}, "r1 and r2"),
        ({"kind": "pin"}, "positive radius"),
        ({"kind": "pin", "radius": "40 N"}, "requirements.lock.radius"),
    ],
)
def test_lock_requirement_errors(lock, message):
    with pytest.raises(ProblemError, match=message):
        _problem(lock=lock)


@pytest.mark.parametrize(
    "kept",
    ["static_safety_min", "life_min"],
)
def test_a_rating_requirement_without_a_catalogue_screw_is_refused_naming_it(kept):
    """fin_actuator with its screw given by hand (d0, p fixed, no catalogue): the static
    safety and the life need the catalogue's ratings; each is refused on its own, naming
    itself and how to give a catalogue."""
    import tomllib
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    data = tomllib.loads((root / "problems" / "fin_actuator.toml").read_text())
    for key in ("catalogue", "nut_stiffness_rule", "mounting_factors"):
        data["screw"].pop(key, None)
    for name in ("static_safety_min", "life_min"):
        if name != kept:
            data["requirements"].pop(name, None)
    data["variables"]["d0"], data["variables"]["p"] = "20 mm", "5 mm"
    with pytest.raises(ProblemError) as caught:
        od.solve(od.load(data), starts=1)
    assert str(caught.value) == (
        f'requirements.{kept}: needs a catalogue screw ([screw] catalogue = "HIWIN")'
    )


def test_the_screw_yield_row_is_the_nut_force_over_the_permissible_load_with_no_unit():
    """fin_actuator (check_yield on by default): the row is F / F_yield(d1), a plain ratio
    bounded by 1 - shown without a unit."""
    import tomllib
    from pathlib import Path

    from optdesign.models import screw_sizing
    from optdesign.problem.drive_requirements import drive_blocks

    root = Path(__file__).resolve().parents[2]
    problem = od.load(tomllib.loads((root / "problems" / "fin_actuator.toml").read_text()))
    q = problem.quantities(problem.design_dict(problem.midpoint()))
    blocks = {b.name: b for b in drive_blocks(q, problem.phi_labels)}
    row = blocks["screw_yield"]
    # the catalogue row (1 on a catalogue screw) is a plain number too
    on_catalogue = next(
        b for b in blocks.values() if "is a screw of the catalogue" in b.description
    )
    assert (on_catalogue.unit, on_catalogue.lower, on_catalogue.upper) == ("", 1.0, None)
    assert (row.unit, row.lower, row.upper) == ("", None, 1.0)
    assert row.description == "nut force / permissible shaft load"
    force = np.abs(np.asarray(q.nut_force, dtype=float)).ravel()
    expected = force / float(screw_sizing.yield_load(float(q.screw.d1)))
    assert np.asarray(row.expr, dtype=float).ravel() == pytest.approx(expected, rel=1e-12)


ROOT = Path(__file__).resolve().parents[2]


def test_the_dn_row_names_the_diameter_of_its_rule():
    from optdesign.problem.drive_requirements import drive_blocks

    def dn_text(rule, limit=None):
        data = tomllib.loads((ROOT / "problems" / "fin_actuator.toml").read_text())
        data["requirements"]["dn_rule"] = rule
        if limit is not None:
            data["requirements"]["dn_max"] = limit
        problem = problem_from_dict(data)
        q = problem.quantities(problem.design_dict(problem.midpoint()))
        return next(b for b in drive_blocks(q, problem.phi_labels) if b.name == "dn").description

    assert dn_text("ball-centre").startswith("d_m x screw speed (DN value; rule ball-centre")
    assert dn_text("HIWIN") == (
        "d0 x screw speed (DN value; rule HIWIN: ground limit 90,000 on the nominal diameter)"
    )
    # a limit given as a number names no grade
    assert dn_text("HIWIN", 70000) == (
        "d0 x screw speed (DN value; rule HIWIN: limit 70,000 on the nominal diameter)"
    )
