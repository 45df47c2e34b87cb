"""A formulation written outside the package, for tests/studies/test_formulation_registry.py: one
NLP start from the declared start, for a caller who wants the local optimum nearest to
the design they wrote. A new formulation is this module and one
``od.register_formulation`` line; no study changes."""

from __future__ import annotations

from dataclasses import dataclass, field

import optdesign as od
from optdesign.formulations.nlp.solve import solve_nlp


@dataclass
class SingleStart:
    """The ``single`` formulation: ``applies`` and ``solve`` read the caller's request."""

    name: str = "single"
    description: str = "one NLP start from the declared start"
    #: the requests it solved (what the test reads)
    seen: list[od.SolveRequest] = field(default_factory=list)

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
        return result
