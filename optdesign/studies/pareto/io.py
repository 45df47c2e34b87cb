"""Files of a front: ``front.csv`` (a row per point) and ``front.json`` (everything)."""

from __future__ import annotations

import csv
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from optdesign.problem.design_problem import DesignProblem
from optdesign.solvers.result import clean_json
from optdesign.studies.pareto.front import Front


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
    lines = [",".join(fields)]
    for r in rows:
        lines.append(
            _csv_line([f"{v:.12g}" if isinstance(v, float) else str(v) for v in r.values()])
        )
    return atomic_write_text(Path(path), "\n".join(lines) + "\n")


def _csv_line(cells: list[str]) -> str:
    import io

    buf = io.StringIO()
    csv.writer(buf, lineterminator="").writerow(cells)
    return buf.getvalue()


def read_front_csv(path: Path | str, objectives: Sequence[str]) -> np.ndarray:
    """Objective values of the on-front rows of a ``front.csv``."""
    with Path(path).open() as fh:
        rows = [r for r in csv.DictReader(fh) if r.get("on_front", "True") == "True"]
    return np.array([[float(r[k]) for k in objectives] for r in rows], dtype=float)


def write_front_json(fronts: Sequence[Front], path: Path | str, **meta) -> Path:
    """``front.json``: every front with its points, rejected points and metrics."""
    from optdesign.storage import atomic_write_text

    data = clean_json({**meta, "fronts": [f.to_dict() for f in fronts]})
    return atomic_write_text(Path(path), json.dumps(data, indent=1))
