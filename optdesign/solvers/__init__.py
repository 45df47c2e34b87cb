"""Solver back-ends behind one :class:`~optdesign.solvers.result.Result` type.

Solvers see generic problems (an NLP in scaled variables, a cvxpy problem, a vectorised
objective); none of them knows a mechanism.
"""

from optdesign.solvers.result import (
    ConstraintReport,
    MultistartInfo,
    Result,
    SolutionStatus,
    TerminationCondition,
)

__all__ = ["ConstraintReport", "MultistartInfo", "Result", "SolutionStatus", "TerminationCondition"]
