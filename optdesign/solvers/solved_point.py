"""The one record of a solved point and the one rule of its success.

:class:`SolvedPoint` holds what every solved point has, whoever solved it and wherever it
is kept: a solve's :class:`~optdesign.solvers.result.Result`, a front task's stored
record (:class:`~optdesign.studies.pareto.records.PointRecord`) and a front's point
(:class:`~optdesign.studies.pareto.front.FrontPoint`) derive from it, and
:func:`is_success` is the rule all of them (and a benchmark run) count a success by.
This module imports nothing of optdesign: every layer may read a solved point.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

#: The statuses of a solve that found a design meeting the requirements.
SOLVED_STATUSES = ("optimal", "feasible")


def is_success(status: str, verified: bool | None = None) -> bool:
    """The one success rule of a solved point (a result, a front's record or point, a
    bench run): a status of :data:`SOLVED_STATUSES` that the independent check on the
    NumPy path did not refuse (``verified`` False). ``verified`` None means not checked
    (yet): a result before :func:`optdesign.formulations.nlp.solve.finish`; a stored front
    record that claims success unchecked is refused before it is read
    (:func:`optdesign.studies.pareto.records.record_problem`)."""
    return status in SOLVED_STATUSES and verified is not False


@dataclass(kw_only=True)
class SolvedPoint:
    """What every solved point has (built by keyword: its subclasses add their own
    fields, and the files they are written to keep their own key order).

    Attributes
    ----------
    status
        The one status word (``"optimal"``, ``"feasible"``, ``"infeasible"``,
        ``"failed"``, ``"max_iterations"``, ``"time_limit"``, ...).
    verified
        The independent check on the NumPy path (None: not checked).
    message
        The back-end's own message, or why the point failed.
    design
        The full design (internal units; empty when the solve returned none).
    objectives
        Every objective of the problem at the design (checked on the NumPy path).
    wall_time_s
        Wall time of the solve.
    iterations
        Solver iterations (None: not reported).
    solver
        The solver back-end that computed the point ("" when none did).
    """

    status: str
    verified: bool | None = None
    message: str = ""
    design: dict[str, float] = field(default_factory=dict)
    objectives: dict[str, float] = field(default_factory=dict)
    wall_time_s: float = 0.0
    iterations: int | None = None
    solver: str = ""

    @property
    def success(self) -> bool:
        """A feasible design the independent check did not refuse (:func:`is_success`)."""
        return is_success(self.status, self.verified)


#: The names of the fields every solved point has, in their order.
SHARED_FIELDS = tuple(f.name for f in fields(SolvedPoint))


def shared_fields(point: SolvedPoint) -> dict[str, Any]:
    """The shared part of ``point`` as keyword arguments of any :class:`SolvedPoint`
    (its design and objectives copied): how one kind of solved point is made from
    another."""
    out = {name: getattr(point, name) for name in SHARED_FIELDS}
    out["design"] = dict(point.design)
    out["objectives"] = dict(point.objectives)
    return out


def in_key_order(d: dict[str, Any], keys: tuple[str, ...]) -> dict[str, Any]:
    """``d`` with ``keys`` first, in their order, then its other keys: a record written
    with the key order its files have always had, whatever its fields' order."""
    return {**{k: d[k] for k in keys if k in d}, **d}
