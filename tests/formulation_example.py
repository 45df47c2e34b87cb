"""A formulation written outside the package, for tests/formulations/test_registry.py: one
NLP start from the declared start, for a caller who wants the local optimum nearest to
the design they wrote. A new formulation is this module and one
``od.register_formulation`` line; no study changes.

It brings the whole protocol (``optdesign.formulations.protocol.Formulation``): besides
``applies`` and ``solve``, its own ``diagnose``, ``sensitivities`` and typed record
(``details``), which the solve pipeline calls and ``result.json`` writes, without a line
of the pipeline naming it. A formulation may leave out the last three: it then gets the
NLP's."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import optdesign as od
from optdesign.formulations.diagnosis import Relaxing, diagnose
from optdesign.formulations.nlp.diagnosis import nlp_diagnosis
from optdesign.formulations.nlp.sensitivities import nlp_sensitivities
from optdesign.formulations.nlp.solution import has_multipliers
from optdesign.formulations.nlp.solve import solve_nlp


@dataclass
class SingleStartDetails:
    """The ``single`` formulation's record: the start it solved from."""

    start: dict[str, float]

    def extra(self) -> dict[str, Any]:
        """Its keys in result.json's ``extra`` object."""
        return {"single_start": dict(self.start)}


@dataclass
class SingleStart:
    """The ``single`` formulation: ``applies`` and ``solve`` read the caller's request."""

    name: str = "single"
    description: str = "one NLP start from the declared start"
    details: type = SingleStartDetails
    #: the requests it solved (what the test reads)
    seen: list[od.SolveRequest] = field(default_factory=list)
    #: the evidence the pipeline asked of it: ("diagnose" | "sensitivities", status)
    evidence: list[tuple[str, str]] = field(default_factory=list)

    def applies(self, problem: od.DesignProblem, request: od.SolveRequest) -> bool | str:
        """Continuous variables and at most one start asked."""
        if any(v.discrete for v in problem.free):
            return "a catalogue variable needs the catalogue formulation"
        if request.starts not in (None, 1):
            return f"runs one start, {request.starts} asked"
        return True

    def solve(self, problem: od.DesignProblem, request: od.SolveRequest) -> od.Result:
        """The NLP from the declared start, labelled with this formulation."""
        self.seen.append(request)
        result = solve_nlp(
            problem, request.objective, starts=1, solver=request.solver, options=request.options
        )
        result.formulation = self.name
        start = problem.start()
        result.details[self.name] = SingleStartDetails(
            {v.name: float(x) for v, x in zip(problem.free, start, strict=True)}
        )
        return result

    def diagnose(self, problem: od.DesignProblem, result: od.Result, request: od.SolveRequest):
        """The NLP's relaxations from the one start's best point."""
        self.evidence.append(("diagnose", result.status))
        diagnose(problem, result, Relaxing(request.solver, request.options), by=nlp_diagnosis)

    def sensitivities(
        self, problem: od.DesignProblem, result: od.Result, request: od.SolveRequest
    ) -> None:
        """What each requirement costs, from the one start's multipliers (no ranges)."""
        self.evidence.append(("sensitivities", result.status))
        if request.sensitivities and has_multipliers(result, request.solver):
            result.sensitivities = nlp_sensitivities(problem, result)
