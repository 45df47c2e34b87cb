"""Files of a front: ``front.csv`` (a row per point, in the summary's units with the unit
in each heading: ``ripple [%]``) and ``front.json`` (everything, internal units).

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

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.result import clean_json
from optdesign.studies.pareto.front import Front
from optdesign.text import csv_cell


def front_rows(front: Front, problem: DesignProblem, rejected: bool = False) -> list[dict]:
    """One dict per point: method, id, objectives and free design variables in the
    summary's units under ``"name [unit]"`` (:func:`optdesign.reports.frames.front_table`,
    the rows of ``Front.to_frame()`` too), status, verified, on_front, active."""
    from optdesign.reports.frames import front_table

    return front_table(front, problem, rejected)


def write_front_csv(
    front: Front | Sequence[Front], problem: DesignProblem, path: Path | str
) -> Path:
    """``front.csv``: one row a point (objectives, design variables, status, ...)."""
    from optdesign.storage import atomic_write_text

    fronts = [front] if isinstance(front, Front) else list(front)
    rows = [r for f in fronts for r in front_rows(f, problem, rejected=True)]
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
    from optdesign.reports.frames import objective_column

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


def write_front_json(fronts: Sequence[Front], path: Path | str, **meta) -> Path:
    """``front.json``: every front with its points, rejected points and metrics."""
    from optdesign.storage import atomic_write_text

    data = clean_json({**meta, "fronts": [f.to_dict() for f in fronts]})
    return atomic_write_text(Path(path), json.dumps(data, indent=1))
