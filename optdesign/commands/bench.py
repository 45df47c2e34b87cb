"""``optdesign bench``: which solver and formulation to use, with evidence.

Runs every solver configuration (:func:`optdesign.bench_configurations`) on a suite of
seeded instances (or on the user's problem files, ``--problem FILE ...``), streams one JSON row per run to ``OUT/bench_runs.jsonl`` (``--resume``
continues it), then writes ``bench_runs.csv``, ``bench_profiles.png`` (Dolan-More profiles of
time and objective gap) and ``summary.md``, all under ``--out`` (default: a new folder).
``--update-readme FILE`` pastes the summary between the generated-block markers of FILE
(the maintainers' benchmarks/README.md); nothing else is ever written outside ``--out``.
"""

from __future__ import annotations

import os
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
    time_limit_option,
)

#: Options spelt otherwise than their API argument (optdesign.bench).
RENAMED = {"problems": "--problem"}


@command("bench")
def _bench(sub):
    p = sub.add_parser("bench", help="benchmark solver configurations on seeded instance families")
    p.add_argument(
        "--suite",
        type=checked(check.suite),
        default=None,
        help="default or quick (the default when no --problem is given)",
    )
    p.add_argument(
        "--problem",
        dest="problems",
        nargs="+",
        type=Path,
        default=None,
        metavar="FILE",
        help="benchmark these problem files (yours) instead of a suite",
    )
    p.add_argument(
        "--solvers",
        nargs="+",
        default=None,
        metavar="CONFIG",
        help="configurations to run (default: all registered; see --list)",
    )
    p.add_argument("--list", action="store_true", help="list the configurations and exit")
    p.add_argument(
        "--workers",
        type=checked(check.workers, literal),
        default=os.cpu_count() or 1,
        help="local processes",
    )
    p.add_argument(
        "--scheduler",
        type=checked(check.scheduler),
        default=None,
        help="Dask scheduler address, tcp://HOST:PORT (instead of local processes)",
    )
    p.add_argument(
        "--out",
        type=checked(check.out_path),
        default=None,
        help="output folder (default: a new one under ./optdesign-out)",
    )
    p.add_argument(
        "--resume", action="store_true", help="continue the run stored in OUT/bench_runs.jsonl"
    )
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="start afresh in an --out folder that holds a previous run's store",
    )
    time_limit_option(
        p, "soft wall-time limit of each solver call, s (default 1; set-up not included)", 1.0
    )
    p.add_argument(
        "--hard-timeout",
        type=checked(check.seconds, literal),
        default=None,
        help="kill a run after this many s (default time limit + 3)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument(
        "--update-readme",
        type=Path,
        default=None,
        metavar="FILE",
        help="paste the summary between the generated-block markers of FILE",
    )
    p.set_defaults(func=run_bench_command)


def run_bench_command(args) -> int:
    from optdesign import api, storage

    if args.list:
        for name, kind, description in api.bench_configurations():
            print(f"{name:20s} {kind:7s} {description}")
        return 0
    with as_options(RENAMED):  # the checks of optdesign.bench, before the folder is made
        check.configs("solvers", args.solvers)
        check.bench_timeouts(args.time_limit, args.hard_timeout)
        check.run_folder(args.out, args.resume, args.overwrite)
        if args.problems is not None and args.suite is not None:
            raise check.ArgumentError(
                "suite", "excludes {problems} (run your problems or a suite)", ("problems",)
            )
        check.readme_file("update_readme", args.update_readme)
    problems = None
    if args.problems is not None:
        problems = [api.load(path) for path in args.problems]  # refused naming the file
    with output_folder(args.out, "bench") as out, storage.lock_folder(out):
        storage.ensure_writable(out)
        return _run_locked(args, problems, out)


def _run_locked(args, problems, out: Path) -> int:
    from optdesign import api
    from optdesign.text import printable

    with as_options(RENAMED):
        report = api.bench(
            problems,
            suite=args.suite,
            solvers=args.solvers,
            out=out,
            workers=args.workers,
            scheduler=args.scheduler,
            resume=args.resume,
            progress=progress_bar(args),
            time_limit=args.time_limit,
            hard_timeout=args.hard_timeout,
            overwrite=args.overwrite,
            update_readme=args.update_readme,
        )
    print(printable(flags(report.summary()), newlines=True))
    paths = report.paths
    written = [out / "bench_runs.jsonl", paths["csv"], paths["profiles"], paths["summary"]]
    print("wrote " + ", ".join(printable(p) for p in written))
    if args.update_readme is not None:
        print(f"updated the generated block of {printable(args.update_readme)}")
    return 0
