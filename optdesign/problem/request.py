"""What a caller asks of a solve, in one typed record: :class:`SolveRequest`.

:func:`optdesign.solve` checks its arguments (:mod:`optdesign.validation`) and builds the
request once; the formulation registry (:mod:`optdesign.formulations.registry`)
picks a formulation with it, and the formulation solves with it - no argument list is
written twice on the way down. A formulation of a user's own receives the same record
(``solve(problem, request)``). The record knows no solver and no formulation: a name
here is checked by the layer that knows the registries.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem


@dataclass(frozen=True)
class SolveRequest:
    """One solve's request: the objective, the formulation asked for, the multistart,
    the back-end and what to compute beside the optimum.

    Attributes
    ----------
    objective
        The objective to minimise (:meth:`for_problem` resolves None to the problem's
        first).
    formulation
        ``"auto"`` or a registered formulation's name.
    starts, seed
        Multistart size and Sobol seed (None: the formulation's default from the
        problem file's ``[solver]``).
    workers
        Local processes for the starts.
    solver, options
        Registered back-end (None: the formulation's default) and its options.
    agree
        NLP multistart: stop once this many starts agree (None: the file's; 0: every
        start).
    time_limit
        Wall-clock seconds of the NLP multistart (None: no limit).
    target_odds
        NLP global search: also go on until the estimated probability that a better
        local optimum exists is below this (None: the stopping rule's own threshold).
    ranges, diagnose, sensitivities
        Also the ranges of the optimal set, the diagnosis of a result with no feasible
        design, what each requirement costs at the optimum.
    contact_models
        Also the backlash of the optimum under each pin contact model (a note).
    """

    objective: str
    formulation: str = "auto"
    starts: int | None = None
    seed: int | None = None
    workers: int = 1
    solver: str | None = None
    options: Mapping[str, Any] | None = None
    agree: int | None = None
    time_limit: float | None = None
    target_odds: float | None = None
    ranges: bool = True
    diagnose: bool = True
    sensitivities: bool = True
    contact_models: bool = False

    @classmethod
    def for_problem(
        cls, problem: DesignProblem, objective: str | None = None, **fields: Any
    ) -> SolveRequest:
        """The request of ``problem`` with ``fields`` (the arguments a caller checked);
        ``objective`` None: the problem's first."""
        return cls(objective=objective or problem.objective_names[0], **fields)
