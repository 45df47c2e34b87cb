"""The corpus as a whole: every case in every form, judged, counted per class.

``python tests/hostile_classes_corpus.py OUT.json`` runs it (see that script for the options);
:func:`run` is what the tests call.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict
from pathlib import Path
from typing import Any

from hostile_classes import workspace
from hostile_classes.judge import judge_api, judge_cli
from hostile_classes.model import CLASSES, Case, Outcome, counts
from hostile_classes.server import ROOT, Server


@functools.cache
def all_cases() -> tuple[Case, ...]:
    """Every case of the corpus (names unique)."""
    from hostile_classes import (
        cases_api,
        cases_files,
        cases_more,
        cases_props,
        cases_units,
        special,
    )

    cases = [
        *special.determinism_cases(),
        *cases_files.class2(),
        *special.signal_cases(),
        *cases_files.class4(),
        *cases_units.cases(),
        *cases_files.class7(),
        *cases_more.cases(),
        *cases_api.cases(),
        *cases_props.cases(),
    ]
    names = [c.name for c in cases]
    dup = {n for n in names if names.count(n) > 1}
    assert not dup, f"case names repeated: {sorted(dup)}"
    for c in cases:
        assert c.cls in CLASSES, c.name
    return tuple(cases)


def case_index() -> dict[str, Case]:
    """Every case the server may be asked to run: the corpus and the control cases."""
    from hostile_classes import controls

    return {c.name: c for c in [*all_cases(), *controls.cases()]}


def _outcome(case: Case, d: dict[str, Any]) -> Outcome:
    return Outcome(
        case.name,
        case.cls,
        d.get("mode", "special"),
        d["verdict"],
        round(float(d.get("seconds", 0.0)), 3),
        d.get("code"),
        str(d.get("message", ""))[:400],
        list(d.get("problems", [])),
    )


def run_case(case: Case, index: int, workdir: Path, server: Server) -> list[Outcome]:
    """Every form of ``case``, each in a fresh folder, judged."""
    outcomes = []
    for mode in case.modes():
        root = workdir / f"{index:04d}-{mode}"
        if root.exists():
            shutil.rmtree(root)
        if mode == "special":
            root.mkdir(parents=True)
            assert case.special is not None
            outcomes += [_outcome(case, d) for d in case.special(root)]
            continue
        workspace.prepare(root, case.text, case.files)
        if case.setup is not None:
            case.setup(root)
        argv = None
        if mode != "api":
            assert case.argv is not None
            argv = [workspace.fill(a, root) for a in case.argv]
            if mode == "json":
                argv.append("--json")
        folders = workspace.out_folders(root, argv)
        before = workspace.snapshot(root, folders)
        io_dir = workdir / "io"
        io_dir.mkdir(exist_ok=True)
        req = {
            "case": case.name,
            "mode": mode,
            "root": str(root),
            "argv": argv,
            "stdout": str(io_dir / f"{index:04d}-{mode}.out"),
            "stderr": str(io_dir / f"{index:04d}-{mode}.err"),
            "timeout": case.timeout,
        }
        if case.fresh:  # global state of an earlier case (plug-ins loaded) must not leak in
            server.stop()
        raw = server.execute(req, case.timeout)
        touched = workspace.changes(before, workspace.snapshot(root, folders))
        out = _read(req["stdout"])
        err = _read(req["stderr"])
        if mode == "api":
            outcomes.append(judge_api(case, raw, out, err, touched, folders))
        else:
            assert argv is not None
            outcomes.append(judge_cli(case, mode, raw, argv, out, err, touched, folders, root))
        _unlock(root)
    return outcomes


def _read(path: str) -> bytes:
    try:
        return Path(path).read_bytes()
    except OSError:
        return b""


def _unlock(root: Path) -> None:
    # A case may leave a read-only folder behind: make it removable.
    for dirpath, dirnames, _ in os.walk(root):
        for d in dirnames:
            p = os.path.join(dirpath, d)
            if not os.path.islink(p):
                os.chmod(p, 0o755)


def run(
    cases: list[Case] | tuple[Case, ...],
    workdir: Path,
    fuzz_examples: int = 0,
    progress: bool = False,
) -> list[Outcome]:
    """Run ``cases`` (and ``fuzz_examples`` draws of the fuzz) in ``workdir``."""
    workdir.mkdir(parents=True, exist_ok=True)
    server = Server(workdir / "_server")
    outcomes: list[Outcome] = []
    try:
        for k, case in enumerate(cases):
            t0 = time.monotonic()
            got = run_case(case, k, workdir, server)
            outcomes += got
            if progress:
                verdicts = ", ".join(f"{o.mode}={o.verdict}" for o in got)
                print(
                    f"[{k + 1}/{len(cases)}] {case.name}: {verdicts} ({time.monotonic() - t0:.1f} s)",
                    file=sys.stderr,
                    flush=True,
                )
        if fuzz_examples:
            from hostile_classes.fuzz import run_fuzz

            outcomes += run_fuzz(server, workdir / "fuzz", fuzz_examples)
    finally:
        server.stop()
    return outcomes


def _commit() -> str:
    try:
        out = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
        )
        return out.stdout.strip()
    except OSError:
        return ""


#: Column headings of the counts (every verdict, zeros included).
HEADINGS = {
    "tried": "tried",
    "cases": "cases",
    "refused": "refused",
    "verified": "verified",
    "honoured": "honoured",
    "wrong_success": "wrong succ",
    "wrong_refusal": "wrong ref",
    "unclear_refusal": "unclear",
    "traceback": "traceback",
    "internal_error": "internal",
    "crash": "crash",
    "hang": "hang",
    "files_touched": "files out",
    "unsafe_terminal": "terminal",
    "unparseable_output": "output",
    "signal_not_honoured": "signal",
    "not_deterministic": "nondeterm",
}


def table(summary: dict[str, dict[str, int]], markdown: bool = False) -> str:
    """The counts, one row per class, every verdict a column (plain text or Markdown)."""
    cols = list(HEADINGS)
    if markdown:
        lines = ["| class | " + " | ".join(HEADINGS[c] for c in cols) + " |"]
        lines.append("|---|" + "---:|" * len(cols))
        for cls, row in summary.items():
            lines.append(f"| {cls} | " + " | ".join(str(row.get(c, 0)) for c in cols) + " |")
        return "\n".join(lines)
    lines = ["class " + " ".join(f"{HEADINGS[c]:>10s}" for c in cols)]
    for cls, row in summary.items():
        lines.append(f"{cls:5s} " + " ".join(f"{row.get(c, 0):10d}" for c in cols))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description="Run the second hostile corpus (issue 21).")
    p.add_argument(
        "out", type=Path, nargs="?", help="JSON file for the counts and every run's verdict"
    )
    p.add_argument("--classes", default="", help="comma list of classes (default: all)")
    p.add_argument("--fast", action="store_true", help="only the fast test's subset")
    p.add_argument("--match", default="", help="only cases whose name contains this")
    p.add_argument(
        "--fuzz",
        type=int,
        default=None,
        help="fuzz draws (default 200 for the whole corpus, else 0)",
    )
    p.add_argument("--workdir", type=Path, default=None, help="keep the case folders here")
    p.add_argument("--quiet", action="store_true", help="no line per case")
    p.add_argument(
        "--table", type=Path, default=None, help="print the counts of a saved OUT.json and stop"
    )
    args = p.parse_args(argv)
    if args.table is not None:
        print(table(json.loads(args.table.read_text())["counts"], markdown=True))
        return 0
    if args.out is None:
        p.error("give the OUT.json file to write")
    cases = list(all_cases())
    if args.classes:
        wanted = set(args.classes.split(","))
        cases = [c for c in cases if c.cls in wanted]
        if "fuzz" in wanted and args.fuzz is None:
            args.fuzz = 200
    if args.fast:
        cases = [c for c in cases if c.fast]
    if args.match:
        cases = [c for c in cases if args.match in c.name]
    if args.fuzz is None:
        args.fuzz = 0 if (args.fast or args.match or args.classes) else 200
    t0 = time.monotonic()
    tmp = None
    if args.workdir is None:
        tmp = tempfile.mkdtemp(prefix="hostile-classes-")
        workdir = Path(tmp)
    else:
        workdir = args.workdir
    try:
        outcomes = run(cases, workdir, args.fuzz, progress=not args.quiet)
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
    summary = counts(outcomes)
    doc = {
        "corpus": "tests/hostile_classes_corpus.py (issue 21)",
        "commit": _commit(),
        "date": time.strftime("%Y-%m-%d %H:%M:%S"),
        "seconds": round(time.monotonic() - t0, 1),
        "command": "python tests/hostile_classes_corpus.py "
        + " ".join(sys.argv[1:] if argv is None else argv),
        "classes": CLASSES,
        "counts": summary,
        "outcomes": [asdict(o) for o in outcomes],
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(doc, indent=1, default=str) + "\n")
    print(table(summary))
    print(f"{len(outcomes)} runs of {len(cases)} cases in {doc['seconds']} s; wrote {args.out}")
    return 0
