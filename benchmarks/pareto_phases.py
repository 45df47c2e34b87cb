"""One ``optdesign pareto`` run as a user runs it, with a timestamp at each phase.

Run by ``benchmarks/command_cost.py --pareto`` in a fresh interpreter:

    python benchmarks/pareto_phases.py EVENTS LAUNCHED -- pareto FILE --objectives ... --out DIR

``EVENTS`` is a JSON Lines file: one line a timed call (process id, name, start, end in
seconds after ``LAUNCHED``, the launching process's ``time.time()``). The probes wrap the
functions of each phase before the command starts, so the forked workers (the front's
and the figure's) inherit them: the parent's imports, loading the file, the worker pool's
start, every front task (anchors' multistarts and tie-breaks, chain points, polish), the
solver builds in the workers, the figure worker's warm-up and drawing, front.csv and
front.json, the page (report.html). The command then runs through ``optdesign.cli.main``
as the console script runs it (its watchdog, ``os._exit`` at the end).
"""

from __future__ import annotations

import functools
import json
import os
import sys
import time

EVENTS, LAUNCHED = sys.argv[1], float(sys.argv[2])


def log(name: str, start: float, end: float) -> None:
    line = {"pid": os.getpid(), "name": name, "a": start - LAUNCHED, "b": end - LAUNCHED}
    with open(EVENTS, "a") as fh:
        fh.write(json.dumps(line) + "\n")


def probe(module, attr: str, name=None, sent: bool = False) -> None:
    """Time every call of ``module.attr`` as ``name`` (a string, or a function of the
    call's arguments giving one). ``sent``: a function sent to a worker, which pickle
    finds by its home module's name: replaced there too."""
    fn = getattr(module, attr)

    @functools.wraps(fn)  # the same qualified name: pickled by reference as before
    def timed(*args, **kwargs):
        t0 = time.time()
        try:
            return fn(*args, **kwargs)
        finally:
            label = name(*args, **kwargs) if callable(name) else (name or attr)
            log(label, t0, time.time())

    setattr(module, attr, timed)
    if sent:
        setattr(sys.modules[fn.__module__], fn.__qualname__, timed)


START = time.time()
import optdesign.cli as cli  # noqa: E402  (the command's first import, timed)
import optdesign.commands.pareto as command  # noqa: E402

log("imports before the command", START, time.time())
t = time.time()
import optdesign.api as api  # noqa: E402
import optdesign.plots.figure_process as figure_process  # noqa: E402
import optdesign.problem as problem_module  # noqa: E402
import optdesign.runtime.processes as processes  # noqa: E402
import optdesign.studies.pareto.eps_solver as eps_solver  # noqa: E402
import optdesign.studies.pareto.methods as methods  # noqa: E402

log("imports the command makes before the front (done here to probe them)", t, time.time())


def _task_name(task, deps) -> str:
    kind = task.get("kind", "?")
    if kind.startswith("anchor"):
        order = task.get("order") or ["?"]
        return f"task {kind} {order[0]}"
    return f"task {kind}"


def _solver_for(fn):
    @functools.wraps(fn)
    def timed(problem, method=None, *args, **kwargs):
        t0 = time.time()
        out = fn(problem, method, *args, **kwargs)
        t1 = time.time()
        if t1 - t0 > 0.002:  # a build (a cached solver returns in microseconds)
            log(f"solver build {method or 'default'}", t0, t1)
        return out

    return timed


probe(problem_module, "load_problem", "load the problem file")
probe(command, "_run_locked", "the fronts and their files")
probe(api, "pareto", "the front (optdesign.pareto)")
_front_outputs = api.front_outputs


def _outputs(*args, **kwargs):
    # the page's modules are the parent's imports after the front: probed when it makes them
    t0 = time.time()
    import optdesign.reports.front_files as front_files
    import optdesign.reports.html as html

    log("imports of the files' writers", t0, time.time())
    probe(front_files, "write_front_csv", "front.csv")
    probe(front_files, "write_front_json", "front.json")
    probe(html, "front_report", "report.html: the page")
    return _front_outputs(*args, **kwargs)


api.front_outputs = _outputs
probe(api, "front_outputs", "the front's files")
probe(methods, "formulation_for", "formulation (parent, before the fork)")
probe(methods, "front_task", _task_name, sent=True)
eps_solver.solver_for = _solver_for(eps_solver.solver_for)
_solve = eps_solver.EpsSolver.solve


def _timed_solve(self, *args, **kwargs):
    # the solve alone: the back-end's work on the NLP (builds are timed above)
    t0 = time.time()
    out = _solve(self, *args, **kwargs)
    log("NLP solve", t0, time.time())
    return out


eps_solver.EpsSolver.solve = _timed_solve
probe(figure_process, "_warm", "figure worker: warm-up (imports)", sent=True)
probe(figure_process, "_draw_in_worker", "front.png: drawn in the figure worker", sent=True)
probe(figure_process, "_draw", "front.png: drawn")

_pool_init = processes.WorkerPool.__init__


def _timed_pool(self, size):
    t0 = time.time()
    _pool_init(self, size)
    log(f"worker pool of {size} started", t0, time.time())


processes.WorkerPool.__init__ = _timed_pool

sys.argv = ["optdesign", *sys.argv[sys.argv.index("--") + 1 :]]
t = time.time()
_exit = os._exit


def _logged_exit(code: int) -> None:
    if os.getpid() == MAIN:
        log("command (cli.main)", t, time.time())
    _exit(code)


MAIN = os.getpid()
os._exit = _logged_exit
sys.exit(cli.main())
