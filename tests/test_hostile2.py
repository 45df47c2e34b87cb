"""The second hostile corpus (issue 21, ``tests/hostile2``): a representative subset of
its cases in the fast suite, the whole corpus under the ``slow`` mark.

Every case runs in a corpus server (a child process: a crash or a hang costs it, not
pytest) through the CLI in the default output mode and with ``--json``, and through the
Python API where it applies; signal and determinism cases run as real processes. A case
passes when every form of it ends as the issue requires (see ``tests/hostile2/model.py``).

KNOWN_FAILURES below lists, in one place, the fast cases that fail on the code the
corpus was written against (issue 21's "before"); each is marked ``xfail(strict=True)``,
so a fix that makes one pass fails the suite until its name is removed here.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from hostile2.controls import cases as control_cases  # noqa: E402
from hostile2.fuzz import run_fuzz  # noqa: E402
from hostile2.model import CLASSES  # noqa: E402
from hostile2.run import all_cases, run_case  # noqa: E402
from hostile2.server import Server  # noqa: E402

#: Fast cases that fail today, by name (each an xfail(strict=True)): empty since the
#: fixes of issue 21 landed; a case that regresses fails the suite.
KNOWN_FAILURES: set[str] = set()
#: Draws of the fuzz in the fast suite (the script runs more).
FAST_FUZZ = 12

FAST = [c for c in all_cases() if c.fast]


def _param(case):
    marks = []
    if case.name in KNOWN_FAILURES:
        reason = f"issue 21, class {case.cls} ({CLASSES[case.cls]}): fails before the fix"
        marks.append(pytest.mark.xfail(strict=True, reason=reason))
    return pytest.param(case, id=case.name, marks=marks)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    s = Server(tmp_path_factory.mktemp("hostile2-server"))
    yield s
    s.stop()


def _failures(outcomes) -> list[str]:
    return [f"{o.mode}: {o.verdict}: {'; '.join(o.problems)[:600]}" for o in outcomes if not o.good]


@pytest.mark.parametrize("case", [_param(c) for c in FAST])
def test_fast_case(case, server, tmp_path):
    outcomes = run_case(case, 0, tmp_path, server)
    assert outcomes
    bad = _failures(outcomes)
    assert not bad, "\n".join(bad)


@pytest.mark.xfail(
    "fuzz" in KNOWN_FAILURES, strict=True, reason="issue 21: fuzz draws fail before the fix"
)
def test_fuzz_of_problem_dicts(server, tmp_path):
    """Derandomised draws through od.load / od.solve: a refusal naming a touched field, a
    failed result naming the violated requirements, or a verified result."""
    outcomes = run_fuzz(server, tmp_path / "fuzz", FAST_FUZZ)
    assert len(outcomes) >= FAST_FUZZ
    bad = [f"{o.case}: {o.verdict}: {o.message}" for o in outcomes if not o.good]
    assert not bad, "\n".join(bad)


def test_the_corpus_has_every_class_and_a_few_hundred_cases():
    cases = all_cases()
    assert len(cases) >= 300
    per = counts_of(cases)
    for cls in CLASSES:
        if cls not in ("fuzz", "control"):
            assert per.get(cls, 0) >= 10, (cls, per.get(cls, 0))
    assert len({c.name for c in cases}) == len(cases)
    fast = {c.cls for c in FAST}
    assert fast >= set(CLASSES) - {"fuzz", "control"}


def counts_of(cases) -> dict[str, int]:
    out: dict[str, int] = {}
    for c in cases:
        out[c.cls] = out.get(c.cls, 0) + 1
    return out


def test_known_failures_name_fast_cases():
    names = {c.name for c in FAST} | {"fuzz"}
    assert KNOWN_FAILURES <= names, sorted(KNOWN_FAILURES - names)


@pytest.mark.parametrize(
    ("name", "verdicts"),
    [
        ("control:a valid file expected refused", {"wrong_success"}),
        ("control:a valid file", {"verified"}),
        ("control:a file written outside", {"files_touched"}),
        ("control:an escape sequence printed", {"unsafe_terminal"}),
        ("control:abort", {"crash"}),
        ("control:sleeps past its time limit", {"hang"}),
        ("control:a formula in front.csv", {"unparseable_output"}),
        ("control:a raw KeyError", {"internal_error"}),
    ],
)
def test_the_judge_is_not_blind(name, verdicts, server, tmp_path):
    case = {c.name: c for c in control_cases()}[name]
    outcomes = run_case(case, 0, tmp_path, server)
    assert {o.verdict for o in outcomes} == verdicts, [
        (o.mode, o.verdict, o.problems) for o in outcomes
    ]


@pytest.mark.slow
def test_full_corpus(tmp_path):
    """The whole corpus and 200 fuzz draws: every case gets a verdict, the counts add up,
    and no case that passed in the saved "before" run fails now (signals and
    determinism, which depend on timing, aside)."""
    out = tmp_path / "corpus2.json"
    proc = subprocess.run(
        [sys.executable, str(HERE / "hostile_corpus2.py"), str(out), "--quiet"],
        capture_output=True,
        text=True,
        timeout=7200,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    print(proc.stdout)
    doc = json.loads(out.read_text())
    total = doc["counts"]["all"]
    assert total["tried"] == sum(v for k, v in total.items() if k not in ("tried", "cases"))
    assert total["cases"] >= 300
    before = HERE.parent / "benchmarks" / "results" / "hostile_corpus2_before.json"
    if before.exists():
        was = {
            (o["case"], o["mode"]): o["verdict"] for o in json.loads(before.read_text())["outcomes"]
        }
        good = {"refused", "verified", "honoured"}
        regressed = [
            f"{o['case']} [{o['mode']}]: {was[(o['case'], o['mode'])]} -> {o['verdict']}"
            for o in doc["outcomes"]
            if o["cls"] not in ("1", "3", "fuzz")
            and was.get((o["case"], o["mode"])) in good
            and o["verdict"] not in good
        ]
        assert not regressed, "\n".join(regressed)
