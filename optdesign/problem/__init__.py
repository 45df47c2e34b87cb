"""Design problems: declared variables, objectives and constraints, from a file or Python.

A problem file (TOML, see ``problems/``) or a dict is validated against the schema of the
mechanism it names (:mod:`optdesign.problem.spec`) and turned into a
:class:`DesignProblem`, which states the objectives and constraints as expressions of the
design's quantities, on the CasADi path or the NumPy path alike.
"""

from optdesign.problem.design_problem import DesignProblem, Expressions
from optdesign.problem.evaluation import Evaluation
from optdesign.problem.load import load, load_problem, problem_from_dict
from optdesign.problem.objectives import (
    BUILTIN_OBJECTIVES,
    ConstraintBlock,
    ConstraintInfo,
    ObjectiveInfo,
    ObjectiveTerm,
)
from optdesign.problem.quantities import Quantities
from optdesign.problem.variables import Variable

__all__ = [
    "BUILTIN_OBJECTIVES",
    "ConstraintBlock",
    "ConstraintInfo",
    "DesignProblem",
    "Evaluation",
    "Expressions",
    "ObjectiveInfo",
    "ObjectiveTerm",
    "Quantities",
    "Variable",
    "load",
    "load_problem",
    "problem_from_dict",
]
