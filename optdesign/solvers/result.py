"""One result schema for every solver (after Pyomo's contrib.solver results).

``termination`` says why the solver stopped, ``solution_status`` what the returned point
is; ``status`` is the one word users and scripts read ("optimal", "feasible",
"infeasible", "failed", "max_iterations", "time_limit").
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from enum import Enum, StrEnum
from typing import Any


class TerminationCondition(StrEnum):
    """Why the solver stopped."""

    CONVERGED = "converged"
    ACCEPTABLE = "acceptable"
    MAX_ITERATIONS = "max_iterations"
    MAX_TIME = "max_time"
    INFEASIBLE = "infeasible"
    UNBOUNDED = "unbounded"
    NUMERICAL_ERROR = "numerical_error"
    ERROR = "error"
    INTERRUPTED = "interrupted"
    UNKNOWN = "unknown"


class SolutionStatus(StrEnum):
    """What the returned point is."""

    OPTIMAL = "optimal"
    FEASIBLE = "feasible"
    INFEASIBLE = "infeasible"
    NO_SOLUTION = "no_solution"


@dataclass
class ConstraintReport:
    """One constraint row at the returned point, in the problem's units.

    ``amount`` is the violation (> 0 violated) in the constraint's unit.
    """

    name: str
    value: float
    lower: float | None
    upper: float | None
    amount: float = 0.0
    unit: str = ""

    def describe(self) -> str:
        bound = []
        if self.lower is not None:
            bound.append(f">= {self.lower:.6g}")
        if self.upper is not None:
            bound.append(f"<= {self.upper:.6g}")
        text = f"{self.name} = {self.value:.6g} {self.unit} ({' and '.join(bound)})".replace(
            "  ", " "
        )
        if self.amount > 0:
            text += f", violated by {self.amount:.3g} {self.unit}".rstrip()
        return text


@dataclass
class MultistartInfo:
    """How a multistart went."""

    n_starts: int
    n_converged: int
    n_at_best: int
    tolerance: float
    objectives: list[float] = field(default_factory=list)
    seed: int = 0
    workers: int = 1


@dataclass
class Result:
    """Outcome of one optimisation, whatever the solver."""

    status: str
    objective: float
    design: dict[str, float]
    solver: str
    formulation: str
    wall_time_s: float
    termination: TerminationCondition = TerminationCondition.UNKNOWN
    solution_status: SolutionStatus = SolutionStatus.NO_SOLUTION
    message: str = ""
    objectives: dict[str, float] = field(default_factory=dict)
    iterations: int | None = None
    n_evals: dict[str, int] = field(default_factory=dict)
    violated: list[ConstraintReport] = field(default_factory=list)
    active: list[ConstraintReport] = field(default_factory=list)
    max_violation: float = math.nan
    verified: bool | None = None
    multistart: MultistartInfo | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    # solver internals kept for warm starts (not written to JSON)
    raw: dict[str, Any] = field(default_factory=dict, repr=False)

    @property
    def success(self) -> bool:
        """A feasible design was found (optimal or feasible)."""
        return self.status in ("optimal", "feasible")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (enums as strings, NaN as None, no solver internals)."""
        d = asdict(self)
        d.pop("raw", None)
        d["termination"] = self.termination.value
        d["solution_status"] = self.solution_status.value
        return _clean(d)

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), indent=kw.pop("indent", 2), **kw)


def _clean(obj):
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    if isinstance(obj, Enum):
        return obj.value
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if hasattr(obj, "item") and callable(obj.item):  # numpy scalars
        return _clean(obj.item())
    return obj
