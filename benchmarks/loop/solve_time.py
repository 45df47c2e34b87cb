"""What the loop's rows cost a solve: ``od.solve(problem, ranges=False)`` (sensitivities
and neighbouring items included) of ``fin_actuator_motor``, of the same with
``fin_actuator_loop``'s ``[loop]`` and rows but ``resonance_margin_min = 2.7`` (the same
optimum, the same search), of ``fin_actuator_loop`` and of ``fin_actuator_cascade`` (its
loop a position/speed cascade), interleaved, ``--runs`` times each. Prints each run's summary ``time`` (the solve), the whole ``od.solve``, the NLP
solves of the branch and bound, and the medians.

    python benchmarks/loop/solve_time.py --runs 3
"""

from __future__ import annotations

import argparse
import copy
import statistics
import time
import tomllib
from pathlib import Path

import optdesign as od

ROOT = Path(__file__).resolve().parents[2]


def _data(name: str) -> dict:
    return tomllib.loads((ROOT / "problems" / f"{name}.toml").read_text())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    same_search = _data("fin_actuator_loop")
    same_search["requirements"]["resonance_margin_min"] = 2.7
    cases = {
        "fin_actuator_motor": _data("fin_actuator_motor"),
        "the same with [loop] and rows, resonance_margin_min = 2.7": same_search,
        "fin_actuator_loop": _data("fin_actuator_loop"),
        "fin_actuator_cascade": _data("fin_actuator_cascade"),
    }
    rows: dict[str, list[tuple[float, float, int]]] = {k: [] for k in cases}
    for k in range(args.runs):
        for label, data in cases.items():
            problem = od.load(copy.deepcopy(data))
            t = time.perf_counter()
            result = od.solve(problem, ranges=False)
            total = time.perf_counter() - t
            info = result.details.catalogue
            solves = info.nlp_solves if info is not None else 0
            rows[label].append((result.wall_time_s, total, solves))
            print(
                f"run {k + 1} {label}: solve {result.wall_time_s:.2f} s, od.solve {total:.2f} s, "
                f"{solves} NLP solves, {result.status}, d = {result.design.get('d')}"
            )
    print("\n| problem | solve (the summary's `time`) | `od.solve` in all | NLP solves |")
    print("|---|---|---|---|")
    for label, runs in rows.items():
        solve = [r[0] for r in runs]
        total = [r[1] for r in runs]
        print(
            f"| {label} | {min(solve):.1f}-{max(solve):.1f} s (median "
            f"{statistics.median(solve):.1f}) | {min(total):.1f}-{max(total):.1f} s (median "
            f"{statistics.median(total):.1f}) | {runs[-1][2]} |"
        )


if __name__ == "__main__":
    main()
