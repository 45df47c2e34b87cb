"""The verdict on a step the catalogue motors cannot give: ``od.solve`` of
``fin_actuator_motor`` with the motor chosen from the catalogue (``[motor] catalogue =
"Yaskawa Sigma-7"``) at the rise times given, each once with its diagnosis (what a user
waits for) and once without (the search alone), with the search's NLP solves
(``details.catalogue.nlp_solves``: the same on any machine) and the motors the closed
forms exclude before it; then the shipped catalogue problems' optima and NLP solves.

    python benchmarks/motor/fast_step.py "40 ms" "50 ms" "60 ms" "72 ms" "100 ms"
"""

from __future__ import annotations

import argparse
import copy
import time
import tomllib
from pathlib import Path

import optdesign as od
from optdesign.problem.parameters import without_impossible_items

ROOT = Path(__file__).resolve().parents[2]


def _data(name: str) -> dict:
    return tomllib.loads((ROOT / "problems" / f"{name}.toml").read_text())


def _catalogue_motor(rise_time: str | None = None) -> dict:
    data = _data("fin_actuator_motor")
    data["motor"] = {k: v for k, v in data["motor"].items() if k != "designation"}
    data["motor"]["catalogue"] = "Yaskawa Sigma-7"
    if rise_time is not None:
        data["motion"]["rise_time"] = rise_time
    return data


def _solve(data: dict, **kw) -> tuple[float, od.Result]:
    problem = od.load(copy.deepcopy(data))
    t = time.perf_counter()
    result = od.solve(problem, ranges=False, sensitivities=False, **kw)
    return time.perf_counter() - t, result


def _nlps(result: od.Result) -> int | None:
    info = result.details.catalogue if result.details else None
    return None if info is None else info.nlp_solves


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("rise_times", nargs="*", default=["40 ms"])
    args = parser.parse_args()
    _solve(_catalogue_motor())  # the solvers built once, outside the figures
    print("| rise time | status | motor | NLP solves | search (s) | with diagnosis (s) |")
    print("|---|---|---|---|---|---|")
    for rise in args.rise_times:
        data = _catalogue_motor(rise)
        kept = without_impossible_items(od.load(copy.deepcopy(data)))[0].by_name["motor"]
        alone, r = _solve(data, diagnose=False)
        full, _ = _solve(data)
        motor = r.design.get("motor") if r.success else "-"
        print(
            f"| {rise} | {r.status} | {motor} (of {len(kept.values)} left) | {_nlps(r)} "
            f"| {alone:.1f} | {full:.1f} |",
            flush=True,
        )
    print("\n| problem | backlash (deg) | NLP solves |\n|---|---|---|")
    for label, data in (
        ("fin_actuator", _data("fin_actuator")),
        ("fin_actuator_motor", _data("fin_actuator_motor")),
        ("motor from the catalogue", _catalogue_motor()),
        ("fin_actuator_loop", _data("fin_actuator_loop")),
    ):
        _, r = _solve(data)
        print(f"| {label} | {r.objective:.10g} | {_nlps(r)} |", flush=True)


if __name__ == "__main__":
    main()
