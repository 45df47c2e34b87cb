"""Benchmark configurations: how to solve a problem (or trace a front), by name.

A configuration of kind ``"nlp"`` is a registered solver back-end
(:func:`optdesign.solvers.make_solver`) with options and a formulation form; ``"gp"`` a GP
back-end (only where the problem is a GP); ``"global"`` differential evolution on the
NumPy path; ``"front"`` a Pareto method; ``"debug"`` hidden configurations that crash,
hang or abort (tests of the sandbox). Any solver registered with
:func:`optdesign.register_solver` is also a configuration by its own name.
"""

from __future__ import annotations

import copy
import os
import signal
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.bonmin import BONMIN_ALGORITHMS
from optdesign.solvers.registry import solver_hints
from optdesign.solvers.result import Result
from optdesign.studies.bench.catalogue_configs import register_catalogue_configs


class NotApplicable(Exception):
    """The configuration does not apply to this instance (e.g. a GP solver on a non-GP)."""


@dataclass(frozen=True)
class Config:
    """A solver configuration.

    Attributes
    ----------
    name
        Registry key (CLI ``--solvers``).
    kind
        ``"nlp"`` (continuous formulation; catalogues enumerated), ``"gp"`` (as nlp, and
        only for GP instances), ``"global"`` (NumPy path), ``"front"`` (two objectives),
        ``"debug"`` (hidden; tests).
    run
        ``run(problem, objective, time_limit) -> Result`` (front configurations:
        ``run(problem, objectives, time_limit) -> dict`` with ``F`` and ``designs``).
    description, options
        What it is, for the summary; the solver options used.
    hidden
        Not part of the default selection.
    time_factor
        Multiplies the soft limit and the hard timeout (a front is a dozen solves).
    applies
        ``applies(problem) -> bool``: whether the configuration has a run on an instance
        (None: every instance of its kind).
    preload
        Modules its runs import (the solver library): the benchmark imports them once
        before the runs are forked, so that no run's time includes importing its solver
        library (a user's process pays that once, not at every solve).
    """

    name: str
    kind: str
    run: Callable[..., Any]
    description: str = ""
    options: dict[str, Any] = field(default_factory=dict)
    hidden: bool = False
    time_factor: float = 1.0
    applies: Callable[[DesignProblem], bool] | None = None
    preload: tuple[str, ...] = ()


#: Modules of the built-in back-ends' libraries (see ``Config.preload``).
SCIPY_MODULES = ("optdesign.solvers.scipy_nlp",)
PYMOO_MODULES = ("pymoo.algorithms.moo.nsga2", "pymoo.optimize", "pymoo.core.problem")


def preload_modules(names: Sequence[str]) -> None:
    """Import the ``preload`` modules of configurations ``names`` (once per process)."""
    import importlib

    for name in names:
        for module in get_config(name).preload:
            importlib.import_module(module)


#: name -> configuration, in registration order.
CONFIGS: dict[str, Config] = {}


def register_config(config: Config) -> Config:
    """Add ``config`` to :data:`CONFIGS` (a later registration of a name replaces it)."""
    CONFIGS[config.name] = config
    return config


def get_config(name: str) -> Config:
    """The configuration ``name``; a registered NLP solver back-end of that name becomes
    a configuration with its default options (made for the caller, not registered: a
    lookup leaves the list of configurations as it was)."""
    if name in CONFIGS:
        return CONFIGS[name]
    from optdesign.solvers.registry import solver_names

    if name in solver_names("nlp"):
        return nlp_config(name, name, {}, description=f"registered solver {name}")
    from optdesign.errors import InputError

    raise InputError(
        "solvers", f"unknown configuration {name!r} (known: {', '.join(default_configs())})"
    )


def nlp_config(
    name: str, solver: str, options: dict[str, Any], form: str = "epigraph", description: str = ""
) -> Config:
    """A configuration that solves the problem's NLP once from its start."""

    def run(problem: DesignProblem, objective: str, time_limit: float) -> Result:
        from optdesign.formulations.nlp.solve import formulation_for
        from optdesign.solvers.registry import make_solver

        nlp = formulation_for(problem, (objective,), form)
        # Each back-end's own wall-time options, as it declares them (sqpmethod has
        # none: the hard timeout covers it).
        opts = {**copy.deepcopy(options), **solver_hints(solver).time_limit(time_limit)}
        return make_solver(nlp, solver, opts).solve(problem.start(), objective)

    preload = solver_hints(solver).preload
    return Config(
        name,
        "nlp",
        run,
        description,
        {**options, "solver": solver, "form": form},
        preload=preload,
    )


#: sqpmethod common options: quiet, bounded iterations, convexified exact Hessian.
SQP_BASE: dict[str, Any] = {
    "print_header": False,
    "print_iteration": False,
    "print_status": False,
    "max_iter": 200,
    "hessian_approximation": "exact",
    "convexify_strategy": "regularize",
    "error_on_fail": False,
}

#: QP solvers of sqpmethod and their quiet options (all in the casadi 3.8 wheel; highs
#: failed on the convexified QPs of the shipped fork problem in a trial: left out).
SQP_QPSOLVERS: dict[str, dict[str, Any]] = {
    "qrqp": {"print_iter": False, "print_header": False, "error_on_fail": False},
    "osqp": {
        "osqp": {"verbose": False, "eps_abs": 1e-9, "eps_rel": 1e-9, "max_iter": 20000},
        "error_on_fail": False,
    },
    "qpoases": {"printLevel": "none", "error_on_fail": False},
}

IPOPT_EXACT = {"hessian_approximation": "exact", "linear_solver": "mumps"}
IPOPT_LBFGS = {"hessian_approximation": "limited-memory", "linear_solver": "mumps"}
IPOPT_SPRAL = {"hessian_approximation": "exact", "linear_solver": "spral"}

#: Differential evolution settings (population = popsize * number of variables).
DE_OPTIONS: dict[str, Any] = {"popsize": 15, "maxiter": 1000, "tol": 1e-6, "polish": False}

#: Front settings: points of the epsilon-constraint sweep, NSGA-II population/generations.
FRONT_OPTIONS: dict[str, Any] = {"eps_points": 12, "pop_size": 40, "generations": 100}


def _de_run(problem: DesignProblem, objective: str, time_limit: float) -> Result:
    from optdesign.solvers.scipy_nlp import differential_evolution

    def evaluate(X: np.ndarray):
        ev = problem.evaluate(X)
        return np.asarray(ev.objectives[objective], dtype=float), np.asarray(
            ev.violation, dtype=float
        )

    catalogues = {k: v.values for k, v in enumerate(problem.free) if v.discrete}
    return differential_evolution(
        evaluate,
        problem.lower(),
        problem.upper(),
        [v.name for v in problem.free],
        catalogues=catalogues,
        seed=0,
        popsize=DE_OPTIONS["popsize"],
        maxiter=DE_OPTIONS["maxiter"],
        tol=DE_OPTIONS["tol"],
        time_limit=time_limit,
    )


def _gp_config(solver: str, description: str, options: Mapping[str, Any] | None = None) -> Config:
    def run(problem: DesignProblem, objective: str, time_limit: float) -> Result:
        from optdesign.programs.gp import build_gp
        from optdesign.solvers.registry import make_solver

        gp = build_gp(problem, objective)
        if not gp.is_gp:
            raise NotApplicable("not a GP: " + gp.explain().splitlines()[0])
        opts = {**(options or {}), **solver_hints(solver, "gp").time_limit(time_limit)}
        return make_solver(gp, solver, opts).solve()

    preload = solver_hints(solver, "gp").preload
    return Config(f"gp-{solver}", "gp", run, description, applies=gp_applies, preload=preload)


def gp_applies(problem: DesignProblem) -> bool:
    """The problem is a GP once its catalogue variables are fixed (the benchmark enumerates
    catalogues): every diagnosis passes but 'takes catalogue values'."""
    from optdesign.programs.gp import build_gp

    return all(
        c.ok or (c.what == "variable" and "catalogue values" in c.reason)
        for c in build_gp(problem).checks
    )


def _front_dict(front) -> dict[str, Any]:
    return {"F": front.F.tolist(), "designs": [dict(p.design) for p in front.points]}


def _eps_front(problem, objectives, time_limit):
    import tempfile

    from optdesign.studies.pareto import CatalogueEpsilon, EpsilonConstraint, compute_front
    from optdesign.studies.pareto.catalogue_front import has_catalogue

    # An instance whose lead comes from a catalogue gets the catalogue front (every point
    # a catalogue design), as `optdesign pareto` does; a continuous sweep would leave it.
    kind = CatalogueEpsilon if has_catalogue(problem) else EpsilonConstraint
    with tempfile.TemporaryDirectory() as tmp:
        method = kind(points=FRONT_OPTIONS["eps_points"])
        return _front_dict(compute_front(problem, list(objectives), method=method, out=tmp))


def _nsga_front(problem, objectives, time_limit):
    from optdesign.studies.pareto import NSGA2, compute_front

    method = NSGA2(FRONT_OPTIONS["pop_size"], FRONT_OPTIONS["generations"], seed=0)
    return _front_dict(compute_front(problem, list(objectives), method=method))


def _debug_crash(problem, objective, time_limit):
    raise RuntimeError("deliberate crash")


def _debug_hang(problem, objective, time_limit):
    while True:
        time.sleep(1.0)


def _debug_abort(problem, objective, time_limit):
    os.kill(os.getpid(), signal.SIGKILL)


def _register_defaults() -> None:
    nlp = [
        ("ipopt-exact", "ipopt", IPOPT_EXACT, "epigraph", "Ipopt, exact Hessian, MUMPS"),
        ("ipopt-lbfgs", "ipopt", IPOPT_LBFGS, "epigraph", "Ipopt, limited-memory Hessian, MUMPS"),
        ("ipopt-spral", "ipopt", IPOPT_SPRAL, "epigraph", "Ipopt, exact Hessian, SPRAL"),
        ("ipopt-naive", "ipopt", IPOPT_EXACT, "naive", "Ipopt exact, naive max/min objective"),
    ]
    for qp, qp_opts in SQP_QPSOLVERS.items():
        opts = {**SQP_BASE, "qpsol": qp, "qpsol_options": qp_opts}
        nlp.append(
            (
                f"sqp-{qp}",
                "sqpmethod",
                opts,
                "epigraph",
                f"CasADi sqpmethod, exact Hessian (regularised), {qp}",
            )
        )
    for method, short in (("SLSQP", "slsqp"), ("trust-constr", "trust-constr")):
        for der in ("exact", "fd"):
            what = "CasADi exact derivatives" if der == "exact" else "finite differences"
            nlp.append(
                (
                    f"{short}-{der}",
                    short,
                    {"derivatives": der},
                    "epigraph",
                    f"scipy {method}, {what}",
                )
            )
    nlp.append(
        (
            "slsqp-naive",
            "slsqp",
            {"derivatives": "exact"},
            "naive",
            "scipy SLSQP exact, naive max/min objective",
        )
    )
    for name, solver, opts, form, desc in nlp:
        register_config(nlp_config(name, solver, opts, form, desc))
    register_config(
        Config(
            "de",
            "global",
            _de_run,
            "scipy differential_evolution on the NumPy path (vectorised)",
            dict(DE_OPTIONS),
            preload=SCIPY_MODULES,
        )
    )
    register_config(Config("debug-crash", "debug", _debug_crash, "raises (tests)", hidden=True))
    register_config(
        Config("debug-hang", "debug", _debug_hang, "sleeps forever (tests)", hidden=True)
    )
    register_config(
        Config("debug-abort", "debug", _debug_abort, "kills its own process (tests)", hidden=True)
    )
    register_config(_gp_config("clarabel", "cvxpy GP (first-order Hertz), Clarabel"))
    register_config(_gp_config("scs", "cvxpy GP (first-order Hertz), SCS", {"max_iters": 100_000}))
    register_config(
        Config(
            "front-epsilon",
            "front",
            _eps_front,
            "epsilon-constraint front (the default sweep back-end, Ipopt tie-breaks)",
            dict(FRONT_OPTIONS),
            time_factor=10.0,
        )
    )
    register_config(
        Config(
            "front-nsga2",
            "front",
            _nsga_front,
            "NSGA-II front (pymoo, NumPy path)",
            dict(FRONT_OPTIONS),
            time_factor=10.0,
            preload=PYMOO_MODULES,
        )
    )
    # the catalogue searches: optdesign's own, and Bonmin's algorithms
    catalogue: list[tuple[str, str, str | None, dict[str, Any] | None, str]] = [
        ("catalogue-bnb", "bnb", None, None, "optdesign catalogue branch and bound (warm nodes)"),
        ("catalogue-enumerate", "enumerate", None, None, "every catalogue combination's NLP"),
    ]
    for alg in BONMIN_ALGORITHMS:
        catalogue.append(
            (
                f"bonmin-{alg.lower()}",
                "minlp",
                "bonmin",
                {"algorithm": alg},
                f"Bonmin {alg} (CasADi), one-hot catalogue items",
            )
        )
    register_catalogue_configs(register_config, Config, catalogue)


def default_configs(include_hidden: bool = False) -> list[str]:
    """Names of the registered configurations (hidden ones on request)."""
    return [n for n, c in CONFIGS.items() if include_hidden or not c.hidden]


# Registered at import so that every process (forked, spawned or a Dask worker) sees the
# same registry.
_register_defaults()
