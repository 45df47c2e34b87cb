"""What ``optdesign pareto`` writes of the fronts of one run: ``front.csv`` (a row per
point, in the summary's units with the unit in each heading: ``ripple [%]``),
``front.json`` (everything, internal units), ``front.png`` and ``report.html``. The fronts
come from :func:`optdesign.pareto`; several methods' fronts arrive with their hypervolumes
against one reference point already computed (:func:`optdesign.api.front_outputs`), so
this module only writes what the records hold.

``front.csv`` is written with :mod:`csv` (a name holding a comma, a quote or a newline
is quoted) and is safe to open in a spreadsheet: a text cell or heading that starts
with ``=``, ``+``, ``-``, ``@``, a tab or a carriage return gets a leading ``'``
(:func:`optdesign.text.csv_cell`); numbers, negative ones too, are written as numbers.
``front.json`` writes a value that is not finite as ``null``.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from optdesign.display.frames import front_table, objective_column
from optdesign.solvers.result import clean_json
from optdesign.text import csv_cell

if TYPE_CHECKING:
    from optdesign.plots.figure_process import FigureProcess
    from optdesign.problem.design_problem import DesignProblem
    from optdesign.studies.pareto.front import Front

#: What draws front.png, in a figure worker (:class:`optdesign.plots.figure_process.
#: FigureProcess`) that imports it ahead.
FRONT_FIGURE = "optdesign.plots.front:draw_front"


def _fronts(front: Front | Sequence[Front]) -> list[Front]:
    """One front or several as a list (a :class:`Front` is a record, not a sequence)."""
    return list(front) if isinstance(front, (list, tuple)) else [front]


def write_front_csv(
    front: Front | Sequence[Front], problem: DesignProblem, path: Path | str
) -> Path:
    """``front.csv``: one row a point (objectives, design variables, status, ...), the
    rows of :func:`~optdesign.display.frames.front_table` with the rejected points."""
    from optdesign.storage import atomic_write_text

    rows = [r for f in _fronts(front) for r in front_table(f, problem, rejected=True)]
    fields = list(rows[0]) if rows else ["method"]
    with io.StringIO() as buf:
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow([csv_cell(f) for f in fields])
        writer.writerows([csv_cell(v, digits=12) for v in r.values()] for r in rows)
        return atomic_write_text(Path(path), buf.getvalue())


def read_front_csv(
    path: Path | str, objectives: Sequence[str], problem: DesignProblem | None = None
) -> np.ndarray:
    """Objective values of the on-front rows of a ``front.csv``.

    ``objectives`` are named as the problem names them: the heading with its unit
    (``"ripple [%]"``), or neutralised for spreadsheets, is found too. With ``problem``
    the values are returned in internal units (a heading's unit must be the one the
    problem shows that objective in; a heading without a unit, as written before units
    were added, is taken as internal); without it, as the file writes them.
    """
    with Path(path).open(newline="") as fh:
        reader = csv.DictReader(fh)
        heads = [_heading(reader.fieldnames or [], k) for k in objectives]
        rows = [r for r in reader if r.get("on_front", "True") == "True"]
    F = np.array([[float(r[h]) for h in heads] for r in rows], dtype=float).reshape(-1, len(heads))
    if problem is not None:
        for j, (k, h) in enumerate(zip(objectives, heads, strict=True)):
            col = objective_column(problem, k)
            if h == csv_cell(k):
                continue  # no unit: internal
            if h != csv_cell(col.header):
                raise ValueError(f"{path}: column {h!r} is not in {col.unit or 'no unit'}")
            F[:, j] /= col.scale
    return F


def _heading(fields: Sequence[str], name: str) -> str:
    """The heading of column ``name`` (``name`` or ``name [unit]``, as csv_cell wrote it)."""
    cell = csv_cell(name)
    for f in fields:
        if f == cell or (f.startswith(cell + " [") and f.endswith("]")):
            return f
    raise KeyError(name)


def write_front_json(fronts: Sequence[Front], path: Path | str, **meta: Any) -> Path:
    """``front.json``: every front with its points, rejected points and metrics."""
    from optdesign.storage import atomic_write_text

    data = clean_json({**meta, "fronts": [f.to_dict() for f in fronts]})
    return atomic_write_text(Path(path), json.dumps(data, indent=1))


def write_front_outputs(
    fronts: Sequence[Any],
    problem: Any,
    out: Path,
    *,
    objectives: Sequence[str],
    points: int,
    created: str,
    plot: bool = True,
    report: bool = True,
    figures: FigureProcess | None = None,
) -> tuple[list[Path], list[str]]:
    """Everything ``optdesign pareto`` writes beside the stores, in folder ``out``:
    ``front.csv``, ``front.json``, ``front.png`` (``plot``) and ``report.html``
    (``report``, when a front has a point). Returns the files written and the notes of
    the outputs that could not be drawn (a figure or a page that fails is a note, not an
    error: the other files are kept). ``figures``: the process that draws front.png
    while the page is made (None: drawn here first)."""
    write_front_csv(fronts, problem, out / "front.csv")
    write_front_json(
        fronts,
        out / "front.json",
        problem=problem.name,
        objectives=list(objectives),
        points=points,
        created=created,
    )
    wrote = [out / "front.csv", out / "front.json"]
    notes: list[str] = []
    if plot:
        from optdesign.plots.figure_process import FigureProcess
        from optdesign.plots.front import front_figure

        figures = figures if figures is not None else FigureProcess()
        figures.submit(
            FRONT_FIGURE,
            out / "front.png",
            lambda: front_figure(problem, fronts),
        )
    if report and any(f.points for f in fronts):
        from optdesign.errors import OptDesignError
        from optdesign.reports.html import front_report
        from optdesign.storage import atomic_write_text

        try:
            page = front_report(problem, fronts)
        except OptDesignError as exc:  # a user's mechanism that cannot draw itself
            notes.append(f"report.html not written: {exc}")
        else:
            atomic_write_text(out / "report.html", page)
            wrote.append(out / "report.html")
    if plot:
        failed = figures.outcome()
        if failed is None:
            wrote.insert(2, out / "front.png")
        else:  # the front's files are written; the report and the summary follow
            notes.insert(0, failed)
    return wrote, notes
