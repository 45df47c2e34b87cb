"""Why a solve found no feasible design, whatever the formulation: the best point found
(its violated requirements by name and amount) and the smallest relaxation of each
requirement in the conflict (:mod:`optdesign.formulations.nlp.relaxation`), or why there
is none.

:func:`diagnose` fills :attr:`Result.diagnosis <optdesign.solvers.result.Result>` of a
result that is not a success (``od.solve(..., diagnose=True)``, the default; the CLI's
``--no-diagnosis`` turns it off). What the relaxations rest on depends on the
formulation, which brings its own diagnosis (its ``diagnose``: ``nlp_diagnosis``,
``catalogue_diagnosis``, ``gp_diagnosis``, ``robust_diagnosis`` in their packages), and
the diagnosis says it in its ``basis``. This module holds what they share: the checks
before any relaxation and the words of the note.

A condition of the physics (:attr:`~optdesign.problem.objectives.ConstraintBlock.physical`:
the linkage passes no dead point and assembles) is never relaxed: a design beyond it
does not work at all. The diagnosis names those the best point violates
(``Diagnosis.physical``), and the summary says that the stroke or the bounds must
change.

A result whose best point violates no requirement (a solver that stopped early, a
catalogue search that missed every feasible item) gets no relaxation but a note saying
so: the problem may well be feasible. A best point whose models are used outside their
ranges of validity gets none either: relaxing a requirement cannot bring a model back
into its range; the note names the models and quantities, and the inputs to check.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from optdesign.display.limits import limits_of
from optdesign.problem.design_problem import DesignProblem
from optdesign.problem.requirements import physical_conditions
from optdesign.problem.validity import is_validity
from optdesign.solvers.constraint_rows import constraint_rows
from optdesign.solvers.registry import solver_for_kind
from optdesign.solvers.result import ConstraintReport, Diagnosis, Result


@dataclass(frozen=True)
class Relaxing:
    """How a diagnosis relaxes the requirements.

    Attributes
    ----------
    solver, options
        The NLP back-end of the relaxations and its options (a GP back-end, or None: the
        registry's default for an NLP).
    relax
        False: the best point only, no relaxation (e.g. for an error message).
    """

    solver: str | None = None
    options: Mapping[str, Any] | None = None
    relax: bool = True


#: A formulation's own diagnosis of a result with no feasible design (``how.solver``: an
#: NLP back-end, resolved by :func:`diagnose`).
Diagnoser = Callable[[DesignProblem, Result, Relaxing], Diagnosis]


def diagnose(
    problem: DesignProblem, result: Result, how: Relaxing | None = None, *, by: Diagnoser
) -> Result:
    """Fill ``result.diagnosis`` (and, when the formulation returned no point, the best
    point found) of a result that is not a success, by the formulation's own diagnosis
    ``by``, relaxing as ``how`` says (None: the default NLP back-end); returns
    ``result``."""
    how = how or Relaxing()
    if result.success:
        return result
    outside = [r for r in result.violated if is_validity(r)]
    if outside:
        result.diagnosis = Diagnosis(basis="the best point found", note=validity_note(outside))
        return result
    result.diagnosis = by(problem, result, replace(how, solver=solver_for_kind(how.solver, "nlp")))
    violated = {r.name.split("[", 1)[0] for r in result.violated}
    result.diagnosis.physical = sorted(violated & physical_conditions(problem))
    missed = [r for r in result.diagnosis.relaxations if r.needed == r.written]
    if missed:
        # a relaxation of nothing: the diagnosis met every requirement as written
        where = f" with {missed[0].at}" if missed[0].at else ""
        found = (
            f"a design meeting every requirement as written exists{where} (found while "
            f"relaxing {missed[0].name}): the solve missed it ({result.status}); more starts "
            "(starts=) may find it"
        )
        old = result.diagnosis.note
        result.diagnosis.note = f"{found}; {old}" if old else found
    return result


def validity_note(outside: list[ConstraintReport]) -> str:
    """Why a best point outside its models' ranges gets no relaxation, naming them."""
    what = sorted({r.name.removeprefix("validity: ").split("[", 1)[0] for r in outside})
    shown = "; ".join(what[:4]) + (f"; and {len(what) - 4} more" if len(what) > 4 else "")
    return (
        f"the best point found lies outside the range where its models hold ({shown}): "
        "no relaxation of a requirement brings a model back into its range; check the "
        "inputs those models read (the pin's material and lug, the fit, [clearances], "
        "pin_length_ratio) and the bounds of the variables (docs/validity.md)"
    )


def nothing_violated(result: Result) -> str:
    """Why a best point that violates no requirement gets no relaxation."""
    return (
        f"no requirement is violated at the best point found: the solver stopped "
        f"({result.status}: {result.message or result.termination.value}) without proving "
        "the problem infeasible; more starts (starts=) may find a feasible design"
    )


def best_point(
    objective: str,
    active: list[ConstraintReport],
    violated: list[ConstraintReport],
    z: Any = None,
) -> Result:
    """A result holding only what :func:`~optdesign.formulations.nlp.relaxation.relaxations`
    reads: the rows of a best point (and its NLP vector)."""
    point = Result(
        status="infeasible", objective=math.nan, formulation="", objective_name=objective
    )
    point.active, point.violated = active, violated
    if z is not None:
        point.raw["z"] = z
    return point


def adopt(result: Result, other: Result) -> None:
    """Give ``result`` the best point of ``other`` (a solve of the same problem)."""
    result.design = dict(other.design)
    result.objectives = dict(other.objectives)
    result.objective = other.objectives.get(result.objective_name, other.objective)
    result.violated, result.active = list(other.violated), list(other.active)
    result.verified = other.verified
    result.max_violation = other.max_violation


def violated_text(problem: DesignProblem, x: np.ndarray, limit: int = 8) -> str:
    """The requirements design ``x`` (free-variable vector) violates, by name and amount
    in the problem file's units, in one line ("" when it meets them all)."""
    _, violated = constraint_rows(problem, np.asarray(x, dtype=float))
    return "; ".join(lim.text() for lim in limits_of(problem, violated)[:limit])
