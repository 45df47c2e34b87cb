"""Solver back-ends behind one contract and one :class:`~optdesign.solvers.result.Result`.

Solvers see generic formulations (an NLP in scaled variables, a GP); none of them knows a
mechanism. :func:`make_solver` builds any registered back-end; :func:`register_solver`
adds one with what it declares of itself (:class:`SolverHints`), which the studies ask
for (:func:`solver_hints`, :func:`default_solver`) instead of naming a back-end.
"""

from optdesign.solvers.registry import (
    SolverHints,
    default_solver,
    make_solver,
    register_solver,
    solver_hints,
    solver_names,
)
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
    "SolverHints",
    "TerminationCondition",
    "default_solver",
    "make_solver",
    "register_solver",
    "solver_hints",
    "solver_names",
]
