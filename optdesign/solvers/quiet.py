"""Solver libraries that print whatever their print options (Bonmin and Cbc some lines to
the C-level stdout; qpOASES, inside CasADi's sqpmethod, its licence banner each time a
memory of the solver is set up, through CasADi's output, which CasADi's Python module
sends to ``sys.stdout``): their calls run with file descriptor 1 on /dev/null and
``sys.stdout`` on a sink (in a notebook, ``sys.stdout`` is not file descriptor 1)."""

from __future__ import annotations

import contextlib
import ctypes
import functools
import io
import os
import sys
import threading
from collections.abc import Iterator
from typing import Any


@functools.cache
def _c_library() -> ctypes.CDLL | None:
    try:
        return ctypes.CDLL(None)
    except OSError:  # no C library to ask (not a POSIX build)
        return None


def _flush_c_stdout() -> None:
    """Flush the C library's stdout buffer: to a file or a pipe it is block-buffered, and
    lines a library printed inside the window would otherwise be written after it, to
    the real stdout."""
    libc = _c_library()
    if libc is not None and hasattr(libc, "fflush"):
        libc.fflush(None)


class _Quiet:
    """The process's one quiet window: fd 1 and ``sys.stdout`` are redirected when the
    first caller enters and restored when the last leaves. Threads (a threaded Dask
    worker) and nested calls share it: two windows each saving and restoring on their
    own would, interleaved, leave stdout on /dev/null for good."""

    lock = threading.Lock()
    depth = 0
    saved_fd: int | None = None
    devnull: int | None = None
    saved_stdout: Any = None

    @classmethod
    def enter(cls) -> None:
        with cls.lock:
            cls.depth += 1
            if cls.depth > 1:
                return
            if sys.stdout is not None:
                sys.stdout.flush()
            _flush_c_stdout()
            try:
                cls.saved_fd = os.dup(1)
            except OSError:  # no stdout at all
                cls.saved_fd = None
            else:
                cls.devnull = os.open(os.devnull, os.O_WRONLY)
                os.dup2(cls.devnull, 1)
            cls.saved_stdout, sys.stdout = sys.stdout, io.StringIO()

    @classmethod
    def leave(cls) -> None:
        with cls.lock:
            cls.depth -= 1
            if cls.depth > 0:
                return
            sys.stdout = cls.saved_stdout
            cls.saved_stdout = None
            if cls.saved_fd is not None:
                _flush_c_stdout()
                os.dup2(cls.saved_fd, 1)
                os.close(cls.saved_fd)
                os.close(cls.devnull)
            cls.saved_fd = cls.devnull = None


@contextlib.contextmanager
def quiet_stdout() -> Iterator[None]:
    """Send file descriptor 1 to /dev/null and ``sys.stdout`` to a sink for the call
    (Python's and the C library's buffered output is flushed first, so nothing printed
    before is lost, and the C library's again before fd 1 is restored, so nothing
    printed inside leaks out). Nested and concurrent calls share one window."""
    _Quiet.enter()
    try:
        yield
    finally:
        _Quiet.leave()
