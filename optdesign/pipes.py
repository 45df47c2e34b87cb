"""A standard output whose reader went away ends the command quietly.

``optdesign solve problem.toml | head -1``: ``head`` closes the pipe after one line and
the next write to it fails with ``BrokenPipeError`` (Python ignores SIGPIPE). That is no
error of the command: its files are written (or are being written), only the reader has
read enough. :class:`QuietPipe` wraps the program's standard output; at the first
broken-pipe error it points the descriptor at the null device, so that every later write
(Python's, a C library's, the final flush) succeeds unread, and the command finishes its
work and exits with its own code - no ``[Errno 32] Broken pipe``, no lost output file.
"""

from __future__ import annotations

import contextlib
import os
from typing import Any, TextIO


class QuietPipe:
    """``stream`` (the program's stdout) with a closed pipe read as "nobody listens"."""

    def __init__(self, stream: TextIO) -> None:
        self._stream = stream
        self.reader_gone = False

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._to_null()
            return len(text)

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._to_null()
            with contextlib.suppress(OSError, ValueError):
                self._stream.flush()  # what was buffered now goes to the null device

    def _to_null(self) -> None:
        self.reader_gone = True
        with contextlib.suppress(OSError, ValueError, AttributeError):
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, self._stream.fileno())
            os.close(null)

    def __getattr__(self, name: str) -> Any:  # fileno, isatty, encoding, buffer...
        return getattr(self._stream, name)
