"""What ``optdesign sweep`` and ``od.sweep(..., out=DIR)`` write beside the sweep's store:
the table, its JSON, the design chart and the page."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from optdesign.errors import OptDesignError
from optdesign.reports.sweep_html import sweep_report
from optdesign.reports.sweep_text import sweep_csv, sweep_document
from optdesign.storage import atomic_write_text


def write_sweep_outputs(
    sweep: Any, out: Path, plot: bool = True
) -> tuple[list[Path], list[str], str]:
    """Everything ``optdesign sweep`` writes beside the store, in folder ``out``:
    ``sweep.csv``, ``sweep.json`` and, with ``plot``, the design chart ``sweep.png`` and
    the page ``sweep.html`` (when a point has a design). Returns the files written, the
    notes of the outputs that could not be drawn (a figure or a user's mechanism that
    cannot draw itself is a note, not the sweep lost) and sweep.json's text."""
    text = json.dumps(sweep_document(sweep), indent=2)
    atomic_write_text(out / "sweep.csv", sweep_csv(sweep))
    atomic_write_text(out / "sweep.json", text)
    wrote = [out / "sweep.csv", out / "sweep.json"]
    notes: list[str] = []
    if plot:
        from optdesign.plots import write_figure

        failed = write_figure(sweep.plot, out / "sweep.png")
        if failed is None:
            wrote.append(out / "sweep.png")
        else:
            notes.append(failed)
        if any(p.design for p in sweep.points):
            try:  # a user's mechanism that cannot draw itself: a note, not the sweep lost
                atomic_write_text(out / "sweep.html", sweep_report(sweep))
                wrote.append(out / "sweep.html")
            except OptDesignError as exc:
                notes.append(f"sweep.html not written: {exc}")
    return wrote, notes, text
