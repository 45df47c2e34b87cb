"""The models' ranges of validity (issue "No answer that cannot be true", item 1): declared
once per model (``VALIDITY`` of each module of optdesign/models), held at the problem
file's fields when it is read, and checked on every result - a design outside a model's
range is never "optimal; verified", through the API and both output modes of the command
line. The corpus of impossible-but-in-range inputs is tests/validity_corpus.py.
"""

from __future__ import annotations

import copy
import importlib
import json
import math
import time
import tomllib
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hostile_corpus import dumps, run_main
from hypothesis import given, settings
from hypothesis import strategies as st
from validity_corpus import all_cases, flagged_cases, refused_cases, run_case

import optdesign as od
from optdesign.errors import ProblemError
from optdesign.models import validity_registry
from optdesign.models.clearance import BACKLASH
from optdesign.models.hertz_line import HALF_WIDTH_RATIO
from optdesign.models.loads import PIN_LENGTH_OVER_SIZE, PIN_SLENDERNESS
from optdesign.models.validity import ELASTIC_MODULUS, Validity
from optdesign.reports.result_json import result_document
from optdesign.studies.verify import is_validity, verify_design

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"


def _shipped(stem: str) -> dict:
    return tomllib.loads((PROBLEMS / f"{stem}.toml").read_text())


def _cs(**edits) -> dict:
    """cs_min_backlash with ``edits`` ("section.key" -> value; "materials.lug" a table)."""
    data = _shipped("cs_min_backlash")
    for path, value in edits.items():
        d = data
        keys = path.split("__")
        for k in keys[:-1]:
            d = d.setdefault(k, {})
        if value is None:
            d.pop(keys[-1], None)
        else:
            d[keys[-1]] = value
    return data


#: The issue's four impossible inputs: (problem, the field a refusal names, the range).
ISSUE_CASES = {
    "a lug 1e-9 mm thick": (
        _cs(requirements__pin_contact="huth", materials__lug={"cheek_thickness": "1e-9 mm"}),
        "materials.lug.cheek_thickness",
        "[0.001 mm, 1000 mm]",
    ),
    "a lug modulus of 1e-6 MPa": (
        _cs(
            requirements__pin_contact="huth",
            materials__lug={"cheek_thickness": "5 mm", "E": "1e-6 MPa"},
        ),
        "materials.lug.E",
        "[100 MPa, 1.2e+06 MPa]",
    ),
    "a fixed clearance of 1 km": (_cs(clearances__A="1 km"), "clearances.A", "[0 mm, 1 mm]"),
    "a pin length ratio of 1e9": (
        _cs(variables__pin_length_ratio=1e9),
        "variables.pin_length_ratio",
        "[0.2, 5]",
    ),
}

#: In range, impossible as a design: cheeks of 1 um around pins of 4 to 30 mm (Huth's t/d
#: of 0.2 to 2 left, and a backlash of tens of degrees).
THIN_CHEEKS = _cs(requirements__pin_contact="huth", materials__lug={"cheek_thickness": "1 um"})


# --- declared once per model ---------------------------------------------------------------
def test_every_model_declares_its_ranges_once_and_says_why():
    modules = {p.stem for p in (ROOT / "optdesign" / "models").glob("*.py")}
    assert set(validity_registry.MODEL_MODULES) == modules - {
        "__init__",
        "_checks",
        "validity_registry",
    }
    ranges = validity_registry.declared_ranges()
    for module in validity_registry.MODEL_MODULES:
        own = validity_registry.ranges_of(module)
        assert own, f"optdesign/models/{module}.py declares no range of validity"
        doc = importlib.import_module(f"optdesign.models.{module}").__doc__
        assert "Validity\n--------" in doc, f"{module}: no Validity section in its docstring"
        for record in own:
            assert ranges[record.name] is record
            assert record.why.strip() and record.model and record.quantity
    # docs/validity.md tables every range by its name
    page = (ROOT / "docs" / "validity.md").read_text()
    missing = [name for name in ranges if f"`{name}`" not in page]
    assert not missing, missing


def test_a_range_says_whether_a_value_lies_in_it_and_why_not():
    r = Validity("x.y", "a model", "a quantity", 0.0, 5.0, "deg", "small angles", open_lower=True)
    assert r.contains(np.array([1e-9, 5.0])).all()
    assert not r.contains(0.0) and not r.contains(5.0 + 1e-12) and not r.contains(math.nan)
    assert r.excess(6.0) == pytest.approx(0.2) and r.excess(math.nan) == math.inf
    assert r.range_text() == "(0 deg, 5 deg]"
    assert r.outside_text(12.9e6) == "1.29e+07 deg > 5 deg"
    assert r.outside_text(0.0) == "0 deg <= 0 deg"
    assert r.refusal(7.0) == "7 deg is outside (0 deg, 5 deg] (a model: small angles)"
    assert ELASTIC_MODULUS.range_text() == "[100 MPa, 1.2e+06 MPa]"
    with pytest.raises(ValueError, match="say why"):
        Validity("x.z", "m", "q", 0.0, 1.0, "", " ")


# --- the issue's impossible inputs: refused when read ----------------------------------------
@pytest.mark.parametrize("case", list(ISSUE_CASES))
def test_the_issues_impossible_inputs_are_refused_by_od_load(case):
    data, field, bounds = ISSUE_CASES[case]
    with pytest.raises(ProblemError) as err:
        od.load(copy.deepcopy(data))
    message = str(err.value)
    assert field in message and bounds in message and "is outside" in message
    assert "\n" not in message


@pytest.mark.parametrize("json_mode", [False, True])
@pytest.mark.parametrize("case", list(ISSUE_CASES))
def test_the_issues_impossible_inputs_are_refused_on_the_command_line(case, json_mode, tmp_path):
    data, field, bounds = ISSUE_CASES[case]
    path = tmp_path / "problem.toml"
    path.write_text(dumps(data))
    argv = ["solve", str(path), "--starts", "1", "--no-ranges"]
    argv += ["--json"] if json_mode else ["--no-plot", "--out", str(tmp_path / "out")]
    code, out, err, _ = run_main(argv)
    assert code == 2 and out == ""
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and field in lines[0] and bounds in lines[0], err


def test_a_file_value_outside_a_models_range_names_the_field_and_the_range():
    """Each kind of field the models read: a material, a lug, a clearance, a pin variable,
    its bounds, a reference design, the backlash requirement, a drive member."""
    cases = [
        (_cs(materials__pin__E="50 MPa"), "materials.pin.E: 50 MPa is outside [100 MPa"),
        (_cs(clearances__O="6 deg"), "clearances.O: 6 deg is outside [0 deg, 5 deg]"),
        (_cs(variables__d={"lower": "4 mm", "upper": "1 m"}), "variables.d.upper: 1000 mm"),
        (_cs(requirements__backlash_max="10 deg"), "backlash_max: 10 deg is outside [0 deg, 5"),
        (
            _cs(variables__pin_length_ratio=None, variables__pin_length="3 m"),
            "variables.pin_length: 3000 mm is outside [0.02 mm, 2500 mm]",
        ),
    ]
    ref = _shipped("duan2017_redesign")
    ref["reference"]["d"] = "0.01 mm"
    cases.append((ref, "reference.d: 0.01 mm is outside [0.1 mm, 500 mm]"))
    for data, expected in cases:
        with pytest.raises(ProblemError, match=expected.replace("[", r"\[").replace(".", r"\.")):
            od.load(data)


# --- in range, outside as a design: flagged, never verified ---------------------------------
@pytest.fixture(scope="module")
def thin_cheeks():
    return od.solve(od.load(copy.deepcopy(THIN_CHEEKS)), starts=1, ranges=False)


def test_a_design_outside_a_models_range_is_never_optimal_nor_verified(thin_cheeks):
    r = thin_cheeks
    assert not r.success and r.status == "infeasible" and r.verified is False
    outside = {x.name.split("[")[0] for x in r.violated if is_validity(x)}
    assert "validity: small-angle clearance: worst-case backlash" in outside
    assert "validity: Huth's lug flexibility: thickness over pin diameter t/d, cheeks" in outside
    backlash = next(
        x for x in r.violated if x.name.startswith("validity: small-angle clearance: w")
    )
    assert backlash.value > 5.0 and backlash.upper == 5.0 and backlash.unit == "deg"
    feasible = next(ln for ln in r.summary().splitlines() if ln.startswith("feasible"))
    assert "NOT verified: the design lies outside the range where its models hold" in feasible
    assert "small-angle clearance: worst-case backlash" in feasible and "> 5 deg" in feasible
    # no relaxation of a requirement is offered for it: the note names the models instead
    assert not r.diagnosis.relaxations and "small-angle clearance" in r.diagnosis.note
    doc = result_document(r)
    assert doc["verified"] is False and doc["validity"]["within"] is False
    models = {e["model"] for e in doc["validity"]["outside"]}
    assert models == {"small-angle clearance", "Huth's lug flexibility"}
    assert all(e["why"] for e in doc["validity"]["outside"])


def test_a_verified_result_says_its_models_hold():
    r = od.solve(od.load(_shipped("cs_min_backlash")), starts=1, ranges=False)
    assert r.success and r.verified
    assert "every model within its range of validity" in r.summary().splitlines()[2]
    assert result_document(r)["validity"] == {"within": True, "outside": []}


@pytest.mark.parametrize("json_mode", [False, True])
def test_the_command_line_says_the_design_lies_outside_its_models_range(json_mode, tmp_path):
    path = tmp_path / "problem.toml"
    path.write_text(dumps(THIN_CHEEKS))
    argv = ["solve", str(path), "--starts", "1", "--no-ranges"]
    argv += ["--json"] if json_mode else ["--no-plot", "--out", str(tmp_path / "out")]
    code, out, err, _ = run_main(argv)
    assert code == 1, err
    if json_mode:
        doc = json.loads(out)
        assert doc["status"] == "infeasible" and doc["verified"] is False
        assert doc["validity"]["within"] is False
        assert any(v["name"].startswith("validity: small-angle") for v in doc["violated"])
    else:
        assert "feasible  NOT verified: the design lies outside the range where" in out
        assert "small-angle clearance: worst-case backlash" in out
        assert "optimal" not in out.splitlines()[1]


def test_a_failed_solve_names_the_models_its_best_point_leaves():
    """A lead angle of a helical cam: the solver finds no feasible design, and the best
    point's rows say which model it left, not only which requirement."""
    data = _cs(variables__d0={"lower": "0.2 mm", "upper": "0.5 mm"})
    data["screw"] = {"kind": "ball", "friction": 0.005}
    r = od.solve(od.load(data), starts=1, ranges=False)
    assert not r.success and r.verified is False
    assert any(x.name == "validity: screw efficiency: lead angle" for x in r.violated)


# --- property: nothing verified lies outside a declared range -------------------------------
def _variant(stem: str, kind: str) -> dict:
    data = _shipped(stem)
    req = data["requirements"]
    if kind in ("open", "soft", "long", "play"):
        # the models kept, the requirements that rarely hold at a random design dropped
        keep = {"deflection", "hinge_moment", "fit", "fit_clearance", "pin_shear_planes"}
        data["requirements"] = {k: v for k, v in req.items() if k in keep}
        data.pop("screw", None)
        data["variables"].pop("d0", None)
        for name in ("p", "d"):  # continuous: the catalogues belong to the screw and pins
            v = data["variables"].get(name)
            if isinstance(v, dict) and "catalogue" in v:
                data["variables"][name] = {"lower": v["lower"], "upper": v["upper"]}
    data.pop("tolerances", None)
    if kind == "soft":  # a polymer pin: within its input range, often beyond Hertz's
        data.setdefault("materials", {})["pin"] = {"E": "300 MPa", "nu": 0.4}
    if kind == "long":  # the longest pins allowed, on the smallest linkages
        data["variables"]["pin_length_ratio"] = 5
    if kind == "play":  # an output shaft's play near the small-angle limit
        data["clearances"] = {"O": "4.97 deg"}
    return data


VARIANTS = [
    (stem, kind)
    for stem in (
        "cs_min_backlash",
        "cs_min_backlash_catalogue",
        "duan2017_redesign",
        "fin_actuator",
        "fork_min_backlash",
        "pivot_min_backlash",
    )
    for kind in ("shipped", "open", "soft", "long", "play")
]


@cache
def _problem(stem: str, kind: str):
    return od.load(_variant(stem, kind))


def _by_hand(problem, x: np.ndarray) -> dict:
    """The bounded quantities of design ``x`` from the problem's public quantities and
    [D17] eq. 10 written out here: L/d, L/size, b/(d/2), worst-case backlash."""
    q = problem.quantities(problem.design_dict(x))
    d = float(q.design["d"])
    L = float(q.design.get("pin_length", q.design.get("pin_length_ratio", 0.0) * d))
    mat = problem.spec.materials.pin
    with np.errstate(all="ignore"):  # a design that does not assemble: NaN, outside
        F = np.abs(np.asarray(q.pin_force, dtype=float))
        b = np.sqrt(4.0 * d * (F / L) * (1.0 - mat.nu**2) / (math.pi * mat.E))
        ev = problem.evaluate(x)
    return {
        PIN_SLENDERNESS: L / d,
        PIN_LENGTH_OVER_SIZE: L / float(ev.objectives["size"]),
        HALF_WIDTH_RATIO: float(np.max(b)) / (0.5 * d),
        BACKLASH: float(ev.objectives["backlash"]),
    }


@settings(max_examples=150)
@given(
    variant=st.sampled_from(VARIANTS),
    u=st.lists(st.floats(0.0, 1.0), min_size=10, max_size=10),
)
def test_no_verified_design_lies_outside_a_declared_range(variant, u):
    """Random designs inside the bounds of the shipped problems (and of variants with a
    soft pin, the longest pins, an output play near the limit, the requirements that
    rarely hold dropped): a design the independent check verifies has every quantity
    computed by hand inside its range, and a design with one outside is not verified
    and names that model."""
    problem = _problem(*variant)
    x = []
    for k, v in enumerate(problem.free):
        value = v.lower + u[k] * (v.upper - v.lower)
        if v.values is not None:
            value = min(v.values, key=lambda c: abs(c - value))
        x.append(value)
    x = np.array(x)
    ok, violated, _ = verify_design(problem, x)
    named = {r.name.split("[")[0].split(",")[0] for r in violated if is_validity(r)}
    for record, value in _by_hand(problem, x).items():
        inside = bool(record.contains(value))
        if ok:
            assert inside, (variant, record.name, value)
        if not inside:
            assert not ok, (variant, record.name, value)
            assert f"validity: {record.model}: {record.quantity}" in named, (record.name, named)


# --- the corpus ----------------------------------------------------------------------------
def test_the_corpus_has_a_hundred_cases_of_each_kind_of_assumption():
    cases = all_cases()
    assert len(cases) >= 100 and len({c.name for c in cases}) == len(cases)
    assert len(refused_cases()) >= 60 and len(flagged_cases()) >= 25


def test_every_impossible_input_of_the_corpus_ends_cleanly():
    """Refused when read with the field and the range named, or solved into a result
    flagged outside the model's range (never a success); the whole corpus in under a
    minute."""
    t0 = time.perf_counter()
    verdicts = [run_case(c) for c in all_cases()]
    seconds = time.perf_counter() - t0
    bad = [f"{v.name}: {v.verdict}: {v.message[:200]}" for v in verdicts if v.verdict != "clean"]
    assert not bad, "\n".join(bad)
    print(f"validity corpus: {len(verdicts)} cases clean in {seconds:.1f} s")
    assert seconds < 60
