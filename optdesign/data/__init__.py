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


def shipped_problem(name: str) -> Path:
    """Path of the shipped problem file ``name`` (with or without ``.toml``)."""
    path = problems_dir() / (name if name.endswith(".toml") else f"{name}.toml")
    if not path.is_file():
        from optdesign.errors import InputError

        known = ", ".join(sorted(p.stem for p in problems_dir().glob("*.toml")))
        raise InputError("problem", f"no shipped problem {name!r} (shipped: {known})")
    return path
