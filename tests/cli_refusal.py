"""What the command line prints when it refuses a problem file: shared by the tests of
the problem's sections (text and ``--json`` output modes alike)."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

from optdesign.cli import main


def command_line_refusal(
    data: dict, folder: Path, json_mode: bool, command: list[str] | None = None
) -> str:
    """Write ``data`` as a problem file in ``folder``, run ``optdesign solve`` on it (or
    ``command``: the subcommand and its options; with ``--json`` when ``json_mode``),
    check that it exits 2 printing nothing on stdout, and return the message (the
    ``error`` of a JSON answer)."""
    from hostile_corpus import dumps

    path = folder / "p.toml"
    path.write_text(dumps(data))
    name, *options = command or ["solve", "--no-report"]
    argv = [name, str(path), "--out", str(folder / "out"), *options]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([*argv, "--json"] if json_mode else argv)
    assert code == 2 and out.getvalue() == ""
    message = err.getvalue()
    if json_mode and message.lstrip().startswith("{"):
        message = json.loads(message)["error"]
    return message
