"""What makes a success a verified result.

From the API: a :class:`Result` that says optimal or feasible, carries ``verified =
True``, whose design is finite, inside the bounds and on the catalogue, and which the
problem re-evaluated now (NumPy path) finds feasible with the same objective; a front
whose points are all that and not dominated; a benchmark with rows. From the CLI: a
``result.json`` saying optimal and verified, with a finite objective and every free
variable inside its bounds; a ``front.csv`` whose on-front rows are verified and finite.
"""

from __future__ import annotations

import csv
import io
import math
from typing import Any

#: Relative tolerance of a bound or of a re-evaluated objective.
TOL = 1e-6


def _finite(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _inside(v: float, lo: float | None, hi: float | None) -> bool:
    if lo is not None and v < lo - TOL * max(1.0, abs(lo)):
        return False
    return not (hi is not None and v > hi + TOL * max(1.0, abs(hi)))


def result_problems(result: Any) -> list[str]:
    """Why an API :class:`Result` is not a verified success (empty: it is)."""
    import numpy as np

    out = []
    if not result.success:
        return [f"status {result.status!r} ({result.message})"]
    if result.verified is not True:
        out.append(f"verified is {result.verified!r}")
    if not _finite(result.objective):
        out.append(f"objective {result.objective!r} is not finite")
    problem = result.problem_object
    if problem is None:
        return [*out, "the result carries no problem"]
    x = []
    for v in problem.free:
        val = result.design.get(v.name)
        if not _finite(val):
            out.append(f"design {v.name} = {val!r} is not finite")
            return out
        if not _inside(val, v.lower, v.upper):
            out.append(f"design {v.name} = {val} outside [{v.lower}, {v.upper}]")
        if v.values is not None and not any(abs(val - c) <= 1e-9 * max(1, c) for c in v.values):
            out.append(f"design {v.name} = {val} is not a catalogue value")
        x.append(val)
    if not problem.free:
        return out
    ev = problem.evaluate(np.array(x, dtype=float))
    if not ev.violation <= TOL:
        out.append(f"re-evaluated, the design violates a requirement by {ev.violation:.3g}")
    name = result.objective_name
    if name in ev.objectives and _finite(result.objective):
        again = float(ev.objectives[name])
        if not abs(again - result.objective) <= 1e-5 * max(1.0, abs(again)):
            out.append(f"objective {result.objective} but {again} re-evaluated")
    return out


def front_problems(front: Any) -> list[str]:
    """Why a :class:`Front` is not a verified front."""
    out = []
    if not front.points:
        return ["the front has no point"]
    objs = front.objectives
    problem = getattr(front, "problem_object", None)
    F = []
    for p in front.points:
        if not p.success or p.verified is not True:
            out.append(f"point {p.id}: status {p.status}, verified {p.verified}")
        for v in problem.free if problem is not None else []:
            val = p.design.get(v.name)
            if not _finite(val) or not _inside(val, v.lower, v.upper):
                out.append(f"point {p.id}: {v.name} = {val!r} outside [{v.lower}, {v.upper}]")
        vals = [p.objectives.get(k) for k in objs]
        if not all(_finite(v) for v in vals):
            out.append(f"point {p.id}: objectives {vals} not finite")
            continue
        F.append(vals)
    for i, a in enumerate(F):
        for j, b in enumerate(F):
            strictly = any(bb < aa - 1e-7 * max(1, abs(aa)) for aa, bb in zip(a, b, strict=True))
            if i != j and all(bb <= aa + 1e-9 for aa, bb in zip(a, b, strict=True)) and strictly:
                out.append(f"front point {i} is dominated by point {j}")
                return out
    return out


def value_problems(value: Any) -> list[str]:
    """Verification of whatever an API call returned."""
    kind = type(value).__name__
    if kind == "Result":
        return result_problems(value)
    if kind == "Front":
        return front_problems(value)
    if kind == "BenchReport":
        rows = getattr(value, "rows", None)
        return [] if rows else ["the benchmark has no row"]
    if isinstance(value, list | tuple):
        return [p for v in value for p in value_problems(v)]
    return []  # a problem, a dict: the case's own check verifies it


def failure_text(value: Any) -> str:
    """What an API failure (a result or a front that is not a success) says, for the
    names an infeasible case must find."""
    kind = type(value).__name__
    if kind == "Result":
        rows = [r.name for r in value.violated]
        return " ".join([value.status, value.message, *rows, *value.notes])
    if kind == "Front":
        pts = [*value.points, *value.rejected]
        return " ".join(f"{p.status} {p.message} {p.rejected} {' '.join(p.active)}" for p in pts)
    return repr(value)[:2000]


def doc_problems(doc: Any) -> list[str]:
    """Why a ``result.json`` document is not a verified success."""
    if not isinstance(doc, dict):
        return ["result.json is not an object"]
    out = []
    if doc.get("status") not in ("optimal", "feasible") or doc.get("success") is not True:
        return [f"status {doc.get('status')!r}"]
    if doc.get("verified") is not True:
        out.append(f"verified is {doc.get('verified')!r}")
    obj = (doc.get("objective") or {}).get("value")
    if not _finite(obj):
        out.append(f"objective {obj!r} is not finite")
    for name, entry in (doc.get("design") or {}).items():
        v = entry.get("value") if isinstance(entry, dict) else None
        if not _finite(v):
            out.append(f"design {name} = {v!r} is not finite")
        elif not entry.get("fixed") and not _inside(v, entry.get("lower"), entry.get("upper")):
            out.append(f"design {name} = {v} outside [{entry.get('lower')}, {entry.get('upper')}]")
    if doc.get("violated"):
        out.append(f"violated: {doc['violated'][:2]}")
    return out


def front_csv_problems(text: str) -> list[str]:
    """Why a ``front.csv`` is not a verified front (its on-front rows)."""
    rows = list(csv.DictReader(io.StringIO(text, newline="")))
    front = [r for r in rows if r.get("on_front") == "True"]
    if not front:
        return ["front.csv has no point on the front"]
    out = []
    fixed = {"method", "id", "status", "verified", "on_front", "active"}
    for r in front:
        if r.get("verified") != "True" or r.get("status") not in ("optimal", "feasible"):
            out.append(
                f"front.csv {r.get('id')}: status {r.get('status')}, verified {r.get('verified')}"
            )
        for k, v in r.items():
            if k not in fixed:
                try:
                    ok = math.isfinite(float(v))
                except (TypeError, ValueError):
                    ok = False
                if not ok:
                    out.append(f"front.csv {r.get('id')}: {k} = {v!r}")
                    break
    return out
