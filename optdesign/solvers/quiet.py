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
from collections.abc import Iterator


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


@contextlib.contextmanager
def quiet_stdout() -> Iterator[None]:
    """Send file descriptor 1 to /dev/null and ``sys.stdout`` to a sink for the call
    (Python's and the C library's buffered output is flushed first, so nothing printed
    before is lost, and the C library's again before fd 1 is restored, so nothing
    printed inside leaks out)."""
    sys.stdout.flush()
    _flush_c_stdout()
    try:
        saved = os.dup(1)
    except OSError:  # no stdout at all
        with contextlib.redirect_stdout(io.StringIO()):
            yield
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        with contextlib.redirect_stdout(io.StringIO()):
            yield
    finally:
        _flush_c_stdout()
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)
