"""A study written outside the package, for tests/studies/test_new_study.py: how far the
multistart's answer depends on its seed. A new study is this module - a function over
the public API returning a typed record, and one command registered with
``optdesign.cli.command`` - plus one line naming the module in
``optdesign.cli.PLUGIN_MODULES``; nothing else changes."""

from __future__ import annotations

import argparse
import json
from dataclasses import asdict, dataclass

import optdesign as od
from optdesign.cli import command


@dataclass(frozen=True)
class SeedSpread:
    """The optimum of one problem found from several multistart seeds.

    Attributes
    ----------
    problem, objective
        What was solved.
    seeds, objectives
        Each seed and the objective its solve reached (internal units; None: no
        feasible design).
    best
        The least objective over the seeds.
    at_best
        How many seeds reached ``best`` within ``tolerance`` (relative).
    """

    problem: str
    objective: str
    seeds: tuple[int, ...]
    objectives: tuple[float | None, ...]
    best: float | None
    at_best: int
    tolerance: float


def seed_spread(problem, seeds=(0, 1, 2), starts: int = 2, tolerance: float = 1e-6) -> SeedSpread:
    """Solve ``problem`` once per seed with ``starts`` starts each (no ranges, no
    sensitivities: the optimum alone) and count the seeds that reach the best."""
    problem = od.load(problem)
    values = []
    for seed in seeds:
        result = od.solve(problem, starts=starts, seed=seed, ranges=False, diagnose=False)
        values.append(float(result.objective) if result.success else None)
    found = [v for v in values if v is not None]
    best = min(found) if found else None
    at_best = sum(
        1 for v in found if best is not None and v <= best + tolerance * max(abs(best), 1e-12)
    )
    return SeedSpread(
        problem.name,
        problem.objective_names[0],
        tuple(int(s) for s in seeds),
        tuple(values),
        best,
        at_best,
        tolerance,
    )


@command("seed-spread")
def _seed_spread_command(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("seed-spread", help="the optimum found from several multistart seeds")
    p.add_argument("file", help="problem file (TOML) or a shipped problem's name")
    p.add_argument("--seeds", type=int, default=3, help="seeds 0..N-1")
    p.add_argument("--starts", type=int, default=2, help="starts per seed")
    p.set_defaults(func=_run)


def _run(args) -> int:
    spread = seed_spread(args.file, range(args.seeds), args.starts)
    print(json.dumps(asdict(spread)))
    return 0 if spread.best is not None else 1
