"""Local worker processes of the task runner: a pipe-per-worker pool, forked task isolation.

Split from :mod:`optdesign.runtime.runner` (which re-exports the public names). Every
process forked here dies with its parent, whatever signal ends the parent (Linux
``PR_SET_PDEATHSIG``), and ignores SIGINT and SIGHUP, which the parent alone handles
(:func:`optdesign.interrupts.child_signals`).
"""

from __future__ import annotations

import contextlib
import gc
import multiprocessing
import os
import pickle
import select
import signal
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from typing import Any

from optdesign.errors import OptDesignError
from optdesign.interrupts import child_signals, deferred, signals_blocked
from optdesign.solvers.blas import limit_blas_threads

#: Callbacks waiting for a core that a run's local workers leave idle
#: (:func:`when_a_worker_idles`).
_ON_IDLE: list[Callable[[], None]] = []


@contextmanager
def when_a_worker_idles(callback: Callable[[], None]) -> Iterator[None]:
    """Call ``callback()`` once, the first time a :class:`WorkerPool` is waited on while
    one of its workers has nothing to do (the run has no task ready for it: a chain
    waiting for the other chain's anchor, the last points of a sweep), and not after the
    block. A command that keeps other work for later (drawing its figures) starts it
    then, on a core its own workers leave idle, instead of competing with them for one.
    The callback runs in the waiting thread and must be quick (start work elsewhere)."""
    _ON_IDLE.append(callback)
    try:
        yield
    finally:
        with contextlib.suppress(ValueError):  # called already
            _ON_IDLE.remove(callback)


def _worker_idle() -> None:
    while _ON_IDLE:
        _ON_IDLE.pop(0)()


if hasattr(os, "register_at_fork"):
    # A forked worker's own pools are not the run's: its copy of a callback would act on
    # the parent's objects (send on the parent's pipes) from the wrong process.
    os.register_at_fork(after_in_child=_ON_IDLE.clear)


@contextmanager
def process_pool(workers: int) -> Iterator[WorkerPool | None]:
    """A pool of ``workers`` local processes (None for ``workers <= 1``).

    Pass it to several :func:`run_tasks` calls (``pool=``) to keep the same worker
    processes, and so their caches, across phases; it is shut down on exit.
    """
    if workers <= 1:
        yield None
        return
    pool = WorkerPool(workers)
    try:
        yield pool
    finally:
        pool.close()


class WorkerPool:
    """Local worker processes, each fed through its own pipe.

    Why not :class:`concurrent.futures.ProcessPoolExecutor`: a task there passes through
    two helper threads on its way to a worker and back, a large share of the time of the
    short points of a Pareto chain; one pipe per worker, written from the scheduling
    thread, makes the round trip several times quicker (the figures: benchmarks/README.md, "Figures behind comments in the code").

    A task that raises re-raises in :meth:`wait` (the same exception when it pickles, a
    :class:`OptDesignError` with the worker's traceback otherwise); a worker that dies is
    reported with its exit code.

    Workers die with this process whatever ends it, SIGKILL included (Linux
    ``PR_SET_PDEATHSIG``, see :func:`die_with_parent`): orphans would keep running, and
    keep the run's stdout open, so that a reader of it through a pipe would wait for
    them. They ignore SIGINT and SIGHUP: Ctrl-C in a terminal, or the terminal closing,
    signals the whole process group, and this process alone decides what an interrupt
    stops. The signals are blocked from the fork until the worker has set that up, so
    none reaches the parent's handler inherited by the fork. Create the pool in the
    thread that outlives it (the main thread): the kernel ties the workers to the
    forking thread.
    """

    def __init__(self, size: int):
        ctx = multiprocessing.get_context("fork" if forks_workers() else "spawn")
        self.size = size
        self.conns: list[Any] = []
        self.procs: list[Any] = []
        # Objects of this process that a forked worker inherits are frozen out of the
        # garbage collector while forking: a collection in the worker would otherwise
        # write to every inherited object and copy its memory page (copy-on-write).
        self.idle: list[int] = []
        self.busy: set[int] = set()
        gc.freeze()
        me = os.getpid()
        try:
            for _ in range(size):
                parent, child = ctx.Pipe()
                # A forked worker inherits the parent ends of its own and the earlier
                # workers' pipes; it closes them, so that the parent's death reaches
                # every worker as end-of-file even where no death signal exists.
                inherited = [*self.conns, parent] if ctx.get_start_method() == "fork" else []
                proc = ctx.Process(target=_worker_loop, args=(child, me, inherited), daemon=True)
                self.conns.append(parent)
                # not inside the fork's callbacks, where it would be lost
                with deferred(), signals_blocked():
                    proc.start()
                child.close()
                self.procs.append(proc)
        except BaseException:  # interrupted while starting: stop the ones started
            self.conns = self.conns[: len(self.procs)]
            self.close()
            raise
        finally:
            gc.unfreeze()
        self.idle = list(range(size))[::-1]

    def submit(self, fn: Callable, args: tuple) -> int:
        """Send ``fn(*args)`` to an idle worker; returns the worker's index."""
        i = self.idle.pop()
        # Busy before the send: an interrupt inside the send leaves a half-read message,
        # and close() must then terminate that worker rather than talk to it.
        self.busy.add(i)
        self.conns[i].send((fn, args))
        return i

    def wait(self) -> list[tuple[int, Any]]:
        """Block until at least one busy worker answers; ``(worker index, result)`` each."""
        from multiprocessing.connection import wait as wait_any

        if _ON_IDLE and len(self.busy) < self.size:
            _worker_idle()
        ready = wait_any([self.conns[i] for i in self.busy])
        out = []
        for i in sorted(self.busy):
            if self.conns[i] not in ready:
                continue
            try:
                ok, value = self.conns[i].recv()
            except (EOFError, ConnectionResetError):  # killed mid-answer: a reset
                self.procs[i].join(1.0)
                _signalled_with_us(self.procs[i].exitcode)
                raise OptDesignError(
                    f"worker process {self.procs[i].pid} died "
                    f"(exit code {self.procs[i].exitcode}) while running a task"
                ) from None
            self.busy.discard(i)
            self.idle.append(i)
            if not ok:
                raise value
            out.append((i, value))
        return out

    def close(self) -> None:
        """Stop the workers: idle ones are asked to exit, busy ones (an interrupted run:
        their results are not wanted any more) are terminated."""
        with deferred():  # a second Ctrl-C waits for this (2 s at most)
            self._close()

    def _close(self) -> None:
        for i, (conn, proc) in enumerate(zip(self.conns, self.procs, strict=True)):
            if i in self.busy:
                proc.terminate()
            else:
                try:
                    conn.send(None)
                except OSError:
                    pass
        for proc in self.procs:
            proc.join(2.0)
            if proc.is_alive():
                proc.kill()
                proc.join(1.0)
        for conn in self.conns:
            conn.close()


def _worker_loop(conn, parent_pid: int | None = None, inherited: Iterable[Any] = ()) -> None:
    if parent_pid is not None:
        die_with_parent(parent_pid)
    for other in inherited:
        other.close()
    child_signals()
    _init_process()
    while True:
        try:
            msg = conn.recv()
        except (EOFError, OSError, KeyboardInterrupt):
            return  # the parent is gone
        if msg is None:
            return
        fn, args = msg
        try:
            reply = (True, fn(*args))
        except BaseException as exc:  # every failure goes back to the parent
            reply = (False, _portable(exc))
        try:
            conn.send(reply)
        except OSError:
            return  # the parent is gone: nobody wants the result
        except Exception as exc:  # e.g. a result that does not pickle
            try:
                conn.send((False, _portable(exc)))
            except OSError:
                return


def _signalled_with_us(exitcode: int | None) -> None:
    """A child that died of SIGTERM may have been signalled with this process (``kill``
    of the whole process group, as ``timeout`` does): let this process's own signal
    arrive and raise (its interrupt, not "a worker died" nor a crash record)."""
    if exitcode == -signal.SIGTERM:
        time.sleep(0.2)


_PR_SET_PDEATHSIG = 1


def die_with_parent(parent_pid: int) -> bool:
    """Make this (just forked) process get SIGKILL when its parent dies.

    Linux ``prctl(PR_SET_PDEATHSIG, SIGKILL)``; then ``os.getppid()`` is checked again,
    since a parent that died between the fork and the ``prctl`` would not be noticed.

    Parameters
    ----------
    parent_pid
        ``os.getpid()`` of the parent, taken before forking.

    Returns
    -------
    bool
        Whether the death signal is armed (False off Linux).
    """
    armed = False
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
        except (OSError, AttributeError):
            armed = False
    if os.getppid() != parent_pid:
        os._exit(1)  # the parent is gone already
    return armed


def fork_call(
    fn: Callable[[], Any], timeout: float | None = None, quiet: bool = False
) -> tuple[str, Any]:
    """Run ``fn()`` in a forked child with a hard timeout.

    Returns ``("ok", value)``, ``("error", text)`` (it raised), ``("timeout", text)``
    (killed after ``timeout`` s) or ``("crash", text)`` (the child died without an
    answer). The child dies with this process (:func:`die_with_parent`) and is killed
    if this process is interrupted while waiting. ``os.fork`` (not multiprocessing), so
    it also works in daemonic workers. ``quiet``: the child's stdout/stderr go to
    /dev/null.
    """
    if not hasattr(os, "fork"):
        raise OptDesignError("task isolation (hard timeout) needs os.fork (a POSIX system)")
    me = os.getpid()
    for stream in (sys.stdout, sys.stderr):  # else the child would write them again
        with contextlib.suppress(Exception):
            stream.flush()
    rfd, wfd = os.pipe()
    # not inside the fork's callbacks, where it would be lost
    with deferred(), signals_blocked():
        pid = os.fork()
        if pid == 0:  # pragma: no cover - the child (coverage does not follow it)
            _fork_child(fn, rfd, wfd, me, quiet)
    os.close(wfd)
    chunks: list[bytes] = []
    status: int | None = None
    deadline = None if timeout is None else time.monotonic() + timeout
    try:
        while True:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                break
            ready, _, _ = select.select([rfd], [], [], left)
            if not ready:
                continue
            chunk = os.read(rfd, 1 << 16)
            if not chunk:
                _, status = os.waitpid(pid, 0)
                break
            chunks.append(chunk)
    finally:
        os.close(rfd)
        if status is None:  # timed out, or this process was interrupted
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
    if status is None:
        return "timeout", f"no result within the hard timeout of {timeout:g} s (killed)"
    try:
        return pickle.loads(b"".join(chunks))
    except Exception:
        if os.WIFSIGNALED(status):
            _signalled_with_us(-os.WTERMSIG(status))
        return "crash", f"worker process died (wait status {status})"


def _fork_child(fn: Callable[[], Any], rfd: int, wfd: int, parent: int, quiet: bool) -> None:
    try:
        os.close(rfd)
        die_with_parent(parent)
        child_signals()
        if quiet:
            import faulthandler

            faulthandler.disable()  # it writes a crash report to its own copy of stderr
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 1)
            os.dup2(devnull, 2)
        try:
            payload = pickle.dumps(("ok", fn()))
        except BaseException as exc:  # every failure becomes an answer
            payload = pickle.dumps(("error", f"{type(exc).__name__}: {exc}"))
        view = memoryview(payload)
        while view:
            view = view[os.write(wfd, view) :]
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
    finally:
        os._exit(0)


def _portable(exc: BaseException) -> BaseException:
    """``exc`` if it survives pickling, else an OptDesignError carrying its traceback."""
    import traceback

    try:
        pickle.loads(pickle.dumps(exc))
        return exc
    except Exception:
        text = "".join(traceback.format_exception(exc))
        return OptDesignError(f"a worker process failed:\n{text}")


def forks_workers() -> bool:
    """Whether local workers are forked from this process (Linux), and so inherit what it
    built before starting them. Elsewhere the platform's default (spawn) is used."""
    return sys.platform.startswith("linux")


def _init_process() -> None:
    # One solver thread per process: the processes are the parallelism.
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    # The environment variable is read when a BLAS library loads; forked workers inherit
    # NumPy's and SciPy's OpenBLAS already loaded with one thread per core. Two workers
    # each running two BLAS threads (SLSQP's QP) on 2 cores oversubscribe the cores.
    # A library loaded later (CasADi's, with the first Ipopt solver) is set to one thread
    # by the solve itself (optdesign.solvers.blas.one_blas_thread), as in the main process.
    limit_blas_threads(1)
