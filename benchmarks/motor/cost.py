"""What the motor costs a solve: ``od.solve`` of ``fin_actuator`` against
``fin_actuator_motor`` (the same actuator with a named motor, its load and a step
response) and against the same problem with the motor chosen from the catalogue
(``[motor] catalogue = "Yaskawa Sigma-7"``, one more catalogue variable), in one process,
the least of ``--rounds`` rounds each (the solver caches built by a first solve), with
each search's NLP solves (``details.catalogue.nlp_solves``: the same on any machine),
and the catalogue choice against an enumeration over the motors named one by one.

    python benchmarks/motor/cost.py --rounds 3
"""

from __future__ import annotations

import argparse
import copy
import math
import time
import tomllib
from pathlib import Path

import optdesign as od
from optdesign.problem.motor_catalogue_variable import motors

ROOT = Path(__file__).resolve().parents[2]
CATALOGUE = "Yaskawa Sigma-7"


def _data(name: str) -> dict:
    return tomllib.loads((ROOT / "problems" / f"{name}.toml").read_text())


def _timed(data: dict, rounds: int) -> tuple[float, od.Result]:
    od.solve(od.load(copy.deepcopy(data)), ranges=False, sensitivities=False)
    best, result = math.inf, None
    for _ in range(rounds):
        problem = od.load(copy.deepcopy(data))
        t = time.perf_counter()
        result = od.solve(problem, ranges=False, sensitivities=False)
        best = min(best, time.perf_counter() - t)
    return best, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    plain = _data("fin_actuator")
    named = _data("fin_actuator_motor")
    chosen = copy.deepcopy(named)
    chosen["motor"] = {k: v for k, v in named["motor"].items() if k != "designation"}
    chosen["motor"]["catalogue"] = CATALOGUE
    rows = {}
    for label, data in (("fin_actuator", plain), ("fin_actuator_motor", named),
                        ("motor from the catalogue", chosen)):  # fmt: skip
        rows[label] = _timed(data, args.rounds)
        t, r = rows[label]
        print(f"{label}: {t:.2f} s, {r.status}, backlash {r.objective:.9g}, {r.design}")
    base = rows["fin_actuator"][0]
    print("\n| solve | time (s) | ratio to fin_actuator | NLP solves |\n|---|---|---|---|")
    for label, (t, r) in rows.items():
        print(f"| {label} | {t:.2f} | {t / base:.2f} | {r.details.catalogue.nlp_solves} |")
    values = []
    for row in motors(CATALOGUE):
        data = copy.deepcopy(named)
        data["motor"]["designation"] = row.designation
        r = od.solve(od.load(data), ranges=False, sensitivities=False)
        values.append(r.objective if r.success else math.inf)
        print(f"  {row.designation}: {r.status} {r.objective:.9g}")
    best = min(values)
    first = next(k for k, v in enumerate(values, 1) if v <= best * (1 + 1e-6))
    got = rows["motor from the catalogue"][1]
    name = motors(CATALOGUE)[first - 1].designation
    print(
        f"enumeration: smallest motor at the optimum {first} ({name}), backlash {best:.9g}; "
        f"catalogue search: motor {got.design['motor']:g}, backlash {got.objective:.9g}"
    )


if __name__ == "__main__":
    main()
