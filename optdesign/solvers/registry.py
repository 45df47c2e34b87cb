"""One factory for every solver back-end, the registry behind it, and what each back-end
declares of itself.

``make_solver(formulation, name, options)`` builds the back-end registered as ``name`` for
a formulation (an :class:`~optdesign.programs.nlp.NLP`, or a GP's
:class:`~optdesign.programs.gp.GPData`); solve, Pareto, catalogue, robust and bench
all go through it. Adding a back-end is one module with a class that follows
:class:`~optdesign.solvers.base.NLPSolver` and one :func:`register_solver` line, from
inside the package or from a user's own code.

No study names a back-end: a study asks the registry. :func:`default_solver` gives the
back-end of a formulation kind when the caller names none, :func:`solver_hints` what a
back-end declares (:class:`SolverHints`: its warm-start options, the options of a solve
that may meet infeasible sub-problems, its iteration and time-limit options, the problem
file's table of its options), and :data:`FRONT_SOLVERS` the back-ends of a Pareto
sweep's roles (:class:`FrontSolvers`).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from optdesign.errors import InputError
from optdesign.solvers.deadline import DEADLINE_OPTION
from optdesign.solvers.ipopt_options import IPOPT_NODE, IPOPT_RANGE, IPOPT_TIE, IPOPT_WARM


@dataclass(frozen=True)
class NodeFirst:
    """A back-end that tries the starts of a catalogue node before the node's own.

    ``solver``: its registry name; ``options``: its options there. Its converged points
    are kept; a start it does not solve goes to the node's back-end from the same point,
    so that every verdict of local infeasibility is the node back-end's."""

    solver: str
    options: Mapping[str, Any]


@dataclass(frozen=True)
class SolverHints:
    """What a back-end declares, so that a study can use it without naming it (every
    field empty: the back-end is used with the caller's options only)."""

    #: options of a warm start from a nearby primal-dual solution (None: takes none)
    warm_start_options: Mapping[str, Any] | None = None
    #: options of the ranges of the optimal set, each solve started warm at the optimum
    #: (None: the warm-start options)
    range_options: Mapping[str, Any] | None = None
    #: options of a solve started at a feasible point close to its optimum (a front's
    #: lexicographic tie-breaks)
    restart_options: Mapping[str, Any] | None = None
    #: options of a solve that may meet an infeasible sub-problem (a catalogue node)
    node_options: Mapping[str, Any] | None = None
    #: a quicker back-end that solves each start of a catalogue node on its thinned grid
    #: first, this one solving the start again where it does not converge (None: none)
    node_first: NodeFirst | None = None
    #: the back-end's return messages (``Result.message``) by which it declares that it
    #: converged to a point of local infeasibility, as opposed to a stop (iterations,
    #: errors) or a solved point that fails the check: a catalogue node whose every
    #: start ended with one of them is not retried (empty: every failed node is)
    infeasible_verdicts: tuple[str, ...] = ()
    #: options of the back-end as the primary solver of a front's sweep
    sweep_options: Mapping[str, Any] | None = None
    #: the option that caps the iterations (None: none a study may set)
    iteration_option: str | None = None
    #: options that make a solve stop at the multistart's deadline
    #: (:mod:`optdesign.solvers.deadline`; None: it finishes the start it is in)
    deadline_options: Mapping[str, Any] | None = None
    #: options that take a wall-time limit in seconds (the benchmark's soft limit)
    time_limit_options: tuple[str, ...] = ()
    #: the problem file's table of this back-end's options (``[solver] ipopt = {...}``)
    file_options: str | None = None
    #: "module:function" checking the back-end's options before any work
    #: (``check(options, field=...)``; None: the back-end checks them when it is built)
    options_check: str | None = None
    #: "module:function" called before any work whatever the options (``check()``,
    #: raising InputError): what the back-end would take from outside its options, e.g.
    #: an options file it reads from the working directory
    preflight: str | None = None
    #: modules a benchmark imports before timing (the back-end's lazy imports)
    preload: tuple[str, ...] = ()
    #: the result carries the constraint and bound multipliers of the NLP it solved
    #: (``raw["lam_g"]``, ``raw["lam_x"]``, in the formulation's scaling), which the
    #: sensitivities of :mod:`optdesign.formulations.nlp.sensitivities` read
    multipliers: bool = False
    #: "module:function" solving a catalogue problem as one mixed-integer NLP
    #: (``solve(minlp, x0, options) ->`` :class:`~optdesign.solvers.base.MINLPSolution`;
    #: ``minlp``: a :class:`~optdesign.formulations.catalogue.minlp_program.CatalogueMINLP`); a
    #: catalogue search given this back-end hands it the whole problem (method
    #: ``"minlp"``) instead of solving its nodes with it. None: an NLP back-end only.
    minlp: str | None = None

    def time_limit(self, seconds: float) -> dict[str, float]:
        """The back-end's own options for a wall-time limit of ``seconds``."""
        return {name: float(seconds) for name in self.time_limit_options}

    def check_options(self, options: Mapping[str, Any], field_name: str) -> None:
        """Refuse options the back-end would refuse, naming ``field_name`` (and what its
        :attr:`preflight` refuses)."""
        if self.preflight is not None:
            module, _, attr = self.preflight.partition(":")
            getattr(importlib.import_module(module), attr)()
        if self.options_check is not None and options:
            module, _, attr = self.options_check.partition(":")
            getattr(importlib.import_module(module), attr)(dict(options), field=field_name)


@dataclass(frozen=True)
class SolverEntry:
    """A registered back-end: ``factory(formulation, options) -> solver``, and what a
    study may ask of it without naming it."""

    name: str
    kind: str  # "nlp" or "gp": which formulation it solves
    factory: Callable[[Any, dict[str, Any]], Any]
    description: str = ""
    hints: SolverHints = field(default_factory=SolverHints)

    @property
    def warm_options(self) -> Mapping[str, Any] | None:
        """Its warm-start options (:attr:`SolverHints.warm_start_options`)."""
        return self.hints.warm_start_options

    @property
    def iteration_option(self) -> str | None:
        """Its iteration cap's option (:attr:`SolverHints.iteration_option`)."""
        return self.hints.iteration_option


@dataclass(frozen=True)
class FrontSolvers:
    """The back-ends of a Pareto front's roles: the sweep's ``primary`` (the default of
    ``solver=``), the ``fallback`` that solves again a start the primary fails (and, used
    throughout, the weighted sums and the catalogue fronts' nodes), the ``tie`` of the
    lexicographic tie-breaks; ``choices``: the sweep back-ends a caller may name."""

    primary: str = "sqpmethod"
    fallback: str = "ipopt"
    tie: str = "ipopt"
    choices: tuple[str, ...] = ("sqpmethod", "slsqp", "ipopt")


#: The roles of a front's back-ends (:mod:`optdesign.studies.pareto.eps_solver`).
FRONT_SOLVERS = FrontSolvers()

_SOLVERS: dict[str, SolverEntry] = {}


def register_solver(
    name: str,
    factory: Callable[[Any, dict[str, Any]], Any],
    kind: str = "nlp",
    description: str = "",
    replace: bool = False,
    warm_options: Mapping[str, Any] | None = None,
    iteration_option: str | None = None,
    hints: SolverHints | None = None,
) -> SolverEntry:
    """Register ``factory(formulation, options) -> solver`` as back-end ``name``, with
    what it declares of itself (``hints``; ``warm_options`` and ``iteration_option``
    fill those two fields of it)."""
    if not isinstance(name, str) or not name.strip() or not name.isprintable():
        raise InputError("register_solver.name", f"expected a name (a string), got {name!r}")
    if not callable(factory):
        raise InputError("register_solver.factory", f"expected a function, got {factory!r}")
    if kind not in ("nlp", "gp"):
        raise InputError("register_solver.kind", f"{kind!r}: use 'nlp' or 'gp'")
    if hints is not None and not isinstance(hints, SolverHints):
        raise InputError("register_solver.hints", f"expected a SolverHints, got {hints!r}")
    if name in _SOLVERS and not replace:
        raise InputError("register_solver", f"a solver {name!r} is registered already")
    hints = hints or SolverHints()
    if warm_options is not None or iteration_option is not None:
        hints = SolverHints(
            **{
                **hints.__dict__,
                "warm_start_options": warm_options or hints.warm_start_options,
                "iteration_option": iteration_option or hints.iteration_option,
            }
        )
    entry = SolverEntry(name, kind, factory, description, hints)
    _SOLVERS[name] = entry
    return entry


#: The back-end of each formulation kind when the caller names none.
DEFAULT_SOLVERS = {"nlp": "ipopt", "gp": "clarabel"}


def default_solver(kind: str = "nlp") -> str:
    """The back-end of formulation kind ``kind`` (``"nlp"`` or ``"gp"``) when the caller
    names none."""
    if kind not in DEFAULT_SOLVERS:
        raise InputError("kind", f"{kind!r}: use 'nlp' or 'gp'")
    return DEFAULT_SOLVERS[kind]


def solver_for_kind(name: str | None, kind: str = "nlp") -> str:
    """``name`` when it is a registered back-end of ``kind``, else the kind's default (a
    study that needs an NLP solve for a GP result, or a GP for a solve that named an NLP
    back-end)."""
    return name if name in solver_names(kind) else default_solver(kind)


def solver_hints(name: str | None, kind: str | None = None) -> SolverHints:
    """What back-end ``name`` (None: the default of ``kind``, else of an NLP) declares;
    InputError listing the registered ones for an unknown name."""
    name = name or default_solver(kind or "nlp")
    _builtins()
    entry = _SOLVERS.get(name)
    if entry is None or (kind is not None and entry.kind != kind):
        entry = solver_entry(name, kind or "nlp")  # the refusal naming the known ones
    return entry.hints


def solver_names(kind: str | None = None) -> list[str]:
    """Registered back-ends (of one formulation kind)."""
    _builtins()
    return [k for k, e in _SOLVERS.items() if kind is None or e.kind == kind]


def solver_entry(name: str, kind: str = "nlp") -> SolverEntry:
    """The entry of ``name``; InputError listing the registered ones otherwise."""
    _builtins()
    entry = _SOLVERS.get(name)
    if entry is None or entry.kind != kind:
        raise InputError(
            "solver", f"unknown {kind} solver {name!r} (known: {', '.join(solver_names(kind))})"
        )
    return entry


def make_solver(
    formulation: Any, name: str | None = None, options: Mapping[str, Any] | None = None
):
    """The back-end ``name`` built for ``formulation`` (default: ipopt for an NLP,
    clarabel for a GP). Options that would read or write a file or load code are
    refused (:func:`optdesign.safe_io.refuse_file_options`)."""
    from optdesign.programs.nlp import NLP
    from optdesign.safe_io import refuse_file_options

    kind = "nlp" if isinstance(formulation, NLP) else "gp"
    name = name or default_solver(kind)
    entry = solver_entry(name, kind)
    # No back-end option may read or write a file or load code (Ipopt's output_file,
    # CasADi's dump/jit, SCS's write_data_filename...), wherever it comes from.
    refuse_file_options(options, "options")
    return entry.factory(formulation, dict(options or {}))


# --- built-in back-ends -------------------------------------------------------------------
def _ipopt(nlp, options):
    from optdesign.solvers.casadi_nlp import CasadiNLPSolver

    return CasadiNLPSolver(nlp, "ipopt", options)


#: sqpmethod's defaults: its iterations, its default QP solver's (qpOASES) and the NaN
#: of a trial step are not printed (a user's options override any of them; a QP solver
#: the user names gets no option of qpOASES). qpOASES still prints its licence banner
#: when it is built.
SQPMETHOD_QUIET: dict[str, Any] = {
    "show_eval_warnings": False,
    "print_header": False,
    "print_iteration": False,
    "print_status": False,
    "error_on_fail": False,
}


#: sqpmethod as a front's primary: a limited-memory (L-BFGS) Hessian, and qpOASES, which
#: together solve a warm sweep point faster than SLSQP with no SciPy imported; a start
#: it does not solve in 200 iterations goes to the front's fallback.
SQPMETHOD_SWEEP: dict[str, Any] = {
    "qpsol": "qpoases",
    "hessian_approximation": "limited-memory",
    "max_iter": 200,
}


#: sqpmethod as the first solver of a catalogue node's starts on its thinned grid (the
#: parent's or a neighbour's optimum nearby, :data:`IPOPT_NODE`'s back-end behind it):
#: the sweep's L-BFGS and qpOASES, to tolerances near Ipopt's, since a leaf's converged
#: point is the design reported. A start it has not solved in 45 iterations (a converged
#: one takes about 8 to 14) is more likely an infeasible box, which Ipopt decides.
SQPMETHOD_NODE: dict[str, Any] = {
    **SQPMETHOD_SWEEP,
    "max_iter": 45,
    "tol_du": 1e-9,
    "tol_pr": 1e-10,
}


def sqpmethod_options(options: Mapping[str, Any]) -> dict[str, Any]:
    """The CasADi options an sqpmethod solver of the registry is built with: ``options``
    over :data:`SQPMETHOD_QUIET`, qpOASES silent unless they say otherwise (the NLP
    back-end's, and a catalogue node's phase-1 problem on it)."""
    merged = {**SQPMETHOD_QUIET, **options}
    if options.get("qpsol", "qpoases") == "qpoases":
        qp = dict(options.get("qpsol_options") or {})
        merged["qpsol_options"] = {"printLevel": "none", "error_on_fail": False, **qp}
    return merged


def nlpsol_options(plugin: str, options: Mapping[str, Any]) -> dict[str, Any]:
    """The CasADi options the registry builds CasADi's ``plugin`` with, from ``options``
    (sqpmethod: :func:`sqpmethod_options`; any other: as given)."""
    return sqpmethod_options(options) if plugin == "sqpmethod" else dict(options)


def _sqpmethod(nlp, options):
    from optdesign.solvers.casadi_nlp import CasadiNLPSolver

    return CasadiNLPSolver(nlp, "sqpmethod", sqpmethod_options(options))


def _bonmin(nlp, options):
    # a continuous NLP: Bonmin with no integer variable (its Ipopt); catalogue problems
    # reach Bonmin through the catalogue search (optdesign.formulations.catalogue.minlp)
    from optdesign.solvers.bonmin import bonmin_nlp_solver

    return bonmin_nlp_solver(nlp, options)


def _scipy(method: str):
    def make(nlp, options):
        from optdesign.solvers.scipy_nlp import ScipyNLPSolver

        opts = dict(options)
        derivatives = opts.pop("derivatives", "exact")
        time_limit = opts.pop("time_limit", float("inf"))
        return ScipyNLPSolver(nlp, method, derivatives, opts, time_limit)

    return make


def _cvxpy(solver: str):
    def make(gp, options):
        from optdesign.solvers.cvxpy_gp import GPSolver

        return GPSolver(gp, solver, options)

    return make


_BUILTINS_DONE = False


def _builtins() -> None:
    global _BUILTINS_DONE
    if _BUILTINS_DONE:
        return
    _BUILTINS_DONE = True
    ipopt = SolverHints(
        warm_start_options=IPOPT_WARM,
        range_options=IPOPT_RANGE,
        restart_options=IPOPT_TIE,
        node_options=IPOPT_NODE,
        node_first=NodeFirst("sqpmethod", SQPMETHOD_NODE),
        infeasible_verdicts=("Infeasible_Problem_Detected",),
        iteration_option="max_iter",
        deadline_options={DEADLINE_OPTION: True},
        time_limit_options=("max_wall_time", "max_cpu_time"),
        file_options="ipopt",
        multipliers=True,
        options_check="optdesign.solvers.casadi_nlp:check_ipopt_options",
    )
    scipy = ("optdesign.solvers.scipy_nlp",)
    sqp = SolverHints(sweep_options=SQPMETHOD_SWEEP)
    slsqp = SolverHints(
        sweep_options={"maxiter": 200}, time_limit_options=("time_limit",), preload=scipy
    )
    cvxpy = ("cvxpy", "optdesign.solvers.cvxpy_gp", "optdesign.programs.gp")
    for name, factory, kind, desc, hints in (
        ("ipopt", _ipopt, "nlp", "Ipopt interior point (CasADi), exact Hessian by default", ipopt),
        ("sqpmethod", _sqpmethod, "nlp", "CasADi SQP (sqpmethod) with a QP solver", sqp),
        ("slsqp", _scipy("SLSQP"), "nlp", "SciPy SLSQP with CasADi exact derivatives", slsqp),
        (
            "trust-constr",
            _scipy("trust-constr"),
            "nlp",
            "SciPy trust-constr",
            SolverHints(time_limit_options=("time_limit",), preload=scipy),
        ),
        (
            "bonmin",
            _bonmin,
            "nlp",
            "Bonmin (CasADi): MINLP on catalogue items, else an NLP",
            SolverHints(
                time_limit_options=("time_limit",),
                options_check="optdesign.solvers.bonmin:check_bonmin_options",
                preflight="optdesign.solvers.bonmin:refuse_options_file",
                minlp="optdesign.solvers.bonmin:solve_minlp",
            ),
        ),
        (
            "clarabel",
            _cvxpy("CLARABEL"),
            "gp",
            "cvxpy GP, Clarabel interior point",
            SolverHints(time_limit_options=("time_limit",), preload=cvxpy),
        ),
        (
            "scs",
            _cvxpy("SCS"),
            "gp",
            "cvxpy GP, SCS first-order conic",
            SolverHints(time_limit_options=("time_limit_secs",), preload=cvxpy),
        ),
    ):
        if name not in _SOLVERS:
            register_solver(name, factory, kind, desc, hints=hints)
