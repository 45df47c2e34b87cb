"""What a store must match before its records are reused: format, identity, records.

A store's first line carries the run's identity (:func:`optdesign.storage.open_store`).
Since store format 2 it holds the identity's *components* - for a front: the problem's
content, its formulation, the objectives, the method's settings, the solver and every
solver option, the optdesign version - with a hash of them all as ``key``. A resume whose
identity differs is refused naming the components that changed (:func:`describe_difference`);
a store of another format is refused naming its version (:func:`version_problem`); and
each stored record must pass the run's own check (finite objectives, a design inside the
bounds that the independent check confirms...) before it is trusted
(:func:`check_records`).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Mapping
from typing import Any

#: Labels of the usual components in messages (others are shown by their own name).
LABELS = {
    "problem": "the problem's content",
    "formulation": "the problem's formulation (its functions, bounds and scales)",
    "objectives": "the objectives",
    "method": "the method's settings",
    "solver": "the solver or its options",
    "optdesign": "the optdesign version",
    "problems": "the problems' content or their [solver] options",
    "runs": "the instances or configurations",
    "time_limit": "the time limit",
    "hard_timeout": "the hard timeout",
    "suite": "the suite",
}

#: Longest value shown in a message (longer ones are only named).
_SHOWN = 80


def canonical(obj: Any) -> str:
    """Canonical JSON of ``obj`` (sorted keys; non-JSON values as text): what is hashed."""
    return json.dumps(obj, sort_keys=True, default=str, separators=(",", ":"))


def digest(obj: Any, n: int = 16) -> str:
    """A short content hash of ``obj`` (its canonical JSON)."""
    return hashlib.sha256(canonical(obj).encode()).hexdigest()[:n]


def identity_key(key: str | Mapping[str, Any] | None) -> str | None:
    """The ``key`` stored for an identity: the string itself, or the hash of the components."""
    if key is None or isinstance(key, str):
        return key
    return digest(dict(key))


def _flat(obj: Any, prefix: str = "") -> dict[str, Any]:
    """Nested dicts as dotted paths (``solver.ipopt.tol``), for naming what changed."""
    if isinstance(obj, Mapping) and obj:
        out: dict[str, Any] = {}
        for k, v in obj.items():
            out.update(_flat(v, f"{prefix}.{k}" if prefix else str(k)))
        return out
    return {prefix: obj}


def _shown(value: Any) -> str:
    text = "absent" if value is _ABSENT else canonical(value)
    return text if len(text) <= _SHOWN else text[: _SHOWN - 3] + "..."


_ABSENT = object()


def describe_difference(
    stored: Mapping[str, Any] | None,
    stored_key: str | None,
    new: Mapping[str, Any] | None,
    new_key: str | None,
) -> str:
    """Which components of a run's identity changed, with the old and new values."""
    if stored is None or new is None:
        return f"its identity is {stored_key!r}, this run's {new_key!r}"
    parts = []
    for comp in [*new, *(k for k in stored if k not in new)]:
        old_v, new_v = stored.get(comp, _ABSENT), new.get(comp, _ABSENT)
        if canonical(old_v) == canonical(new_v) and (old_v is _ABSENT) == (new_v is _ABSENT):
            continue
        label = LABELS.get(comp, comp)
        a = _flat(old_v) if isinstance(old_v, Mapping) else {"": old_v}
        b = _flat(new_v) if isinstance(new_v, Mapping) else {"": new_v}
        details = []
        for path in [*b, *(p for p in a if p not in b)]:
            x, y = a.get(path, _ABSENT), b.get(path, _ABSENT)
            if x is not _ABSENT and y is not _ABSENT and canonical(x) == canonical(y):
                continue
            where = f"{comp}.{path}" if path else comp
            details.append(f"{where}: stored {_shown(x)}, now {_shown(y)}")
        parts.append(f"{label} changed ({'; '.join(details[:3])})")
    return "; ".join(parts) or "its identity differs"


def version_problem(has_identity: bool, version: Any, current: int) -> str | None:
    """Why a store of format ``version`` cannot be read by this optdesign (None: it can)."""
    if not has_identity or (type(version) is int and version == current):
        return None
    if type(version) is int and version > current:
        who = "a newer optdesign"
    elif type(version) is int:
        who = "an older optdesign"
    else:
        who = "something other than optdesign"
    return (
        f"it is in store format {_shown(version)[:40]} (written by {who}); this optdesign "
        f"reads format {current} only"
    )


def check_records(
    records: Mapping[str, Mapping[str, Any]],
    lines: Mapping[str, int],
    check: Callable[[Mapping[str, Any]], str | None],
) -> tuple[str, int | str, str] | None:
    """The first record that fails ``check``: (id, line, why), or None if all pass.

    Records are trusted (shown, verified, used as warm starts) only once checked: a
    hand-edited NaN or a design outside the bounds refuses the resume.
    """
    for rid, record in records.items():
        try:
            why = check(record)
        except Exception as exc:  # a check that cannot read the record: not a record
            why = f"cannot be read ({type(exc).__name__}: {exc})"
        if why:
            return rid, lines.get(rid, "?"), why
    return None
