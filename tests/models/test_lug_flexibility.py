"""Huth's flexibility of a pin in its lug or clevis (issue 26): the model against an
independent implementation's values, its invariants, its place beside the other pin
contact models (file, NLP, GP, the ``--contact-models`` spread)."""

from __future__ import annotations

import copy
import json
import math
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError, OptDesignError, ProblemError
from optdesign.mechanisms.joints import CONTACT_MODELS, PinJoint
from optdesign.models.lug_flexibility import HUTH_CONSTANTS, Lug, huth_approach, huth_compliance
from optdesign.problem import load_problem, problem_from_dict
from optdesign.programs.gp import build_gp
from optdesign.units import convert, unit_factor

ROOT = Path(__file__).resolve().parents[2]
FIN = ROOT / "problems" / "fin_actuator.toml"
STEEL = 2.1e5


@pytest.mark.parametrize(
    ("planes", "fastener", "stiffness_lbf_in"),
    [
        (1, "riveted", 147424.0),
        (2, "riveted", 365896.0556),
        (1, "bolted", 152589.0),
        (2, "bolted", 378714.0),
    ],
)
def test_huth_stiffness_against_pynastran(planes, fastener, stiffness_lbf_in):
    """pyNastran's independent implementation (pyNastran/dev/tools/test_huth.py) asserts
    1/C for d = 0.1875 in, t1 = 0.040 in, t2 = 0.063 in, aluminium sheets
    (E1 = E2 = 10.5e6 psi) and a titanium fastener (E3 = 16e6 psi): the same joints in
    mm and MPa, converted back with pint, to the digits it prints."""
    d = convert("0.1875 in", "mm", "d")
    t1, t2 = convert("0.040 in", "mm", "t1"), convert("0.063 in", "mm", "t2")
    E12, E3 = convert("10.5e6 psi", "MPa", "E1"), convert("16e6 psi", "MPa", "E3")
    C = huth_compliance(d, t1, t2, E12, E12, E3, planes, fastener)  # mm/N
    k = (1.0 / C) / unit_factor("lbf/in", "N/mm", "k")
    assert k == pytest.approx(stiffness_lbf_in, rel=1e-5)


def test_paper_pin_under_the_four_contact_models():
    """[D17]'s pin (d 10, L 20 mm, 20 kN, steel, H7/g6 at its largest clearance): the
    load-dependent part of the joint's clearance under each model. Huth's, for a clevis
    whose cheeks are each half the middle lug (t1 = L = 20, t2 = 10 mm, double shear),
    is 28.08 um: near Palmgren's 25.97 um, 2.5 times eq. 11's 11.04 um and 4.8 times the
    conforming 5.87 um - the bulk and the pin's bending that the Hertz-type models omit.
    By hand: C = (15/10)^(2/3) (3/2) (1/20 + 1/20 + 1/40 + 1/40)/2.1e5 = 1.40397e-6 mm/N."""
    lug = Lug(10.0, shear_planes=2)
    added = {}
    for model in CONTACT_MODELS:
        pin = PinJoint(10.0, 20.0, contact=model, lug=lug)
        added[model] = float(pin.clearance(20000.0) - pin.fit_clearance()) * 1e3
    C = 1.5 ** (2 / 3) * 1.5 * (0.05 + 0.05 + 0.025 + 0.025) / STEEL
    assert C == pytest.approx(1.40397e-6, rel=1e-5)
    assert added["huth"] == pytest.approx(C * 20000.0 * 1e3, rel=1e-12)
    assert added["huth"] == pytest.approx(28.08, abs=0.01)
    assert added["palmgren"] == pytest.approx(25.97, abs=0.01)
    assert added["duan2017"] == pytest.approx(11.04, abs=0.01)
    assert added["conforming"] == pytest.approx(5.87, abs=0.01)
    # the inner lug defaults to the pin's loaded length L
    assert Lug(10.0, thickness=20.0, shear_planes=2).compliance(10.0, 99.0, STEEL) == (
        pytest.approx(C, rel=1e-12)
    )
    # linear: the tangent stiffness is 1/C at any load
    pin = PinJoint(10.0, 20.0, contact="huth", lug=lug)
    assert float(pin.contact_stiffness(5000.0)) == pytest.approx(1 / C, rel=1e-12)
    # over a grid (an unloaded point too): the same stiffness at every point, finite
    grid = pin.contact_stiffness(np.array([0.0, 2500.0, -5000.0]))
    assert np.asarray(grid).shape == (3,) and np.allclose(grid, 1 / C, rtol=1e-12)


def test_casadi_matches_numpy():
    d = ca.SX.sym("d")
    expr = huth_approach(12000.0, d, 15.0, 7.0, 7.0e4, 7.2e4, STEEL, 2)
    f = ca.Function("f", [d], [expr])
    for value in (4.0, 8.0, 16.0):
        numeric = huth_approach(12000.0, value, 15.0, 7.0, 7.0e4, 7.2e4, STEEL, 2)
        assert float(f(value)) == pytest.approx(numeric, rel=1e-13)


def test_bad_inputs_name_the_field():
    with pytest.raises(InputError, match=r"materials\.lug\.cheek_thickness.*positive"):
        Lug(0.0)
    with pytest.raises(InputError, match=r"materials\.lug\.E.*positive"):
        Lug(5.0, E=-7.0e4)
    with pytest.raises(InputError, match=r"lug\.shear_planes.*1 or 2"):
        Lug(5.0, shear_planes=3)
    with pytest.raises(InputError, match=r"lug\.fastener"):
        huth_compliance(10.0, 20.0, 10.0, STEEL, STEEL, STEEL, 1, "welded")
    with pytest.raises(InputError, match=r"lug\.t2.*positive"):
        huth_compliance(10.0, 20.0, -1.0, STEEL, STEEL, STEEL)
    with pytest.raises(InputError, match=r"materials\.lug.*needs the lug"):
        PinJoint(10.0, 20.0, contact="huth")


# --- invariants -----------------------------------------------------------------------
_pos = st.floats(0.5, 50.0)
_mod = st.floats(2.0e4, 4.0e5)


@settings(max_examples=80, deadline=None)
@given(
    d=st.floats(2.0, 40.0),
    t1=_pos,
    t2=_pos,
    E1=_mod,
    E2=_mod,
    E3=_mod,
    F=st.floats(1.0, 1.0e5),
    k=st.floats(1.01, 3.0),
    fastener=st.sampled_from(tuple(HUTH_CONSTANTS)),
)
def test_invariants(d, t1, t2, E1, E2, E3, F, k, fastener):
    """Linear in F; falls with d and with each modulus; double shear stiffer than single
    (C_2 < C_1 / 2); both thicknesses scaled by k give C times k^(a - 1)."""

    def C(**change):
        args = dict(d=d, t1=t1, t2=t2, E1=E1, E2=E2, E3=E3, shear_planes=1, fastener=fastener)
        args.update(change)
        return huth_compliance(**args)

    base = C()
    approach = huth_approach(F, d, t1, t2, E1, E2, E3, 1, fastener)
    assert huth_approach(k * F, d, t1, t2, E1, E2, E3, 1, fastener) == pytest.approx(
        k * approach, rel=1e-12
    )
    assert approach == pytest.approx(base * F, rel=1e-12)
    for name in ("d", "E1", "E2", "E3"):
        assert C(**{name: k * locals()[name]}) < base, name
    assert C(shear_planes=2) < 0.5 * base
    a = HUTH_CONSTANTS[fastener][0]
    assert C(t1=k * t1, t2=k * t2) == pytest.approx(base * k ** (a - 1.0), rel=1e-12)


@settings(max_examples=80, deadline=None)
@given(
    t1=_pos,
    t2=_pos,
    planes=st.sampled_from((1, 2)),
    fastener=st.sampled_from(tuple(HUTH_CONSTANTS)),
)
def test_thickness_helps_only_below_a_ratio(t1, t2, planes, fastener):
    """A single thickness is not monotone: the factor ((t1 + t2)/(2d))^a (the pin's
    bending over a longer span) outgrows the bearing terms once that member is much the
    thicker. With equal moduli, C falls with t1 iff a r (n + r) < n (1 + r), r = t1/t2,
    and with t2 iff a s (n s + 1) < 1 + s, s = t2/t1 (from dC/dt = 0); e.g. a bolted
    double-shear clevis gets more compliant with thicker cheeks once they exceed the
    middle lug (s > 1)."""
    a = HUTH_CONSTANTS[fastener][0]
    n = planes
    base = huth_compliance(10.0, t1, t2, STEEL, STEEL, STEEL, n, fastener)
    r, s = t1 / t2, t2 / t1
    for which, margin in (
        ("t1", n * (1 + r) - a * r * (n + r)),
        ("t2", (1 + s) - a * s * (n * s + 1)),
    ):
        if abs(margin) < 1e-3 * (1 + r + s) ** 2:
            continue  # at the turning point the sign is round-off
        h = 1e-4 * (t1 if which == "t1" else t2)
        args = dict(t1=t1 + h, t2=t2) if which == "t1" else dict(t1=t1, t2=t2 + h)
        moved = huth_compliance(10.0, args["t1"], args["t2"], STEEL, STEEL, STEEL, n, fastener)
        assert (moved < base) == (margin > 0), (which, r, s)


# --- in a problem ---------------------------------------------------------------------
def _fin(model: str, lug: dict | None) -> dict:
    data = tomllib.loads(FIN.read_text())
    data["requirements"]["pin_contact"] = model
    if lug is not None:
        data.setdefault("materials", {})["lug"] = lug
    return data


def test_file_inputs_with_units_and_their_errors():
    data = _fin("huth", {"cheek_thickness": "0.2 in", "E": "70 GPa", "fastener": "bolted"})
    problem = problem_from_dict(data, bare="refuse")
    lug = problem.spec.materials.lug
    assert lug.cheek_thickness == pytest.approx(5.08, rel=1e-12)
    assert lug.E == pytest.approx(7.0e4, rel=1e-12)
    q = problem.quantities(problem.design_dict(problem.midpoint()))
    pin = q.pin
    # the crank-slider's rod pins are in double shear (pin_shear_planes = 2); the middle
    # lug is the pin's loaded length L = 1.5 d; the cheeks' modulus is the lug's
    assert pin.lug.shear_planes == 2 and pin.lug.thickness is None
    expected = huth_compliance(pin.d, pin.L, 5.08, 7.0e4, 7.0e4, STEEL, 2)
    assert float(pin.lug_compliance()) == pytest.approx(expected, rel=1e-12)
    with pytest.raises(ProblemError, match=r"materials\.lug: pin_contact \"huth\" needs"):
        problem_from_dict(_fin("huth", None))
    with pytest.raises(ProblemError, match=r"materials\.lug\.cheek_thickness: missing"):
        problem_from_dict(_fin("huth", {"thickness": "9 mm"}))
    with pytest.raises(ProblemError, match=r"materials\.lug\.thickness: must be positive"):
        problem_from_dict(_fin("huth", {"cheek_thickness": "5 mm", "thickness": "0 mm"}))
    with pytest.raises(ProblemError, match=r"materials\.lug\.cheek_thickness.*5 mm"):
        problem_from_dict(_fin("huth", {"cheek_thickness": "5 N"}))
    with pytest.raises(ProblemError, match=r"materials\.lug\.fastener"):
        problem_from_dict(_fin("huth", {"cheek_thickness": "5 mm", "fastener": "glued"}))


def _fin_backlash_at_optimum(data: dict) -> float:
    problem = problem_from_dict(data)
    design = dict(R=105.571, l=59.7942, n=102.087, phi0=math.radians(13.132), d0=25, p=5, d=6)
    x = np.array([design[v.name] for v in problem.free], dtype=float)
    return float(np.ravel(problem.evaluate(x).objectives["backlash"])[0])


def test_spread_shows_huth_or_why_not(fin_lug_optimum):
    """Without [materials.lug] the spread says why Huth's model has no value; with it,
    Huth's backlash at the optimum equals the file written with that model."""
    from optdesign.studies.contact_spread import contact_model_spread

    data = _fin("duan2017", {"cheek_thickness": "5 mm"})
    _, result = fin_lug_optimum
    line = next(n for n in result.notes if n.startswith("backlash by pin contact model"))
    # the shipped file (no lug) at the same design: Huth's model says what it lacks
    bare = contact_model_spread(load_problem(FIN), result.design)
    assert 'huth n/a (materials.lug: pin_contact "huth" needs the lug' in bare
    shown = float(line.split("huth ")[1].split(" deg")[0])
    assert shown == pytest.approx(
        _fin_backlash_at_optimum(_fin("huth", data["materials"]["lug"])), rel=2e-5
    )
    assert shown == pytest.approx(0.0422825, rel=1e-5)


def test_gp_form_with_fixed_thicknesses_and_its_refusal():
    """Fixed lug thicknesses make Huth's approach a monomial in d (C ~ d^-a): the fixed-
    linkage crank-slider stays a GP and its GP optimum equals the NLP's. With the inner
    lug at L = 1.5 d the factor (t1 + t2)^a is a power of a sum: the diagnosis names it."""
    from programs.test_gp import CS_FIXED

    from optdesign.formulations.gp.solve import solve_gp_problem

    data = copy.deepcopy(CS_FIXED)
    data["requirements"]["pin_contact"] = "huth"
    data["materials"] = {"lug": {"thickness": "12 mm", "cheek_thickness": "6 mm"}}
    problem = problem_from_dict(data)
    gp = build_gp(problem)
    assert gp.is_gp, gp.explain()
    r = solve_gp_problem(problem, nlp_starts=2)
    assert r.status == "optimal"
    assert abs(r.details.gp.gap_gp_nlp_rel) < 1e-3
    data["materials"] = {"lug": {"cheek_thickness": "6 mm"}}
    gp = build_gp(problem_from_dict(data))
    assert not gp.is_gp
    bad = {c.name: c for c in gp.failures()}
    assert "power of a sum" in bad["backlash"].reason and "d" in bad["backlash"].term


def test_contact_model_is_refused_by_name():
    with pytest.raises(OptDesignError, match=r"requirements\.pin_contact"):
        problem_from_dict(_fin("tate", None))


@pytest.mark.parametrize("json_mode", [False, True])
def test_spread_on_the_command_line(tmp_path, json_mode):
    """A file with [materials.lug] (units as a user writes them): Huth's backlash in the
    summary's note, in the default output and in --json."""
    text = FIN.read_text().replace(
        "[screw]", '[materials.lug]\ncheek_thickness = "5 mm"\n\n[screw]', 1
    )
    path = tmp_path / "fin_lug.toml"
    path.write_text(text)
    args = [sys.executable, "-m", "optdesign", "solve", str(path), "--contact-models"]
    args += ["--no-ranges", "--out", str(tmp_path / "out")] + (["--json"] if json_mode else [])
    run = subprocess.run(args, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    notes = json.loads(run.stdout)["notes"] if json_mode else [run.stdout]
    line = next(n for n in notes if "backlash by pin contact model" in n)
    value = float(re.search(r"huth ([0-9.]+) deg", line).group(1))
    assert value == pytest.approx(0.0422825, rel=1e-5)
    assert "palmgren 0.0441218 deg" in line
