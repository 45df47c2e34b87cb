"""One verdict per run: how a CLI or API run ended against what its case expects, plus
what is wrong whatever it expects (a crash, a hang, a file touched outside the output
folder, a traceback, an internal error, raw control characters, a broken output file)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from hostile_classes import verify, workspace
from hostile_classes.model import Case, Outcome, worst

Problems = list[tuple[str, str]]


def _names(expect_names: tuple[str, ...], text: str) -> bool:
    low = text.lower()
    return not expect_names or any(n.lower() in low for n in expect_names)


def _always(
    raw: dict[str, Any], out: bytes, err: bytes, touched: list[str], case: Case
) -> Problems:
    problems: Problems = []
    if "crash" in raw:
        problems.append(("crash", f"the process died (status {raw['crash']})"))
    if raw.get("hang"):
        problems.append(("hang", f"still running after {case.timeout:g} s"))
    if touched:
        problems.append(("files_touched", "; ".join(touched[:6])))
    text = (out + err).decode("utf-8", errors="replace")
    if "Traceback (most recent call last)" in text:
        problems.append(("traceback", _tail(err)))
    if "internal error" in err.decode("utf-8", errors="replace"):
        problems.append(("internal_error", _tail(err)))
    for why in workspace.terminal_problems(out + err, case.payload):
        problems.append(("unsafe_terminal", why))
    return problems


def _tail(data: bytes, n: int = 400) -> str:
    lines = [ln for ln in data.decode("utf-8", errors="replace").splitlines() if ln.strip()]
    return (lines[-1] if lines else "")[:n]


def _message(out: bytes, err: bytes) -> str:
    """The run's last word: stderr's last line, or the JSON result's status and what it
    names, or stdout's last line."""
    last = _tail(err)
    if last:
        return last
    try:
        doc = json.loads(out.decode("utf-8"))
    except ValueError:
        return _tail(out)
    if isinstance(doc, dict):
        names = [v.get("name", "") for v in doc.get("violated", []) if isinstance(v, dict)]
        return f"status {doc.get('status')}; violated {', '.join(names[:6])}"[:400]
    return _tail(out)


def _verify_cli_success(argv: list[str], out: bytes, folders: list[Path]) -> list[str]:
    command = argv[0] if argv else ""
    if command == "solve":
        if "--json" in argv:
            try:
                doc = json.loads(out.decode("utf-8"))
            except ValueError as exc:
                return [f"stdout is not the result JSON: {exc}"]
            return verify.doc_problems(doc)
        found = workspace.find(folders, "result.json")
        if not found:
            return ["no result.json written"]
        return verify.doc_problems(workspace.read_json(found[-1]))
    if command == "pareto":
        found = workspace.find(folders, "front.csv")
        if not found:
            return ["no front.csv written"]
        return verify.front_csv_problems(found[-1].read_text(encoding="utf-8"))
    if command == "bench":
        return [] if workspace.find(folders, "summary.md") else ["no summary.md written"]
    return []


def judge_cli(
    case: Case,
    mode: str,
    raw: dict[str, Any],
    argv: list[str],
    out: bytes,
    err: bytes,
    touched: list[str],
    folders: list[Path],
    root: Path,
) -> Outcome:
    problems = _always(raw, out, err, touched, case)
    for why in workspace.check_outputs(folders, case.quote_check):
        problems.append(("unparseable_output", why))
    code = raw.get("code")
    text = (out + err).decode("utf-8", errors="replace")
    exp = case.expect
    end = ""
    if "crash" in raw or raw.get("hang"):
        pass
    elif code == "exception":
        problems.append(("traceback", _tail(err)))
    elif code == 0:
        if exp.kind in ("refuse", "infeasible"):
            problems.append(("wrong_success", "exit 0"))
        else:
            for why in _verify_cli_success(argv, out, folders):
                problems.append(("wrong_success", why))
            end = "verified"
    elif code in (1, 2):
        last = _message(out, err)
        if exp.kind == "success":
            problems.append(("wrong_refusal", f"exit {code}: {last}"))
        elif exp.kind in ("refuse", "either") and code != 2:
            problems.append(("unclear_refusal", f"exit {code}, expected 2: {last}"))
        elif not _names(exp.names, text):
            problems.append(("unclear_refusal", f"names none of {exp.names}: {last}"))
        elif code == 2 and argv and argv[0] in ("solve", "pareto", "bench"):
            lines = [
                ln
                for ln in err.decode(errors="replace").splitlines()
                if ln.startswith("optdesign:")
            ]
            if len(lines) != 1 and not any(
                ln.startswith("usage:") for ln in err.decode(errors="replace").splitlines()
            ):
                problems.append(("unclear_refusal", f"{len(lines)} message lines, expected one"))
        end = "refused"
    else:
        problems.append(("unclear_refusal", f"exit {code!r}: {_tail(err)}"))
    if not end and not problems:
        problems.append(("crash", "the run gave no answer"))
    if case.cli_check is not None and not problems:
        for why in case.cli_check(root, out.decode(errors="replace"), err.decode(errors="replace")):
            problems.append(("wrong_success" if code == 0 else "unclear_refusal", why))
    verdict = worst(problems) if problems else end
    message = _message(out, err)
    return Outcome(
        case.name,
        case.cls,
        mode,
        verdict,
        round(float(raw.get("seconds", 0.0)), 3),
        code if "crash" not in raw else f"crash {raw['crash']}",
        message,
        [f"{k}: {w}" for k, w in problems],
    )


def judge_api(
    case: Case, raw: dict[str, Any], out: bytes, err: bytes, touched: list[str], folders: list[Path]
) -> Outcome:
    problems = _always(raw, out, err, touched, case)
    for why in workspace.check_outputs(folders, case.quote_check):
        problems.append(("unparseable_output", why))
    exp = case.expect
    end = ""
    message = ""
    kind = raw.get("api")
    if kind == "raised":
        message = f"{raw['type']}: {raw['message']}"
        if not raw["optdesign"]:
            problems.append(("internal_error", message[:500]))
        elif exp.kind == "success":
            problems.append(("wrong_refusal", message[:500]))
        elif not _names(exp.names, raw["message"]):
            problems.append(("unclear_refusal", f"names none of {exp.names}: {message[:400]}"))
        end = "refused"
    elif kind == "returned":
        if raw["failed"]:
            message = raw["text"][:500]
            if exp.kind == "success":
                problems.append(("wrong_refusal", f"a failed {raw['kind']}: {message}"))
            elif not _names(exp.names, raw["text"]):
                problems.append(
                    (
                        "unclear_refusal",
                        f"a failed {raw['kind']} naming none of {exp.names}: {message}",
                    )
                )
            end = "refused"
        else:
            message = f"returned a {raw['kind']}"
            if exp.kind in ("refuse", "infeasible"):
                problems.append(("wrong_success", f"returned a {raw['kind']} instead of refusing"))
            for why in raw["problems"]:
                problems.append(("wrong_success", why))
            end = "verified"
    if not end and not problems:
        problems.append(("crash", "the run gave no answer"))
    verdict = worst(problems) if problems else end
    return Outcome(
        case.name,
        case.cls,
        "api",
        verdict,
        round(float(raw.get("seconds", 0.0)), 3),
        kind,
        message[:400],
        [f"{k}: {w}" for k, w in problems],
    )
