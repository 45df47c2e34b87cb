"""Files of a front: ``front.csv`` (a row per point) and ``front.json`` (everything).

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
from typing import Any

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.result import clean_json
from optdesign.studies.pareto.front import Front
from optdesign.text import csv_cell


def front_rows(front: Front, problem: DesignProblem, rejected: bool = False) -> list[dict]:
    """One dict per point: objectives, free design variables, status, method, active."""
    rows = []
    for p in front.points + (front.rejected if rejected else []):
        row: dict[str, Any] = {"method": p.method, "id": p.id}
        for k in front.objectives:
            row[k] = p.objectives.get(k, float("nan"))
        for v in problem.free:
            row[v.name] = p.design.get(v.name, float("nan"))
        row["status"] = p.status
        row["verified"] = p.verified
        row["on_front"] = not p.rejected
        row["active"] = ";".join(p.active)
        rows.append(row)
    return rows


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


def read_front_csv(path: Path | str, objectives: Sequence[str]) -> np.ndarray:
    """Objective values of the on-front rows of a ``front.csv`` (``objectives`` named as
    the problem names them: a heading neutralised for spreadsheets is found too)."""
    with Path(path).open(newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if r.get("on_front", "True") == "True"]
    return np.array([[float(r[csv_cell(k)]) for k in objectives] for r in rows], dtype=float)


def write_front_json(fronts: Sequence[Front], path: Path | str, **meta) -> Path:
    """``front.json``: every front with its points, rejected points and metrics."""
    from optdesign.storage import atomic_write_text

    data = clean_json({**meta, "fronts": [f.to_dict() for f in fronts]})
    return atomic_write_text(Path(path), json.dumps(data, indent=1))
