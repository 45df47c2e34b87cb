"""Reproductions of the source papers: ``optdesign reproduce NAME``.

Each entry maps a name to a module exposing ``run(out: pathlib.Path) -> int`` that
prints a paper-vs-computed table, writes its plots into ``out`` and returns an exit code.
"""

from __future__ import annotations

import importlib
from pathlib import Path

#: name -> module path. Add one line per reproduction.
REPRODUCTIONS: dict[str, str] = {
    "duan2017": "optdesign.reproduce.duan2017",
    "prsm-contact": "optdesign.reproduce.prsm_contact",
    "yang2016": "optdesign.reproduce.yang2016",
    "li2016": "optdesign.reproduce.li2016",
}


def run(name: str, out: Path) -> int:
    """Run the reproduction ``name`` writing into ``out``."""
    module = importlib.import_module(REPRODUCTIONS[name])
    out.mkdir(parents=True, exist_ok=True)
    return int(module.run(out))
