"""Design problems: declared variables, objectives and constraints, from a problem file.

A problem file (TOML, see ``problems/``) is validated into a :class:`ProblemSpec`
(:mod:`optdesign.problem.spec`) and turned into a :class:`DesignProblem`
(:mod:`optdesign.problem.design_problem`), which states the objectives and constraints as
expressions of the design variables, on the CasADi path or the NumPy path alike.
"""

from optdesign.problem.design_problem import ConstraintBlock, DesignProblem, ObjectiveTerm, Variable
from optdesign.problem.load import load_problem, problem_from_dict

__all__ = [
    "ConstraintBlock",
    "DesignProblem",
    "ObjectiveTerm",
    "Variable",
    "load_problem",
    "problem_from_dict",
]
