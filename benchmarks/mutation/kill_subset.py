"""Kill count of a seeded subset of mutants, one mutant at a time, in a copy of ``mutants/``.

Usage::

    python benchmarks/mutation/kill_subset.py MUTANTS_DIR MUTMUT_ALL PATTERN N SEED \
        [--extra tests/test_x.py ...] [--deselect TEST_ID ...] [--only NAMES_FILE] [--python PY]

``MUTANTS_DIR`` is a copy of a mutation run's ``mutants/`` (never the running one: the
tests write caches there), ``MUTMUT_ALL`` the run's ``mutmut results --all true`` listing.
The subset is ``N`` of the mutant names matching the regular expression ``PATTERN``,
drawn by ``random.Random(SEED)`` from the sorted names. Each mutant faces the tests
mutmut's own stats (``mutmut-stats.json``) list for its function - the tests the
mutation run gives it - preceded by the ``--extra`` test files; pytest stops at the
first failure (killed). One line per mutant on stdout (``killed``/``survived``/
``error rc=N``/``timeout``), a summary at the end. Run it at ``nice`` 10 on a shared
machine: it runs one pytest at a time.
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
            covering.get(function, []),
            key=lambda t: (not t.startswith("tests/test_gp.py"), duration.get(t, 0.0), t),
        )
        cmd = ["nice", "-n", "10", args.python, "-m", "pytest", "-q", "-x"]
        cmd += ["-p", "no:cacheprovider", *args.extra, *tests]
        for test in args.deselect:
            cmd += ["--deselect", test]
        env = dict(os.environ, MUTANT_UNDER_TEST=name, PYTHONPATH=str(args.mutants))
        if not args.extra and not tests:
            verdict = "no tests"
        else:
            try:
                rc = subprocess.run(
                    cmd,
                    cwd=args.mutants,
                    env=env,
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                    timeout=args.timeout,
                ).returncode
                verdict = {0: "survived", 1: "killed"}.get(rc, f"error rc={rc}")
            except subprocess.TimeoutExpired:
                verdict = "timeout"
        counts[verdict] = counts.get(verdict, 0) + 1
        print(f"{verdict:10s} {name}", flush=True)
    print("summary:", ", ".join(f"{k} {v}" for k, v in sorted(counts.items())), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
