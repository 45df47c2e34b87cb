"""The formulations a solve can take, registered by name, and the choice among them.

A formulation (:class:`~optdesign.formulations.protocol.Formulation`) says whether it
applies to a problem and solves it, and brings its own diagnosis, sensitivities and typed
record; each built-in one is a package of :mod:`optdesign.formulations` (``nlp``, ``gp``,
``catalogue``, ``robust``) registered below in one line.

``formulation="auto"`` takes the first registered formulation that applies, in this
order: catalogue (a variable takes catalogue values: never solved as continuous), robust
(the file has tolerances: never ignored), gp (the problem is a geometric program in the
chosen objective), then the formulations registered by a user's code in their order,
and nlp last. A formulation named by the caller that does not apply is refused before
any work, with its reason (``--formulation gp: problem 'x' is not a geometric program:
...``).

Adding one is one object and one :func:`register_formulation` line (``od.
register_formulation``). The built-in ones import their solvers on first call, so that
listing the formulations (the argument checks do) imports no solver library.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from optdesign.errors import InputError, ProblemError
from optdesign.formulations.catalogue import CatalogueFormulation
from optdesign.formulations.gp import GPFormulation
from optdesign.formulations.nlp import NLPFormulation
from optdesign.formulations.protocol import Formulation as Formulation
from optdesign.formulations.protocol import LazyFormulation as LazyFormulation
from optdesign.formulations.robust import RobustFormulation
from optdesign.problem.objective_refusals import smooth_form_refusal
from optdesign.problem.request import SolveRequest

if TYPE_CHECKING:
    from optdesign.problem.design_problem import DesignProblem


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
    refusal = smooth_form_refusal(problem, request.objective, "every formulation")
    if refusal:  # one reason for all, rather than the same one four times
        raise ProblemError(f"formulation='auto': {refusal}")
    raise ProblemError("formulation='auto': no formulation applies (" + "; ".join(reasons) + ")")


def choose_formulation(
    problem: DesignProblem, requested: str = "auto", objective: str | None = None
) -> str:
    """The name of the formulation a solve of ``problem`` takes for ``requested`` and
    ``objective`` (None: the problem's first)."""
    request = SolveRequest.for_problem(problem, objective, formulation=requested)
    return pick_formulation(problem, request).name


register_formulation(CatalogueFormulation())
register_formulation(RobustFormulation())
register_formulation(GPFormulation())
register_formulation(NLPFormulation())
