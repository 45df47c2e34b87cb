"""The GP formulation's typed record (``result.details["gp"]``): the back-end's dual and
timing, the program's size, and the exact NLP solved beside it.

``result.json`` writes its fields at the top of ``"extra"`` (``gp_dual``, ``gp_timing``,
``gp_rows``, ``nlp_exact``, ``gap_gp_nlp_rel``), the keys earlier releases wrote.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from optdesign.solvers.details import GPBackEndDetails


@dataclass
class GPRows:
    """Sizes of the geometric program: objective rows, constraint rows, rows before the
    pruning of dominated ones."""

    objective: int
    constraints: int
    before_pruning: int


@dataclass
class ExactNLP:
    """The exact NLP (exact Hertz) solved from the GP design, for the GP's model gap."""

    status: str
    objective: float
    design: dict[str, float | None]
    wall_time_s: float
    starts: int


@dataclass
class GPDetails(GPBackEndDetails):
    """A GP solve: its dual and timing (the back-end's :class:`~optdesign.solvers.details.
    GPBackEndDetails`), its size, and the exact NLP compared with it."""

    rows: GPRows | None = None
    nlp_exact: ExactNLP | None = None
    #: (GP optimum - exact NLP optimum) / |exact NLP optimum| (NaN: the NLP failed).
    gap_gp_nlp_rel: float | None = None

    @classmethod
    def of(cls, solved: GPBackEndDetails | None) -> GPDetails:
        """The record of a GP solve, started from what its back-end reported."""
        if isinstance(solved, GPDetails):
            return solved
        if solved is None:
            return cls()
        return cls(dual=solved.dual, timing=solved.timing)

    def to_json(self) -> dict[str, Any]:
        out = super().to_json()
        if self.rows is not None:
            out["gp_rows"] = asdict(self.rows)
        if self.nlp_exact is not None:
            out["nlp_exact"] = asdict(self.nlp_exact)
        if self.gap_gp_nlp_rel is not None:
            out["gap_gp_nlp_rel"] = self.gap_gp_nlp_rel
        return out
