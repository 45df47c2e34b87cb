"""Reading a problem (optdesign/problem/load.py): every refusal names its field, hostile
structure (nesting, a dict that contains itself, byte-order marks, huge integers) is refused
naming where, and a value of the wrong kind says what the field takes."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
from hostile_corpus import PROBLEMS

import optdesign as od
from optdesign.errors import OptDesignError
from optdesign.problem import load_problem

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(
    ("where", "value", "message"),
    [
        (("requirements", "hinge_moment"), "1e308 kN*m", "'1e308 kN*m' is out of range"),
        (
            ("variables", "d"),
            {"catalogue": "HIWIN"},
            "the HIWIN screw catalogue gives d0 and p only",
        ),
    ],
)
def test_fin_actuator_inputs_refused_naming_their_field(where, value, message):
    """A hinge moment that overflows in internal units, a catalogue screw asked for a
    variable it does not give: each refused naming the field."""
    from optdesign.errors import OptDesignError

    data = tomllib.loads((ROOT / "problems" / "fin_actuator.toml").read_text())
    data[where[0]][where[1]] = value
    with pytest.raises(OptDesignError) as caught:
        od.load(data)
    assert f"{where[0]}.{where[1]}: {message}" in str(caught.value)


BASE = (PROBLEMS / "cs_min_backlash.toml").read_text()


# --- input that helps (issue 16) -------------------------------------------------------
def _load(tmp_path: Path, old: str, new: str):
    assert old in BASE
    f = tmp_path / "p.toml"
    f.write_text(BASE.replace(old, new, 1))
    return load_problem(f)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            'rod_inclination_max = "30 deg"',
            'rod_inclination_max = "200 deg"',
            "requirements.rod_inclination_max: 200 deg is outside [0 deg, 90 deg]",
        ),
        (
            'hinge_moment = "500 N*m"',
            'hinge_moment = "-500 N*m"',
            "requirements.hinge_moment: must be positive, got -500 N*m",
        ),
        (
            "nut_travel_max",
            "max_nut_travel",
            "requirements.max_nut_travel: unknown field; did you mean 'nut_travel_max'?",
        ),
        (
            'upper = "120 mm"',
            'upper = "1e308 mm"',
            "variables.R.upper: 1e308 mm is out of range",
        ),
        ('upper = "120 mm"', "upper = nan", "variables.R.upper: 'nan' is not a finite number"),
        ('fit = "H7/g6"', 'fit = "loose"', "hole letters C, D, E, F, G, H, JS, K"),
    ],
)
def test_messages_name_the_field(tmp_path, old, new, message):
    with pytest.raises(OptDesignError) as exc:
        _load(tmp_path, old, new)
    text = str(exc.value)
    assert message in text
    assert "\n" not in text and "np." not in text


def test_reference_keys_are_checked(tmp_path):
    with pytest.raises(OptDesignError, match=r"reference.RR: unknown field; did you mean 'R'"):
        _load(tmp_path, "[objective]", '[reference]\nRR = "50 mm"\n\n[objective]')


def test_nesting_counts_only_toml_structure(tmp_path):
    """Brackets in comments and strings are text: a valid file with many of them loads."""
    from optdesign.problem.load import MAX_NESTING, _nesting

    assert _nesting("a = [[1], [2]]\n[t]\nb = { c = [1] }\n") == 2
    deep = "[" * (MAX_NESTING + 5)
    assert _nesting(f"# {deep}\ns = \"{deep}\"\nt = '{deep}'\n") == 0
    text = BASE.replace("[objective]", f"# {deep}\n[objective]", 1)
    text = text.replace('name = "cs_min_backlash"', f'name = "cs_min_backlash"  # {deep}', 1)
    f = tmp_path / "p.toml"
    f.write_text(text)
    assert load_problem(f).name == "cs_min_backlash"


def test_dotted_keys_deeper_than_the_limit_are_refused_naming_where(tmp_path):
    """``a.a.a. ... = 1`` nests tables without a bracket: 5000 levels were a RecursionError
    (from a file and from a dict given to od.load)."""
    from optdesign.problem.load import MAX_NESTING

    f = tmp_path / "p.toml"
    f.write_text(BASE + "\n[extra]\n" + ".".join(["a"] * 5000) + " = 1\n")
    with pytest.raises(OptDesignError) as exc:
        load_problem(f)
    where = "extra" + ".a" * MAX_NESTING
    assert str(exc.value).startswith(
        f"{f}: {where}: tables and arrays nested too deeply (at most {MAX_NESTING} levels; "
        "a problem needs 3)"
    )
    deep: object = 1
    for _ in range(5000):
        deep = {"a": deep}
    data = tomllib.loads(BASE)
    data["variables"]["R"] = deep
    with pytest.raises(OptDesignError) as exc:
        od.load(data)
    where = "variables.R" + ".a" * (MAX_NESTING - 1)
    assert str(exc.value).startswith(f"problem: {where}: tables and arrays nested too deeply")
    data["variables"]["R"] = [[[[[[[[[[[[[[1]]]]]]]]]]]]]]  # 14 lists: brackets as deep
    with pytest.raises(OptDesignError, match=r"^problem: variables\.R\[0\]\[0\]"):
        od.load(data)


def test_a_problem_dict_that_contains_itself_is_refused_naming_where():
    data = tomllib.loads(BASE)
    data["x"] = data
    with pytest.raises(OptDesignError) as exc:
        od.load(data)
    assert str(exc.value).startswith("problem: x: refers back to the problem (a table or list")
    data = tomllib.loads(BASE)
    data["variables"]["R"]["lower"] = data["variables"]
    with pytest.raises(OptDesignError) as exc:
        od.load(data)
    assert str(exc.value).startswith(
        "problem: variables.R.lower: refers back to variables (a table or list that contains "
        "itself; a problem is a tree of tables, lists and values)"
    )
    shared = {"lower": "30 mm", "upper": "120 mm"}  # one table twice is no cycle
    data = tomllib.loads(BASE)
    data["variables"]["R"] = data["variables"]["l"] = shared
    assert od.load(data).by_name["l"].upper == 120


def test_a_byte_order_mark_is_read_as_utf8_and_utf16_is_named(tmp_path):
    """A UTF-8 byte-order mark (Windows editors write one) only says the file is UTF-8:
    the file loads. A UTF-16 file is refused naming its encoding."""
    f = tmp_path / "p.toml"
    f.write_bytes(b"\xef\xbb\xbf" + BASE.encode())
    assert load_problem(f).name == "cs_min_backlash"
    f.write_bytes(BASE.encode("utf-16"))
    with pytest.raises(OptDesignError) as exc:
        load_problem(f)
    assert str(exc.value).startswith(
        f"{f}: not a UTF-8 text file (it starts with a UTF-16 byte-order mark; TOML is UTF-8: "
        "save it as UTF-8)"
    )


@pytest.mark.parametrize(
    ("value", "where", "digits"),
    [
        ("1" * 4301, "variables.i_a", 4301),
        ("-" + "9" * 5000, "variables.i_a", 5000),
        ("[1, " + "1_" * 4400 + "1]", "variables.i_a[1]", 4401),
    ],
)
def test_an_integer_longer_than_python_converts_is_refused_naming_the_field(
    tmp_path, value, where, digits
):
    """Python refuses to convert a text of more than 4300 digits ("Exceeds the limit"):
    the message says what is wrong and where, not Python's words."""
    f = tmp_path / "p.toml"
    text = BASE.replace("i_a = 2", f"i_a = {value}", 1)
    f.write_text(text.replace('description = "', f'description = "{"7" * 4400} ', 1))
    with pytest.raises(OptDesignError) as exc:
        load_problem(f)
    assert str(exc.value).startswith(
        f"{f}: {where}: a number of {digits} digits is out of range (an integer is at most "
        "9,007,199,254,740,992)"
    )


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            'mechanism = "crank_slider"',
            'mechanism = "crank_slider"\nscrew = true',
            "screw: expected a table (kind, friction, catalogue, nut, ...), got true",
        ),
        (
            'mechanism = "crank_slider"',
            'mechanism = "crank_slider"\nscrew = "HIWIN"',
            "screw: expected a table (kind, friction, catalogue, nut, ...), got 'HIWIN'",
        ),
        (
            'fit_clearance = "max"',
            "fit_clearance = true",
            "requirements.fit_clearance: expected one of 'min', 'max', got true",
        ),
    ],
)
def test_a_value_of_the_wrong_kind_says_what_the_field_takes(tmp_path, old, new, message):
    with pytest.raises(OptDesignError) as exc:
        _load(tmp_path, old, new)
    assert str(exc.value).startswith(f"{tmp_path / 'p.toml'}: {message}")
