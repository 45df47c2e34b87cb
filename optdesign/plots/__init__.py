"""Plots (matplotlib): the figures of a solve, a front, a sweep and a loop's response,
drawn from the records of :mod:`optdesign.views` and the studies.

The primitives every figure uses - a figure outside pyplot's state, saved atomically, a
user's text drawn plainly - live in :mod:`optdesign.display.figures` (a layer below the
studies, which save figures too) and are re-exported here.
"""

from optdesign.display.figures import (
    ELLIPSIS,
    MAX_DRAWN,
    MAX_TITLE_NAME,
    new_figure,
    plain,
    save_figure,
    write_figure,
)

__all__ = [
    "ELLIPSIS",
    "MAX_DRAWN",
    "MAX_TITLE_NAME",
    "new_figure",
    "plain",
    "save_figure",
    "write_figure",
]
