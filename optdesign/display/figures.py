"""Figures (matplotlib) as primitives: a figure outside pyplot, saved atomically, a user's
text drawn plainly. Every function returns a Figure and leaves the back-end alone.

Importing optdesign never selects a matplotlib back-end, and no figure is made through
pyplot's global state: :func:`new_figure` makes a :class:`matplotlib.figure.Figure` that
pyplot does not track, so a notebook shows a returned figure once (as the cell's value;
the inline back-end draws only the figures pyplot holds) and a script that makes many
figures keeps none open. The command line selects the file-only Agg back-end for itself
(:func:`optdesign.cli.main`). :func:`save_figure` writes a figure as PNG.

Text from a user (a problem's name, an objective's or a constraint's, a label) is drawn
as plain text: :func:`plain` escapes the ``$`` that would start matplotlib's mathtext
(``$\\frac{$`` in a name would otherwise fail when the figure is drawn), shows
control characters escaped and shortens it to :data:`MAX_DRAWN` characters with an
ellipsis (a 900 kB name took matplotlib's text layout minutes, deaf to Ctrl-C).
:func:`write_figure` makes a figure's failure a note instead of losing the command's
other outputs.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from optdesign.text import printable

if TYPE_CHECKING:
    from matplotlib.figure import Figure


#: Most characters of one user text drawn on a figure (a title's name, a label): more
#: does not fit on a figure, and matplotlib lays text out in time that grows with its
#: length, in C code that a Ctrl-C does not stop.
MAX_DRAWN = 120
#: Most characters of a problem's name at the head of a title (the rest of the title
#: must still fit beside it).
MAX_TITLE_NAME = 60
#: What ends a shortened text.
ELLIPSIS = "..."


def plain(text: object, limit: int = MAX_DRAWN) -> str:
    """``text`` drawn literally by matplotlib: one line, control characters escaped
    (:func:`~optdesign.text.printable`), at most ``limit`` characters (a longer text is
    cut and ends with ``...``), every ``$`` escaped as ``\\$`` so that no part of it is
    read as mathtext (an escaped dollar is drawn as ``$``)."""
    s = str(text)
    if len(s) > limit:  # cut before escaping: a 900 kB name is not escaped whole
        s = s[: limit + 1]
    s = printable(s)
    if len(s) > limit:
        s = s[: max(limit - len(ELLIPSIS), 0)] + ELLIPSIS
    return s.replace("$", r"\$")


def new_figure(figsize: tuple[float, float], dpi: int = 120, layout: str | None = None) -> Figure:
    """A figure outside pyplot's state (never shown by a back-end on its own, never left
    open: it is freed with its last reference). ``layout="constrained"`` when a figure
    label (``supxlabel``) must keep its own room below the axes' labels, in a notebook as
    in a file."""
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, dpi=dpi, layout=layout)


def write_figure(draw: Callable[[], Any], path: str | Path, **kw: Any) -> str | None:
    """Draw a figure (``draw()``) and write it as PNG at ``path`` (atomically,
    :func:`save_figure` with ``kw``).

    Returns
    -------
    str or None
        None when written; else a note naming the file and the error. A figure is one
        output among several: its failure must not lose the others (the result, the
        report), so it is reported instead of raised. I/O errors (a full disk, no
        permission) and interrupts are raised as usual.
    """
    from optdesign.storage import atomic_output

    path = Path(path)
    before = _pyplot_figures()
    try:
        fig = draw()
        with atomic_output(path) as tmp:
            save_figure(fig, tmp, **kw)
    except OSError:
        raise
    except Exception as exc:
        # a user's code (a mechanism's sketch) may have opened pyplot figures
        for num in (_pyplot_figures() or set()) - (before or set()):
            sys.modules["matplotlib.pyplot"].close(num)
        return f"{path.name} not written: {type(exc).__name__}: {' '.join(str(exc).split())}"
    return None


def save_figure(fig, path: str | Path, dpi: int = 120, tight: bool = True) -> Path:
    """Lay out ``fig``, write it as PNG at ``path`` (folders made, the file replaced
    atomically), close it if pyplot holds it; return the path."""
    if tight:
        from matplotlib.layout_engine import ConstrainedLayoutEngine, TightLayoutEngine

        engine = fig.get_layout_engine()
        if engine is None:
            # fig.tight_layout()'s own computation, without the placeholder layout engine
            # it leaves on the figure: with one, savefig lays the figure out once more
            # (the PNG is byte-identical; the time it saves: benchmarks/README.md,
            # "Figures behind comments in the code").
            TightLayoutEngine(rect=None).execute(fig)
        elif not isinstance(engine, ConstrainedLayoutEngine):  # savefig runs that one
            fig.tight_layout()
    from optdesign.storage import atomic_output

    path = Path(path)
    # Atomically, through a new temporary file: a link planted at ``path`` (in a reused
    # output folder) is replaced, never followed, and a failed write leaves the old file.
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=path.suffix.lstrip(".").lower() or "png")
    if getattr(fig.canvas, "manager", None) is not None:  # a figure made through pyplot
        import matplotlib.pyplot as plt

        plt.close(fig)
    return path


def _pyplot_figures() -> set[int] | None:
    """The numbers of pyplot's open figures, None when pyplot is not imported (then none
    can be open: importing it here would only cost time)."""
    if "matplotlib.pyplot" not in sys.modules:
        return None
    return set(sys.modules["matplotlib.pyplot"].get_fignums())
