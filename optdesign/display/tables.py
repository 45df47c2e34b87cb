"""Plain-text tables for the terminal: paper-vs-computed comparisons and design tables.

Every cell and heading is one line of :func:`~optdesign.text.printable` text: a name
from a user cannot break the table or reach the terminal as a control sequence."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from optdesign.text import printable


def format_table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """Left-aligned text table with a header rule (cells and headings made
    :func:`~optdesign.text.printable`, one line each)."""
    headers = [printable(h) for h in headers]
    cells = [[printable(_fmt(c)) for c in row] for row in rows]
    widths = [len(h) for h in headers]
    for row in cells:
        for k, c in enumerate(row):
            widths[k] = max(widths[k], len(c))
    line = "  ".join(h.ljust(w) for h, w in zip(headers, widths, strict=True))
    rule = "  ".join("-" * w for w in widths)
    body = ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) for row in cells]
    return "\n".join([line, rule, *body])


def _fmt(value: object) -> str:
    if isinstance(value, float):
        if math.isnan(value):
            return "-"
        return f"{value:.6g}"
    return str(value)


@dataclass
class Comparison:
    """One line of a paper-vs-computed table."""

    quantity: str
    paper: float | None
    computed: float
    unit: str = ""
    note: str = ""

    @property
    def relative_difference(self) -> float:
        """(computed - paper) / |paper|; NaN where the paper prints no number."""
        if self.paper is None or self.paper == 0:
            return float("nan")
        return (self.computed - self.paper) / abs(self.paper)


def comparison_table(items: Sequence[Comparison]) -> str:
    """Side-by-side table: quantity, paper, computed, relative difference, unit, note."""
    rows = []
    for c in items:
        rel = c.relative_difference
        rows.append(
            [
                c.quantity,
                "-" if c.paper is None else _fmt(float(c.paper)),
                _fmt(float(c.computed)),
                "-" if math.isnan(rel) else f"{100 * rel:+.2f} %",
                c.unit,
                c.note,
            ]
        )
    return format_table(["quantity", "paper", "computed", "rel. diff", "unit", "note"], rows)
