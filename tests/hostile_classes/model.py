"""A case of the second corpus, its expectation, the outcome of one run, the verdicts."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

#: The issue's classes (issue 21), by number; "fuzz" is the hypothesis fuzz.
CLASSES: dict[str, str] = {
    "1": "determinism: the same result for any number of workers",
    "2": "files written outside the output folder",
    "3": "signals inside a long solver call",
    "4": "failures that name nothing",
    "5": "units of the wrong dimension",
    "6": "outputs that break or inject",
    "7": "internal errors and crashes on input",
    "8": "resume that mixes runs",
    "9": "the Python API checks less than the CLI",
    "10": "a bug in a user's mechanism",
    "11": "plausible bugs the tests miss (properties of results)",
    "fuzz": "hypothesis fuzz of problem dicts through od.load / od.solve",
    "control": "control cases of the judge (not counted)",
}

#: Verdicts of a run; the first two (and "honoured") are the good ends.
VERDICTS: tuple[str, ...] = (
    "refused",  # refused cleanly: exit 2 / 1 (infeasible) or an OptDesignError, naming the field
    "verified",  # a success whose result is verified (or the same result, class 1)
    "honoured",  # a signal honoured: exit 128+n within the deadline, the one line
    "wrong_success",  # succeeded where it must refuse, or a success that does not verify
    "wrong_refusal",  # a valid case refused or failed
    "unclear_refusal",  # refused, but the exit code is wrong or the message names nothing
    "traceback",
    "internal_error",  # "internal error", or a raw exception from the API
    "crash",  # killed by a signal (segfault, abort, out of memory)
    "hang",  # past the time limit
    "files_touched",  # a file outside the output folder created, deleted, modified
    "unsafe_terminal",  # control characters printed raw
    "unparseable_output",  # result.json, front.csv, report.html broken
    "signal_not_honoured",
    "not_deterministic",
)
GOOD = frozenset({"refused", "verified", "honoured"})

#: Precedence when a run has several problems: the worst first.
PRECEDENCE: tuple[str, ...] = (
    "crash",
    "hang",
    "files_touched",
    "traceback",
    "internal_error",
    "signal_not_honoured",
    "not_deterministic",
    "unsafe_terminal",
    "unparseable_output",
    "wrong_success",
    "wrong_refusal",
    "unclear_refusal",
)


@dataclass(frozen=True)
class Expect:
    """What a correct program does with a case.

    ``kind``: ``"refuse"`` (exit 2 / an OptDesignError), ``"infeasible"`` (exit 1 with the
    violated requirements named, or 2 when the conflict is found before solving; from the
    API a failed result naming them, or an OptDesignError), ``"success"`` (a verified
    result) or ``"either"`` (a refusal naming the field, or a verified result).
    ``names``: the message must contain one of these (case-insensitive).
    """

    kind: str
    names: tuple[str, ...] = ()

    def __post_init__(self):
        assert self.kind in ("refuse", "infeasible", "success", "either"), self.kind


def refuse(*names: str) -> Expect:
    return Expect("refuse", names)


def infeasible(*names: str) -> Expect:
    return Expect("infeasible", names)


def either(*names: str) -> Expect:
    return Expect("either", names)


SUCCESS = Expect("success")


@dataclass
class Case:
    """One hostile input, run in every form that applies.

    Attributes
    ----------
    name
        Unique, ``"<class>:<what>"``.
    cls
        Its class (a key of :data:`CLASSES`).
    expect
        What a correct program does.
    argv
        The CLI form (``optdesign`` arguments), or None. Placeholders: ``@FILE@`` (the
        case's problem file), ``@OUT@`` (its output folder), ``@OUTSIDE@`` (a folder
        outside it), ``@CWD@`` (the working directory), ``@ROOT@``.
    text
        The problem file (placeholders too), or None.
    api
        The API form: ``api(ctx)`` returns what the API returns (a Result, a Front, a
        problem ...) or raises; None when the case has no API form.
    json
        The command has ``--json``: the CLI form runs twice, with and without it.
    setup
        ``setup(root)`` prepares more of the case's folder (links, stores).
    files
        Files written into the working directory with the case's folder (a user's
        modules): name -> text.
    check
        ``check(value, ctx) -> [problems]``: more verification of an API success.
    cli_check
        ``cli_check(root, stdout, stderr) -> [problems]``: more verification of a CLI run
        that ended as expected.
    payload
        Hostile text (a name) that must not reach the terminal raw.
    quote_check
        report.html must escape ``"`` in what its script writes into attributes.
    special
        For classes 1 and 3: ``special(root) -> list[dict]`` runs the case as real
        processes (the parent runs it; no CLI/API form).
    fresh
        Start a fresh server process first: no global state an earlier case left (a
        plug-in loaded from its entry point) leaks in.
    pythonpath
        The working directory is importable during the run (a plug-in's module and its
        entry point live there).
    env
        Extra environment of the run.
    timeout
        Seconds before the run counts as a hang.
    fast
        In the fast test's subset.
    """

    name: str
    cls: str
    expect: Expect
    argv: list[str] | None = None
    text: str | bytes | None = None
    api: Callable[[Any], Any] | None = None
    json: bool = True
    setup: Callable[[Any], None] | None = None
    files: dict[str, str] = field(default_factory=dict)
    check: Callable[[Any, Any], list[str]] | None = None
    cli_check: Callable[[Any, str, str], list[str]] | None = None
    payload: str | None = None
    quote_check: bool = False
    special: Callable[[Any], list[dict[str, Any]]] | None = None
    fresh: bool = False
    pythonpath: bool = False
    env: dict[str, str] = field(default_factory=dict)
    timeout: float = 60.0
    fast: bool = False

    def modes(self) -> list[str]:
        """The runs of this case: ``default`` / ``json`` (CLI), ``api``, ``special``."""
        if self.special is not None:
            return ["special"]
        out = []
        if self.argv is not None:
            out.append("default")
            if self.json:
                out.append("json")
        if self.api is not None:
            out.append("api")
        return out


@dataclass
class Outcome:
    """The verdict of one run of a case."""

    case: str
    cls: str
    mode: str
    verdict: str
    seconds: float
    code: Any = None
    message: str = ""
    problems: list[str] = field(default_factory=list)

    @property
    def good(self) -> bool:
        return self.verdict in GOOD


def worst(problems: list[tuple[str, str]]) -> str:
    """The verdict of a run from its (verdict, why) problems: the worst by precedence."""
    kinds = {k for k, _ in problems}
    for k in PRECEDENCE:
        if k in kinds:
            return k
    raise ValueError(f"no known verdict in {kinds}")


def counts(outcomes: list[Outcome]) -> dict[str, dict[str, int]]:
    """Per class: runs tried, cases, and the number of runs of each verdict."""
    table: dict[str, dict[str, int]] = {}
    cases: dict[str, set[str]] = {}
    for o in outcomes:
        row = table.setdefault(o.cls, {"tried": 0, "cases": 0, **dict.fromkeys(VERDICTS, 0)})
        row["tried"] += 1
        row[o.verdict] += 1
        cases.setdefault(o.cls, set()).add(o.case)
    for cls, names in cases.items():
        table[cls]["cases"] = len(names)
    total = {"tried": 0, "cases": 0, **dict.fromkeys(VERDICTS, 0)}
    for row in table.values():
        for k, v in row.items():
            total[k] += v
    ordered = {k: table[k] for k in CLASSES if k in table}
    ordered["all"] = total
    return ordered
