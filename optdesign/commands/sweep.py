"""``optdesign sweep FILE --vary PATH=START..STOP UNIT:COUNT [--vary ...] [--with
PATH=SWEPT ...]``: how the optimum moves when one or two parameters change
(:func:`optdesign.sweep`); ``--with`` moves another parameter with a swept one.

Writes ``sweep.csv`` (units in the headers), ``sweep.json``, the design chart
``sweep.png`` and the JSONL store ``sweep.jsonl`` (the points as they finish;
``--resume`` continues from them) to the output folder.
"""

from __future__ import annotations

import contextlib
import re
from pathlib import Path

from optdesign import validation as check
from optdesign.cli import (
    as_options,
    checked,
    command,
    flags,
    literal,
    output_folder,
    progress_bar,
)
from optdesign.errors import InputError

_RANGE = re.compile(
    r"^\s*(?P<start>[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(?P<u0>[^.\s][^.]*?)?\s*"
    r"\.\.\s*(?P<stop>[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(?P<u1>.*?)\s*"
    r":\s*(?P<count>\d+)\s*$"
)


def parse_vary(text: str) -> tuple[str, tuple[str, str, int]]:
    """``"requirements.hinge_moment=200..1000N*m:20"`` -> (path, ("200 N*m", "1000 N*m",
    20)); the unit after the stop applies to a start written without one."""
    path, sep, rng = text.partition("=")
    if not sep or not path.strip():
        raise InputError(
            "--vary",
            f"{text!r}: write PATH=START..STOP UNIT:COUNT, e.g. "
            "requirements.hinge_moment=200..1000N*m:20",
        )
    from optdesign.unit_grammar import Refused, check_ascii_digits

    try:  # the path's mistake first: it is what the word was meant to name
        check.vary_path(path.strip())
    except InputError as exc:
        raise InputError("--vary", exc.reason) from None
    m = _RANGE.match(rng)
    if m is None:
        raise InputError(
            "--vary",
            f"{path.strip()}: {rng!r} is not START..STOP UNIT:COUNT (e.g. 200..1000N*m:20)",
        )
    try:  # int() reads every script's digits (the start and stop are checked as quantities)
        check_ascii_digits(m["count"], m["count"])
    except Refused as exc:
        raise InputError("--vary", f"{path.strip()}: count {exc}") from None
    u1 = (m["u1"] or "").strip()
    u0 = (m["u0"] or "").strip() or u1
    start = f"{m['start']} {u0}".strip()
    stop = f"{m['stop']} {u1}".strip()
    return path.strip(), (start, stop, int(m["count"]))


def parse_with(text: str) -> tuple[str, str]:
    """``"loop.bandwidth=requirements.bandwidth_min"`` -> (the path that follows, the
    swept path it follows)."""
    path, sep, follows = (part.strip() for part in text.partition("="))
    if not sep or not path or not follows:
        raise InputError(
            "--with",
            f"{text!r}: write PATH=SWEPT_PATH, e.g. loop.bandwidth=requirements.bandwidth_min",
        )
    for name in (path, follows):
        try:
            check.vary_path(name)
        except InputError as exc:
            raise InputError("--with", exc.reason) from None
    return path, follows


@command("sweep")
def _sweep(sub):
    p = sub.add_parser("sweep", help="the optimum against one or two parameters")
    p.add_argument("file", type=Path, help="problem file (TOML)")
    p.add_argument(
        "--vary",
        action="append",
        required=True,
        help="PATH=START..STOP UNIT:COUNT, e.g. requirements.hinge_moment=200..1000N*m:20 "
        "(once or twice; PATH: requirements.NAME, motion.NAME, load.NAME, "
        "loop.NAME, variables.NAME.lower|upper, variables.NAME)",
    )
    p.add_argument(
        "--with",
        dest="linked",
        action="append",
        default=[],
        metavar="PATH=SWEPT",
        help="move PATH with the swept parameter SWEPT (the same value at every point), "
        "e.g. loop.bandwidth=requirements.bandwidth_min; repeatable",
    )
    p.add_argument("--objective", default=None, help="objective (default: the file's first)")
    p.add_argument(
        "--check-every",
        type=checked(lambda a, v: check.integer(a, v, 1, 10_000), literal),
        default=10,
        help="ignored (every point gets its global search); accepted for older scripts",
    )
    p.add_argument(
        "--starts",
        type=checked(check.starts, literal),
        default=None,
        help="the most starts of each point's global search (default: the file's)",
    )
    p.add_argument(
        "--seed", type=checked(check.seed, literal), default=None, help="seed (default: file's)"
    )
    p.add_argument(
        "--workers",
        type=checked(check.workers, literal),
        default=1,
        help="local processes: the points side by side (default 1)",
    )
    p.add_argument(
        "--scheduler",
        type=checked(check.scheduler),
        default=None,
        help="address of a Dask distributed scheduler (tcp://HOST:PORT)",
    )
    p.add_argument(
        "--out", type=checked(check.out_path), default=None, help="output folder (default: new one)"
    )
    p.add_argument("--resume", action="store_true", help="continue the sweep stored in --out")
    p.add_argument(
        "--overwrite", action="store_true", help="start afresh over a stored sweep in --out"
    )
    p.add_argument(
        "--sensitivities",
        action="store_true",
        help="also each point's log-sensitivity to every binding requirement (in sweep.json)",
    )
    p.add_argument("--json", action="store_true", help="print sweep.json to stdout")
    p.add_argument(
        "--no-plot", action="store_true", help="skip the design charts sweep.png and sweep.html"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run_sweep_command)


def run_sweep_command(args) -> int:
    import optdesign as od
    from optdesign import storage
    from optdesign.cli import stdout_to_stderr
    from optdesign.problem import load_problem

    vary = dict(parse_vary(t) for t in args.vary)
    if len(vary) < len(args.vary):
        raise InputError("--vary", "the same parameter twice")
    linked = dict(parse_with(t) for t in args.linked)
    if len(linked) < len(args.linked):
        raise InputError("--with", "the same parameter twice")
    problem = load_problem(args.file)
    with as_options():
        check.objective_of(problem, args.objective)
        check.run_folder(args.out, args.resume, args.overwrite)
        # before the output folder is made
        check.sweep_parameters(problem, vary, "--vary", linked or None, "--with")
    with output_folder(args.out, f"sweep-{problem.name}") as out, storage.lock_folder(out):
        storage.ensure_writable(out)
        quiet = stdout_to_stderr() if args.json else contextlib.nullcontext()
        with quiet, as_options():  # e.g. a --scheduler that does not answer
            sweep = od.sweep(
                problem,
                vary,
                linked=linked or None,
                objective=args.objective,
                check_every=args.check_every,
                starts=args.starts,
                seed=args.seed,
                out=out,
                resume=args.resume,
                overwrite=args.overwrite,
                progress=progress_bar(args) and not args.json,
                sensitivities=args.sensitivities,
                workers=args.workers,
                scheduler=args.scheduler,
                files=False,  # written below, with the command's --no-plot
            )
        return _write(args, sweep, out)


def _write(args, sweep, out: Path) -> int:
    from optdesign.reports.sweep_files import write_sweep_outputs
    from optdesign.text import printable

    wrote, notes, text = write_sweep_outputs(sweep, out, plot=not args.no_plot)
    if args.json:
        print(text)
    else:
        print(flags(sweep.summary()))
        for note in notes:
            print(f"note: {printable(flags(note))}")
        print("\nwrote " + ", ".join(printable(w) for w in wrote))
    return 0 if any(p.success for p in sweep.points) else 1
