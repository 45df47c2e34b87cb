"""A CasADi ``nlpsol`` Function called as a stateless solve (:class:`NlpsolFunction`).

sqpmethod's QP solver (qpOASES) starts each QP from the last one's working set, across
solves: a result then depends on what the same object solved before (a front differed in
its 16th digit between 1 and 2 workers, and after failed solves every later one failed).
A Python call of an ``nlpsol`` always uses its first memory. The solves of such a plugin
therefore go through an MX call node (:func:`through_call_node`), which takes a memory
from the Function's pool for each evaluation; that memory is then retired (checked out
for good), so that the next solve gets a new one, as on a new Function, for ~0.3 ms
instead of a rebuild's ~30 ms. Every :data:`RETIRED_MEMORIES` solves the Function is
built again, which frees them. qpOASES prints its licence banner when a memory is set
up: unless the options ask for output, the call runs with stdout silenced
(:func:`~optdesign.solvers.quiet.quiet_stdout`). Ipopt keeps no such state and is called
directly. Both the NLP back-end (:mod:`optdesign.solvers.casadi_nlp`) and the phase-1
problem (:mod:`optdesign.solvers.phase_one`) solve through it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping
from typing import Any

import casadi as ca

from optdesign.interrupts import solver_call
from optdesign.solvers.quiet import quiet_stdout

#: Solves of a plugin that keeps state (sqpmethod) before its Function is built again,
#: freeing the memories they retired (~0.1 MB each on a front's NLP of 550 rows).
RETIRED_MEMORIES = 64

SOLVE_INPUTS = ("x0", "p", "lbx", "ubx", "lbg", "ubg", "lam_x0", "lam_g0")
SOLVE_OUTPUTS = ("x", "f", "g", "lam_x", "lam_g", "lam_p")


def asks_to_print(options: Mapping[str, Any]) -> bool:
    """Whether CasADi options ask a solver for output: a ``print_*`` or ``verbose`` option
    set, or a QP solver's print level other than none (``print_time``, which CasADi
    prints after the call from Python, is not counted)."""
    for key, value in options.items():
        if key == "print_time":
            continue
        if (key.startswith("print_") or key.startswith("verbose")) and value:
            return True
        if key.endswith("_options") and isinstance(value, Mapping):
            level = value.get("printLevel", value.get("print_level"))
            if level not in (None, "none", 0) or asks_to_print(value):
                return True
    return False


def through_call_node(solver: ca.Function) -> ca.Function:
    """``solver`` behind an MX call node with the same inputs and outputs: the node
    checks a memory of ``solver`` out of its pool for each evaluation and releases it
    after (a direct call always uses the Function's first memory)."""
    inputs = [ca.MX.sym(name, solver.sparsity_in(name)) for name in SOLVE_INPUTS]
    out = solver(**dict(zip(SOLVE_INPUTS, inputs, strict=True)))
    return ca.Function(
        "optdesign_call",
        inputs,
        [out[name] for name in SOLVE_OUTPUTS],
        list(SOLVE_INPUTS),
        list(SOLVE_OUTPUTS),
    )


class NlpsolFunction:
    """``ca.nlpsol(name, plugin, problem, options)``, built once, whose calls do not
    depend on the calls before (see the module's text).

    Parameters
    ----------
    name, plugin, problem, options
        As :func:`casadi.nlpsol` takes them (``options`` complete: the caller adds its
        plugin's defaults and refuses option files).
    """

    def __init__(self, name: str, plugin: str, problem: dict, options: Mapping[str, Any]):
        self.name = name
        self.plugin = plugin
        self.problem = problem
        self.options = dict(options)
        #: the plugin keeps state from one solve to the next in its memory: each solve
        #: then gets a memory of its own
        self.keeps_state = plugin != "ipopt"
        #: solves print nothing unless the options ask for output (qpOASES's banner at
        #: each new memory is not output anybody asked for)
        self.quiet = not asks_to_print(self.options)
        self.function = self._build()

    def _build(self) -> ca.Function:
        # qpOASES (sqpmethod's QP solver) prints its licence banner to the C stdout when
        # it is built, whatever its print level; Ipopt prints nothing at print_level 0
        quiet = quiet_stdout() if self.keeps_state else contextlib.nullcontext()
        with solver_call(), quiet:
            function = ca.nlpsol(self.name, self.plugin, self.problem, self.options)
        #: the memories this Function's solves used, never handed out again
        self.retired: list[int] = []
        self.wrapped = through_call_node(function) if self.keeps_state else None
        return function

    def __call__(self, **args: Any) -> tuple[dict[str, Any], dict[str, Any]]:
        """One solve: the solution and the solver's statistics."""
        if not self.keeps_state:
            with solver_call():  # a signal meanwhile is raised here, not made a result
                sol = self.function(**args)
            return sol, self.function.stats()
        function = self.function
        quiet = quiet_stdout() if self.quiet else contextlib.nullcontext()
        try:
            with solver_call(), quiet:
                sol = self.wrapped(**args)
        finally:
            # the memory the call node released after its evaluation (or its failure)
            used = function.checkout()
            self.retired.append(used)
        stats = function.stats(used)
        if len(self.retired) >= RETIRED_MEMORIES:
            # the old one (and the call node that holds it) goes first: destroyed after
            # the new one's qpOASES was set up, it made qpOASES's error messages visible
            self.function = self.wrapped = None
            self.function = self._build()
        return sol, stats
