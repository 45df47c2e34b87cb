"""Quantities at the input boundary: the restricted grammar, spellings, angle fields,
non-finite numbers, pint Quantity objects, the bare-number policy."""

from __future__ import annotations

import contextlib
import io
import json
import math
import re
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hostile_corpus import PROBLEMS, dumps
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from units_corpus import (
    API_RIGHT,
    API_WRONG,
    RIGHT,
    WRONG,
    FieldCase,
    load_dict,
    load_file,
    read_back,
    run_api,
    run_cli,
    with_value,
)

import optdesign as od
from optdesign import units
from optdesign.cli import main
from optdesign.errors import InputError, OptDesignError
from optdesign.problem import load_problem
from optdesign.units import (
    FAST_UNITS,
    INTERNAL_UNITS,
    SUGGESTED_UNITS,
    angle_exponent,
    convert,
    parse,
    registry,
    to_internal,
    unit_factor,
)

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module", autouse=True)
def _registry_built():
    registry()  # built once (~0.5 s), outside the timings below


@pytest.mark.parametrize(
    ("text", "dimension", "expected"),
    [
        ("500 N*m", "moment", 500e3),
        ("500 Nm", "moment", 500e3),  # pint alone reads "number metre"
        ("0.5 kNm", "moment", 500e3),
        ("500 N.m", "moment", 500e3),
        ("500 N·m", "moment", 500e3),
        ("500 N m", "moment", 500e3),
        ("500000 Nmm", "moment", 500e3),
        ("12 um", "length", 0.012),
        ("12 µm", "length", 0.012),  # micro sign
        ("12 μm", "length", 0.012),  # Greek mu
        ("90 mm", "length", 90.0),
        ("90*mm", "length", 90.0),
        ("-1.5e1 mm", "length", -15.0),
        (".5 m", "length", 500.0),
        ("30 °", "angle", math.radians(30)),
        ("30°", "angle", math.radians(30)),
        ("30 deg", "angle", math.radians(30)),
        ("30 degree", "angle", math.radians(30)),
        ("1 turn", "angle", 2 * math.pi),
        ("1 rev", "angle", 2 * math.pi),
        ("100 grad", "angle", math.pi / 2),
        ("60 arcmin", "angle", math.radians(1)),
        ("3600 arcsec", "angle", math.radians(1)),
        ("5 %", "dimensionless", 0.05),
        ("200 N/mm^2", "pressure", 200.0),
        ("200 N/mm**2", "pressure", 200.0),
        ("200 N/mm²", "pressure", 200.0),
        ("200 N/(mm*mm)", "pressure", 200.0),
        ("2 kN/mm", "stiffness", 2000.0),
        ("3000 rpm", "speed", 3000.0),  # turns per minute, not 2*pi*3000
        ("3000 1/min", "speed", 3000.0),
        ("50 1/s", "speed", 3000.0),
        ("3 h", "time", 3.0),
        ("90", "length", 90.0),  # bare: internal unit (today's default)
    ],
)
def test_spellings(text, dimension, expected):
    assert to_internal(text, dimension, "f") == pytest.approx(expected, rel=1e-12)


def test_percent_is_not_an_angle_and_an_angle_is_not_a_plain_number():
    # pint treats percent as dimensionless, like rad: a 5 % deflection would be 0.05 rad
    with pytest.raises(InputError) as info:
        to_internal("5 percent", "angle", "requirements.phi_max")
    assert str(info.value) == (
        "requirements.phi_max: '5 percent' is a plain number, expected an angle "
        '(write e.g. "5 deg"; angle units: rad, deg, arcmin, arcsec, turn, grad)'
    )
    with pytest.raises(InputError, match="phi_max: '5 %' is a plain number, expected an angle"):
        to_internal("5 %", "angle", "phi_max")
    with pytest.raises(InputError) as info:
        to_internal("30 deg", "dimensionless", "i_a")
    assert str(info.value) == "i_a: '30 deg' is an angle, expected a plain number (no unit, or %)"
    with pytest.raises(InputError, match=r"'2 rad[*]rad' is angle\^2, expected an angle"):
        to_internal("2 rad*rad", "angle", "phi")


def test_wrong_dimension_names_the_field_and_what_to_write():
    with pytest.raises(InputError) as info:
        to_internal("500 mm", "moment", "requirements.hinge_moment")
    assert str(info.value) == (
        "requirements.hinge_moment: '500 mm' is a length, expected a moment "
        '(write e.g. "500 N*m")'
    )


def test_arithmetic_is_refused_at_once():
    for text in ("10**10**10 mm", "10**10**10", "2**2048 mm", "(10**10)**10 mm", "1e3*1e3 mm"):
        t0 = time.perf_counter()
        with pytest.raises(InputError, match=r"quantity|no arithmetic"):
            to_internal(text, "length", "variables.R.upper")
        # pint itself hangs on the first one; the bound catches a hang, not a slow machine
        assert time.perf_counter() - t0 < 1.0


@pytest.mark.parametrize(
    "value", ["nan mm", "NaN", "inf", "-inf mm", "1e999 mm", float("nan"), float("inf"), -math.inf]
)
def test_non_finite_numbers_are_refused(value):
    with pytest.raises(InputError, match=r"^x: .*(finite|must start with a number)"):
        to_internal(value, "length", "x")


@pytest.mark.parametrize(
    "text",
    [
        "",
        "mm",
        "90 furlongs_of_cheese",
        "90 mm2",
        "90 mm^99",
        "90 (((((mm)))))",
        "90 mm)",
        "90 (mm",
        "90 mm; rm -rf",
        "__import__('os')",
        "90 mm**x",
        "1,5 mm",
        "90 mm * ",
        "0x10 mm",
        "True",
        "2**mm",
        "2 * * mm",
    ],
)
def test_malformed_strings_are_refused_with_the_field(text):
    with pytest.raises(InputError, match=r"^variables\.R: "):
        to_internal(text, "length", "variables.R")


@pytest.mark.parametrize(
    ("text", "digit"),
    [
        ("11\u0660 mm", "'\u0660' (U+0660 ARABIC-INDIC DIGIT ZERO)"),  # read as 110 mm before
        ("\u0661\u0662 mm", "'\u0661' (U+0661 ARABIC-INDIC DIGIT ONE)"),
        ("1\u06f0", "'\u06f0' (U+06F0 EXTENDED ARABIC-INDIC DIGIT ZERO)"),
        ("\uff15\uff10 mm", "'\uff15' (U+FF15 FULLWIDTH DIGIT FIVE)"),
        ("1e\u0661 mm", "'\u0661' (U+0661 ARABIC-INDIC DIGIT ONE)"),
        ("5 mm^\u0662", "'\u0662' (U+0662 ARABIC-INDIC DIGIT TWO)"),
    ],
)
def test_digits_of_another_script_are_refused_naming_the_field_and_the_digit(text, digit):
    """float() and re's \\d read any script's decimal digits: "11\u0660 mm" was 110 mm."""
    with pytest.raises(InputError) as err:
        to_internal(text, "length", "variables.R.upper")
    assert str(err.value).startswith(
        f"variables.R.upper: {text!r} has the digit {digit}: write numbers with the digits 0-9"
    )


def test_superscript_powers_are_not_digits_of_another_script():
    assert to_internal("2 N/mm\u00b2", "pressure", "x") == pytest.approx(2.0)


def test_pint_quantities_are_accepted():
    ureg = registry()
    assert to_internal(ureg.Quantity(500, "N*m"), "moment", "m") == pytest.approx(5e5)
    import pint

    other = pint.UnitRegistry()  # a user's own registry
    assert to_internal(other.Quantity(30, "deg"), "angle", "a") == pytest.approx(math.radians(30))
    with pytest.raises(InputError, match="is a plain number, expected an angle"):
        to_internal(other.Quantity(5, "percent"), "angle", "a")
    with pytest.raises(InputError, match="is a length, expected a force"):
        to_internal(other.Quantity(5, "mm"), "force", "F")
    with pytest.raises(InputError, match="is a moment per angle, expected a moment"):
        to_internal(other.Quantity(5, "N*m/deg"), "moment", "M")
    with pytest.raises(InputError, match="finite"):
        to_internal(other.Quantity(math.nan, "mm"), "length", "L")


def test_bare_number_policy():
    assert to_internal(300, "moment", "hinge_moment") == 300.0  # default: internal units
    for value in (300, "300", 300.0):
        with pytest.raises(InputError) as info:
            to_internal(value, "moment", "hinge_moment", bare="refuse")
        assert str(info.value) == 'hinge_moment: 300 has no unit; write "300 N*m"'
    with pytest.raises(InputError, match=r'write "2\.5 deg"'):
        to_internal("2.5", "angle", "phi", bare="refuse")
    assert to_internal(0, "length", "offset", bare="refuse") == 0.0  # zero may stay bare
    assert to_internal("0", "length", "offset", bare="refuse") == 0.0
    assert to_internal(3, "dimensionless", "i_a", bare="refuse") == 3.0
    assert to_internal("300 N*m", "moment", "m", bare="refuse") == pytest.approx(3e5)
    assert set(SUGGESTED_UNITS) == set(INTERNAL_UNITS)


def test_importing_the_module_does_not_import_pint():
    code = "import sys, optdesign.units; print('pint' in sys.modules)"
    res = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=60
    )
    assert res.stdout.strip() == "False", res.stderr


# --- fuzz ----------------------------------------------------------------------------------
_ALPHABET = st.sampled_from([*"0123456789+-.eE*/^()% °µ·mkNMPadgrsinhutx", "**", " "])


def _only_input_errors(text, dimension):
    # pint's registry is built on first use (the shipped files never need it): build it
    # before timing, so that the bound below measures the parsing of ``text`` alone
    from optdesign.units import registry

    registry()
    t0 = time.perf_counter()
    try:
        value = to_internal(text, dimension, "fuzz")
    except InputError as exc:
        assert exc.field == "fuzz"
    else:
        assert math.isfinite(value)
    assert time.perf_counter() - t0 < 1.0  # a hang, not a timing: a loaded machine may pause a case


@settings(
    max_examples=200,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(text=st.text(max_size=40), dimension=st.sampled_from(sorted(INTERNAL_UNITS)))
def test_fuzz_any_text_raises_only_input_error_quickly(text, dimension):
    _only_input_errors(text, dimension)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(
    parts=st.lists(_ALPHABET, max_size=25),
    dimension=st.sampled_from(sorted(INTERNAL_UNITS)),
)
def test_fuzz_quantity_like_text_raises_only_input_error_quickly(parts, dimension):
    _only_input_errors("".join(parts), dimension)


_UNITS = [
    ("mm", "length", 1.0),
    ("m", "length", 1000.0),
    ("um", "length", 1e-3),
    ("N", "force", 1.0),
    ("kN", "force", 1000.0),
    ("MPa", "pressure", 1.0),
    ("GPa", "pressure", 1000.0),
    ("N*m", "moment", 1000.0),
    ("Nmm", "moment", 1.0),
    ("deg", "angle", math.pi / 180),
    ("rad", "angle", 1.0),
    ("N/mm", "stiffness", 1.0),
    ("h", "time", 1.0),
    ("min", "time", 1 / 60),
]


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    number=st.floats(min_value=-1e12, max_value=1e12, allow_nan=False),
    unit=st.sampled_from(_UNITS),
    space=st.sampled_from(["", " ", "  "]),
)
def test_fuzz_valid_quantities_convert_exactly(number, unit, space):
    from optdesign.units import MIN_MAGNITUDE

    name, dimension, factor = unit
    text = f"{number!r}{space}{name}"
    if 0 < abs(number * factor) < MIN_MAGNITUDE * (1 - 1e-9):
        # below the smallest magnitude a model survives (1e-300 mm overflows a quotient)
        with pytest.raises(InputError, match="out of range"):
            to_internal(text, dimension, "f")
        return
    if abs(number * factor) < MIN_MAGNITUDE * (1 + 1e-9) and number:
        return  # at the floor itself the unit's rounding decides
    got = to_internal(text, dimension, "f")
    assert got == pytest.approx(number * factor, rel=1e-12, abs=1e-300)


# The table of common units (read without pint) against pint's own conversion.


CASES = [(dim, unit) for dim, table in FAST_UNITS.items() for unit in table]


@pytest.mark.parametrize(("dimension", "unit"), CASES)
def test_fast_table_agrees_with_pint(dimension, unit):
    for number in (1.0, 37.5, -0.25):
        fast = to_internal(f"{number} {unit}", dimension, "x")
        parsed = units.parse(f"1 {unit}")
        q = registry().Quantity(number, parsed.unit)
        slow = units._convert(q, parsed.angle, unit, dimension, "x")
        assert math.isclose(fast, slow, rel_tol=1e-14), (unit, fast, slow)


def test_fast_path_leaves_errors_to_pint():
    # A unit of the wrong dimension is not in that dimension's table: pint's message.
    with pytest.raises(units.InputError, match="expected a length"):
        to_internal("3 N", "length", "R")
    assert units._fast_internal("1e999 mm", "length") is None
    # Beyond MAX_MAGNITUDE (1e15) the fast path steps aside and the range is refused.
    assert units._fast_internal("1e308 mm", "length") is None
    assert units._fast_internal("2e12 m", "length") is None  # 2e15 mm
    assert units._fast_internal("1e15 mm", "length") == 1e15
    with pytest.raises(units.InputError, match="out of range"):
        to_internal("1e308 mm", "length", "R.upper")
    assert units._fast_internal("3 mm", "force") is None
    assert units._fast_internal("3 mm mm", "length") is None


def test_problem_file_loads_without_pint(tmp_path):
    import subprocess
    import sys

    code = (
        "import sys; from optdesign.problem.load import load_problem; "
        "load_problem('problems/cs_min_backlash.toml'); "
        "print('pint' in sys.modules)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        cwd=Path(__file__).resolve().parents[1],
    ).stdout
    assert out.strip() == "False"


@pytest.mark.parametrize(("dimension", "unit"), CASES)
def test_report_unit_table_equals_pint(dimension, unit):
    # A report shows a value in the unit the file wrote it in; the common units convert
    # without pint, and must give pint's number bit for bit (or leave it to pint).
    from optdesign.display.shown import _DIMENSION_UNITS, _shown_factor

    factor = _shown_factor(dimension, unit)
    for value in (1.0, 37.5, -0.25, 0.1, 1234.5678, 0.5235987755982988):
        try:
            q = registry().Quantity(value, _DIMENSION_UNITS[dimension]).to(unit)
        except Exception:
            assert factor is None, unit  # pint cannot: the report falls back, as before
            continue
        if factor is not None:
            assert value * factor == float(q.magnitude), (unit, value)


# Angles as a dimension of their own (issue 21, class 5): a quantity is checked by pint's
# dimensionality and by its angle exponent, on the file path, the CLI (both output modes)
# and the Python API; negative exponents and quotients read the same every run.
#
# The corpus is tests/units_corpus.py (``python tests/units_corpus.py`` prints its counts).


DEG = math.pi / 180.0


def _dotted(path) -> str:
    # a list's item as the loader names it: duty_cycle[0].hinge_moment
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path).lstrip(".")


# --- property tests (derandomised: the same examples every run) ----------------------------
#: Unit names with their angle exponent and dimension, written out here (not from pint).
_ATOMS = [
    ("mm", 0, {"[length]": 1}),
    ("m", 0, {"[length]": 1}),
    ("um", 0, {"[length]": 1}),
    ("N", 0, {"[mass]": 1, "[length]": 1, "[time]": -2}),
    ("kN", 0, {"[mass]": 1, "[length]": 1, "[time]": -2}),
    ("Nm", 0, {"[mass]": 1, "[length]": 2, "[time]": -2}),
    ("MPa", 0, {"[mass]": 1, "[length]": -1, "[time]": -2}),
    ("s", 0, {"[time]": 1}),
    ("min", 0, {"[time]": 1}),
    ("h", 0, {"[time]": 1}),
    ("Hz", 0, {"[time]": -1}),
    ("%", 0, {}),
    ("rad", 1, {}),
    ("deg", 1, {}),
    ("°", 1, {}),
    ("mrad", 1, {}),
    ("arcmin", 1, {}),
    ("arcsec", 1, {}),
    ("turn", 1, {}),
    ("rev", 1, {}),
    ("grad", 1, {}),
    ("rpm", 1, {"[time]": -1}),
    ("sr", 2, {}),
]


_atom = st.sampled_from(_ATOMS)


_power = st.integers(min_value=-3, max_value=3).filter(lambda p: p != 0)


_term = st.tuples(_atom, _power, st.sampled_from(["*", "/"]))


def _expression(terms) -> tuple[str, int, dict[str, int]]:
    """Text, angle exponent and dimension of ``terms`` (atom, power, operator)."""
    text, angle, dims = "", 0, {}
    for k, ((name, a, d), power, op) in enumerate(terms):
        sign = -1 if (op == "/" and k > 0) else 1
        factor = name if power == 1 else f"{name}^{power}"
        text += factor if k == 0 else f"{op}{factor}"
        angle += sign * power * a
        for key, e in d.items():
            dims[key] = dims.get(key, 0) + sign * power * e
    return text, angle, {k: v for k, v in dims.items() if v}


_SETTINGS = settings(max_examples=150, deadline=None, derandomize=True)


# --- shipped problems and documentation read the same values --------------------------------
def _dimension_of(text: str) -> str:
    """The dimension a quantity of the shipped files belongs to, from pint and its angle."""
    parsed = parse(text)
    q = registry().Quantity(1.0, parsed.unit)
    for dimension, unit in INTERNAL_UNITS.items():
        if dimension == "speed":
            continue
        target = parse(f"1 {unit}") if unit != "dimensionless" else parse("1")
        target_dims = registry().Quantity(1.0, target.unit or "dimensionless").dimensionality
        if q.dimensionality == target_dims and parsed.angle == target.angle:
            return dimension
    raise AssertionError(f"{text!r} fits no dimension")


def _pint_value(text: str, dimension: str) -> float:
    # pint alone (its own parser, radians dimensionless): right for a right dimension
    return float(registry().Quantity(text).to(INTERNAL_UNITS[dimension]).magnitude)


def _quantity_strings(data, path=()):
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _quantity_strings(v, (*path, k))
    elif isinstance(data, list):
        for k, v in enumerate(data):
            yield from _quantity_strings(v, (*path, k))
    elif isinstance(data, str) and re.match(r"^[-+]?[\d.]+(e[-+]?\d+)?\s*[^\d\s]", data):
        yield path, data


_SHIPPED = sorted((ROOT / "problems").glob("*.toml"))


def _documented_quantities() -> list[str]:
    """Quoted quantities in the code blocks of the README and docs/."""
    found = []
    for doc in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for block in re.findall(r"```(?:toml|python)\n(.*?)```", doc.read_text(), re.S):
            found += re.findall(r"\"([-+]?\d[\d.]*(?:e[-+]?\d+)?\s*[^\d\s\"][^\"]*)\"", block)
    return sorted(set(found))


# --- the corpus: file, dict, CLI, API ---------------------------------------------------
@pytest.mark.parametrize("case", WRONG, ids=lambda c: c.name)
def test_wrong_dimension_is_refused_from_a_file_and_a_dict(case, tmp_path):
    for outcome in (load_file(case, tmp_path), load_dict(case)):
        assert not outcome.accepted, (case.value, outcome.value)
        field = _dotted(case.path)
        # the field (a tolerance given as a string is its band), the value, what it is
        assert re.search(
            rf"{re.escape(field)}(\.band)?: '{re.escape(case.value)}' is ", outcome.message
        )
        assert ", expected " in outcome.message


@pytest.mark.parametrize("case", RIGHT, ids=lambda c: c.name)
def test_right_dimension_reads_the_stated_value(case, tmp_path):
    for outcome in (load_file(case, tmp_path), load_dict(case)):
        assert outcome.accepted, outcome.message
        assert outcome.value == pytest.approx(case.expect, rel=1e-12)


@pytest.mark.parametrize("case", API_WRONG, ids=lambda c: c.name)
def test_api_refuses_the_wrong_dimension(case):
    outcome = run_api(case)
    assert not outcome.accepted, outcome.value
    assert outcome.message.startswith(f"{case.field}: ") or f": {case.field}: " in outcome.message
    assert ", expected " in outcome.message


@pytest.mark.parametrize("case", API_RIGHT, ids=lambda c: c.name)
def test_api_reads_the_right_dimension(case):
    outcome = run_api(case)
    assert outcome.value == pytest.approx(case.expect, rel=1e-12), outcome.message


def test_messages_name_the_field_the_unit_and_the_dimension():
    cases = {
        ("500 N*m/deg", "moment"): "'500 N*m/deg' is a moment per angle, expected a moment "
        '(write e.g. "500 N*m")',
        ("600 kN*m", "rotational_stiffness"): "'600 kN*m' is a moment with no angle, expected a "
        'rotational stiffness, a moment per angle (write e.g. "600 N*m/rad")',
        ("1 Hz", "angular_speed"): "'1 Hz' is a frequency with no angle, expected an angular "
        'speed, an angle per time (write e.g. "1 deg/s")',
        ("30 mm*rad", "length"): "'30 mm*rad' is a length times an angle, expected a length "
        '(write e.g. "30 mm")',
        ("120 deg^2/s", "angular_speed"): "'120 deg^2/s' is angle^2 per time, expected an "
        'angular speed, an angle per time (write e.g. "120 deg/s")',
        ("6 N*m/deg^2", "rotational_stiffness"): "'6 N*m/deg^2' is a moment per angle^2, "
        'expected a rotational stiffness, a moment per angle (write e.g. "6 N*m/rad")',
        ("4 N/(um*rad)", "stiffness"): "'4 N/(um*rad)' is a linear stiffness per angle, "
        'expected a linear stiffness, a force per length (write e.g. "4 N/mm")',
    }
    for (text, dimension), message in cases.items():
        with pytest.raises(InputError) as info:
            to_internal(text, dimension, "requirements.x")
        assert str(info.value) == f"requirements.x: {message}"


@pytest.mark.parametrize("case", WRONG[::4], ids=lambda c: c.name)
@pytest.mark.parametrize("json_mode", [False, True], ids=["text", "json"])
def test_cli_refuses_in_both_output_modes(case, json_mode, tmp_path):
    code, out, err = run_cli(case, tmp_path, json_mode)
    assert code == 2
    assert out == ""  # --json prints nothing on stdout for a refused file
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("optdesign: error: ")
    assert f"{case.field}" in lines[0] and f"'{case.value}' is " in lines[0]
    assert "Traceback" not in err and "internal error" not in err
    assert not (tmp_path / "out").exists()  # refused before any work


def test_cli_reads_angle_units_in_both_output_modes(tmp_path):
    # deflection_rate in rpm, an efficiency in percent, backlash in arcmin: accepted, echoed
    # as written in both output modes, read at their values
    case = FieldCase("echo", "cs_min_backlash", ("requirements", "backlash_max"), "2 arcmin")
    data = with_value(case)
    data["requirements"].update(deflection_rate="20 rpm", efficiency_min="90 %")
    path = tmp_path / "p.toml"
    path.write_text(dumps(data))
    argv = ["solve", str(path), "--starts", "1", "--no-ranges", "--no-report", "--no-plot"]
    argv += ["--no-diagnosis"]
    for json_mode in (False, True):
        out, err = io.StringIO(), io.StringIO()
        extra = ["--json"] if json_mode else []
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main([*argv, *extra, "--out", str(tmp_path / f"o{json_mode}")])
        assert code in (0, 1), err.getvalue()
        if json_mode:
            req = json.loads(out.getvalue())["requirements"]
            assert req["deflection_rate"] == {"value": 20.0, "unit": "rpm"}
            assert req["efficiency_min"] == {"value": 90.0, "unit": "%"}
            assert req["backlash_max"] == {"value": 2.0, "unit": "arcmin"}
        else:
            text = out.getvalue()
            assert "deflection_rate = 20 rpm" in text
            assert "efficiency_min = 90 %" in text
            assert "backlash_max = 2 arcmin" in text
    problem = od.load(path)
    req = problem.spec.requirements
    assert req.deflection_rate == pytest.approx(2 * math.pi / 3, rel=1e-15)
    assert req.efficiency_min == 0.9
    assert req.backlash_max == pytest.approx(2 * DEG / 60, rel=1e-15)


# --- the API's unit arguments ------------------------------------------------------------
def test_add_constraint_checks_its_unit_and_pint_bounds():
    import pint

    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    with pytest.raises(InputError, match=r"^add_constraint\.unit: 'N\*\*' is not a unit"):
        problem.add_constraint("c", lambda q: q.nut_force, upper=5, unit="N**")
    with pytest.raises(
        InputError, match=r"^add_constraint\.unit: 'furlong_of_cheese' is not a unit"
    ):
        problem.add_constraint("c", lambda q: q.nut_force, upper=5, unit="furlong_of_cheese")
    ureg = pint.UnitRegistry()  # a user's own registry
    info = problem.add_constraint(
        "c", lambda q: q.nut_force, upper=ureg.Quantity(3, "kN"), unit="N"
    )
    assert info.upper == 3000.0
    with pytest.raises(
        InputError, match=r"^add_constraint\.upper: .* is an angle, expected a plain number"
    ):
        problem.add_constraint("d", lambda q: q.ratio, upper=ureg.Quantity(30, "deg"), unit="")


def test_add_objective_checks_display_unit_and_scale():
    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    info = problem.add_objective("force", lambda q: q.nut_force, unit="N", display_unit="kN")
    assert info.display_scale == pytest.approx(1e-3, rel=1e-15)
    info = problem.add_objective(
        "soft", lambda q: q.R, unit="rad/(N*mm)", display_unit="urad/(N*m)"
    )
    assert info.display_scale == pytest.approx(1e9, rel=1e-12)  # the built-in compliance's
    with pytest.raises(InputError) as exc:
        problem.add_objective("m", lambda q: q.R, unit="N*mm", display_unit="N*m/deg")
    assert str(exc.value) == (
        "add_objective.display_unit: 'N*m/deg' is a moment per angle and 'N*mm' a moment: "
        "a unit of the same dimension is needed"
    )
    with pytest.raises(InputError, match=r"^add_objective\.display_scale: 1000 does not turn"):
        problem.add_objective(
            "m", lambda q: q.R, unit="N*mm", display_unit="N*m", display_scale=1e3
        )
    with pytest.raises(InputError, match=r"^add_objective\.unit: '5 mm' is not a unit"):
        problem.add_objective("m", lambda q: q.R, unit="5 mm")
    assert problem.add_objective("r", lambda q: q.R, unit="", display_unit="%").display_scale == 100


def test_unit_factor_and_convert_count_angles():
    assert unit_factor("rad", "deg", "f") == pytest.approx(180 / math.pi, rel=1e-15)
    assert unit_factor("N*mm/rad", "N*m/deg", "f") == pytest.approx(1e-3 * DEG, rel=1e-15)
    assert unit_factor("rpm", "deg/s", "f") == pytest.approx(6.0, rel=1e-15)
    assert unit_factor("", "%", "f") == pytest.approx(100.0, rel=1e-15)
    with pytest.raises(InputError, match="is an angle per time and 'Hz' a frequency"):
        unit_factor("Hz", "rad/s", "f")
    assert convert("20 rpm", "rad/s", "f") == pytest.approx(2 * math.pi / 3, rel=1e-15)
    assert convert("3", "N*mm/rad", "f") == 3.0  # bare: already in the unit
    with pytest.raises(InputError, match=r"^f: '3 N\*m' is a moment, expected a moment per angle"):
        convert("3 N*m", "N*mm/rad", "f")


# --- negative exponents and quotients, every run ------------------------------------------
@pytest.mark.parametrize(
    ("text", "dimension", "expected"),
    [
        ("1 N*mm^-2", "pressure", 1.0),
        ("1 N*m^-2", "pressure", 1e-6),
        ("1 N*m**-2", "pressure", 1e-6),
        ("1 N*mm^(-2)", "pressure", 1.0),
        ("2 kN*mm^-1", "stiffness", 2000.0),
        ("2 mm^-1*kN", "stiffness", 2000.0),
        ("3 N/mm^-1", "moment", 3.0),
        ("3 N/(mm^-1)", "moment", 3.0),
        ("5 m^-1*m^2", "length", 5000.0),
        ("1 (1/mm)^-1", "length", 1.0),
        ("1 1/(1/m)", "length", 1000.0),
        ("2 s^-1*deg", "angular_speed", 2 * DEG),
        ("2 deg*min^-1", "angular_speed", 2 * DEG / 60),
        ("7 N*m*deg^-1", "rotational_stiffness", 7e3 / DEG),
        ("7 N*m*(deg^-1)", "rotational_stiffness", 7e3 / DEG),
        ("7 (deg/(N*m))^-1", "rotational_stiffness", 7e3 / DEG),
        ("1 (deg^-1)^-1", "angle", DEG),
        ("4 h*min^-1", "dimensionless", 240.0),
        ("3 (s/min)^-1", "dimensionless", 180.0),
    ],
)
def test_negative_exponents_and_quotients(text, dimension, expected):
    assert to_internal(text, dimension, "f") == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    ("text", "angle"),
    [
        ("1 deg", 1),
        ("1 deg^-1", -1),
        ("1 1/deg", -1),
        ("1 deg^2", 2),
        ("1 deg**-2", -2),
        ("1 N*m/deg", -1),
        ("1 N*m*deg^-1", -1),
        ("1 (deg/s)^-2", -2),
        ("1 1/(1/deg)", 1),
        ("1 (1/deg)^-3", 3),
        ("1 rpm", 1),
        ("1 rpm^-1", -1),
        ("1 Hz", 0),
        ("1 %", 0),
        ("1 sr/deg", 1),
        ("1 turn/rev", 0),
        ("1 mrad*arcmin/arcsec^3", -1),
        ("1 mm", 0),
    ],
)
def test_angle_exponent_of_expressions(text, angle):
    parsed = parse(text)
    assert parsed.angle == angle
    assert angle_exponent(registry().Quantity(1.0, parsed.unit)) == angle  # pint's root units


@_SETTINGS
@given(st.lists(_term, min_size=1, max_size=4))
def test_angle_exponent_adds_subtracts_and_multiplies(terms):
    text, angle, dims = _expression(terms)
    parsed = parse(f"1 {text}")
    assert parsed.angle == angle, text
    q = registry().Quantity(1.0, parsed.unit)
    assert angle_exponent(q) == angle, text  # pint's root units agree
    assert dict(q.dimensionality) == dims, text  # and a sign flipped anywhere shows here


@_SETTINGS
@given(st.lists(_term, min_size=1, max_size=3))
def test_a_unit_times_its_inverse_is_a_plain_number_without_angle(terms):
    text, _, _ = _expression(terms)
    for combined in (f"1 ({text})*({text})^-1", f"1 ({text})/({text})"):
        parsed = parse(combined)
        assert parsed.angle == 0, combined
        q = registry().Quantity(1.0, parsed.unit)
        assert q.dimensionless and q.to("dimensionless").magnitude == pytest.approx(1.0, rel=1e-12)
        assert to_internal(combined.replace("1 ", "2.5 ", 1), "dimensionless", "f") == (
            pytest.approx(2.5, rel=1e-12)
        )


@_SETTINGS
@given(
    st.sampled_from(sorted(INTERNAL_UNITS)),
    # magnitudes the loader accepts: nonzero ones below 1e-12 (internal units) are refused
    st.floats(min_value=-1e6, max_value=1e6, allow_nan=False).filter(lambda x: abs(x) >= 1e-3),
    st.sampled_from(["deg", "rad", "arcmin", "turn", "rpm*s"]),
)
def test_dividing_by_an_angle_and_multiplying_back_changes_nothing(dimension, number, angle):
    unit = INTERNAL_UNITS[dimension]
    if unit == "dimensionless":
        unit = "%"
    base = parse(f"1 {unit}")
    per = parse(f"1 ({unit})/({angle})")
    back = parse(f"1 ({unit})/({angle})*({angle})")
    assert per.angle == base.angle - 1 and back.angle == base.angle
    assert (
        registry().Quantity(1.0, per.unit).dimensionality
        == registry().Quantity(1.0, base.unit).dimensionality
    )
    expected = to_internal(f"{number!r} {unit}", dimension, "f")
    text = f"{number!r} ({unit})/({angle})*({angle})"
    assert to_internal(text, dimension, "f") == pytest.approx(expected, rel=1e-12)
    with pytest.raises(InputError, match=r"^f: '.*' is .*, expected "):
        to_internal(f"{number!r} ({unit})/({angle})", dimension, "f")


@pytest.mark.parametrize("path", _SHIPPED, ids=lambda p: p.stem)
def test_shipped_problems_read_the_same_values(path):
    data = tomllib.loads(path.read_text())
    problem = od.load(path)
    strings = list(_quantity_strings(data))
    assert strings
    for where, text in strings:
        dimension = _dimension_of(text)
        expected = _pint_value(text, dimension)
        assert to_internal(text, dimension, "f") == pytest.approx(expected, rel=1e-14)
        if where[0] == "variables" and "catalogue" in data["variables"][where[1]]:
            continue  # a catalogue bound: the loader keeps the catalogue's values within it
        assert read_back(problem, where) == pytest.approx(expected, rel=1e-14), (where, text)


def test_documented_quantities_read_as_pint_reads_them():
    quantities = _documented_quantities()
    assert "600 kN*m/rad" in quantities and "120 deg/s" in quantities
    for text in quantities:
        dimension = _dimension_of(text)
        assert to_internal(text, dimension, "f") == pytest.approx(
            _pint_value(text, dimension), rel=1e-14
        ), text


# --- units ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("written", "suggested"),
    [
        ("999999999999999 s", '"999999999999999 mm"'),
        ("1e15 s", '"1000000000000000.0 mm"'),
        ("-1e15 s", '"-1000000000000000.0 mm"'),
        ("2.5 s", '"2.5 mm"'),
    ],
)
def test_a_wrong_dimension_suggests_the_number_whole_below_1e15_and_as_a_float_from_it(
    written, suggested
):
    with pytest.raises(InputError) as caught:
        units.to_internal(written, "length", "f")
    assert str(caught.value) == (
        f"f: {written!r} is a time, expected a length (write e.g. {suggested})"
    )


EXAMPLES = '(e.g. "N*mm", "rad/s"; "" for a plain number)'


def _refusal(call, *args) -> str:
    with pytest.raises(InputError) as caught:
        call(*args)
    return str(caught.value)


# --- units: every refusal names its field and says why ----------------------------------
@pytest.mark.parametrize(
    ("unit", "message"),
    [
        (5, 'f.unit: a unit is a string such as "N*mm", got 5'),
        ("m" * 101, "f.unit: too long for a unit (101 characters)"),
        # 100 characters is not too long: the grammar reads it (and finds no such unit)
        ("m" * 100, f"f.unit: cannot read '{'m' * 100}' as a unit: unknown unit '{'m' * 100}'"),
        ("N*foo", f"f.unit: cannot read 'N*foo' as a unit: unknown unit 'foo' {EXAMPLES}"),
        ("N**", "f.unit: cannot read 'N**' as a unit: a power must be a whole number"),
    ],
)
def test_parse_unit_refusals_name_the_field_and_the_reason(unit, message):
    assert _refusal(units.parse_unit, unit, "f.unit").startswith(message)


@pytest.mark.parametrize(
    ("value", "unit", "message"),
    [
        (
            "5 N*m",
            "N*mm/rad",
            "c.upper: '5 N*m' is a moment, expected a moment per angle ('N*mm/rad')",
        ),
        ("5 N*m", "", "c.upper: '5 N*m' is a moment, expected a plain number"),
        (
            "5 xyz",
            "N",
            "c.upper: cannot read '5 xyz' as a quantity: unknown unit 'xyz' (write a number "
            'and a unit, e.g. "500 N*m"; no arithmetic)',
        ),
        ("1e308 kN", "N", "c.upper: '1e308 kN' is out of range"),
        (float("nan"), "N", "c.upper: nan is not a finite number"),
        (5, "N*foo", f"c.upper: cannot read 'N*foo' as a unit: unknown unit 'foo' {EXAMPLES}"),
    ],
)
def test_convert_refusals_name_the_field_and_the_reason(value, unit, message):
    assert _refusal(units.convert, value, unit, "c.upper") == message


def test_convert_reads_strings_and_pint_quantities_in_the_target_unit():
    registry = units.registry()
    assert units.convert("2 kN", "N", "c") == 2000.0
    assert units.convert(registry.Quantity(3.0, "deg"), "rad", "c") == pytest.approx(
        math.radians(3.0), rel=1e-15
    )
    assert units.convert(7, "N", "c") == 7.0  # a bare number: already in the unit


def test_convert_refuses_pint_quantities_that_are_not_one_finite_number():
    registry = units.registry()
    vector = registry.Quantity(np.array([1.0, 2.0]), "N")
    assert _refusal(units.convert, vector, "N", "c.upper") == (
        f"c.upper: expected a scalar quantity, got {vector!r}"
    )
    infinite = registry.Quantity(float("inf"), "N")
    assert _refusal(units.convert, infinite, "N", "c.upper") == (
        f"c.upper: {infinite!r} is not a finite number"
    )


def test_an_object_with_units_that_is_not_pints_is_no_quantity():
    class LooksLikeAQuantity:
        units = "N"
        magnitude = 1.0

    value = LooksLikeAQuantity()
    assert _refusal(units.convert, value, "N", "c.upper") == (
        f"c.upper: expected a number or a quantity string, got {value!r}"
    )


@pytest.mark.parametrize(
    ("unit", "to", "message"),
    [
        (
            "N*mm",
            "N*m/deg",
            "d.unit: 'N*m/deg' is a moment per angle and 'N*mm' a moment: a unit of the "
            "same dimension is needed",
        ),
        (
            "",
            "N",
            "d.unit: 'N' is a force and no unit a plain number: a unit of the same dimension is needed",
        ),
        (
            "N",
            "",
            "d.unit: no unit is a plain number and 'N' a force: a unit of the same dimension is needed",
        ),
        ("N", "N*foo", f"d.unit: cannot read 'N*foo' as a unit: unknown unit 'foo' {EXAMPLES}"),
        ("N*foo", "N", f"d.unit: cannot read 'N*foo' as a unit: unknown unit 'foo' {EXAMPLES}"),
    ],
)
def test_unit_factor_refusals_name_the_field(unit, to, message):
    assert _refusal(units.unit_factor, unit, to, "d.unit") == message


def test_unit_factor_values():
    assert units.unit_factor("kN", "N", "d") == 1000.0
    assert units.unit_factor("deg", "rad", "d") == pytest.approx(math.pi / 180, rel=1e-15)


def test_parse_quantity_names_the_quantity():
    assert _refusal(units.parse_quantity, "5 foo").startswith(
        "quantity: cannot read '5 foo' as a quantity: unknown unit 'foo'"
    )


BASE = (PROBLEMS / "cs_min_backlash.toml").read_text()


# --- input that helps (issue 16) -------------------------------------------------------
def _load(tmp_path: Path, old: str, new: str):
    assert old in BASE
    f = tmp_path / "p.toml"
    f.write_text(BASE.replace(old, new, 1))
    return load_problem(f)


def test_bare_number_refused_with_the_unit_to_write(tmp_path):
    with pytest.raises(OptDesignError) as exc:
        _load(tmp_path, 'hinge_moment = "500 N*m"', "hinge_moment = 300")
    assert str(exc.value).endswith('requirements.hinge_moment: 300 has no unit; write "300 N*m"')
    with pytest.raises(OptDesignError, match=r'variables.R.lower: 30 has no unit; write "30 mm"'):
        _load(tmp_path, 'lower = "30 mm"', "lower = 30")


@pytest.mark.parametrize("spelling", ["500 Nm", "0.5 kNm", "500 N.m", "500 N-m", "500 N m"])
def test_common_moment_spellings(tmp_path, spelling):
    # 500 N*m = 5e5 N*mm (internal unit).
    p = _load(tmp_path, 'hinge_moment = "500 N*m"', f'hinge_moment = "{spelling}"')
    assert p.spec.requirements.hinge_moment == pytest.approx(5e5)


def test_hyphen_only_joins_unit_names():
    assert to_internal("2 lbf-ft", "moment", "m") == pytest.approx(2 * 4.4482216 * 304.8, rel=1e-6)
    with pytest.raises(OptDesignError):
        to_internal("5 mm-2", "length", "x")  # not a power, not a product
