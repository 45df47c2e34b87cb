"""One factory for every solver back-end, and the registry behind it.

``make_solver(formulation, name, options)`` builds the back-end registered as ``name`` for
a formulation (an :class:`~optdesign.formulations.nlp.NLP`, or a GP's
:class:`~optdesign.formulations.gp.GPData`); solve, Pareto, catalogue, robust and bench
all go through it. Adding a back-end is one module with a class that follows
:class:`~optdesign.solvers.base.NLPSolver` and one :func:`register_solver` line, from
inside the package or from a user's own code.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from optdesign.errors import InputError
from optdesign.solvers.ipopt_options import IPOPT_WARM


@dataclass(frozen=True)
class SolverEntry:
    """A registered back-end: ``factory(formulation, options) -> solver``, and what a
    study may ask of it without naming it."""

    name: str
    kind: str  # "nlp" or "gp": which formulation it solves
    factory: Callable[[Any, dict[str, Any]], Any]
    description: str = ""
    #: options of a warm start from a nearby primal-dual solution (None: none)
    warm_options: Mapping[str, Any] | None = None
    #: the option that caps the iterations (None: none a study may set)
    iteration_option: str | None = None


_SOLVERS: dict[str, SolverEntry] = {}


def register_solver(
    name: str,
    factory: Callable[[Any, dict[str, Any]], Any],
    kind: str = "nlp",
    description: str = "",
    replace: bool = False,
    warm_options: Mapping[str, Any] | None = None,
    iteration_option: str | None = None,
) -> SolverEntry:
    """Register ``factory(formulation, options) -> solver`` as back-end ``name``, with
    its warm-start options and its iteration cap's option when it has them."""
    if not isinstance(name, str) or not name.strip() or not name.isprintable():
        raise InputError("register_solver.name", f"expected a name (a string), got {name!r}")
    if not callable(factory):
        raise InputError("register_solver.factory", f"expected a function, got {factory!r}")
    if kind not in ("nlp", "gp"):
        raise InputError("register_solver.kind", f"{kind!r}: use 'nlp' or 'gp'")
    if name in _SOLVERS and not replace:
        raise InputError("register_solver", f"a solver {name!r} is registered already")
    entry = SolverEntry(name, kind, factory, description, warm_options, iteration_option)
    _SOLVERS[name] = entry
    return entry


#: The back-end of each formulation kind when the caller names none.
DEFAULT_SOLVERS = {"nlp": "ipopt", "gp": "clarabel"}


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
    from optdesign.formulations.nlp import NLP
    from optdesign.safe_io import refuse_file_options

    kind = "nlp" if isinstance(formulation, NLP) else "gp"
    name = name or DEFAULT_SOLVERS[kind]
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


def _sqpmethod(nlp, options):
    from optdesign.solvers.casadi_nlp import CasadiNLPSolver

    merged = {**SQPMETHOD_QUIET, **options}
    if options.get("qpsol", "qpoases") == "qpoases":
        qp = dict(options.get("qpsol_options") or {})
        merged["qpsol_options"] = {"printLevel": "none", "error_on_fail": False, **qp}
    return CasadiNLPSolver(nlp, "sqpmethod", merged)


def _bonmin(nlp, options):
    # a continuous NLP: Bonmin with no integer variable (its Ipopt); catalogue problems
    # reach Bonmin through the catalogue search (optdesign.studies.catalogue_minlp)
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
    if "ipopt" not in _SOLVERS:
        register_solver(
            "ipopt",
            _ipopt,
            "nlp",
            "Ipopt interior point (CasADi), exact Hessian by default",
            warm_options=IPOPT_WARM,
            iteration_option="max_iter",
        )
    for name, factory, kind, desc in (
        ("sqpmethod", _sqpmethod, "nlp", "CasADi SQP (sqpmethod) with a QP solver"),
        ("slsqp", _scipy("SLSQP"), "nlp", "SciPy SLSQP with CasADi exact derivatives"),
        ("trust-constr", _scipy("trust-constr"), "nlp", "SciPy trust-constr"),
        ("bonmin", _bonmin, "nlp", "Bonmin (CasADi): MINLP on catalogue items, else an NLP"),
        ("clarabel", _cvxpy("CLARABEL"), "gp", "cvxpy GP, Clarabel interior point"),
        ("scs", _cvxpy("SCS"), "gp", "cvxpy GP, SCS first-order conic"),
    ):
        if name not in _SOLVERS:
            register_solver(name, factory, kind, desc)
