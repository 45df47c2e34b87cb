"""Data shipped with the package: the problem files of ``problems/`` and catalogues."""

from __future__ import annotations

from pathlib import Path


def problems_dir() -> Path:
    """The folder of the shipped problem files (inside the installed package when it
    holds them, else the source tree's ``problems/``)."""
    packaged = Path(__file__).resolve().parent / "problems"
    if packaged.is_dir():
        return packaged
    return Path(__file__).resolve().parents[2] / "problems"
