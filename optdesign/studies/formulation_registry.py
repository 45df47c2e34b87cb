"""The formulations a solve can take, registered by name, and the choice among them.

A formulation is any object with a ``name``, a ``description`` and two methods
(:class:`Formulation`):

- ``applies(problem, request)``: ``True`` when it can solve ``problem`` as ``request``
  asks (its objective included), else the reason it cannot (a string; ``False`` for no
  reason given);
- ``solve(problem, request) -> Result``.

``formulation="auto"`` takes the first registered formulation that applies, in this
order: catalogue (a variable takes catalogue values: never solved as continuous), robust
(the file has tolerances: never ignored), gp (the problem is a geometric program in the
chosen objective), then the formulations registered by a user's code in their order,
and nlp last. A formulation named by the caller that does not apply is refused before
any work, with its reason (``--formulation gp: problem 'x' is not a geometric program:
...``).

Adding one is one object and one :func:`register_formulation` line (``od.
register_formulation``). The built-in ones are :class:`LazyFormulation`\\ s: their
functions are import paths, loaded on first call, so that listing the formulations (the
argument checks do) imports no solver library.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from optdesign.errors import InputError, ProblemError
from optdesign.problem.request import SolveRequest

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem
    from optdesign.solvers.result import Result


@runtime_checkable
class Formulation(Protocol):
    """A way to solve a problem (see the module's docstring).

    ``time_limit`` (optional, default False): the solve stops at ``request.time_limit``;
    otherwise a result solved under a time limit says in a note that it was not
    applied."""

    name: str
    description: str

    def applies(self, problem: DesignProblem, request: SolveRequest) -> bool | str: ...

    def solve(self, problem: DesignProblem, request: SolveRequest) -> Result: ...


def _load(ref: str | Callable[..., Any]) -> Callable[..., Any]:
    if callable(ref):
        return ref
    module, _, attr = ref.partition(":")
    return getattr(importlib.import_module(module), attr)


@dataclass(frozen=True)
class LazyFormulation:
    """A :class:`Formulation` whose two functions are ``"module:function"`` paths (or
    callables), imported on first call."""

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


#: name -> formulation, in the order ``auto`` tries them (nlp last).
FORMULATIONS: dict[str, Formulation] = {}


def register_formulation(formulation: Formulation, replace: bool = False) -> Formulation:
    """Register ``formulation`` under its ``name`` (``auto`` tries the formulations in
    registration order, nlp last); a name registered already is replaced only with
    ``replace=True``."""
    name = getattr(formulation, "name", None)
    if not isinstance(name, str) or not name.strip() or not name.isprintable() or name == "auto":
        raise InputError("register_formulation.name", f"expected a name (a string), got {name!r}")
    for method in ("applies", "solve"):
        if not callable(getattr(formulation, method, None)):
            raise InputError(
                f"register_formulation.{method}",
                f"{formulation!r} has no {method}(problem, request) method",
            )
    if name in FORMULATIONS and not replace:
        raise InputError("register_formulation", f"a formulation {name!r} is registered already")
    FORMULATIONS[name] = formulation
    if "nlp" in FORMULATIONS and name != "nlp":
        FORMULATIONS["nlp"] = FORMULATIONS.pop("nlp")
    return formulation


def formulation_names() -> list[str]:
    """The registered formulations' names, in the order ``auto`` tries them."""
    return list(FORMULATIONS)


def why_not(formulation: Formulation, problem: DesignProblem, request: SolveRequest) -> str | None:
    """None when ``formulation`` applies to ``problem`` as ``request`` asks, else the
    reason it does not."""
    verdict = formulation.applies(problem, request)
    if isinstance(verdict, str):
        return verdict or f"does not apply to problem {problem.name!r}"
    return None if verdict else f"does not apply to problem {problem.name!r}"


def pick_formulation(problem: DesignProblem, request: SolveRequest) -> Formulation:
    """The formulation of ``request``: the one it names, refused with its reason when it
    does not apply (a problem with no free variable is checked, whichever it names), or
    for ``auto`` the first that applies, with the request's objective."""
    requested = request.formulation
    if requested != "auto":
        if requested not in FORMULATIONS:
            raise InputError(
                "formulation",
                f"unknown formulation {requested!r} (known: auto, {', '.join(FORMULATIONS)})",
            )
        formulation = FORMULATIONS[requested]
        reason = why_not(formulation, problem, request) if problem.free else None
        if reason is not None:
            raise ProblemError(f"formulation={requested!r}: {reason}")
        return formulation
    reasons = []
    for name, formulation in FORMULATIONS.items():
        reason = why_not(formulation, problem, request)
        if reason is None:
            return formulation
        reasons.append(f"{name}: {reason}")
    raise ProblemError("formulation='auto': no formulation applies (" + "; ".join(reasons) + ")")


def choose_formulation(
    problem: DesignProblem, requested: str = "auto", objective: str | None = None
) -> str:
    """The name of the formulation a solve of ``problem`` takes for ``requested`` and
    ``objective`` (None: the problem's first)."""
    request = SolveRequest.for_problem(problem, objective, formulation=requested)
    return pick_formulation(problem, request).name


for _formulation in (
    LazyFormulation(
        "catalogue",
        "optdesign.studies.catalogue:solve_catalogue_formulation",
        "optdesign.studies.catalogue:catalogue_applies",
        "branch and bound (or enumeration) over the catalogue values, NLP at each node",
    ),
    LazyFormulation(
        "robust",
        "optdesign.studies.robust:solve_robust_formulation",
        "optdesign.studies.robust:robust_applies",
        "risk measure (CVaR or mean + k std) of the objective under the tolerances",
    ),
    LazyFormulation(
        "gp",
        "optdesign.studies.gp:solve_gp_formulation",
        "optdesign.studies.gp:gp_applies",
        "geometric program (first-order Hertz) with a dual certificate, exact NLP beside it",
    ),
    LazyFormulation(
        "nlp",
        "optdesign.studies.nlp_solve:solve_nlp_formulation",
        "optdesign.studies.nlp_solve:nlp_applies",
        "NLP (epigraph form) with Sobol multistart",
        time_limit=True,
    ),
):
    register_formulation(_formulation)
