"""What ``optdesign pareto`` writes and says about the fronts of one run: ``front.csv`` and
``front.json`` (several methods' hypervolumes against one reference point), and why a
front has no point. The fronts come from :func:`optdesign.pareto`."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from optdesign.studies.diagnosis import violated_text
from optdesign.studies.pareto import common_hypervolumes, write_front_csv, write_front_json


def write_front_files(
    fronts: Sequence[Any],
    problem: Any,
    out: Path,
    *,
    objectives: Sequence[str],
    points: int,
    created: str,
) -> list[Path]:
    """``front.csv`` and ``front.json`` of ``fronts`` (of one problem) in folder ``out``;
    the files written."""
    if len(fronts) > 1:
        # Hypervolumes of different methods are comparable only with one reference point.
        common_hypervolumes(fronts)
    write_front_csv(fronts, problem, out / "front.csv")
    write_front_json(
        fronts,
        out / "front.json",
        problem=problem.name,
        objectives=list(objectives),
        points=points,
        created=created,
    )
    return [out / "front.csv", out / "front.json"]


def no_point_text(problem: Any, front: Any) -> str:
    """Why a front has no point: the requirements its least violating design violates."""
    head = f"{front.method}: no feasible design"
    designs = [p.design for p in front.rejected if p.design]
    if not designs:
        return head
    X = np.array([[d[v.name] for v in problem.free] for d in designs])
    worst = np.asarray(problem.evaluate(X).violation, dtype=float)
    best = X[int(np.argmin(np.where(np.isfinite(worst), worst, np.inf)))]
    shown = violated_text(problem, best)
    return f"{head} among {len(designs)} designs; the least violating one: {shown or 'none'}"
