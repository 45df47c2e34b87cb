"""A wall-clock deadline for a study (``time_limit=`` of :func:`optdesign.solve`,
``--time-limit`` of ``optdesign solve``), shared by every solve inside it.

:func:`deadline` sets it for the duration of a ``with`` block (a deadline set inside
another keeps the earlier of the two); :func:`passed` says whether it has passed. The
multistart starts no start after it, and an Ipopt solve built with
:data:`DEADLINE_OPTION` stops at its next iteration once it has passed (an Ipopt
iteration callback; status ``time_limit``). Worker processes forked inside the block
inherit it. Measured on the monotonic clock, never the time of day.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator

#: A back-end option (popped before the back-end sees its options): build the Ipopt
#: solver with the iteration callback that stops it at the deadline.
DEADLINE_OPTION = "optdesign_deadline"

_DEADLINE: float | None = None


@contextlib.contextmanager
def deadline(seconds: float | None) -> Iterator[None]:
    """The deadline ``seconds`` from now for the block (None: no new deadline)."""
    global _DEADLINE
    saved = _DEADLINE
    if seconds is not None:
        end = time.monotonic() + float(seconds)
        _DEADLINE = end if saved is None else min(saved, end)
    try:
        yield
    finally:
        _DEADLINE = saved


def passed() -> bool:
    """Whether a deadline is set and has passed."""
    return _DEADLINE is not None and time.monotonic() >= _DEADLINE
