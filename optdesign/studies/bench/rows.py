"""One benchmark run as a typed record: :class:`BenchRow`.

A run is computed in a forked child (:mod:`.sandbox`), which returns the row as a JSON
dict; the runner streams that dict to ``bench_runs.jsonl``. Everything after the store
reads :class:`BenchRow`: :func:`~optdesign.studies.bench.run.run_bench` converts each
record once (:meth:`BenchRow.from_dict`, which also refuses a stored row that is not one),
and the metrics, the report and :class:`~optdesign.studies.bench.BenchReport` read
attributes. :meth:`BenchRow.to_dict` gives back the stored JSON exactly (the same keys,
in the same order, with the same values), so a store written before this record existed
resumes, and one written since reads as before.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

#: Keys every stored row has, with the JSON type each holds ("number": int or float, not
#: bool). A row from the sandbox or from a failure in the worker always has them.
REQUIRED: dict[str, str] = {
    "instance": "text",
    "family": "text",
    "seed": "integer",
    "mechanism": "text",
    "objective_name": "text",
    "catalogue": "flag",
    "config": "text",
    "kind": "text",
    "applicable": "flag",
    "status": "text",
    "success": "flag",
    "time_s": "number",
}

#: Computed from all rows of a benchmark (:func:`~optdesign.studies.bench.scoring.add_gaps`),
#: never stored.
DERIVED = ("gap", "best_known", "hypervolume")


class BenchRowError(ValueError):
    """A stored row that is not a benchmark row; the message says why (read after
    "record ID ...")."""


@dataclass
class BenchRow:
    """One (instance, configuration) run of the benchmark.

    Attributes
    ----------
    instance, family, seed, mechanism
        The instance (``family-seed``; ``family`` ``"user"`` for the caller's problems)
        and its mechanism.
    objective_name
        The objective minimised (``"a+b"`` for a front instance).
    catalogue
        The instance has catalogue variables.
    config, kind
        The configuration run and its kind (``"nlp"``, ``"gp"``, ``"de"``, ``"front"``,
        ``"debug"``).
    applicable
        False when the configuration does not apply (status ``"n/a"``; left out of the
        statistics).
    status, reason, success
        The run's status (a solver status, or ``"timeout"``, ``"crash"``, ``"error"``,
        ``"skipped"``, ``"n/a"``), why, and whether it counts (:func:`is_success` of the
        status and the independent check).
    time_s
        Wall time of the run (catalogue combinations summed).
    objective, violation, verified
        The objective and the largest violation on the NumPy path at the row's design, and
        whether the independent check passed (None: no design to check). The check
        covers the bounds, every requirement and every objective (a finite number within
        its physical range, :attr:`~optdesign.problem.objectives.ObjectiveInfo.valid`):
        a design it refuses is not recorded (objective and design None, the reason says
        why), so a row never holds a NaN or a negative ripple as its objective.
    iterations, n_evals, n_subproblems
        Solver iterations, evaluation counters (summed over catalogue combinations), and
        the number of continuous problems solved (catalogue combinations).
    design, solver_objective
        The design (internal units): the best solved one, else the best verified point of
        an unfinished solve (time or iteration limit, a solver failure: not a success),
        else None; and the objective the solver reported there, for a success only (an
        unfinished iterate's epigraph variable is no objective).
    front
        A front run's objective vectors.
    id
        The runner's task id (``instance|config``).
    gap, best_known, hypervolume
        Computed over the whole benchmark (:func:`~.metrics.add_gaps`), never stored:
        the gap to the best value any configuration found on the instance (None for a
        failure), that best value, a front's hypervolume.
    stored_keys
        The keys of the stored JSON row, in its order (rows differ in which they carry:
        an n/a row has no objective, a failure no design); empty for a row built in code,
        whose :meth:`to_dict` writes every stored field.
    """

    instance: str
    family: str
    seed: int
    mechanism: str
    objective_name: str
    catalogue: bool
    config: str
    kind: str
    applicable: bool = True
    status: str = "failed"
    reason: str = ""
    success: bool = False
    time_s: float = 0.0
    objective: float | None = None
    violation: float | None = None
    verified: bool | None = None
    iterations: int | None = None
    n_evals: dict[str, int] = field(default_factory=dict)
    n_subproblems: int | None = None
    design: dict[str, float] | None = None
    solver_objective: float | None = None
    front: list[list[float]] | None = None
    id: str = ""
    gap: float | None = None
    best_known: float | None = None
    hypervolume: float | None = None
    stored_keys: tuple[str, ...] = field(default=(), repr=False, compare=False)

    @property
    def is_front(self) -> bool:
        """A front run (its measure is a hypervolume, not an objective)."""
        return self.front is not None

    def to_dict(self) -> dict[str, Any]:
        """The row as stored in ``bench_runs.jsonl`` (the keys it was read with, in their
        order), with ``gap``, ``best_known`` and ``hypervolume`` where computed."""
        keys = self.stored_keys or tuple(k for k in _STORED if k != "id" or self.id)
        out = {k: getattr(self, k) for k in keys}
        for k in DERIVED:
            if getattr(self, k) is not None and k not in out:
                out[k] = getattr(self, k)
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> BenchRow:
        """The row of a stored JSON dict (values as stored: nothing is converted).

        Raises
        ------
        BenchRowError
            A required key is missing or of the wrong type, a key is unknown, the time is
            not a finite number of seconds >= 0, or the objective is not a number.
        """
        if not isinstance(data, Mapping):
            raise BenchRowError("is not a table")
        if not isinstance(data.get("status"), str) or not isinstance(data.get("success"), bool):
            raise BenchRowError("has no status or success flag")
        t = data.get("time_s")
        if not (is_number(t) and math.isfinite(t) and t >= 0):
            raise BenchRowError(f"has a time that is not a finite number ({t!r:.40})")
        if data.get("objective") is not None and not is_number(data["objective"]):
            raise BenchRowError("has an objective that is not a number")
        for key, kind in REQUIRED.items():
            if not _is(kind, data.get(key)):
                raise BenchRowError(f"has no {kind} field {key!r}")
        unknown = [k for k in data if k not in _STORED and k not in DERIVED]
        if unknown:
            raise BenchRowError(f"has an unknown field {unknown[0]!r}")
        return cls(**dict(data), stored_keys=tuple(data))


def is_number(v: Any) -> bool:
    """An int or a float, not a bool (JSON's numbers)."""
    return isinstance(v, int | float) and not isinstance(v, bool)


def _is(kind: str, v: Any) -> bool:
    if kind == "text":
        return isinstance(v, str)
    if kind == "flag":
        return isinstance(v, bool)
    if kind == "integer":
        return isinstance(v, int) and not isinstance(v, bool)
    return is_number(v)


#: The fields a stored row may carry, in the order a row built in code writes them.
_STORED = tuple(f.name for f in fields(BenchRow) if f.name not in (*DERIVED, "stored_keys"))
