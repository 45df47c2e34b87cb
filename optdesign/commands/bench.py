"""``optdesign bench``: which solver and formulation to use, with evidence.

Runs every solver configuration (:data:`optdesign.studies.bench.CONFIGS`) on a suite of
seeded instances, streams one JSON row per run to ``OUT/bench_runs.jsonl`` (``--resume``
continues it), then writes ``bench_runs.csv``, ``bench_profiles.png`` (Dolan-More profiles of time
and objective gap) and ``summary.md``; when ``OUT/../README.md`` has the generated-block
markers, the summary is pasted between them.
"""

from __future__ import annotations

import os
from pathlib import Path

from optdesign import storage
from optdesign.cli import command, default_out


@command("bench")
def _bench(sub):
    p = sub.add_parser("bench", help="benchmark solver configurations on seeded instance families")
    p.add_argument("--suite", choices=["default", "quick"], default="default")
    p.add_argument(
        "--solvers",
        nargs="+",
        default=None,
        metavar="CONFIG",
        help="configurations to run (default: all registered; see --list)",
    )
    p.add_argument("--list", action="store_true", help="list the configurations and exit")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="local processes")
    p.add_argument(
        "--scheduler", default=None, help="Dask scheduler address (instead of local processes)"
    )
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output folder (default: benchmarks/results if present, else a new one)",
    )
    p.add_argument(
        "--resume", action="store_true", help="continue the run stored in OUT/bench_runs.jsonl"
    )
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="start over: replace the store of an earlier run in OUT (without it, a folder "
        "holding one is refused unless --resume)",
    )
    p.add_argument(
        "--time-limit",
        type=float,
        default=1.0,
        help="soft wall-time limit of each solver call, s (default 1; set-up not included)",
    )
    p.add_argument(
        "--hard-timeout",
        type=float,
        default=None,
        help="kill a run after this many s (default time limit + 3)",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--no-readme", action="store_true", help="do not update OUT/../README.md")
    p.set_defaults(func=run_bench_command)


def run_bench_command(args) -> int:
    from optdesign.errors import InputError
    from optdesign.studies import bench

    if args.list:
        for name in bench.default_configs():
            c = bench.CONFIGS[name]
            print(f"{name:20s} {c.kind:7s} {c.description}")
        return 0
    if args.workers < 1:
        raise InputError("--workers", f"must be at least 1, got {args.workers}")
    if args.time_limit <= 0:
        raise InputError("--time-limit", f"must be positive, got {args.time_limit}")
    solvers = None
    if args.solvers:
        solvers = [s for item in args.solvers for s in item.split(",") if s]
    out = args.out
    if out is None:
        out = (
            Path("benchmarks/results")
            if Path("benchmarks/README.md").exists()
            else default_out("bench")
        )
    if args.resume and args.overwrite:
        raise InputError("--overwrite", "excludes --resume (start over, or continue)")
    with storage.lock_folder(out):
        storage.ensure_writable(out)
        if args.overwrite:
            storage.discard_store(Path(out) / "bench_runs.jsonl")
        return _run_locked(args, bench, solvers, out)


def _run_locked(args, bench, solvers, out) -> int:
    res = bench.run_bench(
        args.suite,
        solvers,
        out,
        workers=args.workers,
        scheduler=args.scheduler,
        resume=args.resume,
        progress=not args.no_progress,
        time_limit=args.time_limit,
        hard_timeout=args.hard_timeout,
    )
    print(res["summary"])
    paths = res["paths"]
    print(
        f"wrote {out / 'bench_runs.jsonl'}, {paths['csv']}, {paths['profiles']}, {paths['summary']}"
    )
    readme = Path(out).resolve().parent / "README.md"
    if not args.no_readme and readme.exists():
        if bench.update_readme(readme, res["summary"]):
            print(f"updated the generated block of {readme}")
    return 0
