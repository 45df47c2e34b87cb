"""CasADi ``nlpsol`` back-ends: Ipopt (default) and sqpmethod (or any nlpsol plugin).

The CasADi solver is built once per NLP and reused by every solve: the objective
weights are its parameter ``p``, the bounds are arguments of each call, and primal and
dual values warm-start it.

A signal during a call stops Ipopt within an iteration (CasADi checks for Python signals
between function evaluations) but CasADi then returns the solve as failed
(``NonIpopt_Exception_Thrown``) or raises a ``RuntimeError``: every call runs inside
:func:`optdesign.interrupts.solver_call`, which raises the interrupt instead.
"""

from __future__ import annotations

import contextlib
import difflib
import io
import math
import re
import signal
import time
from collections.abc import Mapping
from functools import lru_cache
from typing import Any

import casadi as ca
import numpy as np

from optdesign.errors import InputError
from optdesign.interrupts import Interrupted, solver_call
from optdesign.programs.nlp import NLP, Bounds, Start, Target
from optdesign.safe_io import refuse_file_options, without_option_files
from optdesign.solvers.base import failed_result, make_result, resolve
from optdesign.solvers.blas import one_blas_thread, rescan_blas
from optdesign.solvers.deadline import passed as deadline_passed
from optdesign.solvers.ipopt_options import IPOPT_WARM  # noqa: F401 (its users import it here)
from optdesign.solvers.nlpsol_call import NlpsolFunction
from optdesign.solvers.result import Result, TerminationCondition

#: Ipopt defaults, each chosen for the shape of these problems (a few scaled design
#: variables, hundreds of inequality rows over the grid angles); the measurements behind
#: each are in benchmarks/README.md, "Figures behind comments in the code".
#:
#: - quiet, tight tolerances: optima are compared to 1e-4 relative, constraints to 1e-6;
#: - 500 iterations: converging starts need well under 100, and a start still running is
#:   stuck near a toggle position, where the search has better starts;
#: - MUMPS with the AMD ordering: the step system is small and very sparse, and the default
#:   ordering's analysis costs more than the factorisation;
#: - bound multipliers started from mu / slack: multipliers of 1 on the epigraph's many rows
#:   put the first iterates far from the central path;
#: - the Hessian's regularisation capped at 1e4: on the scaled problem (variables in
#:   [0, 1], rows ~1) a larger one only comes from a start stuck at a linkage's singular
#:   position, where Ipopt would refactorise up to 1e20 at every iteration;
#: - a restoration phase ended after 200 successive iterations: at the cap above, a stuck
#:   start's restoration phase goes on with zero steps until the iteration limit (19 of the
#:   six-bar's 72 ripple starts, 25 of its 32 s of Ipopt); the restoration phases of every
#:   shipped problem's searches are shorter (the same iterations at 100, on the catalogue
#:   nodes too; at 50 some nodes' verdicts change).
IPOPT_DEFAULTS: dict[str, Any] = {
    "print_level": 0,
    "sb": "yes",
    "tol": 1e-10,
    "constr_viol_tol": 1e-9,
    "acceptable_tol": 1e-7,
    "max_iter": 500,
    "mu_strategy": "adaptive",
    "mumps_pivot_order": 0,
    "bound_mult_init_method": "mu-based",
    "max_hessian_perturbation": 1e4,
    "max_resto_iter": 200,
}

_IPOPT_STATUS = {
    "Solve_Succeeded": (TerminationCondition.CONVERGED, "optimal"),
    "Solved_To_Acceptable_Level": (TerminationCondition.ACCEPTABLE, "optimal"),
    "Feasible_Point_Found": (TerminationCondition.CONVERGED, "feasible"),
    "Infeasible_Problem_Detected": (TerminationCondition.INFEASIBLE, "infeasible"),
    "Maximum_Iterations_Exceeded": (TerminationCondition.MAX_ITERATIONS, "max_iterations"),
    "Maximum_CpuTime_Exceeded": (TerminationCondition.MAX_TIME, "time_limit"),
    "Maximum_WallTime_Exceeded": (TerminationCondition.MAX_TIME, "time_limit"),
    "Diverging_Iterates": (TerminationCondition.UNBOUNDED, "failed"),
    "User_Requested_Stop": (TerminationCondition.INTERRUPTED, "failed"),
    # NonIpopt_Exception_Thrown: only CasADi's KeyboardInterruptException escapes its
    # callbacks (a signal handler raised); raised as the interrupt, never a result.
    "Restoration_Failed": (TerminationCondition.NUMERICAL_ERROR, "failed"),
    "Error_In_Step_Computation": (TerminationCondition.NUMERICAL_ERROR, "failed"),
    "Invalid_Number_Detected": (TerminationCondition.NUMERICAL_ERROR, "failed"),
    "Search_Direction_Becomes_Too_Small": (TerminationCondition.NUMERICAL_ERROR, "failed"),
}


@lru_cache(maxsize=1)
def ipopt_documentation() -> str:
    """Ipopt's own documentation of its options (this build's), as text."""
    x = ca.MX.sym("x")
    buf = io.StringIO()
    opts = {
        "print_options_documentation": "yes",
        "print_advanced_options": "yes",
        "print_options_mode": "text",
        "max_iter": 0,
        "option_file_name": "",  # never an ipopt.opt of the working directory
    }
    # CasADi prints through Python's sys.stdout
    with solver_call(), contextlib.redirect_stdout(buf):
        solver = ca.nlpsol(
            "options", "ipopt", {"x": x, "f": x**2}, {"ipopt": opts, "print_time": False}
        )
        solver(x0=1.0)
    return buf.getvalue()


@lru_cache(maxsize=1)
def ipopt_option_names() -> frozenset[str]:
    """Every option this Ipopt build knows, read from Ipopt's own documentation output."""
    names = frozenset(re.findall(r"^([a-z]\w*)\s{2,}", ipopt_documentation(), re.MULTILINE))
    return names | {"sb"}  # "sb" (suppress the banner) is undocumented


#: Options that name a shared library for Ipopt to load: a problem file may not set them
#: (loading a library runs its code, and a missing one crashed the process).
LIBRARY_OPTIONS = ("hsllib", "pardisolib")


def _option_block(name: str) -> str:
    doc = ipopt_documentation()
    m = re.search(rf"^{re.escape(name)}\s{{2,}}.*?(?=^[a-z]\w*\s{{2,}}\(|\Z)", doc, re.M | re.S)
    return m.group(0) if m else ""


@lru_cache(maxsize=64)
def runtime_library(option: str, value: str) -> str | None:
    """The library Ipopt loads at run time for ``option = value`` (e.g. ``libhsl.so`` for
    ``linear_solver = "ma97"``), read from Ipopt's documentation; None if it loads none."""
    block = _option_block(option)
    m = re.search(
        rf"^\s+- {re.escape(value)}\s+\[(.*?)\](?=\s*(?:^\s+- |\Z|^\S))", block, re.M | re.S
    )
    if m is None:
        return None
    text = " ".join(m.group(1).split())
    if "library" not in text or "runtime" not in text.replace("run time", "runtime"):
        return None
    holder = "pardisolib" if "pardiso" in text.lower() else "hsllib"
    default = re.search(r'\("([^"]+)"\)', _option_block(holder))
    return default.group(1) if default else None


@lru_cache(maxsize=16)
def library_loads(name: str) -> bool:
    """Whether the shared library ``name`` loads (the dynamic loader's search, as Ipopt's)."""
    import ctypes

    try:
        ctypes.CDLL(name)
    except OSError:
        return False
    return True


def option_choices(option: str) -> list[str]:
    """The values Ipopt's documentation lists for a choice option."""
    return re.findall(r"^\s+- (\S+)\s+\[", _option_block(option), re.M)


@lru_cache(maxsize=1)
def available_linear_solvers() -> tuple[str, ...]:
    """The ``linear_solver`` values this Ipopt build can use: its documented choices whose
    run-time library (HSL, Pardiso) is installed and that Ipopt accepts."""
    out = []
    for value in option_choices("linear_solver"):
        lib = runtime_library("linear_solver", value)
        if lib is not None and not library_loads(lib):
            continue
        try:
            _try_ipopt_option("linear_solver", value, "linear_solver")
        except InputError:
            continue
        out.append(value)
    return tuple(out)


def check_ipopt_options(options: Mapping[str, Any], field: str = "solver.ipopt") -> None:
    """Refuse an option Ipopt does not know (with the nearest name) or a value it refuses,
    and every option that would read or write a file or load code (``output_file``,
    ``option_file_name``, ``hsllib``..., see :func:`optdesign.safe_io.file_option_problem`).

    Each option is tried on a one-variable problem, so the check is Ipopt's own.

    Raises
    ------
    InputError
        Naming ``field.<option>`` and the reason.
    """
    refuse_file_options(options, field)  # first: never tried, even on a probe
    known = ipopt_option_names()
    for key, value in options.items():
        where = f"{field}.{key}"
        if key not in known:
            close = difflib.get_close_matches(key, sorted(known), n=1, cutoff=0.6)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise InputError(where, f"unknown Ipopt option{hint}")
        if isinstance(value, bool) or not isinstance(value, str | int | float):
            raise InputError(where, f"expected a number or a string, got {value!r}")
        if isinstance(value, float) and not math.isfinite(value):
            # Ipopt takes nan and inf for a tolerance without a word, then stops at once
            # or never: a value no option means
            raise InputError(where, f"{value!r} is not a finite number")
        if isinstance(value, int) and not -(2**31) < value < 2**31:
            # Ipopt's integers are 32 bits: a larger one wraps around to another value
            raise InputError(where, f"{value} is outside Ipopt's integers (|n| < 2**31)")
        if key in LIBRARY_OPTIONS:
            raise InputError(
                where,
                "a problem file may not name a library for Ipopt to load (loading runs its "
                "code); install it where the loader finds the default name",
            )
        lib = runtime_library(key, value) if isinstance(value, str) else None
        if lib is not None and not library_loads(lib):
            # Trying it is not safe: Ipopt refuses it, then its solver object crashes the
            # process when it is freed (ma97).
            choices = ""
            if key == "linear_solver":
                choices = f"; available: {', '.join(available_linear_solvers())}"
            raise InputError(where, f"{value!r} needs {lib}, which is not installed{choices}")
        _try_ipopt_option(key, value, where)


@lru_cache(maxsize=256)
def _try_ipopt_option(key: str, value: Any, where: str) -> None:
    x = ca.MX.sym("x")
    buf = io.StringIO()
    opts = {"print_level": 0, "sb": "yes", "max_iter": 0, key: value, "option_file_name": ""}
    if key == "print_options_documentation":
        return  # prints the whole manual; the solve itself checks it
    try:
        with solver_call(), contextlib.redirect_stdout(buf):
            solver = ca.nlpsol(
                "check", "ipopt", {"x": x, "f": x**2}, {"ipopt": opts, "print_time": False}
            )
            solver(x0=1.0)
    except RuntimeError as exc:
        reason = str(exc).strip().splitlines()[-1].split(": ")[-1]
        raise InputError(where, f"Ipopt refuses {value!r} ({reason})") from None
    if solver.stats().get("return_status") == "Invalid_Option":
        raise InputError(where, f"Ipopt refuses {value!r} (out of the option's range)")


class _DeadlineCallback(ca.Callback):
    """Ipopt's iteration callback: stop (User_Requested_Stop) once the study's deadline
    (:mod:`optdesign.solvers.deadline`) has passed. Its inputs are the solver's outputs
    at the current iterate; only the clock is read."""

    def __init__(self, nz: int, ng: int, n_p: int) -> None:
        ca.Callback.__init__(self)
        self._sizes = {"x": nz, "lam_x": nz, "g": ng, "lam_g": ng, "lam_p": n_p, "f": 1}
        self.construct("optdesign_deadline", {})

    def get_n_in(self) -> int:
        return ca.nlpsol_n_out()

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return ca.nlpsol_out(i)

    def get_name_out(self, i: int) -> str:
        return "ret"

    def get_sparsity_in(self, i: int):
        n = self._sizes.get(ca.nlpsol_out(i), 0)
        return ca.Sparsity.dense(n, 1) if n else ca.Sparsity(0, 0)

    def eval(self, arg):
        return [1 if deadline_passed() else 0]


class CasadiNLPSolver:
    """A reusable CasADi NLP solver for one :class:`NLP`.

    Parameters
    ----------
    nlp
        The formulation.
    plugin
        ``"ipopt"`` (default), ``"sqpmethod"``, ...
    options
        Plugin options (Ipopt options go in flat, e.g. ``{"hessian_approximation":
        "limited-memory"}``; others as CasADi expects them).
    """

    def __init__(self, nlp: NLP, plugin: str = "ipopt", options: Mapping[str, Any] | None = None):
        from optdesign.solvers.deadline import DEADLINE_OPTION

        self.nlp = nlp
        self.plugin = plugin
        options = dict(options or {})
        watch = bool(options.pop(DEADLINE_OPTION, False))
        opts: dict[str, Any] = {"print_time": False}
        if watch and plugin == "ipopt":
            # stops the solve at its next iteration once the study's deadline has passed
            self._watch = _DeadlineCallback(nlp.z.numel(), nlp.g.numel(), nlp.p.numel())
            opts["iteration_callback"] = self._watch
        if plugin == "ipopt":
            check_ipopt_options(options or {})
            opts["ipopt"] = {**IPOPT_DEFAULTS, **(options or {})}
        else:
            refuse_file_options(options, "options")
            opts.update(options or {})
        # No Ipopt (this one, or one nested in a QP solver's options) reads ipopt.opt
        # from the working directory.
        opts = without_option_files(opts)
        self.options = opts
        #: the solver, called as a stateless solve (:mod:`optdesign.solvers.nlpsol_call`)
        self.function = NlpsolFunction(
            "optdesign", plugin, {"x": nlp.z, "p": nlp.p, "f": nlp.f, "g": nlp.g}, opts
        )
        rescan_blas()  # the plugin may have loaded CasADi's OpenBLAS, for one_blas_thread

    @property
    def name(self) -> str:
        return self.plugin

    @one_blas_thread()
    def solve(
        self, start: Start | Any, target: Target | str | None = None, bounds: Bounds | None = None
    ) -> Result:
        """Solve from ``start`` (a :class:`Start`, or a design vector) for ``target``."""
        nlp = self.nlp
        start, target, bounds = resolve(nlp, start, target, bounds)
        args: dict[str, Any] = {
            "x0": start.z0,
            "p": nlp.params(target, bounds.parameters),
            "lbx": bounds.lbz,
            "ubx": bounds.ubz,
            "lbg": bounds.lbg,
            "ubg": bounds.ubg,
        }
        if start.lam_x0 is not None:
            args["lam_x0"] = start.lam_x0
        if start.lam_g0 is not None:
            args["lam_g0"] = start.lam_g0
        t0 = time.perf_counter()
        try:
            sol, stats = self.function(**args)
        except RuntimeError as exc:  # CasADi raises on evaluation errors it cannot recover
            wall = time.perf_counter() - t0
            return failed_result(self.plugin, nlp, target, str(exc).splitlines()[0], wall)
        wall = time.perf_counter() - t0
        return_status = str(stats.get("return_status", ""))
        if return_status == "User_Requested_Stop" and deadline_passed():
            return_status = "Maximum_WallTime_Exceeded"  # the study's time limit stopped it
        if return_status == "NonIpopt_Exception_Thrown":
            # a signal handler raised inside the call (one that solver_call does not know
            # of, e.g. the user's own): an interrupt all the same
            raise Interrupted(signal.SIGINT)
        term, status = _IPOPT_STATUS.get(
            return_status,
            (
                TerminationCondition.CONVERGED
                if stats.get("success")
                else TerminationCondition.UNKNOWN,
                "optimal" if stats.get("success") else "failed",
            ),
        )
        iters = stats.get("iter_count")
        n_evals = {
            k.removeprefix("n_call_"): int(v)
            for k, v in stats.items()
            if k.startswith("n_call_") and isinstance(v, int | float)
        }
        return make_result(
            self.plugin,
            nlp,
            target,
            bounds,
            np.asarray(sol["x"], dtype=float).ravel(),
            np.asarray(sol["lam_x"], dtype=float).ravel(),
            np.asarray(sol["lam_g"], dtype=float).ravel(),
            status,
            term,
            return_status,
            int(iters) if iters is not None else None,
            n_evals,
            wall,
        )
