"""The solver of a sweep's points: one NLP for the whole sweep where the swept parameters
allow it, so that a point's global search and its warm starts from its neighbours cost
solves, not a new formulation (:meth:`SweepSolver.search`, :meth:`SweepSolver.warm`).

- The hinge moment enters the model only as the load of every force
  (:attr:`optdesign.problem.quantities.Quantities.hinge_moment`): it becomes a parameter
  of the NLP (a value per solve, like a catalogue item's data), one CasADi function for
  every point.
- A requirement that only sets the limits of rows (``nut_travel_max``,
  ``pin_bearing_pressure_max``, a band's side...) leaves the functions as they are: the
  rows keep the scales of the first formulation and take the point's limits (the
  scaling changes neither the feasible set nor the optimum). Which requirements are so
  is not listed but checked: at both ends of the range the model's rows, evaluated at the
  middle of the bounds, must equal the base problem's, value for value.
- Anything else (the stroke, a variable's bound, a fixed variable) builds the point's
  own NLP (mode ``"rebuild"``).

Every point's result is checked on the point's own problem on the NumPy path
(:func:`optdesign.formulations.nlp.solve.finish`), whichever NLP solved it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.programs.nlp import Bounds
from optdesign.solvers.registry import default_solver
from optdesign.solvers.result import Result

HINGE = "requirements.hinge_moment"


class _Parametric(DesignProblem):
    """A view of a problem whose NLP takes the hinge moment as a parameter."""

    def parameters(self) -> dict[str, float]:
        return {**super().parameters(), "hinge_moment": self.spec.requirements.hinge_moment}


def _parametric(problem: DesignProblem) -> DesignProblem:
    view = object.__new__(_Parametric)
    view.__dict__.update(problem.__dict__)
    view._touch()  # its own formulation and solver in the caches
    return view


def _rows(problem: DesignProblem):
    with np.errstate(all="ignore"):
        ex = problem.expressions(problem.design_dict(problem.midpoint()))
    blocks = {
        b.name: (np.asarray(b.expr, dtype=float), b.lower is None, b.upper is None)
        for b in ex.constraints
    }
    terms = {k: np.asarray(t.expr, dtype=float) for k, t in ex.objectives.items()}
    return blocks, terms, set(problem.objective_limits())


def _same_functions(a: DesignProblem, b: DesignProblem) -> bool:
    """The rows and objectives of ``a`` and ``b`` are the same functions (equal values at
    the middle of the bounds, the same rows bounded on the same sides)."""
    (ba, ta, la), (bb, tb, lb) = _rows(a), _rows(b)
    if la != lb or ba.keys() != bb.keys() or ta.keys() != tb.keys():
        return False
    for name, (ea, lo_a, hi_a) in ba.items():
        eb, lo_b, hi_b = bb[name]
        if (lo_a, hi_a) != (lo_b, hi_b) or not np.array_equal(ea, eb, equal_nan=True):
            return False
    return all(np.array_equal(ta[k], tb[k], equal_nan=True) for k in ta)


def sweep_mode(problem: DesignProblem, paths: Sequence[str], ends) -> str:
    """``"shared"`` (one NLP for every point) or ``"rebuild"`` (each point its own).

    ``ends``: for each path, the two values at the ends of its range (internal units)."""
    from optdesign.problem.parameters import at_values

    for path, (lo, hi) in zip(paths, ends, strict=True):
        if path == HINGE:
            continue
        if not path.startswith("requirements.") or path.startswith("requirements.deflection"):
            return "rebuild"
        if not all(_same_functions(problem, at_values(problem, {path: v})) for v in (lo, hi)):
            return "rebuild"
    return "shared"


class SweepSolver:
    """Ipopt on the one NLP of a sweep (mode ``"shared"``): a point's global search and
    its single warm-started solves, each on the point's bounds and parameters."""

    def __init__(self, problem: DesignProblem, paths: Sequence[str], objective: str):
        from optdesign.formulations.nlp.solve import _objective_set, solver_for

        self.paths = list(paths)
        self.objective = objective
        view = _parametric(problem) if HINGE in paths else problem
        self.backend = solver_for(
            view, default_solver("nlp"), None, _objective_set(problem, objective)
        )
        self.nlp = self.backend.nlp
        self.target = self.nlp.target(objective)
        self.limits_only = any(p != HINGE for p in paths)

    def bounds(self, point: DesignProblem) -> Bounds:
        """The bounds and parameters of the point's problem, in the shared NLP's scales."""
        nlp = self.nlp
        params = None
        if "hinge_moment" in nlp.param_names:
            params = nlp.param_defaults.copy()
            params[nlp.param_names.index("hinge_moment")] = point.spec.requirements.hinge_moment
        lbg, ubg = nlp.lbg, nlp.ubg
        if self.limits_only:
            lbg, ubg = lbg.copy(), ubg.copy()
            with np.errstate(all="ignore"):
                ex = point.expressions(point.design_dict(point.midpoint()))
            blocks = {b.name: (b.lower, b.upper) for b in ex.constraints}
            eps = {row: name for name, row in nlp.eps_rows.items()}
            limits = point.objective_limits()
            for i, name in enumerate(nlp.g_names):
                s = nlp.g_scale[i]
                if i in eps:
                    ubg[i] = limits.get(eps[i], np.inf) / s
                    continue
                lo_hi = blocks.get(name.split("[", 1)[0])
                if lo_hi is not None:
                    lo, hi = lo_hi
                    lbg[i] = -np.inf if lo is None else lo / s
                    ubg[i] = np.inf if hi is None else hi / s
        return Bounds(nlp.lbz, nlp.ubz, lbg, ubg, params)

    def warm(self, point: DesignProblem, x0: np.ndarray) -> Result:
        """One solve of the point from ``x0`` (its neighbour's design), checked."""
        from optdesign.formulations.nlp.solve import finish

        bounds = self.bounds(point)
        start = self.nlp.start(x0=x0, parameters=bounds.parameters)
        return finish(point, self.backend.solve(start, self.target, bounds), self.objective)

    def search(
        self, point: DesignProblem, starts: int | None, seed: int, agree: int | None = None
    ) -> Result:
        """The point's global search on the shared NLP, checked: the search a cold solve
        of the point runs (:func:`optdesign.formulations.nlp.solve.solve_nlp`) - the point's
        declared start, if any, then tilted random starts drawn on the point's own
        problem with ``seed`` until the odds say stop (``starts``: the most starts, None:
        :func:`~optdesign.formulations.nlp.solve.planned_starts`; ``agree``: None, the file's)
        - with the point's bounds and parameters in the shared NLP."""
        from optdesign.formulations.nlp.solve import (
            finish,
            own_starts,
            planned_starts,
            tilted_starts,
        )
        from optdesign.search.global_phase import global_search, search_globality

        bounds = self.bounds(point)
        result = global_search(
            lambda x: self.backend.solve(
                self.nlp.start(x0=x, parameters=bounds.parameters), self.target, bounds
            ),
            tilted_starts(point, self.objective, seed),
            own=own_starts(point),
            max_starts=planned_starts(point, starts),
            agree=agree if agree is not None else point.spec.solver.agree,
            seed=seed,
        )
        result.globality = search_globality(result.multistart)
        return finish(point, result, self.objective)
