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


@dataclass(frozen=True)
class SolverEntry:
    """A registered back-end: ``factory(formulation, options) -> solver``."""

    name: str
    kind: str  # "nlp" or "gp": which formulation it solves
    factory: Callable[[Any, dict[str, Any]], Any]
    description: str = ""


_SOLVERS: dict[str, SolverEntry] = {}


def register_solver(
    name: str,
    factory: Callable[[Any, dict[str, Any]], Any],
    kind: str = "nlp",
    description: str = "",
    replace: bool = False,
) -> SolverEntry:
    """Register ``factory(formulation, options) -> solver`` as back-end ``name``."""
    if not isinstance(name, str) or not name.strip() or not name.isprintable():
        raise InputError("register_solver.name", f"expected a name (a string), got {name!r}")
    if not callable(factory):
        raise InputError("register_solver.factory", f"expected a function, got {factory!r}")
    if kind not in ("nlp", "gp"):
        raise InputError("register_solver.kind", f"{kind!r}: use 'nlp' or 'gp'")
    if name in _SOLVERS and not replace:
        raise InputError("register_solver", f"a solver {name!r} is registered already")
    entry = SolverEntry(name, kind, factory, description)
    _SOLVERS[name] = entry
    return entry


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
    name = name or ("ipopt" if kind == "nlp" else "clarabel")
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
    for name, factory, kind, desc in (
        ("ipopt", _ipopt, "nlp", "Ipopt interior point (CasADi), exact Hessian by default"),
        ("sqpmethod", _sqpmethod, "nlp", "CasADi SQP (sqpmethod) with a QP solver"),
        ("slsqp", _scipy("SLSQP"), "nlp", "SciPy SLSQP with CasADi exact derivatives"),
        ("trust-constr", _scipy("trust-constr"), "nlp", "SciPy trust-constr"),
        ("clarabel", _cvxpy("CLARABEL"), "gp", "cvxpy GP, Clarabel interior point"),
        ("scs", _cvxpy("SCS"), "gp", "cvxpy GP, SCS first-order conic"),
    ):
        if name not in _SOLVERS:
            register_solver(name, factory, kind, desc)
