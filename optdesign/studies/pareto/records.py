"""Typed records of a front's computation, as stored (one JSON line per task).

A :class:`PointRecord` is what a task returns: the checked result of one solve (an
anchor's multistart, a tie-break, an epsilon point, a weighted-sum point) with what the
next tasks need (the solution and multipliers for warm starts, the front's local slope).
Records cross processes and the resumable store as JSON dicts (:meth:`PointRecord.
to_dict` / :meth:`PointRecord.from_dict`); floats survive exactly (``json`` writes
``repr``), so a resumed chain of warm starts is the same computation.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from typing import Any, ClassVar

import numpy as np

from optdesign.formulations.nlp.solution import nlp_solution
from optdesign.formulations.nlp.solve import finish
from optdesign.formulations.verify import verify_design
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.evaluation import relative_violation
from optdesign.solvers.result import Result, clean_json
from optdesign.solvers.solved_point import SolvedPoint, in_key_order, shared_fields
from optdesign.tolerances import FEASIBILITY_TOL


@dataclass
class RawSolution:
    """A solver's final point and multipliers, for warm starts of later solves.

    ``nlp`` is the fingerprint of the formulation they belong to: primal and dual values
    are reused only on the same formulation (same variables and rows).
    """

    z: np.ndarray
    lam_x: np.ndarray
    lam_g: np.ndarray
    nlp: str

    def to_dict(self) -> dict[str, Any]:
        return {
            "z": json_vector(self.z),
            "lam_x": json_vector(self.lam_x),
            "lam_g": json_vector(self.lam_g),
            "nlp": self.nlp,
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> RawSolution:
        return cls(vector(d["z"]), vector(d["lam_x"]), vector(d["lam_g"]), str(d["nlp"]))


@dataclass
class AnchorStarts:
    """How an anchor's global search went: starts planned, run and agreeing on the best;
    the distinct optima the counted starts reached, the estimated probability that a
    better one exists, and why the search stopped (:mod:`optdesign.search`)."""

    n_starts: int
    n_planned: int
    n_at_best: int
    agree: int | None
    stopped_early: bool
    optima: int = 0
    counted: int = 0
    p_better: float | None = None
    stop: str = ""


@dataclass(kw_only=True)
class PointRecord(SolvedPoint):
    """One stored record (see the module docstring): a solved point
    (:class:`~optdesign.solvers.solved_point.SolvedPoint`, whose success rule it keeps)
    with what the front's next tasks need. Built by keyword.

    Attributes
    ----------
    id, kind, target
        The task's id, which task made it (``"anchor"``, ``"eps"``, ...), the objective
        it minimised.
    x
        The free variables' values, in the problem's order (None: no design).
    eps, weights
        The epsilon bounds, or the weights, that defined the point.
    active, violated
        The names of the active and violated rows (a :class:`Result` keeps the rows).
    fallback
        What replaced a failed solve ("" when none did).
    raw, multistart
        The warm start of later solves; an anchor's multistart.
    order, n_solves, slope, warm, retried
        An anchor's order of objectives; the solves behind the point; the front's local
        slope; the record it started warm from; why it was re-solved.
    """

    id: str
    kind: str
    target: str
    x: list[float] | None = None
    eps: dict[str, float] = field(default_factory=dict)
    weights: dict[str, float] = field(default_factory=dict)
    active: list[str] = field(default_factory=list)
    violated: list[str] = field(default_factory=list)
    fallback: str = ""
    raw: RawSolution | None = None
    multistart: AnchorStarts | None = None
    order: list[str] = field(default_factory=list)
    n_solves: int = 1
    slope: float | None = None
    warm: str | None = None
    retried: str = ""

    #: The key order of :meth:`to_dict`: the one the front stores have always had.
    KEYS: ClassVar[tuple[str, ...]] = (
        "id",
        "kind",
        "status",
        "verified",
        "target",
        "message",
        "x",
        "design",
        "objectives",
        "eps",
        "weights",
        "active",
        "violated",
        "wall_time_s",
        "iterations",
        "solver",
    )

    def to_dict(self) -> dict[str, Any]:
        d = {
            f.name: getattr(self, f.name)
            for f in fields(self)
            if f.name not in ("raw", "multistart")
        }
        out = clean_json(in_key_order(d, self.KEYS))
        out["raw"] = self.raw.to_dict() if self.raw is not None else None
        out["multistart"] = asdict(self.multistart) if self.multistart is not None else None
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PointRecord:
        names = {f.name for f in fields(cls)}
        kw = {k: v for k, v in d.items() if k in names}
        kw["raw"] = RawSolution.from_dict(d["raw"]) if d.get("raw") else None
        kw["multistart"] = AnchorStarts(**d["multistart"]) if d.get("multistart") else None
        for key in ("design", "objectives", "eps", "weights"):
            kw[key] = {k: (math.nan if v is None else v) for k, v in (d.get(key) or {}).items()}
        return cls(**kw)


def record_from_result(
    problem: DesignProblem,
    result: Result,
    kind: str,
    target: str,
    eps: Mapping[str, float],
    task_id: str = "",
    nlp_fingerprint: str = "",
) -> PointRecord:
    """Check a result independently (NumPy path, epsilon bounds included) and record it."""
    result = finish(problem, result, target)
    status = result.status
    x = [result.design[v.name] for v in problem.free] if result.design else None
    if result.design and result.objectives:
        # The epsilon bounds are constraints of this point: check them on the NumPy path too.
        for k, v in eps.items():
            if (
                np.isfinite(v)
                and relative_violation(result.objectives[k], None, v) > FEASIBILITY_TOL
            ):
                status = "infeasible"
                result.verified = False
    active = sorted(
        {r.name for r in result.active if "_envelope[" not in r.name},
        key=lambda s: (s.split("[")[0], s),
    )
    raw = None
    solution = nlp_solution(result) if nlp_fingerprint else None
    if solution is not None:
        raw = RawSolution(solution.z, solution.lam_x, solution.lam_g, nlp_fingerprint)
    return PointRecord(
        **{**shared_fields(result), "status": status},
        id=task_id,
        kind=kind,
        target=target,
        x=x,
        eps={k: float(v) for k, v in eps.items() if np.isfinite(v)},
        active=active,
        violated=[r.name for r in result.violated][:20],
        fallback=result.details.fallback,
        raw=raw,
    )


def json_vector(v) -> list | dict:
    """A float vector as a JSON-able list (non-finite entries as None) or, when most
    entries are exactly zero (SLSQP's multipliers of inactive rows), as ``{"size",
    "index", "value"}`` of the nonzero ones: same values, ~20x smaller."""
    a = np.asarray(v, dtype=float).ravel()
    nz = np.flatnonzero(a != 0.0)
    if 2 * len(nz) < len(a):
        return {"size": len(a), "index": nz.tolist(), "value": _finite_list(a[nz])}
    return _finite_list(a)


def _finite_list(a: np.ndarray) -> list:
    out = a.tolist()
    if not np.isfinite(a).all():
        out = [x if math.isfinite(x) else None for x in out]
    return out


def vector(obj) -> np.ndarray:
    """Inverse of :func:`json_vector` (None -> nan)."""
    if isinstance(obj, dict):
        a = np.zeros(int(obj["size"]))
        a[np.asarray(obj["index"], dtype=int)] = np.asarray(
            [math.nan if v is None else v for v in obj["value"]], dtype=float
        )
        return a
    return np.asarray([math.nan if v is None else v for v in obj], dtype=float)


# --- trusting a stored record -----------------------------------------------------------
#: A stored objective must equal its recomputation at the stored design to this
#: (relative): the same code on the same design gives the same value, so a larger
#: difference is a record edited by hand or damaged.
RECHECK_RTOL = 1e-7

#: How far (relative to the span, at least 1) a stored design may lie outside the bounds.
BOUNDS_RTOL = 1e-9

_TEXT = ("kind", "status", "target")
_OPTIONAL_TEXT = ("message", "solver", "fallback", "retried")
_TABLES = ("design", "objectives", "eps", "weights")
_LISTS = ("active", "violated", "order")


def _num(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def _vector_ok(v: Any) -> bool:
    if isinstance(v, dict):
        return (
            isinstance(v.get("size"), int)
            and isinstance(v.get("index"), list)
            and isinstance(v.get("value"), list)
            and len(v["index"]) == len(v["value"])
            and all(isinstance(i, int) and 0 <= i < v["size"] for i in v["index"])
            and all(x is None or _num(x) for x in v["value"])
        )
    return isinstance(v, list) and all(x is None or _num(x) for x in v)


def _shape_problem(d: Mapping[str, Any]) -> str | None:
    """Why ``d`` is not a front record as this code writes them (None: it is one)."""
    for name in _TEXT:
        if not isinstance(d.get(name), str):
            return f"has no text field {name!r}"
    for name in _OPTIONAL_TEXT:
        if name in d and not isinstance(d[name], str):
            return f"field {name!r} is not text"
    if d.get("verified") not in (True, False, None):
        return "field 'verified' is not true, false or null"
    for name in _TABLES:
        table = d.get(name)
        if table is not None and not (
            isinstance(table, dict) and all(v is None or _num(v) for v in table.values())
        ):
            return f"field {name!r} is not a table of numbers"
    for name in _LISTS:
        items = d.get(name)
        if items is not None and not (
            isinstance(items, list) and all(isinstance(s, str) for s in items)
        ):
            return f"field {name!r} is not a list of names"
    if d.get("x") is not None and not (
        isinstance(d["x"], list) and all(v is None or _num(v) for v in d["x"])
    ):
        return "field 'x' is not a list of numbers"
    for name, ok in (
        ("wall_time_s", lambda v: _num(v)),
        ("n_solves", lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0),
        ("iterations", lambda v: v is None or (isinstance(v, int) and not isinstance(v, bool))),
        ("slope", lambda v: v is None or _num(v)),
        ("warm", lambda v: v is None or isinstance(v, str)),
    ):
        if name in d and not ok(d[name]):
            return f"field {name!r} has a value of the wrong type ({d[name]!r:.40})"
    raw = d.get("raw")
    if raw is not None and not (
        isinstance(raw, dict)
        and isinstance(raw.get("nlp"), str)
        and all(_vector_ok(raw.get(k)) for k in ("z", "lam_x", "lam_g"))
    ):
        return "field 'raw' is not a solution with its multipliers"
    ms = d.get("multistart")
    if ms is not None:
        names = {f.name for f in fields(AnchorStarts)}
        if not isinstance(ms, dict) or set(ms) != names:
            return "field 'multistart' is not a multistart record"
    return None


def record_problem(problem: DesignProblem, record: Mapping[str, Any], nlp=None) -> str | None:
    """Why a stored front record cannot be trusted, or None if it can.

    Every record must have the fields and types this code writes. A record that counts
    as a solution (status optimal or feasible, not refused by the independent check)
    must also hold: a design with every free variable, finite and inside the bounds
    (catalogue variables on a catalogue value, fixed variables at their value), finite
    objectives equal (to :data:`RECHECK_RTOL`) to the NumPy path's at that design, no
    violated requirement and its epsilon bounds met - the independent check, again.
    With ``nlp`` (the formulation), a stored warm start of that formulation must have
    its size.
    """
    why = _shape_problem(record)
    if why is not None:
        return why
    rec = PointRecord.from_dict(record)
    if rec.raw is not None and nlp is not None and rec.raw.nlp == nlp.fingerprint:
        if len(rec.raw.z) != len(nlp.lbz) or len(rec.raw.lam_x) != len(nlp.lbz):
            return "holds a warm start of the wrong size"
        if not np.isfinite(rec.raw.z).all():
            return "holds a warm start that is not finite"
    if not rec.success:
        return None  # shown as failed: never trusted as a design
    if rec.verified is not True:
        return f"has status {rec.status!r} without the independent check"
    return _design_problem(problem, rec)


def _design_problem(problem: DesignProblem, rec: PointRecord) -> str | None:
    free = problem.free
    missing = [v.name for v in free if v.name not in rec.design]
    if missing:
        return f"has no value of {missing[0]} in its design"
    x = np.array([rec.design[v.name] for v in free], dtype=float)
    lo, hi = problem.lower(), problem.upper()
    for k, v in enumerate(free):
        tol = BOUNDS_RTOL * max(hi[k] - lo[k], 1.0)
        if not (math.isfinite(x[k]) and lo[k] - tol <= x[k] <= hi[k] + tol):
            return f"has {v.name} = {x[k]:.10g} {v.unit}, outside its bounds [{lo[k]:g}, {hi[k]:g}]"
        if v.discrete and min(abs(x[k] - c) for c in v.values) > tol:
            return f"has {v.name} = {x[k]:.10g} {v.unit}, not one of its catalogue values"
    for name, value in problem.fixed_values.items():
        stored = rec.design.get(name, value)
        if not math.isclose(stored, value, rel_tol=1e-12, abs_tol=1e-15):
            # every digit shown: a difference the tolerance sees must be visible
            return f"has the fixed variable {name} = {stored!r}, the problem {value!r}"
    if rec.x is not None and (
        len(rec.x) != len(x) or not np.allclose(rec.x, x, rtol=1e-12, atol=0.0, equal_nan=False)
    ):
        return "has an 'x' that is not its design"
    for name, value in rec.objectives.items():
        if not math.isfinite(value):
            return f"has objective {name} = {value}"
    ok, violated, objectives = verify_design(problem, x)
    if not ok:
        return f"has a design that violates {violated[0].describe()}"
    for name, value in objectives.items():
        value = float(value)
        if name not in rec.objectives:
            return f"has no value of objective {name}"
        stored = rec.objectives[name]
        if abs(stored - value) > RECHECK_RTOL * max(abs(value), 1e-12):
            return f"has objective {name} = {stored:.10g}, but its design gives {value:.10g}"
    for name, bound in rec.eps.items():
        if (
            name in objectives
            and relative_violation(float(objectives[name]), None, bound) > FEASIBILITY_TOL
        ):
            return f"has objective {name} above its epsilon bound {bound:.10g}"
    return None
