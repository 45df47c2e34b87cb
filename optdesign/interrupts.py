"""SIGINT, SIGTERM and SIGHUP as an exception in the main thread, also inside solver calls.

The CLI (:func:`optdesign.cli.run_guarded`) installs :func:`interrupts_as_exceptions`:
the three signals then raise :class:`Interrupted`, so every ``finally`` and context
manager on the way out runs (workers stopped, store closed) and the command ends with
one line.

Python runs a signal handler between any two bytecodes of the main thread, including
inside the callbacks of ``os.fork`` (where an exception is printed and dropped: the
interrupt would be lost) and between writing a record and counting it. Code that must
not be cut there wraps itself in :func:`deferred`: a signal arriving inside is raised
when the section ends.

Solver libraries lose the exception. CasADi calls ``PyErr_CheckSignals`` between the
function evaluations of an Ipopt iteration: the handler runs and raises, CasADi turns the
exception into its own ``KeyboardInterruptException``, Ipopt stops with
``NonIpopt_Exception_Thrown``, and the call *returns* (or raises a ``RuntimeError`` from
another plug-in) as if the start had merely failed - the multistart went on with the
next start. So every handler here also records the signal (:func:`received`), and every
call into a solver library runs inside :func:`solver_call`, which raises
:class:`Interrupted` when the call returns with a signal recorded, whatever the library
made of it. Without the CLI's handlers (library use, a notebook), :func:`solver_call`
puts a recording twin of Python's own SIGINT handler in place for the duration of the
call, so Ctrl-C raises :class:`KeyboardInterrupt` as soon as the solver returns.

Two cases are left that no code on the main thread can catch, and the CLI runs
:func:`start_watchdog` for them: a thread woken by every signal (Python's wakeup file
descriptor). Native code that does not come back to Python within a second (one long
factorisation, a conic solver without signal checks) cannot be stopped from Python:
when the main thread is still inside a solver call ``WATCHDOG_GRACE`` s after the
signal, and outside any critical section, the watchdog ends the process itself with the
same line and exit code (a solver call writes nothing, so every record written before
it is all there is to keep). And C code that calls back into Python may drop the
handler's exception (NumPy's conversion of an object that is not an array clears any
error raised while it asks for the shape): when no :class:`Interrupted` is alive
``RERAISE_AFTER`` s after the signal, the command did not hear it, and the watchdog
sends the signal to the main thread again.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
import weakref
from collections.abc import Callable, Iterator

from optdesign.text import printable

#: The signals a command turns into :class:`Interrupted` (SIGHUP: the terminal closed).
SIGNALS: tuple[signal.Signals, ...] = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)
)

#: Seconds the main thread has, after a signal, to leave a solver call by itself before
#: the watchdog ends the process (the whole budget from the signal to the exit is 1 s).
WATCHDOG_GRACE = 0.5
#: Seconds after which a signal whose exception nobody holds is sent again.
RERAISE_AFTER = 0.1

_depth = 0  # nesting of deferred() sections in the main thread
_pending: int | None = None  # a signal that arrived inside one
_received: int | None = None  # the signal that interrupts this command (see received())
_native = 0  # nesting of solver_call() in the main thread
_streams: tuple[object, object] | None = None  # sys.stdout/err when the solver call began
_muted = False  # the solver call's output is dropped (it was interrupted)
# Held by a critical section of the main thread (deferred) and by whoever prints the
# final line: the watchdog never ends the process in the middle of a record.
_exit_lock = threading.RLock()
# The store of the last run that finished in this command: an interrupt after the
# solving (writing the front, the plot) still names what is saved.
_last_store: dict[str, object] | None = None
# The store a run is writing now: (path, function giving its current record count).
_active_store: tuple[str, Callable[[], int]] | None = None
_watch_fds: tuple[int, int] | None = None
_live: weakref.ref[Interrupted] | None = None  # the last Interrupted raised here


class Interrupted(KeyboardInterrupt):
    """SIGINT, SIGTERM or SIGHUP received (a :class:`KeyboardInterrupt`, so that
    ``except Exception`` clauses let it through)."""

    def __init__(self, signum: int):
        global _live
        self.signum = int(signum)
        super().__init__(signal.Signals(signum).name)
        if _main_thread():
            _live = weakref.ref(self)  # alive while it propagates (see start_watchdog)


def _interrupt_alive() -> bool:
    return _live is not None and _live() is not None


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def _handler(signum: int, frame: object) -> None:
    global _pending, _received
    if _depth:
        _received = _pending = signum
        return
    exc = Interrupted(signum)  # before _received: the watchdog sees both or neither
    _received = signum
    _mute_solver()
    raise exc


def _library_handler(signum: int, frame: object) -> None:
    # Python's default SIGINT handler, recording the signal (see solver_call).
    global _received
    _received = signum
    _mute_solver()
    raise Interrupted(signum)


class _Mute:
    """A stream that drops what it is given (a solver's last words once interrupted)."""

    def write(self, text: str) -> int:
        return len(text)

    def flush(self) -> None:
        pass


def _mute_solver() -> None:
    # Interrupted inside a solver call: what the library prints on its way out (CasADi's
    # 'WARNING("KeyboardInterruptException")', Ipopt's "Unknown Exception caught") is not
    # for the user, whose one line is the interrupt's. Restored when the call returns.
    global _muted
    if _native and not _muted:
        _muted = True
        sys.stdout = sys.stderr = _Mute()  # type: ignore[assignment]


def received() -> int | None:
    """The signal that interrupted the running command (None: none).

    Recorded by the handlers even where their exception is lost (inside a solver
    library); cleared when a command starts or ends (:func:`interrupts_as_exceptions`),
    and in library use when :func:`solver_call` has raised it.
    """
    return _received


@contextlib.contextmanager
def solver_call() -> Iterator[None]:
    """A call into a solver library: a signal received meanwhile is raised when it returns.

    The library may swallow the handler's exception (CasADi returns a failed solve) or
    replace it (CasADi's ``RuntimeError("KeyboardInterrupt")``); either way
    :class:`Interrupted` is raised here instead. Re-entrant; a no-op outside the main
    thread (signal handlers run only there). While the call runs in library use (Python's
    default SIGINT handler installed), a handler that also records the signal takes its
    place. The CLI's watchdog may end the process while the main thread is inside one
    (see :func:`start_watchdog`), so nothing in it may write outputs.
    """
    global _native, _received, _muted, _streams
    if not _main_thread():
        yield
        return
    own = (
        not _native
        and signal.getsignal(signal.SIGINT) is signal.default_int_handler
        and _received is None
    )
    if own:
        signal.signal(signal.SIGINT, _library_handler)
    if not _native:
        _streams = (sys.stdout, sys.stderr)
    _native += 1
    # Made while the call still counts as one (the watchdog looks for a live Interrupted
    # once the main thread is out of solver calls).
    exc: Interrupted | None = None
    try:
        yield
    except Exception:
        if _received is None:
            raise
        exc = Interrupted(_received)  # the library's own form of the interrupt
    else:
        if _received is not None and not _depth:
            exc = Interrupted(_received)  # returned as if nothing had happened
    finally:
        _native -= 1
        if not _native:
            if _muted and _streams is not None:
                sys.stdout, sys.stderr = _streams  # type: ignore[assignment]
            _muted, _streams = False, None
        if own:
            signal.signal(signal.SIGINT, signal.default_int_handler)
            _received = None  # raised now: the next call starts afresh
    if exc is not None:
        raise exc from None


@contextlib.contextmanager
def deferred(drop: bool = False) -> Iterator[None]:
    """A critical section: an interrupt arriving inside is raised when it ends.

    Re-entrant. A no-op outside the main thread (signal handlers run only there). When
    the section ends with an exception already propagating, that one goes on (the run
    is ending anyway). ``drop``: an interrupt arriving inside is dropped (for the
    cleanup of a run that is being interrupted already). The CLI's watchdog waits for
    the section to end before it ends the process.
    """
    global _depth, _pending
    if not _main_thread():
        yield
        return
    if _depth == 0:
        _exit_lock.acquire()
    _depth += 1
    try:
        yield
    except BaseException:
        _depth -= 1
        if _depth == 0:
            _pending = None
            _exit_lock.release()
        raise
    # made before the section ends (the watchdog looks for a live Interrupted outside)
    exc = Interrupted(_pending) if _depth == 1 and _pending is not None and not drop else None
    _depth -= 1
    if _depth == 0:
        _pending = None
        _exit_lock.release()
        if exc is not None:
            raise exc


@contextlib.contextmanager
def interrupts_as_exceptions() -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP raise :class:`Interrupted` in the main thread meanwhile.

    Outside the main thread nothing is installed (Python allows handlers only there).
    An exception other than the interrupt leaving the block once a signal is received
    (a library's wrapping of it) is replaced by :class:`Interrupted`. The previous
    handlers are restored on exit.
    """
    global _received
    if not _main_thread():
        yield
        return
    _received = None
    previous = {s: signal.signal(s, _handler) for s in SIGNALS}
    try:
        yield
    except Exception:
        # Any failure once a signal is received is its consequence (a library that
        # wrapped the handler's exception in its own): the interrupt it is.
        if _received is None:
            raise
        raise Interrupted(_received) from None
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
        _received = None


@contextlib.contextmanager
def signals_blocked() -> Iterator[None]:
    """Block the three signals in this thread meanwhile (around a fork: the child
    unblocks them once it has its own dispositions, :func:`child_signals`; here they
    are delivered when the block ends)."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def child_signals() -> None:
    """Dispositions of a forked worker or task process, then unblock the signals.

    SIGINT and SIGHUP go to a whole process group (a terminal's Ctrl-C, a closed
    terminal): the parent alone decides what they stop, so a child ignores them. SIGTERM
    kills at once (the parent's handler, inherited through fork, would raise inside the
    task instead); the parent stops busy workers with it.
    """
    with contextlib.suppress(ValueError):  # not the main thread: cannot change handlers
        for s in SIGNALS:
            signal.signal(s, signal.SIG_DFL if s == signal.SIGTERM else signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)


def _after_fork_in_child() -> None:
    # A forked child starts with none of the parent's interrupt state: no section open
    # (the parent forks inside one), no signal received, no watchdog.
    global _depth, _pending, _received, _native, _muted, _streams, _live
    global _exit_lock, _watch_fds, _active_store, _last_store
    _depth, _pending, _received, _native, _muted, _streams = 0, None, None, 0, False, None
    _live = None
    _exit_lock = threading.RLock()
    _active_store = _last_store = None
    if _watch_fds is not None:
        with contextlib.suppress(ValueError, OSError):
            signal.set_wakeup_fd(-1)
        for fd in _watch_fds:
            with contextlib.suppress(OSError):
                os.close(fd)
        _watch_fds = None


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork_in_child)


#: The name of the watchdog's thread (:func:`start_watchdog`).
WATCHDOG_THREAD = "optdesign-watchdog"


def fork_safe_threads() -> bool:
    """Whether this process runs no thread but its main one and the watchdog: a fork
    copies no other thread, so one that held a lock (the import lock, a logging lock)
    would leave it held in the child forever; the watchdog holds none while it waits,
    and the child drops its state (:func:`_after_fork_in_child`)."""
    main = threading.main_thread()
    return all(t is main or t.name == WATCHDOG_THREAD for t in threading.enumerate())


def start_watchdog(finish: Callable[[int], None], grace: float = WATCHDOG_GRACE) -> bool:
    """Make sure a signal ends the command although the main thread cannot hear it.

    A daemon thread wakes on every signal that has a Python handler (Python writes the
    signal's number to its wakeup file descriptor from the C-level handler, even while
    the main thread runs native code). If ``grace`` s later the main thread is still
    inside :func:`solver_call` and outside any critical section, it calls
    ``finish(signum)``, which must end the process (the CLI prints the one line and
    calls ``os._exit``); the main thread cannot start a critical section (a store
    write) meanwhile. If instead the handler ran but no :class:`Interrupted` is alive
    ``RERAISE_AFTER`` s after the signal (outside critical sections, which raise it at
    their end), its exception was dropped by code between the handler and the command:
    the signal is sent to the main thread again. Native code that holds the GIL would
    stop this thread too (CasADi's solvers and Clarabel release it). Main thread only;
    returns whether the watchdog runs.
    """
    global _watch_fds
    if not _main_thread() or _watch_fds is not None:
        return False
    r, w = os.pipe()
    os.set_blocking(w, False)
    try:
        signal.set_wakeup_fd(w, warn_on_full_buffer=False)
    except (ValueError, OSError):
        os.close(r)
        os.close(w)
        return False
    _watch_fds = (r, w)
    main = threading.main_thread().ident
    threading.Thread(
        target=_watch, args=(r, finish, grace, main), name=WATCHDOG_THREAD, daemon=True
    ).start()
    return True


def _watch(fd: int, finish: Callable[[int], None], grace: float, main: int | None) -> None:
    numbers = {int(s) for s in SIGNALS}
    while True:
        try:
            data = os.read(fd, 64)
        except OSError:
            return
        ours = [b for b in data if b in numbers]
        if not data:
            return
        if ours:
            _watch_one(ours[-1], finish, grace, main)


def _watch_one(signum: int, finish: Callable[[int], None], grace: float, main: int | None) -> None:
    # After one signal: the main thread normally raises it and unwinds (ending the
    # process itself); watch it for a while in case it cannot.
    t0 = time.monotonic()
    while (waited := time.monotonic() - t0) < 10.0:
        time.sleep(0.02)
        if _native:
            if waited >= grace and _exit_lock.acquire(timeout=0.05):
                try:
                    if _native:  # still inside, and no record can be started now
                        finish(_received or signum)
                finally:
                    _exit_lock.release()
        elif (
            waited >= RERAISE_AFTER
            and _received is not None
            and not _depth
            and not _interrupt_alive()
            and main is not None
        ):
            with contextlib.suppress(OSError, ValueError):
                signal.pthread_kill(main, _received)  # heard again: a new round
            return


def exit_lock() -> threading.RLock:
    """The lock of the final line: hold it while printing it (the watchdog ends the
    process only while it holds it)."""
    return _exit_lock


def note_active_store(path: str | None, count: Callable[[], int] | None = None) -> None:
    """The store a run writes now and how to read its record count (``None``: no run),
    for the message of an interrupt that ends the process from the watchdog."""
    global _active_store
    _active_store = None if path is None or count is None else (str(path), count)


def note_store(path: str, records: int) -> None:
    """Remember ``path`` (holding ``records`` records) as the store of the last run that
    completed, for the message of an interrupt that comes after it."""
    global _last_store
    _last_store = {"path": str(path), "records": int(records)}


def saved_store(exc: BaseException | None = None) -> dict[str, object] | None:
    """What an interrupted command has saved: the interrupted run's store (from the
    exception, else the run in progress), else the store of the last run that completed
    (``None`` before any)."""
    store = getattr(exc, "run_store", None)
    if store:
        return store
    if _active_store is not None:
        path, count = _active_store
        return {"path": path, "records": int(count())}
    return _last_store


def forget_store() -> None:
    """Start of a command: no store saved yet."""
    global _last_store, _active_store
    _last_store = _active_store = None


def exit_code(exc: KeyboardInterrupt) -> tuple[str, int]:
    """(signal name, exit code 128 + its number) of an interrupt; SIGINT for a plain
    KeyboardInterrupt."""
    signum = getattr(exc, "signum", signal.SIGINT)
    return signal.Signals(signum).name, 128 + int(signum)


def message(signum: int, store: dict[str, object] | None, resume: str = "resume=True") -> str:
    """The one line of an interrupted command (naming the saved store when there is one,
    and ``resume``, how the caller continues it: the command line passes ``--resume``)."""
    name = signal.Signals(signum).name
    if not store:
        return f"optdesign: interrupted ({name})"
    n = store["records"]
    return (
        f"optdesign: interrupted ({name}); {n} record{'' if n == 1 else 's'} saved in "
        f"{printable(str(store['path']))}, {resume} continues"
    )
