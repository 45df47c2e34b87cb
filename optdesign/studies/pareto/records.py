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
from typing import Any

import numpy as np

from optdesign.problem.design_problem import DesignProblem, relative_violation
from optdesign.solvers.result import Result, clean_json
from optdesign.studies.solve import finish
from optdesign.studies.verify import VERIFY_TOL


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
    """How an anchor's multistart went: starts planned, run, and agreeing on the best."""

    n_starts: int
    n_planned: int
    n_at_best: int
    agree: int | None
    stopped_early: bool


@dataclass
class PointRecord:
    """One stored record (see the module docstring); ``kind`` says which task made it."""

    id: str
    kind: str
    status: str
    verified: bool | None
    target: str
    message: str = ""
    x: list[float] | None = None
    design: dict[str, float] = field(default_factory=dict)
    objectives: dict[str, float] = field(default_factory=dict)
    eps: dict[str, float] = field(default_factory=dict)
    weights: dict[str, float] = field(default_factory=dict)
    active: list[str] = field(default_factory=list)
    violated: list[str] = field(default_factory=list)
    wall_time_s: float = 0.0
    iterations: int | None = None
    solver: str = ""
    fallback: str = ""
    raw: RawSolution | None = None
    multistart: AnchorStarts | None = None
    order: list[str] = field(default_factory=list)
    n_solves: int = 1
    slope: float | None = None
    warm: str | None = None
    retried: str = ""

    @property
    def ok(self) -> bool:
        """A verified, feasible point."""
        return self.status in ("optimal", "feasible") and self.verified is True

    def to_dict(self) -> dict[str, Any]:
        d = {
            f.name: getattr(self, f.name)
            for f in fields(self)
            if f.name not in ("raw", "multistart")
        }
        out = clean_json(d)
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
            if np.isfinite(v) and relative_violation(result.objectives[k], None, v) > VERIFY_TOL:
                status = "infeasible"
                result.verified = False
    active = sorted(
        {r.name for r in result.active if "_envelope[" not in r.name},
        key=lambda s: (s.split("[")[0], s),
    )
    raw = None
    if result.raw and nlp_fingerprint:
        raw = RawSolution(
            np.asarray(result.raw["z"], dtype=float),
            np.asarray(result.raw["lam_x"], dtype=float),
            np.asarray(result.raw["lam_g"], dtype=float),
            nlp_fingerprint,
        )
    return PointRecord(
        id=task_id,
        kind=kind,
        status=status,
        verified=result.verified,
        target=target,
        message=result.message,
        x=x,
        design=dict(result.design),
        objectives=dict(result.objectives),
        eps={k: float(v) for k, v in eps.items() if np.isfinite(v)},
        active=active,
        violated=[r.name for r in result.violated][:20],
        wall_time_s=result.wall_time_s,
        iterations=result.iterations,
        solver=result.solver,
        fallback=str(result.extra.get("fallback", "")),
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
