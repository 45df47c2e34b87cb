"""The mechanism's necessary conditions, checked on a problem before any solve: the
stroke, the mechanism's own requirements and the variables' bounds handed to
:meth:`~optdesign.mechanisms.base.Mechanism.impossible`.

A proof found here is the verdict of the solve (``od.solve``, ``optdesign solve``): no
multistart runs and no relaxation is searched, and the summary names the requirements in
the conflict and what would lift it. No proof says nothing: the problem may still be
infeasible, which the search then finds.
"""

from __future__ import annotations

from typing import Any

from optdesign.errors import ProblemError
from optdesign.models.impossibility import Impossibility
from optdesign.user_code import call_method


def impossibilities(problem: Any) -> list[Impossibility]:
    """The proofs of :meth:`Mechanism.impossible` for ``problem`` (a
    :class:`~optdesign.problem.design_problem.DesignProblem`): empty when none holds."""
    req = problem.spec.requirements
    stroke = (float(req.deflection.min), float(req.deflection.max))
    own = {
        name: getattr(req, name)
        for name in problem.mechanism.requirements
        if getattr(req, name, None) is not None
    }
    # a variable the file omits holds its declared default
    bounds = {
        name: (float(info.default), float(info.default))
        for name, info in problem.mechanism.variable_table().items()
        if info.default is not None
    }
    bounds.update({v.name: _range(v) for v in problem.variables})
    found = call_method(
        problem.mechanism, "impossible", stroke, own, bounds, doing="checking the stroke"
    )
    if not isinstance(found, list | tuple) or not all(isinstance(f, Impossibility) for f in found):
        raise ProblemError(
            f"mechanism {problem.mechanism.label()!r}: impossible() must return a list of "
            f"Impossibility records, got {type(found).__name__}"
        )
    return list(found)


def _range(var: Any) -> tuple[float, float]:
    """A variable's (lower, upper): its bounds, its catalogue's items, or its value."""
    if var.lower is not None and var.upper is not None:
        return float(var.lower), float(var.upper)
    if var.values:
        return float(min(var.values)), float(max(var.values))
    return float(var.value), float(var.value)
