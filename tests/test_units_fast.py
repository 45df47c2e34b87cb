"""The table of common units (read without pint) against pint's own conversion."""

import math
from pathlib import Path

import pytest

from optdesign import units
from optdesign.units import FAST_UNITS, registry, to_internal

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
    from optdesign.reports.display_units import _DIMENSION_UNITS, _shown_factor

    factor = _shown_factor(dimension, unit)
    for value in (1.0, 37.5, -0.25, 0.1, 1234.5678, 0.5235987755982988):
        try:
            q = registry().Quantity(value, _DIMENSION_UNITS[dimension]).to(unit)
        except Exception:
            assert factor is None, unit  # pint cannot: the report falls back, as before
            continue
        if factor is not None:
            assert value * factor == float(q.magnitude), (unit, value)
