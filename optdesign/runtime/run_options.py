"""Where and how a study's tasks run, apart from what they compute: :class:`RunOptions`,
shared by the Pareto fronts and the sweeps (both run through
:func:`optdesign.runtime.runner.run_tasks`)."""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any


def study_folder(out: Path | str | None, kind: str) -> Path:
    """The folder of a study's store: ``out`` (made if missing), or a new temporary
    folder ``optdesign-KIND-...`` (never a folder of committed files by default)."""
    folder = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix=f"optdesign-{kind}-"))
    folder.mkdir(parents=True, exist_ok=True)
    return folder


@dataclass
class RunOptions:
    """Where and how a study's tasks run (not what they compute).

    Attributes
    ----------
    out
        The folder of the store (None: a new temporary folder).
    workers, scheduler
        Local processes, or a Dask scheduler (its address or client).
    resume, overwrite
        Continue the store in ``out``; start afresh over it.
    progress
        Show a progress bar.
    on_record
        Called with each record as it comes in (fronts).
    time_limit
        Wall-clock seconds of the study: no point begins after it (epsilon fronts).
    """

    out: Path | str | None = None
    workers: int = 1
    scheduler: str | Any | None = None
    resume: bool = False
    progress: bool = False
    on_record: Callable | None = None
    overwrite: bool = False
    time_limit: float | None = None

    def folder(self, kind: str) -> Path:
        """:func:`study_folder` of :attr:`out`."""
        return study_folder(self.out, kind)
