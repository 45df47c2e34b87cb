"""A new study is one module and one command (tests/study_example.py): registered by
naming its module in optdesign.cli.PLUGIN_MODULES, it runs from the command line beside
the built-in ones, and its function from Python."""

from __future__ import annotations

import json
import sys

import pytest

import optdesign as od
from optdesign import cli


@pytest.fixture
def with_study(monkeypatch):
    """The study's one line (its module among the plug-ins), undone after the test: the
    commands' table is a copy, and the module is imported afresh to register into it."""
    monkeypatch.setattr(cli, "PLUGIN_MODULES", [*cli.PLUGIN_MODULES, "study_example"])
    monkeypatch.setattr(cli, "COMMANDS", dict(cli.COMMANDS))
    monkeypatch.delitem(sys.modules, "study_example", raising=False)


def test_a_study_module_adds_a_command_beside_the_built_in_ones(with_study, capsys):
    parser = cli.build_parser()
    commands = parser._subparsers._group_actions[0].choices
    assert {"solve", "pareto", "sweep", "bench", "seed-spread"} <= set(commands)
    code = cli.main(["seed-spread", "cs_min_backlash", "--seeds", "2", "--starts", "1"])
    out = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert code == 0
    assert out["problem"] == "cs_min_backlash" and out["seeds"] == [0, 1]
    # the study's numbers are the solves' own: each seed's one start, solved again here
    for seed, value in zip(out["seeds"], out["objectives"], strict=True):
        alone = od.solve("cs_min_backlash", starts=1, seed=seed, ranges=False)
        assert value == pytest.approx(alone.objective, rel=1e-9)
    assert out["best"] == pytest.approx(min(out["objectives"]), rel=1e-12)
    assert 1 <= out["at_best"] <= 2


def test_a_study_refuses_bad_input_through_the_library_it_calls(with_study, capsys):
    code = cli.main(["seed-spread", "no_such_problem"])
    err = capsys.readouterr().err
    assert code != 0 and "no_such_problem" in err
