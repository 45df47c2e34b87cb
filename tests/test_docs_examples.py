"""The examples written in the README and docs/ run as written (issue 23): the README's
Python blocks in a fresh folder holding the shipped problems, the docs' doctests."""

from __future__ import annotations

import doctest
import re
import shutil
from pathlib import Path

import pytest

from optdesign.mechanisms import registry

ROOT = Path(__file__).resolve().parents[1]


def python_blocks(page: Path) -> list[str]:
    """The ```python blocks of a Markdown page, in order."""
    return re.findall(r"^```python\n(.*?)^```", page.read_text(), flags=re.S | re.M)


@pytest.fixture
def mechanisms_restored():
    saved = dict(registry._REGISTRY)
    yield
    registry._REGISTRY.clear()
    registry._REGISTRY.update(saved)


def test_the_readmes_python_examples_run_as_written(tmp_path, monkeypatch, mechanisms_restored):
    blocks = python_blocks(ROOT / "README.md")
    assert len(blocks) >= 2
    shutil.copytree(ROOT / "problems", tmp_path / "problems")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(blocks[0], "README.md (first python block)", "exec"), namespace)
    result, front = namespace["result"], namespace["front"]
    assert result.status == "optimal" and result.verified
    assert result.objective == pytest.approx(0.0362197, rel=1e-5)  # cs_min_backlash's optimum
    assert len(front.points) == 30
    assert (tmp_path / "out" / "front.html").stat().st_size > 10_000
    sweep = namespace["sweep"]  # continuation over the hinge moment, the user's rows too
    assert [p.success for p in sweep.points] == [True] * 9
    assert sweep.points[4].objective == pytest.approx(result.objective, rel=1e-6)  # 500 N*m
    bench = namespace["report"]
    assert bench.configs == ["ipopt-exact", "slsqp-exact", "de"]
    assert len(bench.rows) >= 3 and {row.config for row in bench.rows} == set(bench.configs)
    # the mechanism snippet registers a working mechanism
    exec(compile(blocks[1], "README.md (second python block)", "exec"), namespace)
    yoke = namespace["ScotchYoke"]
    assert registry._REGISTRY["scotch_yoke"] is yoke


@pytest.mark.parametrize("page", ["clearance_and_backlash.md"])
def test_the_docs_doctests_pass(page):
    outcome = doctest.testfile(str(ROOT / "docs" / page), module_relative=False, verbose=False)
    assert outcome.attempted > 0 and outcome.failed == 0
