"""optdesign: design optimisation of screw-driven actuator linkages.

Internal unit system (every number inside the package): millimetre (mm), newton (N),
megapascal (MPa = N/mm^2), newton-millimetre (N*mm) for moments, radian (rad) for angles.
Output backlash is *reported* in degrees. Quantities with units are accepted at the input
boundary (problem files, the API's bounds, the CLI) and converted by
:mod:`optdesign.units`.

The public API (see :mod:`optdesign.api` and the README)::

    import optdesign as od
    problem = od.load("problems/cs_min_backlash.toml")
    result = od.solve(problem)
    front = od.pareto(problem, ["ripple", "backlash"], points=30)

Data flow, one package per stage: ``models/`` (pure physics through :mod:`optdesign.math`)
-> ``mechanisms/`` (plug-ins) -> ``problem/`` -> ``formulations/`` -> ``solvers/`` ->
``studies/`` -> this API -> ``cli``, ``plots/``, ``reports/``. Names are imported lazily:
``import optdesign`` costs little until a function is used.

The physics (every model's equations, assumptions, validity and checks) is documented in
the repository's ``docs/`` (``docs/README.md``); bracketed keys such as [D17] in the
docstrings are the papers of ``docs/references.md``.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.3.0"

#: public name -> "module:attribute" (or "module" for a module), imported on first use.
_EXPORTS: dict[str, str] = {
    "load": "optdesign.problem.load:load",
    "solve": "optdesign.api:solve",
    "pareto": "optdesign.api:pareto",
    "bench": "optdesign.api:bench",
    "bench_configurations": "optdesign.api:bench_configurations",
    "report": "optdesign.api:report",
    "sweep": "optdesign.api:sweep",
    "simulate": "optdesign.api:simulate",
    "Sweep": "optdesign.studies.sweep:Sweep",
    "DesignProblem": "optdesign.problem.design_problem:DesignProblem",
    "Quantities": "optdesign.problem.quantities:Quantities",
    "Result": "optdesign.solvers.result:Result",
    "SolvedPoint": "optdesign.solvers.solved_point:SolvedPoint",
    "is_success": "optdesign.solvers.solved_point:is_success",
    "Front": "optdesign.studies.pareto:Front",
    "Mechanism": "optdesign.mechanisms.base:Mechanism",
    "VariableInfo": "optdesign.mechanisms.base:VariableInfo",
    "RequirementInfo": "optdesign.mechanisms.base:RequirementInfo",
    "Rows": "optdesign.mechanisms.base:Rows",
    "Sketch": "optdesign.mechanisms.base:Sketch",
    "Joint": "optdesign.mechanisms.joints:Joint",
    "PinJoint": "optdesign.mechanisms.joints:PinJoint",
    "register_mechanism": "optdesign.mechanisms.registry:register_mechanism",
    "registered_mechanisms": "optdesign.mechanisms.registry:registered",
    "register_solver": "optdesign.solvers.registry:register_solver",
    "register_formulation": "optdesign.formulations.registry:register_formulation",
    "formulation_names": "optdesign.formulations.registry:formulation_names",
    "SolveRequest": "optdesign.problem.request:SolveRequest",
    "make_solver": "optdesign.solvers.registry:make_solver",
    "solver_names": "optdesign.solvers.registry:solver_names",
    "SolverHints": "optdesign.solvers.registry:SolverHints",
    "solver_hints": "optdesign.solvers.registry:solver_hints",
    "default_solver": "optdesign.solvers.registry:default_solver",
    "OptDesignError": "optdesign.errors:OptDesignError",
    "InputError": "optdesign.errors:InputError",
    "ProblemError": "optdesign.errors:ProblemError",
    "math": "optdesign.math",
    "units": "optdesign.units",
}

__all__ = ["__version__", *_EXPORTS]


def __getattr__(name: str) -> Any:
    target = _EXPORTS.get(name)
    if target is None:
        raise AttributeError(f"module 'optdesign' has no attribute {name!r}")
    module, _, attr = target.partition(":")
    value = importlib.import_module(module)
    if attr:
        value = getattr(value, attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
