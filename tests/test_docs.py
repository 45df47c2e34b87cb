"""The pages name what exists: every repository path, ``optdesign.*`` module (or its
attribute) and test named in README.md, docs/*.md and benchmarks/README.md exists. A
renamed test or a moved module fails here instead of leaving a stale page."""

from __future__ import annotations

import importlib
import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [
    ROOT / "README.md",
    *sorted((ROOT / "docs").glob("*.md")),
    ROOT / "benchmarks" / "README.md",
    ROOT / "tests" / "README.md",
]
#: How docs/README.md spells a test reference in general: not a name to check.
PLACEHOLDERS = {"tests/FILE.py", "test_function"}
_TOP = "optdesign|tests|benchmarks|examples|problems|docs|\\.ci"
_SUB = "models|mechanisms|studies|reports|solvers|formulations|programs|plots|problem|commands|reproduce|runtime"
PATH = re.compile(rf"(?<![\w./-])(?:(?:{_TOP})/[\w./*-]*|(?:{_SUB})/[\w./*-]+\.py)")
MODULE = re.compile(r"(?<![\w./-])optdesign(?:\.\w+)+(?![\w/])")
TEST_REF = re.compile(r"(tests/[\w/]+\.py)|::(test_\w+)")
TEST_NAME = re.compile(r"(?<![\w:/])(test_\w+)(?![\w.])")


def _spans(text: str) -> list[str]:
    """What a page names: code spans and link targets."""
    return re.findall(r"`([^`\n]+)`", text) + re.findall(r"\]\(([^)\s#]+)", text)


def _exists(page: Path, path: str) -> bool:
    path = path.rstrip(".")
    bases = [ROOT, ROOT / "optdesign", page.parent]
    if "*" in path:
        return any(list(b.glob(path)) for b in bases)
    return any((b / path).exists() for b in bases)


def _module_exists(dotted: str) -> bool:
    parts = dotted.split(".")
    for k in range(len(parts), 0, -1):
        name = ".".join(parts[:k])
        try:
            spec = importlib.util.find_spec(name)
        except (ImportError, ValueError):
            spec = None
        if spec is None:
            continue
        obj = importlib.import_module(name)
        for attr in parts[k:]:
            if not hasattr(obj, attr):
                return False
            obj = getattr(obj, attr)
        return True
    return False


def _tests_in(path: Path) -> set[str]:
    return set(re.findall(r"^\s*(?:async )?def (test_\w+)", path.read_text(), re.M))


ALL_TESTS = {name for f in (ROOT / "tests").rglob("*.py") for name in _tests_in(f)} | {
    f.stem for f in (ROOT / "tests").rglob("test_*.py")
}


def _stale(page: Path) -> list[str]:
    text = page.read_text()
    out = []
    for span in _spans(text):
        if span.startswith(("http://", "https://")):
            continue
        for path in PATH.findall(span):
            if path not in PLACEHOLDERS and not _exists(page, path):
                out.append(f"path {path}")
        for dotted in MODULE.findall(span):
            if not _module_exists(dotted):
                out.append(f"module {dotted}")
    # tests: tests/FILE.py::test_name (a "::test_name" belongs to the last file named)
    current = None
    for line in text.splitlines():
        for file, name in TEST_REF.findall(line):
            if file:
                current = file
                continue
            if current in PLACEHOLDERS:
                continue
            if current is None:
                out.append(f"test ::{name} without its file")
            elif not (ROOT / current).exists() or name not in _tests_in(ROOT / current):
                out.append(f"test {current}::{name}")
        for name in TEST_NAME.findall(line):
            if name not in PLACEHOLDERS and name not in ALL_TESTS:
                out.append(f"test {name}")
    return sorted(set(out))


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_path_module_and_test_a_page_names_exists(page):
    assert _stale(page) == []


def test_the_check_finds_what_is_stale(tmp_path):
    """The check itself: a removed module, a renamed test, a moved file are found."""
    page = tmp_path / "page.md"
    page.write_text(
        "`optdesign/studies/front_metrics.py`, `optdesign.studies.nothing`,\n"
        "`tests/studies/test_solve.py::test_fork_optimum_by_hand`, `::test_known_optimum_values`\n"
        "`models/_math.py`, `optdesign/math.py`, `optdesign.math.grid_max`, `test_no_such`\n"
    )
    assert _stale(page) == [
        "module optdesign.studies.nothing",
        "path models/_math.py",
        "path optdesign/studies/front_metrics.py",
        "test test_no_such",
        "test tests/studies/test_solve.py::test_fork_optimum_by_hand",
    ]
