"""What the global search costs on the shipped problems: ``od.solve`` and a 50-point
front (with its files, and without), and the whole ``optdesign solve`` command, timed for this tree and for a baseline
tree (an earlier commit checked out elsewhere, e.g. ``git worktree add /tmp/base
f433943``), interleaved round by round in one run so that both see the same machine.

    python benchmarks/global_search/cost.py --baseline /tmp/base --rounds 3

Each measurement runs in a fresh interpreter with ``PYTHONPATH`` set to the tree; the
in-process figures are the least of the rounds (the machine's noise only adds), the
command's the median. Prints one JSON line per measurement and a table of the ratios.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve()
TREE = HERE.parents[2]
SOLVES = ["cs_min_backlash", "cs_min_ripple", "pivot_min_backlash", "fork_min_backlash"]

SOLVE_SNIPPET = """
import json, sys, time
import optdesign as od
name = sys.argv[1]
p = od.load(f"problems/{name}.toml"); od.solve(p)  # the NLP cache built once
p = od.load(f"problems/{name}.toml")
t = time.perf_counter(); r = od.solve(p); dt = time.perf_counter() - t
ms = r.multistart
print(json.dumps({"t": dt, "objective": r.objective, "starts": ms.n_starts if ms else 0}))
"""

FRONT_SNIPPET = """
import json, tempfile, time
import optdesign as od
p = od.load("problems/cs_min_backlash.toml")
with tempfile.TemporaryDirectory() as out:
    t = time.perf_counter()
    front = od.pareto(p, ["ripple", "backlash"], points=50, out=out + "/f")
    dt = time.perf_counter() - t
ends = [front.points[0].objectives, front.points[-1].objectives]
print(json.dumps({"t": dt, "points": len(front.points), "ends": ends}))
"""


FRONT_ALONE_SNIPPET = """
import json, time
import optdesign as od
p = od.load("problems/cs_min_backlash.toml")
t = time.perf_counter()
front = od.pareto(p, ["ripple", "backlash"], points=50)
dt = time.perf_counter() - t
ends = [front.points[0].objectives, front.points[-1].objectives]
print(json.dumps({"t": dt, "points": len(front.points), "ends": ends}))
"""


def _python(tree: Path, *args: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(tree), "MPLBACKEND": "Agg"}
    done = subprocess.run(
        [sys.executable, *args], cwd=tree, env=env, capture_output=True, text=True, check=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def _command(tree: Path, problem: str) -> float:
    env = {**os.environ, "PYTHONPATH": str(tree), "MPLBACKEND": "Agg"}
    with tempfile.TemporaryDirectory() as out:
        t = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "optdesign", "solve", f"problems/{problem}.toml", "--out", out],
            cwd=tree,
            env=env,
            capture_output=True,
            check=True,
        )
        return time.perf_counter() - t


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", type=Path, required=True, help="the earlier tree")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    trees = {"baseline": args.baseline.resolve(), "this": TREE}
    rows: dict[tuple[str, str], list[float]] = {}
    for _ in range(args.rounds):
        for label, tree in trees.items():
            for name in SOLVES:
                rec = _python(tree, "-c", SOLVE_SNIPPET, name)
                rows.setdefault((f"od.solve {name}", label), []).append(rec["t"])
                print(json.dumps({"tree": label, "case": name, **rec}), flush=True)
            rec = _python(tree, "-c", FRONT_SNIPPET)
            rows.setdefault(("50-point front cs_min_backlash", label), []).append(rec["t"])
            print(json.dumps({"tree": label, "case": "front", **rec}), flush=True)
            rec = _python(tree, "-c", FRONT_ALONE_SNIPPET)
            rows.setdefault(("the same front, no files", label), []).append(rec["t"])
            print(json.dumps({"tree": label, "case": "front alone", **rec}), flush=True)
            t = _command(tree, "cs_min_ripple")
            rows.setdefault(("optdesign solve cs_min_ripple (command)", label), []).append(t)
            print(json.dumps({"tree": label, "case": "command", "t": t}), flush=True)
    print("\n| work | baseline (s) | this tree (s) | ratio |\n|---|---|---|---|")
    for case in dict.fromkeys(c for c, _ in rows):
        pick = statistics.median if "command" in case else min
        a, b = pick(rows[(case, "baseline")]), pick(rows[(case, "this")])
        print(f"| {case} | {a:.3f} | {b:.3f} | {b / a:.2f} |")


if __name__ == "__main__":
    main()
