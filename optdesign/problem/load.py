"""Load and validate a problem (TOML file or dict) into a :class:`DesignProblem`.

Errors name the field (``variables.R.lower: ...``) and never show a traceback in the CLI.
The schema comes from the mechanism the problem names (:func:`optdesign.problem.spec.
spec_model`), so a new mechanism plug-in brings its variables and requirements with it.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from optdesign.errors import InputError, ProblemError
from optdesign.mechanisms.registry import get_mechanism, registered
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.spec import ProblemSpec, spec_model
from optdesign.problem.variables import parse_variable, variable_table


def load_problem(path: str | Path) -> DesignProblem:
    """Read, validate and build the problem in the TOML file ``path``."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ProblemError(f"{path}: cannot read problem file ({exc.strerror})") from None
    except UnicodeDecodeError:
        raise ProblemError(f"{path}: not a text file (TOML must be UTF-8)") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProblemError(f"{path}: not valid TOML ({exc})") from None
    data.setdefault("name", path.stem)
    return problem_from_dict(data, source=str(path))


def load(problem: str | Path | Mapping[str, Any] | DesignProblem) -> DesignProblem:
    """A problem from a file path, a dict (the parsed-TOML form) or a problem (returned)."""
    if isinstance(problem, DesignProblem):
        return problem
    if isinstance(problem, Mapping):
        return problem_from_dict(dict(problem))
    return load_problem(problem)


def validate_spec(
    data: dict[str, Any], mechanism: type, source: str = "problem", internal: bool = False
) -> ProblemSpec:
    """Validate ``data`` against the schema of ``mechanism``; ProblemError naming fields.

    ``internal``: ``data`` is a validated spec's own dump (numbers in internal units).
    """
    try:
        return spec_model(mechanism).model_validate(data, context={"internal": internal})
    except ValidationError as exc:
        lines = []
        for err in exc.errors():
            loc = ".".join(str(p) for p in err["loc"] if not str(p).startswith("function-"))
            msg = err["msg"].removeprefix("Value error, ")
            if err["type"] == "extra_forbidden":
                msg = "unknown field"
            lines.append(f"{loc}: {msg}")
        raise ProblemError(f"{source}: invalid problem file\n  " + "\n  ".join(lines)) from None


def problem_from_dict(data: dict[str, Any], source: str = "problem") -> DesignProblem:
    """Validate a problem given as a dict (the parsed TOML)."""
    if not isinstance(data, dict):
        raise ProblemError(f"{source}: a problem is a table of sections, got {type(data).__name__}")
    name = data.get("mechanism")
    if not isinstance(name, str):
        raise ProblemError(
            f"{source}: mechanism: give the mechanism's name "
            f"(registered: {', '.join(registered())})"
        )
    try:
        cls = get_mechanism(name)
    except InputError as exc:
        raise ProblemError(f"{source}: {exc}") from None
    spec = validate_spec(data, cls, source)
    table = variable_table(cls)
    variables = []
    for var_name, raw in spec.variables.items():
        if var_name not in table:
            raise ProblemError(
                f"variables.{var_name}: unknown variable for a {cls.label()} "
                f"(known: {', '.join(table)})"
            )
        variables.append(parse_variable(var_name, raw, table[var_name], cls.name, spec.screw))
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
