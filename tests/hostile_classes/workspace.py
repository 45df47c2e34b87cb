"""A case's folder, the snapshot of what lies outside its output folder, and the checks of
the output files and of the text printed to the terminal.

Layout of a case's folder ``root``::

    root/cwd/           the run's working directory
        problem.toml    the case's file (when it has one)
        sentinel.txt    a file nobody may touch
        link_file  ->   ../outside/target.txt   (a symbolic link pointing outside)
        link_dir   ->   ../outside
        optdesign-out/  the default output folder (the output folder when no --out)
    root/outside/       files the run must never touch: target.txt, victim.txt, keep/
    root/out/           the --out folder of the case (``@OUT@``)

Everything under ``root`` except the output folder is snapshotted before and after the
run (type, size, mtime, content digest, link target): a file created, deleted or changed
there is a file touched outside the output folder.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import re
import stat
from pathlib import Path
from typing import Any

SENTINEL = "do not touch: a file outside the output folder\n"


def paths(root: Path) -> dict[str, Path]:
    return {
        "@ROOT@": root,
        "@CWD@": root / "cwd",
        "@OUTSIDE@": root / "outside",
        "@OUT@": root / "out",
        "@FILE@": root / "cwd" / "problem.toml",
    }


def fill(text: str, root: Path) -> str:
    """``text`` with the placeholders of ``root`` filled in."""
    for key, value in paths(root).items():
        text = text.replace(key, str(value))
    return text


def prepare(root: Path, text: str | bytes | None, files: dict[str, str] | None = None) -> None:
    """Make the case's folder: sentinels, links pointing outside, the problem file, the
    case's own files (a user's modules) in the working directory."""
    cwd, outside = root / "cwd", root / "outside"
    (outside / "keep").mkdir(parents=True, exist_ok=True)
    cwd.mkdir(parents=True, exist_ok=True)
    for name in ("target.txt", "victim.txt", "keep/secret.txt"):
        (outside / name).write_text(SENTINEL)
    (cwd / "sentinel.txt").write_text(SENTINEL)
    os.symlink("../outside/target.txt", cwd / "link_file")
    os.symlink("../outside", cwd / "link_dir")
    if text is not None:
        data = fill(text, root).encode() if isinstance(text, str) else text
        (cwd / "problem.toml").write_bytes(data)
    for name, content in (files or {}).items():
        (cwd / name).write_text(content)


def out_folders(root: Path, argv: list[str] | None) -> list[Path]:
    """The output folders of a run: its ``--out`` (relative to the working directory), else
    the default one; an API run writes under ``root/out``."""
    if argv is None:
        return [root / "out"]
    found = []
    for k, a in enumerate(argv):
        if a == "--out" and k + 1 < len(argv):
            p = Path(argv[k + 1])
            found.append(p if p.is_absolute() else root / "cwd" / p)
    return found or [root / "cwd" / "optdesign-out"]


def snapshot(root: Path, exclude: list[Path]) -> dict[str, tuple]:
    """Every entry under ``root`` (links not followed), except the ``exclude`` folders."""
    skip = {os.path.normpath(str(p)) for p in exclude}
    out: dict[str, tuple] = {}
    for dirpath, dirnames, filenames in os.walk(root, followlinks=False):
        keep = []
        for d in dirnames:
            full = os.path.join(dirpath, d)
            if os.path.normpath(full) in skip:
                continue
            keep.append(d)
        dirnames[:] = keep
        for name in [*keep, *filenames]:
            full = os.path.join(dirpath, name)
            rel = os.path.relpath(full, root)
            try:
                st = os.lstat(full)
            except OSError:
                continue
            if stat.S_ISLNK(st.st_mode):
                out[rel] = ("link", os.readlink(full))
            elif stat.S_ISDIR(st.st_mode):
                out[rel] = ("dir",)
            elif stat.S_ISREG(st.st_mode):
                out[rel] = ("file", st.st_size, st.st_mtime_ns, _digest(full, st.st_size))
            else:
                out[rel] = ("special", stat.S_IFMT(st.st_mode))
    return out


def _digest(path: str, size: int) -> str:
    if size > 50_000_000:
        return "large"
    try:
        with open(path, "rb") as fh:
            return hashlib.sha1(fh.read()).hexdigest()
    except OSError:
        return "unreadable"


def changes(before: dict[str, tuple], after: dict[str, tuple]) -> list[str]:
    """What changed between two snapshots, one line each."""
    out = []
    for rel in sorted(set(before) | set(after)):
        a, b = before.get(rel), after.get(rel)
        if a == b:
            continue
        if a is None:
            out.append(f"created {rel}")
        elif b is None:
            out.append(f"deleted {rel}")
        else:
            out.append(f"modified {rel} ({a[0]} -> {b[0]})")
    return out


# --- the terminal --------------------------------------------------------------------------
_UNSAFE = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")


def terminal_problems(data: bytes, payload: str | None = None) -> list[str]:
    """Control characters printed raw (ESC, CR, NUL, C1, bidi overrides), and a hostile
    name printed as is when it holds a line break."""
    text = data.decode("utf-8", errors="replace")
    out = []
    m = _UNSAFE.search(text)
    if m is not None:
        start = max(0, m.start() - 30)
        out.append(f"raw control character {m.group()!r} in {text[start : m.end() + 30]!r}")
    if payload and any(c in payload for c in "\n\u2028\u2029") and payload in text:
        out.append(f"the name {payload[:40]!r} printed with its line breaks")
    return out


# --- output files --------------------------------------------------------------------------
def _strict_json(text: str) -> Any:
    def no_constant(name: str) -> Any:
        raise ValueError(f"non-standard JSON constant {name}")

    return json.loads(text, parse_constant=no_constant)


_FORMULA = ("=", "+", "-", "@", "\t", "\r")


def _number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def check_csv(text: str) -> list[str]:
    """front.csv: read by the csv module, one header, rows as long as it, no cell that a
    spreadsheet would take for a formula."""
    out = []
    try:
        rows = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as exc:
        return [f"front.csv is not CSV: {exc}"]
    if not rows:
        return ["front.csv is empty"]
    header = rows[0]
    if len(set(header)) != len(header) or any(not h for h in header):
        out.append(f"front.csv header has empty or repeated fields: {header[:8]}")
    for k, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            out.append(f"front.csv row {k} has {len(row)} cells, the header {len(header)}")
            break
    for k, row in enumerate(rows, start=1):
        for cell in row:
            if cell.startswith(_FORMULA) and not _number(cell):
                out.append(f"front.csv row {k}: cell {cell[:30]!r} starts a formula")
                return out
    return out


_DATA = re.compile(
    r'<script type="application/json" id="report-data">(.*?)</script', re.DOTALL | re.IGNORECASE
)
#: The page's escape of text into HTML: a function ``esc`` or an arrow function with its
#: table of replacements on the line before (``const ESC = {...}; const esc = (s) =>``).
_ESC_FUNCTION = re.compile(
    r"(?:function esc\((\w+)\)\s*\{(.*?)\n|const ESC = (\{.*?\});\s*\n\s*const esc = )",
    re.DOTALL,
)


def check_report(text: str, quote: bool = False) -> list[str]:
    """report.html: the embedded JSON parses and cannot end its element early (no ``<!--``,
    ``<script``, U+2028/9 inside); with ``quote``, the page's own escaping of text that
    its script writes into attributes covers ``"``."""
    m = _DATA.search(text)
    if m is None:
        return ["report.html has no embedded data element"]
    body = m.group(1)
    out = []
    try:
        _strict_json(body)
    except ValueError as exc:
        out.append(f"report.html's embedded JSON does not parse: {exc}")
    for bad in ("<!--", "<script", "\u2028", "\u2029"):
        if bad in body.lower():
            out.append(f"report.html's embedded JSON holds {bad!r} raw")
    if quote:
        esc = _ESC_FUNCTION.search(text)
        body_ = (esc and (esc.group(2) or esc.group(3))) or ""
        if not any(q in body_ for q in ("&quot;", "&#34;", "&#x22;")):
            out.append('report.html escapes no " in text its script writes into attributes')
    return out


def check_outputs(folders: list[Path], quote: bool = False) -> list[str]:
    """Every result file under the output folders parses."""
    out: list[str] = []
    for folder in folders:
        if not folder.is_dir() or folder.is_symlink():
            continue
        for path in sorted(folder.rglob("*")):
            if path.is_symlink() or not path.is_file():
                continue
            name = path.name
            try:
                if name in ("result.json", "front.json"):
                    _strict_json(path.read_text(encoding="utf-8"))
                elif name == "front.csv":
                    out += check_csv(path.read_text(encoding="utf-8"))
                elif name == "report.html":
                    out += check_report(path.read_text(encoding="utf-8"), quote)
                elif name.endswith(".png") and not name.startswith("."):
                    if path.read_bytes()[:8] != b"\x89PNG\r\n\x1a\n":
                        out.append(f"{name} is not a PNG")
            except (ValueError, UnicodeDecodeError) as exc:
                out.append(f"{path.relative_to(folder)} does not parse: {exc}")
    return out


def find(folders: list[Path], name: str) -> list[Path]:
    """Files called ``name`` under the output folders."""
    found: list[Path] = []
    for folder in folders:
        if folder.is_dir():
            found += sorted(p for p in folder.rglob(name) if p.is_file() and not p.is_symlink())
    return found


def read_json(path: Path) -> Any:
    return _strict_json(path.read_text(encoding="utf-8"))
