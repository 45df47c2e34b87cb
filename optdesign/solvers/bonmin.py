"""Bonmin as optdesign uses it: its options, its MINLP solve, and the back-end of a
continuous NLP (no CasADi import at module level: the registry lists it).

Bonmin (in CasADi's wheel) solves MINLPs by its algorithms ``B-BB`` (NLP-based branch
and bound), ``B-OA`` (outer approximation) and ``B-Hyb`` (hybrid); the last two are
exact only for convex problems. On a continuous NLP it runs its Ipopt.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

from optdesign.errors import InputError
from optdesign.solvers.quiet import quiet_stdout

#: Bonmin's algorithms (``bonmin.algorithm``) offered as choices and bench configurations.
BONMIN_ALGORITHMS = ("B-BB", "B-OA", "B-Hyb")

#: Bonmin quiet: no log of its tree, its NLPs, its (MI)LPs, nor Ipopt's banner.
BONMIN_QUIET: dict[str, Any] = {
    "bb_log_level": 0,
    "nlp_log_level": 0,
    "lp_log_level": 0,
    "milp_log_level": 0,
    "oa_log_level": 0,
    "fp_log_level": 0,
    "print_level": 0,
    "sb": "yes",
}

#: Bonmin's return statuses that carry an integer-feasible point.
BONMIN_FOUND = ("SUCCESS", "FEASIBLE")

#: The options file Bonmin reads from the working directory at every solve, whatever its
#: options say (CasADi's interface calls Bonmin's ``readOptionsFile()``; unlike Ipopt's
#: ``option_file_name`` nothing turns it off): one planted there could set Bonmin's
#: options and write its log over any file (``output_file``), so no solve starts beside one.
OPTIONS_FILE = "bonmin.opt"


def refuse_options_file() -> None:
    """InputError ``solver`` when the working directory holds a ``bonmin.opt`` (a file, a
    link, even a broken one) that Bonmin would read."""
    path = os.path.abspath(OPTIONS_FILE)
    if os.path.lexists(path):
        raise InputError(
            "solver",
            f"bonmin: refused: {path} would be read by Bonmin at the solve (options, and "
            "files it may write); options come from the problem file's [solver] or "
            "options=. Remove it or run from another folder",
        )


def bonmin_options(options: Mapping[str, Any] | None) -> dict[str, Any]:
    """Bonmin's options: quiet, ``B-BB`` unless ``algorithm`` names another of
    :data:`BONMIN_ALGORITHMS`, then the caller's (Bonmin's own names)."""
    opts = {**BONMIN_QUIET, "algorithm": "B-BB", **dict(options or {})}
    check_bonmin_options(opts)
    return opts


def check_bonmin_options(options: Mapping[str, Any], field: str = "options") -> None:
    """Refuse an unknown ``algorithm`` before any work, naming ``field``."""
    algorithm = options.get("algorithm", "B-BB")
    if algorithm not in BONMIN_ALGORITHMS:
        raise InputError(
            f"{field}.algorithm",
            f"{algorithm!r} is not a Bonmin algorithm (use {', '.join(BONMIN_ALGORITHMS)})",
        )


def solve_minlp(minlp: Any, x0: Any, options: Mapping[str, Any] | None = None):
    """Bonmin on a mixed-integer NLP (``minlp``: x, f, g, its bounds and ``discrete``
    flags, e.g. :class:`~optdesign.formulations.catalogue.minlp_program.CatalogueMINLP`) from
    ``x0``; a :class:`~optdesign.solvers.base.MINLPSolution` (an evaluation error Bonmin
    cannot recover from is a status ``"error: ..."``, no point)."""
    import casadi as ca
    import numpy as np

    from optdesign.interrupts import solver_call
    from optdesign.solvers.base import MINLPSolution

    opts = bonmin_options(options)
    refuse_options_file()
    solver = ca.nlpsol(
        "optdesign_bonmin",
        "bonmin",
        {"x": minlp.x, "f": minlp.f, "g": minlp.g},
        # a trial point where a model is undefined (NaN) is Bonmin's to handle, as it is
        # Ipopt's: CasADi's warning on each would only alarm
        {
            "discrete": minlp.discrete,
            "print_time": False,
            "show_eval_warnings": False,
            "bonmin": opts,
        },
    )
    with solver_call(), quiet_stdout():
        try:
            sol = solver(x0=x0, lbx=minlp.lbx, ubx=minlp.ubx, lbg=minlp.lbg, ubg=minlp.ubg)
            status = str(solver.stats().get("return_status", ""))
        except RuntimeError as exc:
            sol, status = None, f"error: {str(exc).splitlines()[-1]}"
    if sol is None or status not in BONMIN_FOUND:
        return MINLPSolution(status, False, None, None, opts["algorithm"])
    x = np.asarray(sol["x"], dtype=float).ravel()
    return MINLPSolution(status, True, x, float(sol["f"]), opts["algorithm"])


def bonmin_nlp_solver(nlp, options: Mapping[str, Any] | None = None):
    """Bonmin as a back-end of a continuous NLP (no integer variable: its Ipopt), quiet."""
    from optdesign.solvers.casadi_nlp import CasadiNLPSolver

    class BonminNLPSolver(CasadiNLPSolver):
        def solve(self, *args: Any, **kwargs: Any):
            refuse_options_file()
            with quiet_stdout():
                return super().solve(*args, **kwargs)

    return BonminNLPSolver(nlp, "bonmin", {"bonmin": bonmin_options(options)})
