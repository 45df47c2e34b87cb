"""Bonmin's options as optdesign uses it (no CasADi import: the registry lists it).

Bonmin (in CasADi's wheel) solves MINLPs by its algorithms ``B-BB`` (NLP-based branch
and bound), ``B-OA`` (outer approximation) and ``B-Hyb`` (hybrid); the last two are
exact only for convex problems. On a continuous NLP it runs its Ipopt.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator, Mapping
from typing import Any

from optdesign.errors import InputError

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


@contextlib.contextmanager
def quiet_stdout() -> Iterator[None]:
    """Bonmin and Cbc write some lines to the C-level stdout whatever their log levels:
    send file descriptor 1 to /dev/null for the call."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:  # no stdout at all
        yield
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


def bonmin_options(options: Mapping[str, Any] | None) -> dict[str, Any]:
    """Bonmin's options: quiet, ``B-BB`` unless ``algorithm`` names another of
    :data:`BONMIN_ALGORITHMS`, then the caller's (Bonmin's own names)."""
    opts = {**BONMIN_QUIET, "algorithm": "B-BB", **dict(options or {})}
    if opts["algorithm"] not in BONMIN_ALGORITHMS:
        raise InputError(
            "options.algorithm",
            f"{opts['algorithm']!r} is not a Bonmin algorithm (use {', '.join(BONMIN_ALGORITHMS)})",
        )
    return opts


def bonmin_nlp_solver(nlp, options: Mapping[str, Any] | None = None):
    """Bonmin as a back-end of a continuous NLP (no integer variable: its Ipopt), quiet."""
    from optdesign.solvers.casadi_nlp import CasadiNLPSolver

    class BonminNLPSolver(CasadiNLPSolver):
        def solve(self, *args: Any, **kwargs: Any):
            with quiet_stdout():
                return super().solve(*args, **kwargs)

    return BonminNLPSolver(nlp, "bonmin", {"bonmin": bonmin_options(options)})
