"""Quantities at the input boundary: the restricted grammar, spellings, angle fields,
non-finite numbers, pint Quantity objects, the bare-number policy."""

from __future__ import annotations

import math
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from optdesign.errors import InputError
from optdesign.units import INTERNAL_UNITS, SUGGESTED_UNITS, registry, to_internal

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
