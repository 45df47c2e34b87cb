"""What the case modules share: the shipped problems as text, edits of them, the usual
command lines and API forms."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from hostile_classes.model import Case, Expect

ROOT = Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "problems"
DATA = Path(__file__).resolve().parent / "data"

#: A solve that gets past the checks is cheap: one start, no ranges. Without --out the
#: default mode writes into the default output folder (./optdesign-out), --json nothing.
SOLVE = ["solve", "@FILE@", "--starts", "1", "--no-ranges"]
#: The same, writing result.json, solution.png and report.html into the case's folder.
SOLVE_OUT = [*SOLVE, "--out", "@OUT@"]


def base(name: str) -> str:
    """A shipped problem file (or one of tests/hostile_classes/data) as text."""
    path = PROBLEMS / f"{name}.toml"
    if not path.exists():
        path = DATA / f"{name}.toml"
    return path.read_text()


def sub(text: str, old: str, new: str) -> str:
    """``text`` with the first ``old`` replaced (which must be there)."""
    assert old in text, old
    return text.replace(old, new, 1)


def add(text: str, section: str, line: str) -> str:
    """``line`` added at the top of ``[section]`` (the section is created if missing)."""
    head = f"[{section}]\n"
    if head in text:
        return text.replace(head, head + line + "\n", 1)
    return text + f"\n{head}{line}\n"


def drop(text: str, line_start: str) -> str:
    """``text`` without the line that starts with ``line_start``."""
    lines = text.splitlines(keepends=True)
    hits = [ln for ln in lines if ln.startswith(line_start)]
    assert len(hits) == 1, (line_start, len(hits))
    return "".join(ln for ln in lines if not ln.startswith(line_start))


def toml_str(s: str) -> str:
    """A TOML basic string holding ``s``: JSON's escapes are TOML's, and DEL and the C1
    controls, which JSON leaves raw and TOML refuses raw, escaped too."""
    text = json.dumps(s, ensure_ascii=False)
    return "".join(f"\\u{ord(c):04x}" if 0x7F <= ord(c) <= 0x9F else c for c in text)


def solving(**kw: Any):
    """An API form: the case's file as a dict through od.load, then od.solve(**kw) (no
    ranges unless asked)."""
    kw.setdefault("ranges", False)

    def api(ctx: Any) -> Any:
        import optdesign as od

        return od.solve(od.load(ctx.data()), **kw)

    return api


def api_solve(ctx: Any) -> Any:
    return solving(starts=1)(ctx)


def api_load(ctx: Any) -> Any:
    import optdesign as od

    return od.load(ctx.data())


def file_case(
    cls: str,
    what: str,
    text: str,
    expect: Expect,
    argv: list[str] | None = None,
    api: Any = api_solve,
    **kw: Any,
) -> Case:
    """A problem-file case: the CLI form (``solve`` by default, with and without --json)
    and the API form (the file as a dict through od.load and od.solve)."""
    return Case(f"{cls}:{what}", cls, expect, argv=list(argv or SOLVE), text=text, api=api, **kw)


def value_check(path: str, expected: float, rel: float = 1e-6):
    """A check of a loaded problem: the spec value at ``path`` (dots) is ``expected``
    (internal units)."""

    def check(value: Any, ctx: Any) -> list[str]:
        spec = value.spec if hasattr(value, "spec") else value.problem_object.spec
        obj: Any = spec
        for part in path.split("."):
            obj = obj[int(part)] if part.isdigit() else getattr(obj, part)
        got = float(obj)
        if abs(got - expected) <= rel * max(1.0, abs(expected)):
            return []
        return [f"{path} = {got!r}, expected {expected!r}"]

    return check
