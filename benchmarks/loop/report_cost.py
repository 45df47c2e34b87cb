"""What the section "Time response" costs ``optdesign solve``: the command on
``fin_actuator_loop`` (which has a ``[loop]``) run with this tree and with a tree
without the section (``--before``: e.g. ``git archive <commit> | tar -x -C DIR``),
alternately, ``--runs`` times each; then, in this process, the section's own
evaluation (:func:`optdesign.views.time_response.time_response_view`) of the optimum
and the page's build with and without it, alternately. Medians; the machine may be
shared.

    python benchmarks/loop/report_cost.py --before /tmp/base --runs 3
    python benchmarks/loop/report_cost.py --in-process --runs 5    # the page's build only
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _command(tree: Path, problem: str) -> float:
    """Wall time of ``optdesign solve problems/PROBLEM.toml --out DIR`` run from ``tree``
    (its own package first on the path); checks that it wrote report.html."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    with tempfile.TemporaryDirectory() as out:
        t = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "optdesign", "solve", f"problems/{problem}.toml", "--out", out],
            cwd=tree,
            env=env,
            check=True,
            stdout=subprocess.DEVNULL,
        )
        elapsed = time.perf_counter() - t
        page = (Path(out) / "report.html").read_text()
    print(f"  {tree}: {elapsed:.2f} s, section {'Time response' in page}, {len(page)} bytes")
    return elapsed


def _section(runs: int) -> None:
    """In this process, alternately: the page of the optimum as written now, and the same
    page with the section's evaluation switched off (the page before it, byte for byte);
    then the evaluation alone."""
    import optdesign as od
    from optdesign.reports import html
    from optdesign.views.time_response import time_response_view

    problem = od.load(ROOT / "problems" / "fin_actuator_loop.toml")
    result = od.solve(problem, ranges=False, sensitivities=False)
    with_section, without, alone = [], [], []
    for _ in range(runs):
        t = time.perf_counter()
        page = html.solve_report(result)
        with_section.append(time.perf_counter() - t)
        html.time_response_view = lambda *args: None
        try:
            t = time.perf_counter()
            plain = html.solve_report(result)
            without.append(time.perf_counter() - t)
        finally:
            html.time_response_view = time_response_view
        t = time.perf_counter()
        view = time_response_view(problem, result.design)
        alone.append(time.perf_counter() - t)
    r = view.simulation.response
    a, b = statistics.median(with_section), statistics.median(without)
    print(
        f"solve_report: with the section {a:.3f} s ({len(page)} bytes), without {b:.3f} s "
        f"({len(plain)} bytes), medians of {runs}; +{a - b:.3f} s"
    )
    print(
        f"time_response_view: median {statistics.median(alone):.3f} s (min {min(alone):.3f}, "
        f"max {max(alone):.3f}); horizon {view.horizon:.3f} s, {len(r.event_times)} events, "
        f"{r.times.size} samples"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", type=Path, help="a tree without the section")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--problem", default="fin_actuator_loop")
    parser.add_argument("--in-process", action="store_true", help="the page's build only")
    args = parser.parse_args()
    if args.in_process:
        _section(args.runs)
        return
    before, after = [], []
    for k in range(args.runs):
        print(f"run {k + 1}")
        before.append(_command(args.before.resolve(), args.problem))
        after.append(_command(ROOT, args.problem))
    b, a = statistics.median(before), statistics.median(after)
    print(
        f"optdesign solve {args.problem}: before {b:.2f} s, after {a:.2f} s (medians of "
        f"{args.runs}); after / before {a / b:.3f}, +{a - b:.2f} s"
    )
    _section(args.runs)


if __name__ == "__main__":
    main()
