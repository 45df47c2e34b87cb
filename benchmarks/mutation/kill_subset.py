"""Kill count of a seeded subset of mutants, one mutant at a time, in a copy of ``mutants/``.

Usage::

    python benchmarks/mutation/kill_subset.py MUTANTS_DIR MUTMUT_ALL PATTERN N SEED \
        [--extra TEST ...] [--no-covering] [--then TEST ...] [--deselect TEST_ID ...] \
        [--only NAMES_FILE] [--python PY]

``MUTANTS_DIR`` is a copy of a mutation run's ``mutants/`` (never the running one: the
tests write caches there), ``MUTMUT_ALL`` the run's ``mutmut results --all true`` listing.
The subset is ``N`` of the mutant names matching the regular expression ``PATTERN``,
drawn by ``random.Random(SEED)`` from the sorted names. Each mutant faces the
``--extra`` tests, then the tests mutmut's own stats (``mutmut-stats.json``) list for
its function - the tests the mutation run gives it - unless ``--no-covering``; pytest
stops at the first failure (killed). ``--then`` tests run on each survivor
(``killed-then`` when they kill it: a before/after count in one pass). One line per
mutant on stdout (``killed``, ``killed-then``, ``survived``, ``error rc=N``,
``timeout``), a summary at the end. It runs one pytest at a time, at ``nice`` 10.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import subprocess
import sys
from pathlib import Path


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("mutants", type=Path)
    ap.add_argument("listing", type=Path)
    ap.add_argument("pattern")
    ap.add_argument("n", type=int)
    ap.add_argument("seed", type=int)
    ap.add_argument("--extra", nargs="*", default=[])
    ap.add_argument(
        "--no-covering", action="store_true", help="only the --extra tests, not mutmut's"
    )
    ap.add_argument(
        "--then",
        nargs="*",
        default=[],
        help="tests run on each survivor (verdict 'killed-then' when they fail)",
    )
    ap.add_argument("--deselect", nargs="*", default=[], help="test ids left out")
    ap.add_argument("--only", type=Path, help="run only these names (one a line)")
    ap.add_argument("--python", default=sys.executable)
    ap.add_argument("--timeout", type=float, default=600.0)
    args = ap.parse_args()

    names = sorted(
        line.strip().split(":")[0]
        for line in args.listing.read_text(encoding="utf-8").splitlines()
        if re.search(args.pattern, line)
    )
    subset = random.Random(args.seed).sample(names, min(args.n, len(names)))
    if args.only:
        wanted = set(args.only.read_text(encoding="utf-8").split())
        subset = [s for s in subset if s in wanted]
    stats = json.loads((args.mutants / "mutmut-stats.json").read_text(encoding="utf-8"))
    covering = stats["tests_by_mangled_function_name"]
    duration = stats["duration_by_test"]
    counts: dict[str, int] = {}
    for name in subset:
        function = re.sub(r"__mutmut_\d+$", "", name)
        tests = sorted(
            [] if args.no_covering else covering.get(function, []),
            key=lambda t: (
                not t.startswith("tests/programs/test_gp.py"),
                duration.get(t, 0.0),
                t,
            ),
        )
        cmd = ["nice", "-n", "10", args.python, "-m", "pytest", "-q", "-x"]
        cmd += ["-p", "no:cacheprovider", *args.extra, *tests]
        for test in args.deselect:
            cmd += ["--deselect", test]
        env = dict(os.environ, MUTANT_UNDER_TEST=name, PYTHONPATH=str(args.mutants))
        verdict = run(cmd, env, args) if args.extra or tests else "no tests"
        if verdict in ("survived", "no tests") and args.then:
            then = cmd[: cmd.index("no:cacheprovider") + 1] + args.then
            for test in args.deselect:
                then += ["--deselect", test]
            verdict = {"killed": "killed-then"}.get(run(then, env, args), verdict)
        counts[verdict] = counts.get(verdict, 0) + 1
        print(f"{verdict:10s} {name}", flush=True)
    print("summary:", ", ".join(f"{k} {v}" for k, v in sorted(counts.items())), flush=True)
    return 0


def run(cmd: list[str], env: dict[str, str], args: argparse.Namespace) -> str:
    """pytest's verdict on one mutant: killed (a test failed), survived, or why neither."""
    try:
        rc = subprocess.run(
            cmd,
            cwd=args.mutants,
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            timeout=args.timeout,
        ).returncode
    except subprocess.TimeoutExpired:
        return "timeout"
    return {0: "survived", 1: "killed"}.get(rc, f"error rc={rc}")


if __name__ == "__main__":
    raise SystemExit(main())
