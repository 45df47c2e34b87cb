"""What a formulation is: a way to solve a design problem, and everything that depends on
how it solved it.

A formulation is any object with a ``name``, a ``description`` and these members
(:class:`Formulation`):

- ``applies(problem, request)``: ``True`` when it can solve ``problem`` as ``request``
  asks (its objective included), else the reason it cannot (a string; ``False`` for no
  reason given);
- ``solve(problem, request) -> Result``;
- ``diagnose(problem, result, request)``: fill ``result.diagnosis`` of a result that is
  not a success (the smallest relaxation of each conflicting requirement);
- ``sensitivities(problem, result, request)``: fill what the optimum's neighbourhood
  says, as ``request`` asks: what each requirement costs (``result.sensitivities``,
  ``result.item_steps``) and the range of each variable over the near-optimal set
  (``result.ranges``);
- ``details``: the type of its typed record, which it keeps in ``result.details[name]``
  (None: it keeps none).

Optional: ``time_limit`` (default False: the solve does not stop at
``request.time_limit``, and a result solved under one says so in a note) and
``check(problem, request)`` (refuse, before any work, a request it cannot honour although
it applies).

Only ``name``, ``applies`` and ``solve`` are required: a formulation without
``diagnose`` or ``sensitivities`` gets the NLP's (:data:`NLP_EVIDENCE`), which read the
result's own rows and multipliers. :class:`FormulationBase` gives those defaults to a
subclass, and loads its functions by import path on first call: a built-in formulation's
package declares one subclass of it, naming its functions.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Protocol, runtime_checkable

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem
    from optdesign.problem.request import SolveRequest
    from optdesign.solvers.result import Result


@runtime_checkable
class Formulation(Protocol):
    """A way to solve a problem, with its diagnosis and sensitivities (see the module's
    docstring)."""

    name: str
    description: str
    details: type | None

    def applies(self, problem: DesignProblem, request: SolveRequest) -> bool | str: ...

    def solve(self, problem: DesignProblem, request: SolveRequest) -> Result: ...

    def diagnose(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None: ...

    def sensitivities(
        self, problem: DesignProblem, result: Result, request: SolveRequest
    ) -> None: ...


def _load(ref: str | Callable[..., Any]) -> Callable[..., Any]:
    if callable(ref):
        return ref
    module, _, attr = ref.partition(":")
    return getattr(importlib.import_module(module), attr)


class FormulationBase:
    """A formulation whose functions are ``"module:function"`` paths, imported on first
    call (listing the formulations imports no solver library), with the defaults of the
    optional members: no time limit, no record, no check, and the NLP's diagnosis and
    sensitivities. A built-in formulation's package subclasses it with its own paths.

    Attributes
    ----------
    applies_by, solve_by
        ``(problem, request) -> bool | str`` and ``(problem, request) -> Result``.
    diagnosis_by
        Its own diagnosis, a :data:`~optdesign.formulations.diagnosis.Diagnoser`
        (default: the NLP's relaxations).
    sensitivities_by
        ``(problem, result, request) -> None`` (default: the NLP's, which read only an
        NLP's own result); "" when the solve reports them already.
    """

    name: ClassVar[str]
    description: ClassVar[str] = ""
    details: ClassVar[type | None] = None
    time_limit: ClassVar[bool] = False
    applies_by: ClassVar[str] = ""
    solve_by: ClassVar[str] = ""
    diagnosis_by: ClassVar[str] = "optdesign.formulations.nlp.diagnosis:nlp_diagnosis"
    sensitivities_by: ClassVar[str] = "optdesign.formulations.nlp.sensitivities:nlp_evidence"

    def applies(self, problem: DesignProblem, request: SolveRequest) -> bool | str:
        """True, or the reason the formulation cannot solve ``problem`` as asked."""
        return _load(self.applies_by)(problem, request)

    def solve(self, problem: DesignProblem, request: SolveRequest) -> Result:
        """The formulation's result for ``problem`` as ``request`` asks."""
        return _load(self.solve_by)(problem, request)

    def check(self, problem: DesignProblem, request: SolveRequest) -> None:
        """Refuse, before any work, a request the formulation cannot honour (nothing)."""

    def diagnose(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """Fill ``result.diagnosis`` with the formulation's own diagnosis."""
        from optdesign.formulations.diagnosis import Relaxing, diagnose

        how = Relaxing(request.solver, request.options)
        diagnose(problem, result, how, by=_load(self.diagnosis_by))

    def sensitivities(self, problem: DesignProblem, result: Result, request: SolveRequest) -> None:
        """Fill what the optimum's neighbourhood says, as ``request`` asks."""
        if self.sensitivities_by:
            _load(self.sensitivities_by)(problem, result, request)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r})"


#: The evidence of a formulation that brings none of its own.
NLP_EVIDENCE = FormulationBase()


def diagnose_with(formulation: Any) -> Callable[[DesignProblem, Result, SolveRequest], None]:
    """``formulation``'s diagnosis (the NLP's when it has none)."""
    return getattr(formulation, "diagnose", None) or NLP_EVIDENCE.diagnose


def sensitivities_with(
    formulation: Any,
) -> Callable[[DesignProblem, Result, SolveRequest], None]:
    """``formulation``'s sensitivities (the NLP's when it has none)."""
    return getattr(formulation, "sensitivities", None) or NLP_EVIDENCE.sensitivities


def check_with(formulation: Any, problem: DesignProblem, request: SolveRequest) -> None:
    """Run ``formulation``'s refusals before any work (none when it has no ``check``)."""
    check = getattr(formulation, "check", None)
    if check is not None:
        check(problem, request)


@dataclass(frozen=True)
class LazyFormulation:
    """A :class:`Formulation` whose two functions are ``"module:function"`` paths (or
    callables), imported on first call; its diagnosis and sensitivities are the NLP's."""

    name: str
    solver: str | Callable[[DesignProblem, SolveRequest], Result]
    predicate: str | Callable[[DesignProblem, SolveRequest], bool | str]
    description: str = ""
    time_limit: bool = False

    def applies(self, problem: DesignProblem, request: SolveRequest) -> bool | str:
        """True, or the reason the formulation cannot solve ``problem`` as asked."""
        return _load(self.predicate)(problem, request)

    def solve(self, problem: DesignProblem, request: SolveRequest) -> Result:
        """The formulation's result for ``problem`` as ``request`` asks."""
        return _load(self.solver)(problem, request)
