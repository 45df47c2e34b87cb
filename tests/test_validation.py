"""One validation layer (issue 21, class 9): the Python API refuses what the command line
refuses, before any work, with the same message.

Each case is one refusal written once: the API call, the command line, the argument and
the reason. The API must raise ``InputError`` with ``"{argument}: {reason}"``; the
command line (in-process ``optdesign.cli.main``, default output and ``--json`` where the
command has it) must exit 2 with one line naming the option and the same reason, and
make no output folder.
"""

from __future__ import annotations

import pickle
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import optdesign as od
from optdesign.cli import main, option
from optdesign.errors import InputError
from optdesign.validation import ArgumentError

ROOT = Path(__file__).resolve().parents[1]
BACKLASH = str(ROOT / "problems" / "cs_min_backlash.toml")
RIPPLE = str(ROOT / "problems" / "cs_min_ripple.toml")
CATALOGUE = str(ROOT / "problems" / "cs_min_backlash_catalogue.toml")
SOLVERS = "ipopt, sqpmethod, slsqp, trust-constr, bonmin, clarabel, scs"


@dataclass
class Case:
    """One refusal: ``api`` (function, args, kwargs), ``argv`` (the command line, without
    ``--out``), the refused ``argument`` and its ``reason``, where ``{name}`` marks another
    argument (shown as ``name`` by the API, as its option by the command line)."""

    id: str
    api: tuple[Any, tuple, dict]
    argv: list[str]
    argument: str
    reason: str
    renamed: dict[str, str] = field(default_factory=dict)

    def api_message(self) -> str:
        return f"{self.argument}: {self.reason}".replace("{", "").replace("}", "")

    def cli_message(self) -> str:
        text = self.reason
        for word in ("out", "resume", "problems"):
            text = text.replace("{" + word + "}", option(word, self.renamed))
        return f"{option(self.argument, self.renamed)}: {text}"


def solve(argument: str, value: Any, word: str, reason: str) -> Case:
    kwargs = {argument: value}
    return Case(
        f"solve-{argument}-{word}",
        (od.solve, (BACKLASH,), kwargs),
        ["solve", BACKLASH, option(argument), word],
        argument,
        reason,
    )


def pareto(argument: str, value: Any, word: str | None, reason: str, **more: Any) -> Case:
    """A refusal of od.pareto / optdesign pareto (``word`` None: a flag option)."""
    problem = more.pop("problem", RIPPLE)
    objectives = more.pop("objectives", "ripple,size")
    renamed = {"pop_size": "--pop"}
    extra = [a for k, v in more.items() for a in _words(k, v, renamed)]
    opt = [option(argument, renamed)] + ([] if word is None else [word])
    api_kwargs = {**more, argument: value} if argument != "objectives" else dict(more)
    api_objectives = value if argument == "objectives" else objectives
    if argument == "objectives":
        opt = []
        objectives = word
    return Case(
        f"pareto-{argument}-{word}",
        (od.pareto, (problem, api_objectives), api_kwargs),
        ["pareto", problem, "--objectives", objectives, *extra, *opt],
        argument,
        reason,
        renamed,
    )


def _words(key: str, value: Any, renamed: dict[str, str] | None = None) -> list[str]:
    """The command-line words of an API keyword (a flag for True)."""
    return [option(key, renamed)] + ([] if value is True else [str(value)])


def bench(argument: str, value: Any, words: list[str], reason: str, **more: Any) -> Case:
    extra = [a for k, v in more.items() for a in _words(k, v)]
    return Case(
        f"bench-{argument}-{'-'.join(words) or 'flag'}",
        (od.bench, (), {**more, argument: value}),
        ["bench", *extra, option(argument), *words],
        argument,
        reason,
    )


CASES = [
    # --- solve ---------------------------------------------------------------------
    solve("starts", 0, "0", "0 is outside 1..10000"),
    solve("starts", -2, "-2", "-2 is outside 1..10000"),
    solve("starts", 10**9, "1000000000", "1000000000 is outside 1..10000"),
    solve("starts", 2.5, "2.5", "2.5 is not an integer"),
    solve("starts", "x", "x", "'x' is not an integer"),
    solve(
        "starts", 10**400, "1" + "0" * 400, "an integer of more than 100 digits is outside 1..10000"
    ),
    solve("seed", -1, "-1", "-1 is outside 0..4294967295"),
    solve("seed", 2**64, str(2**64), "18446744073709551616 is outside 0..4294967295"),
    solve("workers", 0, "0", "0 is outside 1..256"),
    solve("workers", 100_000, "100000", "100000 is outside 1..256"),
    solve(
        "formulation",
        "nlpp",
        "nlpp",
        "unknown formulation 'nlpp' (did you mean 'nlp'? known: auto, catalogue, robust, gp, nlp)",
    ),
    solve(
        "formulation",
        "nosuch",
        "nosuch",
        "unknown formulation 'nosuch' (known: auto, catalogue, robust, gp, nlp)",
    ),
    solve(
        "solver",
        "ipoptt",
        "ipoptt",
        f"unknown solver 'ipoptt' (did you mean 'ipopt'? known: {SOLVERS})",
    ),
    solve(
        "objective",
        "backlsh",
        "backlsh",
        "unknown objective 'backlsh' (did you mean 'backlash'? known: ripple, backlash, "
        "backlash_rss, size, nut_travel, motor_torque, drive_loss, screw_mass, motor_inertia, "
        "hinge_compliance, motor_peak_torque, motor_rms_torque, natural_period, resonance_gain, bandwidth_period, sensitivity_peak, limit_cycle_amplitude, motor_mass, lock_force)",
    ),
    # --- pareto --------------------------------------------------------------------
    pareto("points", 1, "1", "1 is outside 2..10000"),
    pareto("points", 2.5, "2.5", "2.5 is not an integer"),
    pareto("points", 10**7, "10000000", "10000000 is outside 2..10000"),
    pareto("workers", 0, "0", "0 is outside 1..256"),
    pareto("starts", 0, "0", "0 is outside 1..10000"),
    pareto("seed", -1, "-1", "-1 is outside 0..4294967295"),
    pareto("pop_size", 2, "2", "2 is outside 4..100000", method="nsga2"),
    pareto("generations", 0, "0", "0 is outside 1..100000", method="nsga2"),
    pareto("objectives", ["ripple"], "ripple", "give two or three objectives, got ['ripple']"),
    pareto(
        "objectives",
        ["ripple", "ripple"],
        "ripple,ripple",
        "repeated objective in ['ripple', 'ripple']",
    ),
    pareto(
        "objectives",
        ["ripple", "sise"],
        "ripple,sise",
        "unknown objective 'sise' (did you mean 'size'? known: ripple, backlash, backlash_rss, "
        "size, nut_travel, motor_torque, drive_loss, screw_mass, motor_inertia, "
        "hinge_compliance, motor_peak_torque, motor_rms_torque, natural_period, resonance_gain, bandwidth_period, sensitivity_peak, limit_cycle_amplitude, motor_mass, lock_force)",
    ),
    pareto(
        "method",
        "epsilonn",
        "epsilonn",
        "unknown method 'epsilonn' (did you mean 'epsilon'? known: epsilon, uniform, "
        "weighted_sum, nsga2)",
    ),
    pareto(
        "method",
        "weighted_sum",
        "weighted_sum",
        "weighted_sum would leave the catalogue: with catalogue variables use epsilon or nsga2",
        problem=CATALOGUE,
        objectives="backlash,ripple",
    ),
    pareto(
        "time_limit",
        5,
        "5",
        "not applied by the nsga2 method: only a continuous epsilon sweep stops at a time limit",
        method="nsga2",
    ),
    pareto(
        "time_limit",
        5,
        "5",
        "not applied by a catalogue front: only a continuous epsilon sweep stops at a time limit",
        problem=CATALOGUE,
        objectives="backlash,ripple",
    ),
    pareto("resume", True, None, "give the {out} folder of the run to resume"),
    pareto("overwrite", True, None, "excludes {resume} (start over, or continue)", resume=True),
    # --- bench ---------------------------------------------------------------------
    bench(
        "suite",
        "quik",
        ["quik"],
        "unknown suite 'quik' (did you mean 'quick'? known: default, quick)",
    ),
    bench(
        "solvers",
        ["ipopt-exakt"],
        ["ipopt-exakt"],
        "unknown configuration 'ipopt-exakt' (did you mean 'ipopt-exact'? known: ipopt-exact, "
        "ipopt-lbfgs, ipopt-spral, ipopt-naive, sqp-qrqp, sqp-osqp, sqp-qpoases, slsqp-exact, "
        "slsqp-fd, trust-constr-exact, trust-constr-fd, slsqp-naive, de, gp-clarabel, gp-scs, "
        "front-epsilon, front-nsga2)",
    ),
    bench("workers", 0, ["0"], "0 is outside 1..256"),
    bench("time_limit", float("nan"), ["nan"], "nan is outside (0, 86400]"),
    bench("time_limit", -1, ["-1"], "-1 is outside (0, 86400]"),
    bench("time_limit", 1e9, ["1e9"], "1e+09 is outside (0, 86400]"),
    bench("hard_timeout", 0, ["0"], "0 is outside (0, 86400]"),
    bench(
        "scheduler",
        "tcp://host:99999",
        ["tcp://host:99999"],
        "'tcp://host:99999' is not a scheduler's address: no port 1..65535 (write "
        "SCHEME://HOST:PORT, e.g. tcp://127.0.0.1:8786)",
    ),
    pareto(
        "scheduler",
        "not a url",
        "not a url",
        "'not a url' is not a scheduler's address: no port 1..65535 (write "
        "SCHEME://HOST:PORT, e.g. tcp://127.0.0.1:8786)",
    ),
    bench(
        "time_limit",
        10**400,
        ["1" + "0" * 400],
        "an integer of more than 100 digits is outside (0, 86400]",
    ),
    bench(
        "update_readme",
        str(ROOT / "pyproject.toml"),
        [str(ROOT / "pyproject.toml")],
        f"{ROOT / 'pyproject.toml'} has no generated-block markers",
    ),
    bench(
        "update_readme",
        str(ROOT / "no-such-readme.md"),
        [str(ROOT / "no-such-readme.md")],
        f"{ROOT / 'no-such-readme.md'} does not exist",
    ),
    bench("resume", True, [], "give the {out} folder of the run to resume"),
    bench("overwrite", True, [], "excludes {resume} (start over, or continue)", resume=True),
]


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.id)
def test_the_api_refuses_with_the_command_lines_message(case, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # nothing may appear here either
    fn, args, kwargs = case.api
    with pytest.raises(InputError) as caught:
        fn(*args, **kwargs)
    assert str(caught.value) == case.api_message()
    assert caught.value.field == case.argument
    assert list(tmp_path.iterdir()) == []


#: Every case in the default output mode, and with --json where the command has it.
MODES = [(c, "default") for c in CASES] + [(c, "json") for c in CASES if c.argv[0] == "solve"]


@pytest.mark.parametrize(("case", "mode"), MODES, ids=lambda x: getattr(x, "id", x))
def test_the_command_line_refuses_with_the_apis_message(case, mode, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out"
    argv = [*case.argv, "--out", str(out)] + (["--json"] if mode == "json" else [])
    if "--resume" in argv and "--overwrite" not in argv:
        argv = argv[: argv.index("--out")]  # the refusal is about the missing --out
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's refusal
        code = exc.code
    captured = capsys.readouterr()
    assert code == 2
    assert captured.out == ""
    last = captured.err.strip().splitlines()[-1]
    assert last.endswith(case.cli_message()), (last, case.cli_message())
    assert last.startswith("optdesign")
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_every_command_line_option_is_an_api_argument():
    """solve, pareto and bench: each option that changes what is computed maps to an
    argument of od.solve / od.pareto / od.bench (the output-only ones excepted)."""
    import inspect

    from optdesign.cli import build_parser
    from optdesign.validation import _pareto_options

    parser = build_parser()
    subparsers = next(a for a in parser._actions if a.dest == "command").choices
    outputs = {"json", "no_plot", "no_report", "no_diagnosis", "list", "out"}
    api = {
        "solve": set(inspect.signature(od.solve).parameters) | {"file"},
        "pareto": set(inspect.signature(od.pareto).parameters) | set(_pareto_options()) | {"file"},
        "bench": set(inspect.signature(od.bench).parameters),
    }
    renamed = {"no_ranges": "ranges", "no_progress": "progress", "pop": "pop_size"}
    for name, arguments in api.items():
        dests = {a.dest for a in subparsers[name]._actions if a.dest != "help"}
        missing = {renamed.get(d, d) for d in dests - outputs} - arguments
        assert not missing, (name, missing)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: od.solve(BACKLASH, starts=True), "starts: True is not an integer"),
        (lambda: od.solve(BACKLASH, workers=2.0), "workers: 2.0 is not an integer"),
        (lambda: od.solve(BACKLASH, agree=-1), "agree: -1 is outside 0..10000"),
        (lambda: od.solve(BACKLASH, ranges="no"), "ranges: 'no' is not True or False"),
        (
            lambda: od.solve(BACKLASH, sensitivity=False),
            "sensitivity: unknown argument of solve() (did you mean 'sensitivities'? known: "
            "formulation, objective, starts, seed, workers, solver, options, ranges, agree, "
            "diagnose, sensitivities, contact_models, time_limit, target_odds)",
        ),
        (lambda: od.solve(BACKLASH, target_odds=0.0), "target_odds: 0 is outside (0, 0.5]"),
        (lambda: od.solve(BACKLASH, target_odds=0.9), "target_odds: 0.9 is outside (0, 0.5]"),
        (lambda: od.solve(BACKLASH, sensitivities=1), "sensitivities: 1 is not True or False"),
        (
            lambda: od.sweep(RIPPLE, {"requirements.hinge_moment": ("2 N*m", "3 N*m", 2)}, out=""),
            "out: an empty path names no folder: give the folder to write",
        ),
        (
            lambda: od.pareto(RIPPLE, "ripple,size", out=" "),
            "out: an empty path names no folder: give the folder to write",
        ),
        (
            lambda: od.solve(BACKLASH, options=[1]),
            "options: expected a dict of solver options, got [1]",
        ),
        (
            lambda: od.solve(BACKLASH, options={"max_itr": 5}),
            "options.max_itr: unknown Ipopt option; did you mean 'max_iter'?",
        ),
        (
            lambda: od.load(5),
            "problem: expected a problem file path, a problem dict or a DesignProblem, got 5",
        ),
        (
            lambda: od.load(b"x.toml"),
            "problem: expected a problem file path, a problem dict or a DesignProblem, got b'x.toml'",
        ),
        (
            lambda: od.pareto(RIPPLE, "ripple,size", pointz=5),
            "pointz: unknown option of pareto() (did you mean 'points'? known: out, workers, "
            "scheduler, resume, overwrite, progress, files, on_record, time_limit, starts, seed, agree, "
            "solver, spacing, eps_values, retry_starts, extra_starts, deterministic, pop_size, "
            "generations, name)",
        ),
        (
            lambda: od.pareto(RIPPLE, "ripple,size", pop_size=50),
            "pop_size: not an option of method 'epsilon' (it is one of nsga2)",
        ),
        (
            lambda: od.pareto(RIPPLE, "ripple,size", name="../x"),
            "name: '../x' is not a name: use letters, digits and underscores, not starting with a digit, at most 64 characters (it becomes a column header, a JSON key and a file label)",
        ),
        (
            lambda: od.pareto(RIPPLE, "ripple,size", eps_values=[1, float("nan")]),
            "eps_values: nan is not a finite number",
        ),
        (lambda: od.pareto(RIPPLE, 5), "objectives: expected a list of names, got 5"),
        (
            lambda: od.bench(problems=BACKLASH),
            "problems: expected a list of problems (files, dicts or problems), got '/",
        ),
        (
            lambda: od.bench(problems=[BACKLASH], suite="quick"),
            "suite: excludes problems (run your problems or a suite)",
        ),
        (lambda: od.bench(time_limit=True), "time_limit: True is not a number"),
        (
            lambda: od.bench(problems=[]),
            "problems: give at least one problem (or None for a suite)",
        ),
    ],
)
def test_api_only_arguments_are_checked_before_any_work(call, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError) as caught:
        call()
    assert str(caught.value).startswith(message)
    assert list(tmp_path.iterdir()) == []


def test_numpy_integers_are_integers_and_a_refusal_crosses_processes():
    problem = od.load(BACKLASH)
    result = od.solve(problem, starts=np.int64(1), seed=np.uint32(3), ranges=np.bool_(False))
    assert result.status == "optimal" and result.multistart.seed == 3
    err = ArgumentError("overwrite", "excludes {resume} (start over)", ("resume",))
    back = pickle.loads(pickle.dumps(err))
    assert str(back) == "overwrite: excludes resume (start over)"
    assert back.render(lambda a: "--" + a) == "excludes --resume (start over)"


def test_overwrite_discards_the_store_of_the_method_that_runs(tmp_path):
    seen = {}

    class Stub:
        name = "stub"

        def run(self, problem, objectives, run):
            seen["store left"] = (tmp_path / "stub.jsonl").exists()
            seen["other store"] = (tmp_path / "epsilon.jsonl").exists()
            return "front"

    (tmp_path / "stub.jsonl").write_text('{"old": 1}\n')
    (tmp_path / "epsilon.jsonl").write_text('{"old": 1}\n')
    assert od.pareto(RIPPLE, "ripple,size", method=Stub(), out=tmp_path, overwrite=True) == "front"
    assert seen == {"store left": False, "other store": True}
    with pytest.raises(InputError, match=r"starts: goes into the method object, not pareto\(\)"):
        od.pareto(RIPPLE, "ripple,size", method=Stub(), starts=3)


@pytest.mark.slow
def test_overwrite_starts_a_front_afresh_through_the_api(tmp_path):
    """``overwrite`` (the command line's --overwrite) discards the method's own store,
    the catalogue front's ``epsilon-catalogue.jsonl`` too."""
    from optdesign.errors import OptDesignError

    args = (CATALOGUE, "backlash,ripple")
    first = od.pareto(*args, points=3, out=tmp_path, workers=1)
    store = tmp_path / "epsilon-catalogue.jsonl"
    written = store.read_text().splitlines()
    with pytest.raises(OptDesignError, match=r"epsilon-catalogue\.jsonl holds \d+ records"):
        od.pareto(*args, points=3, out=tmp_path, workers=1)
    again = od.pareto(*args, points=3, out=tmp_path, workers=1, overwrite=True)
    # the same front, solved again (not read back): the catalogue front's memo of this
    # process (node bounds, proofs, the thinned grid's learnt angles) seeds the second
    # run, whose points are the same optima reached by another path: equal to Ipopt's
    # tolerances (2e-9 relative), not bit for bit
    np.testing.assert_allclose(again.F, first.F, rtol=1e-8)
    assert len(store.read_text().splitlines()) == len(written)  # a new store, not appended


@pytest.mark.parametrize("under", [False, True])
def test_an_out_that_is_a_file_is_refused_before_any_work(tmp_path, capsys, under):
    from optdesign.cli import main

    sentinel = tmp_path / "results.txt"
    sentinel.write_text("a file, not a folder\n")
    out = sentinel / "run" if under else sentinel
    fork = str(ROOT / "problems" / "fork_min_backlash.toml")
    with pytest.raises(InputError, match=r"^out: .* a file, not a folder"):
        od.pareto(fork, ["size", "backlash"], points=3, out=out)
    with pytest.raises(InputError, match=r"^out: .* a file, not a folder"):
        od.bench(problems=[fork], solvers=["ipopt-exact"], out=out)
    argv = ["pareto", fork, "--objectives", "size,backlash", "--points", "3", "--out", str(out)]
    assert main(argv) == 2
    assert "--out: " in capsys.readouterr().err
    assert sentinel.read_text() == "a file, not a folder\n"


def test_bench_configurations_are_the_command_lines_list(capsys):
    # optdesign bench --list prints od.bench_configurations(), the names od.bench takes
    configs = od.bench_configurations()
    assert [c[0] for c in configs][:2] == ["ipopt-exact", "ipopt-lbfgs"]
    assert ("gp-clarabel", "gp", "cvxpy GP (first-order Hertz), Clarabel") in configs
    assert "debug-crash" not in {c[0] for c in configs}
    assert "debug-crash" in {c[0] for c in od.bench_configurations(hidden=True)}
    assert main(["bench", "--list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == [c[0] for c in configs]


@pytest.mark.parametrize("command", ["solve", "sweep", "pareto", "bench", "reproduce"])
def test_an_empty_out_is_refused_not_read_as_the_working_folder(
    command, tmp_path, capsys, monkeypatch
):
    # Path("") is ".": every file of the run would land in the working folder
    monkeypatch.chdir(tmp_path)
    argv = {
        "solve": ["solve", RIPPLE],
        "sweep": ["sweep", RIPPLE, "--vary", "requirements.hinge_moment=200:300:2 N*m"],
        "pareto": ["pareto", RIPPLE, "--objectives", "ripple,size"],
        "bench": ["bench", "--suite", "quick"],
        "reproduce": ["reproduce", "duan2017"],
    }[command]
    with pytest.raises(SystemExit) as caught:
        main([*argv, "--out", ""])
    assert caught.value.code == 2
    assert "argument --out: an empty path names no folder" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_command_line_number_in_another_scripts_digits_is_refused(tmp_path, capsys, monkeypatch):
    # optdesign.cli.literal: int("\u0663") is 3; the option must not read it as a number
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as caught:
        main(["solve", RIPPLE, "--starts", "\u0663", "--out", str(tmp_path / "o")])
    assert caught.value.code == 2
    assert "argument --starts: '\u0663' is not an integer" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_library_messages_name_api_arguments_and_the_command_line_shows_its_options(
    tmp_path, capsys
):
    """A refusal raised by the library speaks the API's words (``formulation='gp'``); the
    command line prints the same refusal with its own option (``--formulation gp``)."""
    from optdesign.cli import flags

    problem = od.load(BACKLASH)
    with pytest.raises(od.ProblemError) as refused:
        od.solve(problem, formulation="catalogue")
    assert str(refused.value).startswith("formulation='catalogue': no variable takes")
    assert flags(str(refused.value)).startswith("--formulation catalogue: no variable takes")
    assert flags("more starts (starts=) may find it; restarts=3 starts=5") == (
        "more starts (--starts) may find it; restarts=3 starts=5"
    )
    assert flags("resume=True: x; start over with overwrite=True") == (
        "--resume: x; start over with --overwrite"
    )
    code = main(["solve", str(BACKLASH), "--formulation", "catalogue", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2
    assert "optdesign: error: --formulation catalogue: no variable takes catalogue" in err
