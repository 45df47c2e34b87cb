"""Solver back-ends behind one contract and one :class:`~optdesign.solvers.result.Result`.

Solvers see generic formulations (an NLP in scaled variables, a GP); none of them knows a
mechanism. :func:`make_solver` builds any registered back-end; :func:`register_solver`
adds one.
"""

from optdesign.solvers.registry import make_solver, register_solver, solver_names
from optdesign.solvers.result import (
    Certificate,
    ConstraintReport,
    MultistartInfo,
    Result,
    SolutionStatus,
    TerminationCondition,
)

__all__ = [
    "Certificate",
    "ConstraintReport",
    "MultistartInfo",
    "Result",
    "SolutionStatus",
    "TerminationCondition",
    "make_solver",
    "register_solver",
    "solver_names",
]
