"""Command line: ``optdesign reproduce|solve|pareto|bench ...``.

Errors that a user can act on (:class:`optdesign.errors.OptDesignError`) are printed as
one line naming the field, with exit code 2 and no traceback. SIGINT (Ctrl-C) and
SIGTERM end a run cleanly - workers stopped, finished records saved - with one line and
exit code 130 or 143 (128 + the signal number, as a shell reports a killed command).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import signal
import sys
import time
from collections.abc import Callable
from pathlib import Path

from optdesign.errors import InfeasibleRequirementsError, OptDesignError
from optdesign.interrupts import (
    Interrupted,
    exit_code,
    forget_store,
    interrupts_as_exceptions,
    saved_store,
)

__all__ = ["COMMANDS", "Interrupted", "build_parser", "command", "main", "run_guarded"]

#: subcommand name -> function(subparsers) that registers it. Add one line per command.
COMMANDS: dict[str, Callable[[argparse._SubParsersAction], None]] = {}


def command(name: str):
    """Decorator registering a subcommand builder."""

    def deco(fn):
        COMMANDS[name] = fn
        return fn

    return deco


def default_out(prefix: str) -> Path:
    """A new output folder under the working directory, e.g. ``optdesign-out/duan2017-...``."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    base = Path.cwd() / "optdesign-out" / f"{prefix}-{stamp}"
    path, k = base, 1
    while path.exists():
        k += 1
        path = base.with_name(f"{base.name}-{k}")
    return path


@command("reproduce")
def _reproduce(sub):
    from optdesign.reproduce import REPRODUCTIONS

    p = sub.add_parser("reproduce", help="recompute a source paper's numbers and plots")
    p.add_argument("paper", choices=sorted(REPRODUCTIONS))
    p.add_argument("--out", type=Path, default=None, help="output folder (default: new one)")

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
    "optdesign.commands.bench",
]


def bounded_int(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse type: an integer from ``lo`` to ``hi`` (sizes are capped, so that a
    typo cannot start unbounded work)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"{value} is outside {lo}..{hi}")
        return value

    return parse


def bounded_float(lo: float, hi: float) -> Callable[[str], float]:
    """An argparse type: a finite number with ``lo < value <= hi``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        if not lo < value <= hi:  # also refuses nan
            raise argparse.ArgumentTypeError(f"{text} is outside ({lo:g}, {hi:g}]")
        return value

    return parse


#: Caps of the command-line sizes (a front of 10^7 points is a typo, not a study).
MAX_WORKERS = 256
MAX_STARTS = 10_000
MAX_POINTS = 10_000
MAX_SEED = 2**32 - 1


def _version() -> str:
    from optdesign import __version__

    return __version__


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every registered subcommand."""
    _load_plugins()
    parser = argparse.ArgumentParser(
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
        feasible design, the requirements named); 2 for an :class:`OptDesignError` or an I/O error
        (disk full, no permission); 128 + signal number for SIGINT (130) / SIGTERM (143);
        1 for any other exception (one line; ``OPTDESIGN_DEBUG=1`` re-raises it).
    """
    forget_store()
    try:
        with interrupts_as_exceptions():
            code = func()
    except InfeasibleRequirementsError as exc:  # no feasible design: a result, exit 1
        print(f"optdesign: infeasible: {exc}", file=sys.stderr)
        return 1
    except OptDesignError as exc:
        print(f"optdesign: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # e.g. no space left while writing the results
        print(f"optdesign: error: {exc}", file=sys.stderr)
        return 2
    except Exception as exc:
        # Last resort: a bug (or an input no check foresaw) is one line, not a traceback;
        # OPTDESIGN_DEBUG=1 shows the traceback for a report.
        if os.environ.get("OPTDESIGN_DEBUG"):
            raise
        text = " ".join(str(exc).split())[:300]
        print(
            f"optdesign: internal error: {type(exc).__name__}: {text} "
            "(set OPTDESIGN_DEBUG=1 for the traceback, and please report it)",
            file=sys.stderr,
        )
        return 1
    except KeyboardInterrupt as exc:
        name, code = exit_code(exc)
        store = saved_store(exc)
        if store:
            n = store["records"]
            print(
                f"optdesign: interrupted ({name}); {n} record{'' if n == 1 else 's'} saved "
                f"in {store['path']}, --resume continues",
                file=sys.stderr,
            )
        else:
            print(f"optdesign: interrupted ({name})", file=sys.stderr)
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
        _late_signals_exit()
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


def _late_signals_exit() -> None:
    """SIGINT / SIGTERM outside the command (before it starts, or after it while the
    program ends): the same one line and exit code 130 / 143 as during the run, not a
    traceback or a silent death by the signal. Every output is complete by then (written
    atomically), so exiting at once is safe. run_guarded puts these handlers back when
    the command ends."""

    def handler(signum: int, frame: object) -> None:
        name, code = exit_code(Interrupted(signum))
        store = saved_store(Interrupted(signum))
        with contextlib.suppress(Exception):
            sys.stdout.flush()
        line = f"optdesign: interrupted ({name})"
        if store:
            n = store["records"]
            line += (
                f"; {n} record{'' if n == 1 else 's'} saved in {store['path']}, --resume continues"
            )
        with contextlib.suppress(Exception):
            print(line, file=sys.stderr, flush=True)
        os._exit(code)

    with contextlib.suppress(ValueError):  # not the main thread
        signal.signal(signal.SIGINT, handler)
        signal.signal(signal.SIGTERM, handler)


if __name__ == "__main__":
    sys.exit(main())
