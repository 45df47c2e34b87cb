"""Load and validate a problem (TOML file or dict) into a :class:`DesignProblem`.

Errors name the field (``variables.R.lower: ...``) and never show a traceback in the CLI.
The schema comes from the mechanism the problem names (:func:`optdesign.problem.spec.
spec_model`), so a new mechanism plug-in brings its variables and requirements with it.
"""

from __future__ import annotations

import difflib
import re
import stat
import sys
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from optdesign import argument_checks as validation
from optdesign.errors import InputError, ProblemError
from optdesign.mechanisms.registry import get_mechanism, registered
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.spec_validation import validate_spec
from optdesign.problem.variables import parse_variable, variable_table
from optdesign.units import Bare

#: Largest problem file read (a real one is a few kB).
MAX_FILE_BYTES = 1_000_000
#: Deepest nesting of tables and arrays in a problem file (a real one needs 4).
MAX_NESTING = 12


def read_problem_text(path: Path) -> str:
    """The text of a problem file: a regular, UTF-8 file of at most MAX_FILE_BYTES.

    A named pipe, a device (``/dev/zero``) or a folder is refused before it is opened,
    so that reading can neither block nor grow without bound. A UTF-8 byte-order mark at
    the start (as Windows editors write one) is dropped: it says only that the file is
    UTF-8, which TOML requires anyway. A UTF-16 file is refused naming its encoding.
    """
    try:
        st = path.stat()
    except OSError as exc:
        raise ProblemError(f"{path}: cannot read problem file ({exc.strerror})") from None
    if not stat.S_ISREG(st.st_mode):
        kind = "a folder" if stat.S_ISDIR(st.st_mode) else "not a regular file"
        raise ProblemError(f"{path}: cannot read problem file ({kind})")
    if st.st_size > MAX_FILE_BYTES:
        raise ProblemError(
            f"{path}: problem file too large ({st.st_size} bytes, at most {MAX_FILE_BYTES})"
        )
    try:
        with path.open("rb") as fh:
            raw = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ProblemError(f"{path}: cannot read problem file ({exc.strerror})") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ProblemError(f"{path}: problem file too large (at most {MAX_FILE_BYTES} bytes)")
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise ProblemError(
            f"{path}: not a UTF-8 text file (it starts with a UTF-16 byte-order mark; "
            "TOML is UTF-8: save it as UTF-8)"
        )
    if b"\x00" in raw:
        raise ProblemError(f"{path}: not a text file (a binary file; TOML is UTF-8 text)")
    try:
        return raw.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        raise ProblemError(
            f"{path}: not a text file (byte {exc.start} is not UTF-8; TOML must be UTF-8)"
        ) from None


def _shipped_or(path: Path) -> Path:
    """``path``, or the shipped problem of that name (``cs_min_backlash``) when no such
    file exists and the name has no folder: the shipped files work from any folder."""
    if path.exists() or path.parent != Path("."):
        return path
    from optdesign.data import problems_dir

    shipped = problems_dir() / (path.name if path.suffix == ".toml" else f"{path.name}.toml")
    return shipped if shipped.is_file() else path


def _nesting(text: str) -> int:
    # Deepest bracket nesting outside strings, checked before tomllib (recursive) sees it.
    depth = deepest = 0
    quote = ""
    escaped = False
    comment = False
    for ch in text:
        if comment:
            comment = ch != "\n"
        elif quote:
            if escaped:
                escaped = False
            elif ch == "\\" and quote == '"':
                escaped = True
            elif ch == quote:
                quote = ""
        elif ch in "\"'":
            quote = ch
        elif ch == "#":
            comment = True
        elif ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth -= 1
        elif ch == "\n":
            depth = max(depth, 0)
    return deepest


#: An integer's digits in a TOML text (not a float's: no point or exponent next to them).
_LONG_RUN = re.compile(r"(?<![\w.])[+-]?[0-9][0-9_]*(?![\w.])")


def _too_many_digits(text: str, error: str) -> str | None:
    """What is wrong, and where, when tomllib failed on an integer longer than Python
    converts (``sys.get_int_max_str_digits()``, 4300 by default); None for any other
    error. TOML's integers are 64-bit, a problem's at most :data:`MAX_INTEGER`.

    The field is found by parsing the text again with each such number replaced by an
    inline table ``{optdesign_long_number_K = 0}``: a value where the number was a value,
    plain text where it was inside a string or a comment.
    """
    m = re.search(r"value has (\d+) digits", error)
    if m is None:
        return None
    limit = sys.get_int_max_str_digits() or int(m.group(1)) - 1
    runs = [r for r in _LONG_RUN.finditer(text) if _digits(r.group()) > limit]
    if not runs:
        return None
    marked, end = [], 0
    for k, run in enumerate(runs):
        marked += [text[end : run.start()], f"{{optdesign_long_number_{k} = 0}}"]
        end = run.end()
    found = _marked(_toml_or_none("".join(marked) + text[end:]), len(runs))
    if found is None:  # (a long number in a bare key, say): the first one's line
        where = f"line {text.count(chr(10), 0, runs[0].start()) + 1}"
        count = _digits(runs[0].group())
    else:
        where, k = found
        count = _digits(runs[k].group())
    return (
        f"{where}: a number of {count} digits is out of range (an integer is at most "
        f"{MAX_INTEGER:,})"
    )


def _digits(run: str) -> int:
    return len(run.replace("_", "").lstrip("+-"))


def _toml_or_none(text: str) -> dict[str, Any] | None:
    try:
        return tomllib.loads(text)
    except (ValueError, RecursionError):  # TOMLDecodeError is a ValueError
        return None


def _marked(data: Any, marks: int) -> tuple[str, int] | None:
    """(dotted path, K) of the first ``{optdesign_long_number_K = 0}`` in ``data``
    (0 <= K < ``marks``)."""
    stack: list[tuple[str, Any]] = [("", data)]
    while stack:  # depth first, in the file's order
        path, value = stack.pop()
        if isinstance(value, dict):
            mark = re.fullmatch(r"optdesign_long_number_([0-9]{1,9})", "".join(value))
            if mark is not None and int(mark.group(1)) < marks:
                return path, int(mark.group(1))
            children = [(f"{path}.{k}" if path else k, v) for k, v in value.items()]
        elif isinstance(value, list):
            children = [(f"{path}[{k}]", v) for k, v in enumerate(value)]
        else:
            continue
        stack += reversed(children)
    return None


def load_problem(path: str | Path) -> DesignProblem:
    """Read, validate and build the problem in the TOML file ``path``.

    A problem file gives every dimensioned value its unit: a bare number there is refused
    with the unit to write (``hinge_moment: 300 has no unit; write "300 N*m"``).
    """
    path = _shipped_or(Path(path))
    text = read_problem_text(path)
    if _nesting(text) > MAX_NESTING:
        raise ProblemError(f"{path}: arrays or tables nested too deeply (at most {MAX_NESTING})")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProblemError(f"{path}: not valid TOML ({exc})") from None
    except ValueError as exc:  # e.g. an integer of more than 4300 digits
        too_long = _too_many_digits(text, str(exc))
        if too_long is not None:
            raise ProblemError(f"{path}: {too_long}") from None
        raise ProblemError(f"{path}: not valid TOML ({' '.join(str(exc).split())[:120]})") from None
    except RecursionError:
        raise ProblemError(f"{path}: arrays or tables nested too deeply") from None
    data.setdefault("name", path.stem)
    return problem_from_dict(data, source=str(path), bare="refuse", folder=str(path.parent))


def load(problem: str | Path | Mapping[str, Any] | DesignProblem) -> DesignProblem:
    """A problem from a file path, a dict (the parsed-TOML form) or a problem (returned).

    Raises
    ------
    InputError
        (argument ``problem``) for anything else, e.g. a number or bytes.
    """
    if isinstance(problem, DesignProblem):
        return problem
    if isinstance(problem, Mapping):  # a dict as given: a cycle is named from its root
        return problem_from_dict(problem if isinstance(problem, dict) else dict(problem))
    try:
        path = validation.path("problem", problem)
    except validation.ArgumentError:
        raise validation.ArgumentError(
            "problem",
            "expected a problem file path, a problem dict or a DesignProblem, got "
            + validation.shown(problem),
        ) from None
    return load_problem(path)


def problem_from_dict(
    data: dict[str, Any],
    source: str = "problem",
    bare: Bare = "internal",
    folder: str | None = None,
) -> DesignProblem:
    """Validate a problem given as a dict (the parsed TOML).

    ``bare``: a number without a unit for a dimensioned field is taken in internal units
    (``"internal"``, a dict from Python) or refused (``"refuse"``, a problem file).
    ``folder``: where the files the problem names are read from (None: the working
    folder).
    """
    if not isinstance(data, dict):
        raise ProblemError(f"{source}: a problem is a table of sections, got {type(data).__name__}")
    _check_raw(data, source)
    name = data.get("mechanism")
    if not isinstance(name, str):
        misspelt = [k for k in data if difflib.get_close_matches(str(k), ["mechanism"], 1, 0.6)]
        hint = (
            f"; is {misspelt[0]!r} a misspelling?" if "mechanism" not in data and misspelt else ""
        )
        raise ProblemError(
            f"{source}: mechanism: give the mechanism's name "
            f"(registered: {', '.join(registered())}){hint}"
        )
    try:
        cls = get_mechanism(name)
    except InputError as exc:
        raise ProblemError(f"{source}: {exc}") from None
    spec = validate_spec(data, cls, source, bare=bare, folder=folder)
    table = variable_table(cls)
    variables = []
    for var_name, raw in _with_motor_variable(spec).items():
        if var_name not in table:
            close = difflib.get_close_matches(var_name, list(table), n=1, cutoff=0.6)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise ProblemError(
                f"variables.{var_name}: unknown variable for a {cls.label()} "
                f"({hint}known: {', '.join(table)})"
            )
        try:
            variables.append(
                parse_variable(var_name, raw, table[var_name], cls.name, spec.screw, bare)
            )
        except ProblemError as exc:
            raise ProblemError(f"{source}: {exc}" if source != "problem" else str(exc)) from None
    declared = {v.name for v in variables}
    if spec.tolerances is not None:
        for var_name in spec.tolerances.variables():
            if var_name not in declared:
                raise ProblemError(
                    f"tolerances.{var_name}: {var_name} is not a variable of this problem"
                )
    problem = DesignProblem(spec, variables, cls)
    # Reports show numbers in the units the file wrote (degrees in, degrees out).
    problem.written_units = written_units(data)
    return problem


def _with_motor_variable(spec) -> dict[str, Any]:
    """The file's variables, with the motor's when ``[motor] catalogue`` names one (the
    variable ``motor``, every motor of the catalogue, unless the file declares it itself,
    e.g. with bounds on the motors' numbers); a ``motor`` variable needs that catalogue."""
    variables = dict(spec.variables)
    catalogue = spec.motor.catalogue if spec.motor is not None else None
    if "motor" in variables and catalogue is None:
        raise ProblemError(
            'variables.motor: the motor variable needs [motor] catalogue = "Yaskawa Sigma-7" '
            "(the catalogue whose motors it numbers)"
        )
    if catalogue is not None:
        raw = variables.setdefault("motor", {"catalogue": catalogue})
        if not isinstance(raw, dict) or raw.get("catalogue") != catalogue:
            raise ProblemError(
                f"variables.motor: with [motor] catalogue = {catalogue!r}, declare it as "
                f'{{ catalogue = "{catalogue}" }} (bounds on the motors\' numbers allowed)'
            )
        if spec.motor.catalogue_text is not None:  # a user's CSV: its motors' numbers
            from optdesign.problem.motor_catalogue_variable import motor_numbers, spec_catalogue

            numbers = motor_numbers(spec_catalogue(spec.motor))
            variables["motor"] = {k: v for k, v in raw.items() if k != "catalogue"}
            variables["motor"]["values"] = numbers
    return variables


#: Largest integer a problem accepts: every integer of the file is also used as a float
#: somewhere (a count, a seed, a bound), and floats are exact up to 2**53.
MAX_INTEGER = 2**53


def _check_raw(
    data: Any, source: str, path: str = "", depth: int = 0, inside: dict[int, str] | None = None
) -> None:
    """What no field accepts, refused before the schema sees it: an integer beyond
    :data:`MAX_INTEGER` (a 400-digit number overflows the conversion to float), a NUL
    character in a key or a string (no name, unit or option contains one), tables and
    arrays nested deeper than :data:`MAX_NESTING` (``a.a.a. ... = 1`` in a file, whose
    dotted keys no bracket count sees) and a table or list that contains itself (a dict
    from Python). Recursion stops at that depth, so no input reaches Python's limit."""
    inside = {id(data): path or "the problem"} if inside is None else inside
    items = data.items() if isinstance(data, Mapping) else enumerate(data)
    for key, value in items:
        here = f"{path}[{key}]" if isinstance(key, int) else f"{path}.{key}" if path else key
        if isinstance(key, str) and "\x00" in key:
            raise ProblemError(f"{source}: {here!r}: a NUL character in a key")
        if isinstance(value, Mapping | list | tuple):
            if id(value) in inside:
                raise ProblemError(
                    f"{source}: {here}: refers back to {inside[id(value)]} (a table or list "
                    "that contains itself; a problem is a tree of tables, lists and values)"
                )
            if depth + 1 > MAX_NESTING:
                raise ProblemError(
                    f"{source}: {here}: tables and arrays nested too deeply (at most "
                    f"{MAX_NESTING} levels; a problem needs 3)"
                )
            inside[id(value)] = here
            _check_raw(value, source, here, depth + 1, inside)
            del inside[id(value)]
        elif isinstance(value, str) and "\x00" in value:
            raise ProblemError(f"{source}: {here}: a NUL character in the text")
        elif isinstance(value, int) and not isinstance(value, bool) and abs(value) > MAX_INTEGER:
            raise ProblemError(
                f"{source}: {here}: an integer of about {int(value.bit_length() * 0.30103) + 1} digits is out of "
                f"range (at most {MAX_INTEGER:,})"
            )


_UNIT_TEXT = re.compile(r"^\s*[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?\s*(.*?)\s*$")


def written_units(data: Mapping[str, Any], prefix: str = "") -> dict[str, str]:
    """The unit text of every quantity string in the parsed problem file ``data``.

    Returns path -> unit, e.g. ``{"variables.phi0.lower": "deg", "requirements.
    hinge_moment": "N*m"}``; bare numbers and non-quantity strings are left out.
    """
    out: dict[str, str] = {}
    for key, value in data.items():
        path = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(written_units(value, path + "."))
        elif isinstance(value, str):
            match = _UNIT_TEXT.match(value)
            if match and match.group(1):
                out[path] = match.group(1)
    return out
