"""Load and validate a problem file (TOML) into a :class:`DesignProblem`.

Errors name the field (``variables.R.lower: ...``) and never show a traceback in the CLI.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from optdesign.errors import InputError, ProblemError
from optdesign.problem.design_problem import UNITS, DesignProblem, Variable
from optdesign.problem.spec import VARIABLE_DESCRIPTIONS, VARIABLE_DIMENSIONS, ProblemSpec
from optdesign.units import to_internal

#: Catalogues a discrete variable may name (physics.md 10).
CATALOGUES: dict[str, tuple[float, ...]] = {
    "ISO 3408": (1, 2, 2.5, 3, 4, 5, 6, 8, 10, 12, 16, 20, 25, 32, 40),
    "ISO 2338": (3, 4, 5, 6, 8, 10, 12, 16, 20, 25),
}

#: Variables that must be positive when fixed or bounded.
POSITIVE = {"R", "l", "p", "i_a", "d", "pin_length", "pin_length_ratio"}


def load_problem(path: str | Path) -> DesignProblem:
    """Read, validate and build the problem in the TOML file ``path``."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ProblemError(f"{path}: cannot read problem file ({exc.strerror})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProblemError(f"{path}: not valid TOML ({exc})") from None
    data.setdefault("name", path.stem)
    return problem_from_dict(data, source=str(path))


def problem_from_dict(data: dict[str, Any], source: str = "problem") -> DesignProblem:
    """Validate a problem given as a dict (the parsed TOML)."""
    try:
        spec = ProblemSpec.model_validate(data)
    except ValidationError as exc:
        lines = []
        for err in exc.errors():
            loc = ".".join(str(p) for p in err["loc"] if not str(p).startswith("function-"))
            msg = err["msg"].removeprefix("Value error, ")
            if err["type"] == "extra_forbidden":
                msg = "unknown field"
            lines.append(f"{loc}: {msg}")
        raise ProblemError(f"{source}: invalid problem file\n  " + "\n  ".join(lines)) from None
    variables = [_variable(spec.mechanism, name, raw) for name, raw in spec.variables.items()]
    return DesignProblem(spec, variables)


def _variable(mechanism: str, name: str, raw: Any) -> Variable:
    known = VARIABLE_DIMENSIONS[mechanism]
    field = f"variables.{name}"
    if name not in known:
        raise ProblemError(
            f"{field}: unknown variable for a {mechanism} (known: {', '.join(known)})"
        )
    dim = known[name]
    unit = UNITS[dim]
    desc = VARIABLE_DESCRIPTIONS[name]

    def q(value: Any, sub: str) -> float:
        try:
            return to_internal(value, dim, f"{field}.{sub}" if sub else field)
        except InputError as exc:
            raise ProblemError(str(exc)) from None

    if not isinstance(raw, dict):
        value = q(raw, "")
        _check_sign(name, value, field)
        return Variable(name, desc, unit, value=value)
    allowed = {"value", "lower", "upper", "start", "values", "catalogue"}
    extra = set(raw) - allowed
    if extra:
        raise ProblemError(
            f"{field}.{sorted(extra)[0]}: unknown field (allowed: {sorted(allowed)})"
        )
    if "value" in raw:
        if set(raw) - {"value"}:
            raise ProblemError(f"{field}: a fixed value excludes bounds and catalogues")
        value = q(raw["value"], "value")
        _check_sign(name, value, field)
        return Variable(name, desc, unit, value=value)
    lower = q(raw["lower"], "lower") if "lower" in raw else None
    upper = q(raw["upper"], "upper") if "upper" in raw else None
    values = None
    if "values" in raw or "catalogue" in raw:
        if "values" in raw:
            if not isinstance(raw["values"], list) or not raw["values"]:
                raise ProblemError(f"{field}.values: must be a non-empty list")
            values = [q(v, f"values[{k}]") for k, v in enumerate(raw["values"])]
        else:
            cat = raw["catalogue"]
            if cat not in CATALOGUES:
                raise ProblemError(
                    f"{field}.catalogue: unknown catalogue {cat!r} (known: {', '.join(CATALOGUES)})"
                )
            values = list(CATALOGUES[cat])
        if lower is not None:
            values = [v for v in values if v >= lower - 1e-12]
        if upper is not None:
            values = [v for v in values if v <= upper + 1e-12]
        if not values:
            raise ProblemError(f"{field}: no catalogue value lies within the bounds")
        values = sorted(set(values))
        lower, upper = values[0], values[-1]
    if lower is None or upper is None:
        missing = "lower" if lower is None else "upper"
        raise ProblemError(f"{field}.{missing}: a free variable needs both bounds")
    if lower > upper:
        raise ProblemError(
            f"{field}: lower bound {lower:g} {unit} is above upper bound {upper:g} {unit}"
        )
    _check_sign(name, lower, f"{field}.lower")
    start = q(raw["start"], "start") if "start" in raw else None
    if start is not None and not lower <= start <= upper:
        raise ProblemError(f"{field}.start: {start:g} lies outside [{lower:g}, {upper:g}]")
    if lower == upper:
        return Variable(name, desc, unit, value=lower)
    return Variable(name, desc, unit, lower, upper, None, tuple(values) if values else None, start)


def _check_sign(name: str, value: float, field: str) -> None:
    if name in POSITIVE and not value > 0:
        raise ProblemError(f"{field}: must be positive, got {value:g}")
