"""Hostile input through the real command line (issue 13) and input that helps (issue 16).

The corpus (tests/hostile_corpus.py: generated mutations of every shipped problem file,
hand-written files, bad command lines) runs in one child process through
``optdesign.cli.main``; a handful of cases run as true subprocesses (a named pipe, a
device, ``--json`` purity, ``--version``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from hostile_corpus import PROBLEMS, all_cases, handwritten_cases, run_case

import optdesign as od
from optdesign.errors import OptDesignError
from optdesign.problem import load_problem
from optdesign.units import to_internal

HERE = Path(__file__).resolve().parent
BASE = (PROBLEMS / "cs_min_backlash.toml").read_text()


def _env() -> dict[str, str]:
    env = dict(os.environ)
    root = str(HERE.parent)
    env["PYTHONPATH"] = root + os.pathsep + env.get("PYTHONPATH", "")
    env.pop("OPTDESIGN_DEBUG", None)
    return env


def _cli(*args: str, timeout: float = 60, cwd: Path | None = None):
    return subprocess.run(
        [sys.executable, "-m", "optdesign", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=_env(),
        cwd=cwd,
    )


def test_corpus_is_refused_cleanly(tmp_path):
    """Every case of the corpus: exit 2 (or 1 where infeasible), the field named, no
    traceback, no internal error, no hang; the counts go to the issue's closing note."""
    report = tmp_path / "corpus.json"
    proc = subprocess.run(
        [sys.executable, str(HERE / "hostile_corpus.py"), str(report), str(tmp_path / "cases")],
        capture_output=True,
        text=True,
        timeout=300,
        env=_env(),
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    data = json.loads(report.read_text())
    counts = data["counts"]
    print("hostile corpus:", counts)
    failures = [
        f"{o['name']}: {o['verdict']} (exit {o['code']}): {o['message']}"
        for o in data["outcomes"]
        if o["verdict"] != "refused"
    ]
    assert not failures, "\n".join(failures[:30])
    assert counts["tried"] >= 150
    assert counts["refused"] == counts["tried"]
    # One line per refusal (argparse adds its usage line).
    long = [
        o["name"]
        for o in data["outcomes"]
        if not o["name"].startswith("argv:") and o["detail"]["stderr_lines"] > 1
    ]
    assert not long


def test_corpus_covers_each_class():
    names = [c.name for c in all_cases()]
    for needle in ("=nan", "=inf", "=1e400", "=arith", "=bool", "=list", "typo ", "bogus_key"):
        assert sum(needle in n for n in names) >= 8, needle
    assert sum(n.startswith("argv:") for n in names) >= 30
    assert sum(n.startswith("file:") for n in names) >= 80


def test_a_case_that_succeeds_is_caught(tmp_path):
    """The judge is not blind: a valid file counts as a wrong success."""
    case = handwritten_cases()[0]
    case.text = BASE
    case.name = "valid"
    outcome = run_case(case, tmp_path)
    assert outcome.verdict == "wrong success"


@pytest.mark.parametrize("kind", ["fifo", "dev_zero", "folder"])
def test_special_files_are_refused_without_blocking(tmp_path, kind):
    if kind == "fifo":
        path = tmp_path / "pipe.toml"
        os.mkfifo(path)
    elif kind == "dev_zero":
        path = Path("/dev/zero")
    else:
        path = tmp_path
    proc = _cli("solve", str(path), "--json", timeout=30)
    assert proc.returncode == 2
    assert "not a regular file" in proc.stderr or "a folder" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_json_stdout_holds_only_the_json_with_a_verbose_solver(tmp_path):
    """[solver] ipopt print_level = 5: Ipopt's log goes to stderr, stdout parses as JSON
    (two workers: their output too)."""
    f = tmp_path / "p.toml"
    f.write_text(BASE + "\n[solver]\nipopt = { print_level = 5 }\n")
    proc = _cli("solve", str(f), "--json", "--starts", "2", "--workers", "2", "--no-ranges")
    assert proc.returncode == 0, proc.stderr[-1000:]
    result = json.loads(proc.stdout)
    assert result["status"] == "optimal"
    assert "EXIT: Optimal Solution Found" in proc.stderr


def test_version():
    from optdesign import __version__

    proc = _cli("--version")
    assert proc.returncode == 0
    assert proc.stdout.strip() == f"optdesign {__version__}"


def test_an_unforeseen_error_is_one_line(monkeypatch, capsys):
    """The last-resort handler: a bug is a message and exit 1, the traceback only with
    OPTDESIGN_DEBUG."""
    from optdesign.cli import run_guarded

    def boom():
        raise ZeroDivisionError("division by zero")

    monkeypatch.delenv("OPTDESIGN_DEBUG", raising=False)
    assert run_guarded(boom) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error: ZeroDivisionError" in err
    monkeypatch.setenv("OPTDESIGN_DEBUG", "1")
    with pytest.raises(ZeroDivisionError):
        run_guarded(boom)


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
