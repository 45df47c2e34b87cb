"""No reported optimum outside a declared range: the property over random problems
(issue 35, "No answer that cannot be true").

Draws problems from the shipped ones (tests/validity_problems.py, ``random_problem``:
a shipped problem as written or as one of tests/test_validity.py's variants, its
requirement values redrawn, its bounds narrowed or shifted, the pin's material, fit,
contact model, shear planes and length, the fixed clearances and the gear ratio
perturbed, every input inside its declared range), solves each with
``od.solve(problem, starts=2, ranges=False, sensitivities=False)`` and judges the result
against the quantities the models' ranges bound, recomputed by hand (``by_hand``). A
result reported a success or verified with one of them outside its range is a
``violation``; the other verdicts are ``verified``, ``unchecked`` (a success the
independent check did not run on), ``flagged`` (not verified, the range named),
``failed`` (no feasible design), ``refused`` (the drawn file refused when read) and
``error`` (a crash).

One JSON line per problem is appended to ``results.jsonl`` as it is solved; a rerun skips
the seeds already there. Run from the repository root, at low priority on a shared
machine:

    nice -n 19 python benchmarks/validity/run.py --count 1000
    python benchmarks/validity/run.py --summary
"""

from __future__ import annotations

import argparse
import collections
import json
import statistics
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))

from validity_problems import VERDICTS, run_one  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results.jsonl"


def done_seeds(path: Path) -> set[int]:
    """The seeds already recorded in ``path`` (a line cut short by a kill is skipped)."""
    seeds = set()
    if path.exists():
        for line in path.read_text().splitlines():
            try:
                seeds.add(int(json.loads(line)["seed"]))
            except (ValueError, KeyError):
                continue
    return seeds


def compute(seeds: list[int], starts: int, workers: int, path: Path) -> None:
    """Solve and judge ``seeds`` not yet in ``path``, appending one line each."""
    todo = [s for s in seeds if s not in done_seeds(path)]
    print(f"{len(todo)} problems to solve ({len(seeds) - len(todo)} already in {path.name})")
    t0 = time.perf_counter()

    def record(rec: dict) -> None:
        with path.open("a") as fh:
            fh.write(json.dumps(rec) + "\n")
        line = f"{rec['seed']:5d} {rec['stem']:26s} {rec['kind']:7s} {rec['verdict']:9s}"
        print(f"{line} {rec['time_s']:6.2f}s", flush=True)

    if workers == 1:
        for seed in todo:
            record(run_one(seed, starts))
    else:
        with ProcessPoolExecutor(workers) as pool:
            futures = [pool.submit(run_one, seed, starts) for seed in todo]
            for future in as_completed(futures):
                record(future.result())
    print(f"{len(todo)} problems in {time.perf_counter() - t0:.0f} s")


def summary(path: Path, seeds: list[int] | None = None) -> dict:
    """Counts per verdict (and per shipped problem) of the records in ``path``."""
    records = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    if seeds is not None:
        wanted = set(seeds)
        records = [r for r in records if r["seed"] in wanted]
    counts = collections.Counter(r["verdict"] for r in records)
    by_stem: dict[str, collections.Counter] = collections.defaultdict(collections.Counter)
    for r in records:
        by_stem[r["stem"]][r["verdict"]] += 1
    print(f"{len(records)} problems, {sum(r['time_s'] for r in records):.0f} s of solving")
    print("  " + ", ".join(f"{v} {counts[v]}" for v in VERDICTS))
    for stem in sorted(by_stem):
        print(f"  {stem:26s} " + ", ".join(f"{v} {by_stem[stem][v]}" for v in VERDICTS))
    times = [r["time_s"] for r in records]
    if times:
        print(
            f"  time per problem: median {statistics.median(times):.2f} s, max {max(times):.1f} s"
        )
    unnamed = [r for r in records if r.get("unnamed")]
    print(f"  by-hand quantities outside a range that no violated row names: {len(unnamed)}")
    for r in unnamed:
        print(f"    seed {r['seed']} {r['stem']} {r['kind']} {r['verdict']}: {r['unnamed']}")
    warned = [r for r in records if r.get("warnings")]
    print(f"  problems that printed a NumPy RuntimeWarning: {len(warned)}")
    for r in warned:
        print(f"    seed {r['seed']} {r['stem']} {r['kind']}: {r['warnings']}")
    for r in records:
        if r["verdict"] in ("violation", "error", "unchecked"):
            what = r.get("outside") or r.get("message")
            print(f"  {r['verdict']}: seed {r['seed']} {r['stem']} {r['kind']}: {what}")
    return dict(counts)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=1000, help="problems (seeds 0..count-1)")
    parser.add_argument("--first", type=int, default=0, help="first seed")
    parser.add_argument("--starts", type=int, default=2, help="starts of each solve")
    parser.add_argument("--workers", type=int, default=1, help="processes (2 cores: 1)")
    parser.add_argument("--results", type=Path, default=RESULTS, help="the JSON-lines file")
    parser.add_argument("--summary", action="store_true", help="only count what is there")
    args = parser.parse_args(argv)
    seeds = list(range(args.first, args.first + args.count))
    if not args.summary:
        compute(seeds, args.starts, args.workers, args.results)
    counts = summary(args.results, seeds)
    return 1 if counts.get("violation") or counts.get("error") else 0


if __name__ == "__main__":
    raise SystemExit(main())
