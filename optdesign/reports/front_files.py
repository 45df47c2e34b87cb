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
) -> tuple[list[Path], list[str]]:
    """Everything ``optdesign pareto`` writes beside the stores, in folder ``out``:
    ``front.csv``, ``front.json`` (:func:`write_front_files`), ``front.png`` (``plot``)
    and ``report.html`` (``report``, when a front has a point). Returns the files written
    and the notes of the outputs that could not be drawn (a figure or a page that fails
    is a note, not an error: the other files are kept)."""
    wrote = write_front_files(
        fronts, problem, out, objectives=objectives, points=points, created=created
    )
    notes: list[str] = []
    if plot:
        from optdesign.plots import write_figure
        from optdesign.plots.front import plot_fronts

        failed = write_figure(lambda: plot_fronts(problem, fronts), out / "front.png")
        if failed is None:
            wrote.append(out / "front.png")
        else:  # the front's files are written; the report and the summary follow
            notes.append(failed)
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
    return wrote, notes


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
