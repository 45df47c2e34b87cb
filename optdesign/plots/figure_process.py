"""A process that draws a command's figures while the command computes.

Importing matplotlib and laying a figure out take about as long as solving a shipped
problem, and a command needs the figure only at its end. :class:`FigureProcess` starts
one worker process at the start of the command (:class:`optdesign.runtime.processes.
WorkerPool`: forked, dies with this process, leaves Ctrl-C to it); the worker imports
matplotlib while this process solves, then draws each figure it is sent (a record of
evaluated curves: drawing evaluates no model) and writes the PNG, while this process
writes its other outputs. On two cores the figure leaves the command's critical path;
on one it costs what it cost in process.

The worker is started only where it is forked (Linux) from a process running no thread
but its main one and the command's signal watchdog
(:func:`optdesign.interrupts.fork_safe_threads`). Elsewhere, or when the worker cannot start or dies, figures are drawn in
process, with the same outcome.

Outcome of a figure: None when written, else a note naming the file and the error
(:func:`optdesign.plots.write_figure`'s contract: a figure is one output among several,
its failure must not lose the others).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from optdesign.errors import OptDesignError
from optdesign.interrupts import fork_safe_threads
from optdesign.plots import write_figure
from optdesign.runtime.processes import WorkerPool, forks_workers


def _warm(modules: Sequence[str] = ()) -> None:
    """What the worker imports while the command computes: matplotlib, and ``modules``
    (those of the figures it will draw)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.figure
    from matplotlib.backends import backend_agg  # noqa: F401

    for module in modules:
        importlib.import_module(module)


def _draw(module: str, function: str, record: Any, path: str) -> str | None:
    draw = getattr(importlib.import_module(module), function)
    return write_figure(lambda: draw(record), path)


def _draw_in_worker(module: str, function: str, record: Any, path: str) -> str | None:
    """:func:`_draw` in the worker, which selects the file-only back-end first (the
    process drawing in process keeps its own)."""
    _warm()
    return _draw(module, function, record, path)


class FigureProcess:
    """Draws figures in a worker process started before the work that precedes them
    (see the module's docstring). Use as a context manager: the worker is started on
    entry and stopped on exit."""

    def __init__(self, warm: bool = True, draws: Sequence[str] = ()) -> None:
        #: import matplotlib in the worker as soon as it starts (False: when
        #: :meth:`warm_up` is called, or with the first figure, for a command whose own
        #: work keeps every core busy until then)
        self.warm = warm
        #: the ``"module:function"`` paths of the figures to come, imported by the warm-up
        self.modules = tuple(dict.fromkeys(d.partition(":")[0] for d in draws))
        self._warmed = False  # the warm-up was sent to the worker
        self._pool: WorkerPool | None = None
        #: the worker's task in flight: "" for the warm-up, else the figure's path
        self._inflight: str | None = None
        #: the outcomes of the figures submitted, in order (None: written); the one the
        #: worker draws is filled in when it answers
        self._outcomes: list[str | None] = []
        self._waiting = 0  # figures submitted whose outcome is not yet read

    def __enter__(self) -> FigureProcess:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def forked(self) -> bool:
        """Whether figures are drawn in a worker process (else in process)."""
        return self._pool is not None

    @property
    def pid(self) -> int | None:
        """The worker's process id (None when figures are drawn in process)."""
        return None if self._pool is None else self._pool.procs[0].pid

    def start(self) -> None:
        """Start the worker where it is safe (see the module's docstring)."""
        if self._pool is not None or not forks_workers() or not fork_safe_threads():
            return
        try:
            self._pool = WorkerPool(1)
        except (OSError, OptDesignError):  # no process to spare: draw in process
            self.close()
            return
        if self.warm:
            self.warm_up()

    def warm_up(self) -> None:
        """Let the worker import matplotlib and the figures' modules now (once; nothing
        when figures are drawn in process or the worker is busy). A command whose
        workers take every core calls it when one of them idles
        (:func:`optdesign.runtime.processes.when_a_worker_idles`)."""
        if self._pool is None or self._warmed or self._inflight is not None:
            return
        self._warmed = True
        try:
            self._pool.submit(_warm, (self.modules,))
        except (OSError, OptDesignError):  # the worker is gone: figures in process
            self.close()
            return
        self._inflight = ""

    def submit(self, draw: str, path: str | Path, prepare: Callable[[], Any]) -> None:
        """Write the figure ``draw(prepare())`` as PNG at ``path``; ``draw`` is a
        ``"module:function"`` path (the worker imports it), ``prepare`` evaluates the
        record it draws, here. A failure of either is the figure's note; the outcome
        comes from :meth:`outcome`, in the order submitted."""
        self._waiting += 1
        self._settle()
        try:
            record = prepare()
        except OSError:
            raise
        except Exception as exc:  # what the figure shows could not be evaluated

            def fail(error: Exception = exc) -> Any:
                raise error

            self._outcomes.append(write_figure(fail, path))
            return
        module, _, function = draw.partition(":")
        job = (module, function, record, str(path))
        if self._pool is not None:
            try:
                self._pool.submit(_draw_in_worker, job)
            except Exception:  # a record that does not pickle, a worker gone: in process
                self.close()
            else:
                self._inflight = str(path)
                return
        self._outcomes.append(_draw(*job))

    def outcome(self) -> str | None:
        """The outcome of the oldest figure submitted (None: written; else the note).
        I/O errors writing it are raised, as :func:`write_figure` raises them."""
        if not self._waiting:
            raise RuntimeError("outcome(): no figure was submitted")
        if not self._outcomes:
            self._settle()
        self._waiting -= 1
        return self._outcomes.pop(0)

    def _settle(self) -> None:
        """Wait for the worker's task in flight, if any, and keep its outcome."""
        if self._inflight is None or self._pool is None:
            return
        path, self._inflight = self._inflight, None
        try:
            ((_, note),) = self._pool.wait()
        except OSError:
            raise
        except OptDesignError:  # the worker died
            code = self._pool.procs[0].exitcode
            self.close()
            note = f"the figure process ended (exit code {code})"
            if path:
                self._outcomes.append(f"{Path(path).name} not written: {note}")
            return
        if path:
            self._outcomes.append(note)

    def close(self) -> None:
        """Stop the worker (it also stops when this process ends)."""
        if self._pool is not None:
            self._pool.close()
        self._pool = None
        self._inflight = None
