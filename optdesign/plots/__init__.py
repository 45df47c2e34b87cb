"""Plots (matplotlib): every function returns a Figure and leaves the back-end alone.

Importing optdesign never selects a matplotlib back-end: in a notebook figures show as
usual; the command line selects the file-only Agg back-end for itself
(:func:`optdesign.cli.main`). :func:`save_figure` writes a figure as PNG.

Text from a user (a problem's name, an objective's or a constraint's, a label) is drawn
as plain text: :func:`plain` escapes the ``$`` that would start matplotlib's mathtext
(``$\\frac{$`` in a name would otherwise fail when the figure is drawn) and shows
control characters escaped. :func:`write_figure` makes a figure's failure a note
instead of losing the command's other outputs.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from optdesign.text import printable


def plain(text: object) -> str:
    """``text`` drawn literally by matplotlib: one line, control characters escaped
    (:func:`~optdesign.text.printable`), every ``$`` escaped as ``\\$`` so that no part
    of it is read as mathtext (an escaped dollar is drawn as ``$``)."""
    return printable(text).replace("$", r"\$")


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
    import matplotlib.pyplot as plt

    from optdesign.storage import atomic_output

    path = Path(path)
    before = set(plt.get_fignums())
    try:
        fig = draw()
        with atomic_output(path) as tmp:
            save_figure(fig, tmp, **kw)
    except OSError:
        raise
    except Exception as exc:
        for num in set(plt.get_fignums()) - before:  # the figures this draw opened
            plt.close(num)
        return f"{path.name} not written: {type(exc).__name__}: {' '.join(str(exc).split())}"
    return None


def save_figure(fig, path: str | Path, dpi: int = 120, tight: bool = True) -> Path:
    """Lay out ``fig``, write it as PNG at ``path`` (folders made, the file replaced
    atomically), close it; return the path."""
    import matplotlib.pyplot as plt

    if tight:
        from matplotlib.layout_engine import TightLayoutEngine

        if fig.get_layout_engine() is None:
            # fig.tight_layout()'s own computation, without the placeholder layout engine
            # it leaves on the figure: with one, savefig lays the figure out once more
            # (the PNG is byte-identical; figures: benchmarks/README.md).
            TightLayoutEngine(rect=None).execute(fig)
        else:
            fig.tight_layout()
    from optdesign.storage import atomic_output

    path = Path(path)
    # Atomically, through a new temporary file: a link planted at ``path`` (in a reused
    # output folder) is replaced, never followed, and a failed write leaves the old file.
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=path.suffix.lstrip(".").lower() or "png")
    plt.close(fig)
    return path
