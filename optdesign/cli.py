"""Command line: ``optdesign reproduce|solve|pareto|bench ...``.

Errors that a user can act on (:class:`optdesign.errors.OptDesignError`) are printed as
one line naming the field, with exit code 2 and no traceback; a message that echoes an
input is shown :func:`~optdesign.text.printable` (its control characters and newlines
escaped), so it stays one line and never reaches the terminal raw. SIGINT (Ctrl-C),
SIGTERM and SIGHUP end a run cleanly - workers stopped, finished records saved - with one
line and exit code 130, 143 or 129 (128 + the signal number, as a shell reports a killed
command), within a second, solver calls included (:mod:`optdesign.interrupts`).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from optdesign import interrupts, validation
from optdesign.errors import InfeasibleRequirementsError, InputError, OptDesignError
from optdesign.interrupts import (
    Interrupted,
    exit_code,
    forget_store,
    interrupts_as_exceptions,
    saved_store,
)
from optdesign.text import printable

__all__ = [
    "COMMANDS",
    "Interrupted",
    "as_options",
    "build_parser",
    "checked",
    "command",
    "main",
    "run_guarded",
]

#: subcommand name -> function(subparsers) that registers it. Add one line per command.
COMMANDS: dict[str, Callable[[argparse._SubParsersAction], None]] = {}


def command(name: str):
    """Decorator registering a subcommand builder."""

    def deco(fn):
        COMMANDS[name] = fn
        return fn

    return deco


def default_out(prefix: str) -> Path:
    """A new output folder under the working directory, e.g. ``optdesign-out/duan2017-...``.

    ``prefix`` may hold a problem's name, which comes from a file: it is reduced to a
    safe slug (:func:`optdesign.safe_io.slug`: no ``/``, no ``..``, no leading dot, no
    control character, at most 60 characters), so the folder is always a new child of
    ``./optdesign-out``.
    """
    from optdesign.safe_io import slug

    stamp = time.strftime("%Y%m%d-%H%M%S")
    root = Path.cwd() / "optdesign-out"
    # The parent is the program's choice, not the user's: a link planted there (or a file)
    # would send the outputs elsewhere, so it must be a real folder or not exist yet.
    if os.path.islink(root) or (os.path.lexists(root) and not root.is_dir()):
        what = "a link" if os.path.islink(root) else "not a folder"
        raise InputError(
            "--out",
            f"the default output folder's parent {root} is {what}: give --out, or remove it",
        )
    base = root / f"{slug(prefix)}-{stamp}"
    path, k = base, 1
    while os.path.lexists(path):
        k += 1
        path = root / f"{base.name}-{k}"
    return path


@contextlib.contextmanager
def output_folder(out: Path | None, prefix: str):
    """``out``, or a new default folder (:func:`default_out`) that is removed again if the
    command leaves nothing in it but its lock: a run refused or stopped before it wrote a
    file leaves no empty folder behind. A folder the user named is never removed."""
    if out is not None:
        yield out
        return
    path = default_out(prefix)
    try:
        yield path
    finally:
        from optdesign.storage import LOCK_NAME

        with contextlib.suppress(OSError):
            if {e.name for e in os.scandir(path)} <= {LOCK_NAME}:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(path / LOCK_NAME)
                os.rmdir(path)
                os.rmdir(path.parent)  # optdesign-out itself, when nothing else is in it


@command("reproduce")
def _reproduce(sub):
    from optdesign.reproduce import REPRODUCTIONS

    p = sub.add_parser("reproduce", help="recompute a source paper's numbers and plots")
    p.add_argument("paper", choices=sorted(REPRODUCTIONS))
    p.add_argument(
        "--out",
        type=checked(validation.out_path),
        default=None,
        help="output folder (default: new one)",
    )

    def run(args):
        from optdesign import storage
        from optdesign.reproduce import run as run_reproduction

        out = args.out or default_out(args.paper)
        storage.ensure_writable(out)  # an --out that is a file: one line, before any work
        return run_reproduction(args.paper, out)

    p.set_defaults(func=run)


def _load_plugins() -> None:
    # Subcommands living in other modules register themselves on import.
    import importlib

    for module in PLUGIN_MODULES:
        importlib.import_module(module)


#: Modules that register further subcommands with @command (solve, pareto, bench ...).
PLUGIN_MODULES: list[str] = [
    "optdesign.commands.solve",
    "optdesign.commands.pareto",
    "optdesign.commands.sweep",
    "optdesign.commands.bench",
    "optdesign.commands.simulate",
]


def literal(text: str) -> int | float | str:
    """A command-line word as the value a Python caller would pass: an int, else a float,
    else the text itself (the checks of :mod:`optdesign.validation` then say what is
    wrong with it, as they do for the API). A word with digits of another script stays
    text: ``int`` would read ``"\u0663"`` (ARABIC-INDIC DIGIT THREE) as 3, unseen."""
    if any(ch.isdecimal() and not ch.isascii() for ch in text):
        return text
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def checked(check: Callable[[str, Any], Any], parse: Callable[[str], Any] = str):
    """An argparse type from a check of :mod:`optdesign.validation`: ``parse`` the word,
    then ``check(argument, value)``; a refusal becomes argparse's error with the check's
    own reason (``argument --starts: 0 is outside 1..10000``)."""

    def convert(text: str) -> Any:
        try:
            return check("value", parse(text))
        except InputError as exc:
            raise argparse.ArgumentTypeError(exc.reason) from None

    return convert


def time_limit_option(parser: argparse.ArgumentParser, help: str, default: float | None = None):
    """The ``--time-limit`` option of a command: seconds, checked as the API checks its
    ``time_limit``."""
    parser.add_argument(
        "--time-limit", type=checked(validation.seconds, literal), default=default, help=help
    )


def progress_bar(args: argparse.Namespace) -> bool:
    """Whether a command draws a progress bar: not refused (``--no-progress``) and
    standard error is a terminal. Elsewhere tqdm would draw nothing (a log fills with
    no redraws), and importing it (asyncio with it, ~30 ms) is spared."""
    return not args.no_progress and sys.stderr.isatty()


def option(argument: str, renamed: Mapping[str, str] | None = None) -> str:
    """The command-line option of an API argument: ``--time-limit`` for ``time_limit``
    (``renamed`` for options spelt otherwise, e.g. ``{"pop_size": "--pop"}``)."""
    if renamed and argument in renamed:
        return renamed[argument]
    return "--" + argument.replace("_", "-")


#: The API's arguments that the library's own messages name (``more starts (starts=)``,
#: ``formulation='nlp'``, ``resume=True``): the command line shows them as its options.
MENTIONED_ARGUMENTS = ("starts", "formulation", "resume", "overwrite")

_MENTION = re.compile(
    r"\b(" + "|".join(MENTIONED_ARGUMENTS) + r")=(True\b|'([^'\s]*)'|(?=[\s),;]|$))"
)


def flags(text: str) -> str:
    """A library message in the command line's words: each mention of an API argument
    (``starts=``, ``formulation='catalogue'``, ``resume=True``) shown as its option
    (``--starts``, ``--formulation catalogue``, ``--resume``)."""

    def shown(match: re.Match) -> str:
        flag = option(match[1])
        return f"{flag} {match[3]}" if match[3] is not None else flag

    return _MENTION.sub(shown, text)


@contextlib.contextmanager
def as_options(renamed: Mapping[str, str] | None = None):
    """Refusals of the shared checks (:class:`~optdesign.validation.ArgumentError`)
    raised inside name the command-line options instead of the API's arguments."""
    try:
        yield
    except validation.ArgumentError as exc:

        def name(a: str) -> str:
            return option(a, renamed)

        raise InputError(name(exc.argument), exc.render(name)) from None


#: Caps of the command-line sizes, the API's (optdesign.validation).
MAX_WORKERS = validation.MAX_WORKERS
MAX_STARTS = validation.MAX_STARTS
MAX_POINTS = validation.MAX_POINTS
MAX_SEED = validation.MAX_SEED


def _version() -> str:
    from optdesign import __version__

    return __version__


class _Parser(argparse.ArgumentParser):
    """argparse's parser, whose refusals (which echo the words given, e.g. unrecognized
    arguments) are shown :func:`~optdesign.text.printable`, on one line."""

    def error(self, message: str):
        super().error(printable(message))


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every registered subcommand (they share its class)."""
    _load_plugins()
    parser = _Parser(
        prog="optdesign",
        description="Design optimisation of ball-screw actuator transmissions.",
    )
    parser.add_argument("--version", action="version", version=f"optdesign {_version()}")
    sub = parser.add_subparsers(dest="command", required=True)
    for builder in COMMANDS.values():
        builder(sub)
    return parser


@contextlib.contextmanager
def stdout_to_stderr():
    """Send everything printed while it is open - a solver's log, from this process or
    from its workers - to stderr, so that stdout carries only a command's own output
    (``solve --json``). Restores stdout on exit."""
    saved_fd = None
    try:
        fd, err_fd = sys.stdout.fileno(), sys.stderr.fileno()
    except (AttributeError, OSError, ValueError):  # a StringIO (tests): Python level only
        fd = err_fd = None
    if fd is not None and err_fd is not None and fd != err_fd:
        sys.stdout.flush()
        saved_fd = os.dup(fd)
        os.dup2(err_fd, fd)  # C libraries and child processes write to fd 1
    try:
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        if saved_fd is not None:
            sys.stderr.flush()
            os.dup2(saved_fd, fd)
            os.close(saved_fd)


def run_guarded(func: Callable[[], int | None]) -> int:
    """Run ``func`` as a command: user errors and interrupts become one line and an exit code.

    Returns
    -------
    int
        ``func``'s code (0 for None); 1 for an :class:`InfeasibleRequirementsError` (no
        feasible design, the requirements named); 2 for an :class:`OptDesignError` or an
        I/O error (disk full, no permission); 128 + signal number for SIGINT (130),
        SIGTERM (143) and SIGHUP (129); 1 for any other exception (one line;
        ``OPTDESIGN_DEBUG=1`` re-raises it).
    """
    forget_store()
    try:
        with interrupts_as_exceptions():
            code = func()
    except InfeasibleRequirementsError as exc:  # no feasible design: a result, exit 1
        print(f"optdesign: infeasible: {printable(flags(str(exc)))}", file=sys.stderr)
        return 1
    except OptDesignError as exc:
        if os.environ.get("OPTDESIGN_DEBUG") and exc.__cause__ is not None:
            # e.g. a user's function that raised: its own traceback, down to its file
            # and line, before the one line
            import traceback

            traceback.print_exception(exc, file=sys.stderr)
        print(f"optdesign: error: {printable(flags(str(exc)))}", file=sys.stderr)
        return 2
    except OSError as exc:  # e.g. no space left while writing the results
        print(f"optdesign: error: {printable(exc)}", file=sys.stderr)
        return 2
    except Exception as exc:
        # Last resort: a bug (or an input no check foresaw) is one line, not a traceback;
        # OPTDESIGN_DEBUG=1 shows the traceback for a report.
        if os.environ.get("OPTDESIGN_DEBUG"):
            raise
        text = printable(" ".join(str(exc).split())[:300])
        print(
            f"optdesign: internal error: {type(exc).__name__}: {text} "
            "(set OPTDESIGN_DEBUG=1 for the traceback, and please report it)",
            file=sys.stderr,
        )
        return 1
    except KeyboardInterrupt as exc:
        _, code = exit_code(exc)
        line = interrupts.message(code - 128, saved_store(exc), resume=option("resume"))
        with interrupts.exit_lock():  # not interleaved with the watchdog's line
            print(line, file=sys.stderr)
        return code
    return int(code or 0)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``optdesign`` console script."""
    # The command line writes figures to files: the Agg back-end, chosen here for this
    # process only (the library itself never changes the user's back-end).
    os.environ.setdefault("MPLBACKEND", "Agg")

    def run() -> int | None:
        parser = build_parser()
        args = parser.parse_args(argv)
        return args.func(args)

    if argv is None:  # the program itself, not a call from Python
        from optdesign.pipes import QuietPipe

        sys.stdout = QuietPipe(sys.stdout)  # `optdesign ... | head -1` ends quietly
        _late_signals_exit()
        interrupts.start_watchdog(_finish_interrupted)
    code = run_guarded(run)
    if argv is None:
        _exit_now(code)
    return code


def _exit_now(code: int) -> None:
    """End the program without the interpreter's shutdown.

    Every output is written (atomically) and every worker stopped by now; the shutdown
    that follows would only free memory (a second or more with the solvers loaded), and
    during it Python has put the default signal handlers back, so a Ctrl-C there would
    kill the program silently with the signal instead of exit 130 and the one line."""
    import logging

    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    with contextlib.suppress(Exception):
        logging.shutdown()
    os._exit(code)


def _finish_interrupted(signum: int) -> None:
    """End the program at once with the one line and 128 + ``signum``: the main thread
    cannot unwind (a signal before or after the command, or one that finds it stuck in
    native solver code - see :func:`optdesign.interrupts.start_watchdog`). Every output
    is complete (written atomically, or not yet begun) and no record half-written."""
    line = interrupts.message(signum, saved_store(None), resume=option("resume")) + "\n"
    # Flushed from a helper thread: the main thread may hold a stream's lock (stuck in
    # native code that prints); what it had buffered is not worth a hang.
    flusher = threading.Thread(target=_flush_streams, daemon=True)
    flusher.start()
    flusher.join(0.1)
    with contextlib.suppress(OSError):
        os.write(2, line.encode(errors="replace"))
    os._exit(128 + int(signum))


def _flush_streams() -> None:
    for stream in (sys.__stdout__, sys.__stderr__):
        with contextlib.suppress(Exception):
            stream.flush()


def _late_signals_exit() -> None:
    """SIGINT / SIGTERM / SIGHUP outside the command (before it starts, or after it while
    the program ends): the same one line and exit code 130 / 143 / 129 as during the run,
    not a traceback or a silent death by the signal. Every output is complete by then
    (written atomically), so exiting at once is safe. run_guarded puts these handlers
    back when the command ends."""

    def handler(signum: int, frame: object) -> None:
        with interrupts.exit_lock():
            _finish_interrupted(signum)

    with contextlib.suppress(ValueError):  # not the main thread
        for s in interrupts.SIGNALS:
            signal.signal(s, handler)


if __name__ == "__main__":
    sys.exit(main())
