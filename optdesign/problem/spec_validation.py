"""A problem's spec validated against its mechanism's schema, with refusals that name
the field (the unknown one with the nearest valid name). Shared by the loader, a
problem's edits (:meth:`DesignProblem.set_objective`) and its unpickling.
"""

from __future__ import annotations

import difflib
import re
from typing import Any, get_args

from pydantic import ValidationError

from optdesign.errors import ProblemError
from optdesign.problem.spec import ProblemSpec, spec_model
from optdesign.problem.spec_types import expected
from optdesign.units import Bare


def validate_spec(
    data: dict[str, Any],
    mechanism: type,
    source: str = "problem",
    internal: bool = False,
    bare: Bare = "internal",
    folder: str | None = None,
) -> ProblemSpec:
    """Validate ``data`` against the schema of ``mechanism``; ProblemError naming fields.

    ``internal``: ``data`` is a validated spec's own dump (numbers in internal units).
    ``bare``: a bare number for a dimensioned field is internal, or refused (files).
    ``folder``: where a file the problem names (a motor CSV) is read from (the problem
    file's folder; None: the working folder).
    The error is one line: every invalid field with its reason, an unknown field with the
    nearest valid name.
    """
    model = spec_model(mechanism)
    context = {"internal": internal, "bare": "internal" if internal else bare, "folder": folder}
    try:
        return model.model_validate(data, context=context)
    except ValidationError as exc:
        lines = []
        for err in exc.errors():
            parts = [str(p) for p in err["loc"] if not str(p).startswith("function-")]
            # a list's item as in the file's arrays: duty_cycle[0].time, not duty_cycle.0.time
            loc = ".".join(parts).replace(".[", "[")
            loc = re.sub(r"\.(\d+)(?=\.|$)", r"[\1]", loc)
            msg = err["msg"].removeprefix("Value error, ")
            if err["type"] == "missing":
                msg = "missing (a required field)"
            if err["type"] == "extra_forbidden":
                msg = "unknown field" + _did_you_mean(model, parts)
            if err["type"] in ("model_type", "dict_type"):  # `screw = 5`: say what it takes
                target = _model_at(model, parts)
                what = expected(target) if target is not None else "a table"
                msg = f"expected {what}, got {_shown(err['input'])}"
            head = re.match(r"(\w+): ", msg)  # a table's check naming its own field
            if head is not None:
                loc, msg = f"{loc}.{head.group(1)}" if loc else head.group(1), msg[head.end() :]
            lines.append(f"{loc}: {msg}")
        more = f" (and {len(lines) - 3} more)" if len(lines) > 3 else ""
        raise ProblemError(f"{source}: {'; '.join(lines[:3])}{more}") from None


def _did_you_mean(model: type, parts: list[str]) -> str:
    """`` (did you mean 'x'?; valid: ...)`` for the unknown last key of ``parts``."""
    # Walk the schema to the table that holds the key.
    for key in parts[:-1]:
        field = getattr(model, "model_fields", {}).get(key)
        if field is None:
            return ""
        model = _model_of(field.annotation)
        if model is None:
            return ""
    names = list(getattr(model, "model_fields", {}))
    close = difflib.get_close_matches(parts[-1], names, n=1, cutoff=0.6)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return f"{hint} (valid: {', '.join(names)})" if len(names) <= 40 else hint


def _model_at(model: type, parts: list[str]) -> type | None:
    """The pydantic model of the table at ``parts`` of ``model``'s schema, if any."""
    for key in parts:
        field = getattr(model, "model_fields", {}).get(key)
        found = None if field is None else _model_of(field.annotation)
        if found is None:
            return None
        model = found
    return model


def _shown(value: Any) -> str:
    """A value as a problem file writes it (``true``, ``5``, ``'HIWIN'``), cut short."""
    text = str(value).lower() if isinstance(value, bool) else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _model_of(annotation: Any) -> type | None:
    """The pydantic model inside ``annotation`` (``X``, ``X | None``, ``Annotated[X, ...]``)."""
    if isinstance(annotation, type) and hasattr(annotation, "model_fields"):
        return annotation
    for arg in get_args(annotation):
        found = _model_of(arg)
        if found is not None:
            return found
    return None
