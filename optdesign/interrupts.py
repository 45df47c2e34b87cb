"""SIGINT and SIGTERM as an exception in the main thread, deferred out of critical sections.

The CLI (:func:`optdesign.cli.run_guarded`) installs :func:`interrupts_as_exceptions`:
both signals then raise :class:`Interrupted`, so every ``finally`` and context manager on
the way out runs (workers stopped, store closed) and the command ends with one line.

Python runs a signal handler between any two bytecodes of the main thread, including
inside the callbacks of ``os.fork`` (where an exception is printed and dropped: the
interrupt would be lost) and between writing a record and counting it. Code that must
not be cut there wraps itself in :func:`deferred`: a signal arriving inside is raised
when the section ends. Without the CLI's handler installed (library use) nothing changes:
Python's default SIGINT handler raises KeyboardInterrupt as usual.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

_depth = 0  # nesting of deferred() sections in the main thread
_pending: int | None = None  # a signal that arrived inside one
# The store of the last run that finished in this command: an interrupt after the
# solving (writing the front, the plot) still names what is saved.
_last_store: dict[str, object] | None = None


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM received (a :class:`KeyboardInterrupt`, so that ``except
    Exception`` clauses let it through)."""

    def __init__(self, signum: int):
        self.signum = int(signum)
        super().__init__(signal.Signals(signum).name)


def _handler(signum: int, frame: object) -> None:
    global _pending
    if _depth:
        _pending = signum
        return
    raise Interrupted(signum)


@contextlib.contextmanager
def deferred(drop: bool = False) -> Iterator[None]:
    """A critical section: an interrupt arriving inside is raised when it ends.

    Re-entrant. A no-op outside the main thread (signal handlers run only there). When
    the section ends with an exception already propagating, that one goes on (the run
    is ending anyway). ``drop``: an interrupt arriving inside is dropped (for the
    cleanup of a run that is being interrupted already).
    """
    global _depth, _pending
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _depth += 1
    try:
        yield
    except BaseException:
        _depth -= 1
        if _depth == 0:
            _pending = None
        raise
    _depth -= 1
    if _depth == 0 and _pending is not None:
        signum, _pending = _pending, None
        if not drop:
            raise Interrupted(signum)


@contextlib.contextmanager
def interrupts_as_exceptions() -> Iterator[None]:
    """SIGINT and SIGTERM raise :class:`Interrupted` in the main thread meanwhile.

    Outside the main thread nothing is installed (Python allows handlers only there).
    The previous handlers are restored on exit.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, _handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


def note_store(path: str, records: int) -> None:
    """Remember ``path`` (holding ``records`` records) as the store of the last run that
    completed, for the message of an interrupt that comes after it."""
    global _last_store
    _last_store = {"path": str(path), "records": int(records)}


def saved_store(exc: BaseException) -> dict[str, object] | None:
    """What an interrupted command has saved: the interrupted run's store, else the
    store of the last run that completed (``None`` before any)."""
    return getattr(exc, "run_store", None) or _last_store


def forget_store() -> None:
    """Start of a command: no store saved yet."""
    global _last_store
    _last_store = None


def exit_code(exc: KeyboardInterrupt) -> tuple[str, int]:
    """(signal name, exit code 128 + its number) of an interrupt; SIGINT for a plain
    KeyboardInterrupt."""
    signum = getattr(exc, "signum", signal.SIGINT)
    return signal.Signals(signum).name, 128 + int(signum)
