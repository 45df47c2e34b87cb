"""The global search against references written separately: many seeds of ``od.solve``
on mechanisms with several local optima (tests/multimodal_mechanisms) and on the shipped
problems, each run beside the plain multistart optdesign used before (8 Sobol starts,
stop when 3 agree), in the same process.

For every (case, seed) it records, as it goes (``results.jsonl``; a rerun resumes and
computes only what is missing):

- the global search's value, its relative gap to the reference optimum, the odds it
  reported (``p_better``, ``p_better_any``), starts, optima seen, why it stopped, time;
- the plain multistart's value, gap and time.

``--summary`` prints per case: seeds at the reference (gap <= 1e-6), time ratio of the
global search to the plain multistart (median), and the calibration of the odds: for the
runs that report a probability of a better optimum below a threshold, how often one was
missed. Run from the repository root:

    python benchmarks/global_search/run.py --seeds 10
    python benchmarks/global_search/run.py --summary
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))

import optdesign as od  # noqa: E402
from optdesign.formulations.nlp.solve import finish, solver_for, start_points  # noqa: E402
from optdesign.solvers.multistart import multistart  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results.jsonl"
GAP = 1e-6


def _multimodal(module: str, objective: str):
    import importlib

    mod = importlib.import_module(f"multimodal_mechanisms.{module}")
    ref = json.loads((ROOT / "tests/multimodal_mechanisms" / f"{module}_optimum.json").read_text())
    optima = ref.get("optima", ref)  # double_rocker's record nests them under "optima"
    return lambda: od.load(mod.problem(objective)), float(optima[objective]["value"])


def cases() -> dict:
    out = {}
    for module in ("knee", "six_bar", "double_rocker"):
        for objective in ("backlash", "ripple"):
            path = ROOT / "tests/multimodal_mechanisms" / f"{module}_optimum.json"
            if path.exists():
                out[f"{module}:{objective}"] = _multimodal(module, objective)
    for name in ("cs_min_backlash", "cs_min_ripple", "pivot_min_backlash"):
        out[name] = (lambda n=name: od.load(ROOT / "problems" / f"{n}.toml"), None)
    return out


def plain_multistart(problem, seed: int):
    """optdesign's multistart before the global search: the declared start (else the
    middle of the bounds) and 7 scrambled-Sobol points, stopping once 3 agree."""
    objective = problem.objective_names[0]
    backend = solver_for(problem, None, None, tuple(problem.objective_names))
    target = backend.nlp.target(objective)
    result = multistart(
        lambda x: backend.solve(x, target), start_points(problem, 8, seed), seed=seed, agree=3
    )
    return finish(problem, result, objective)


def run_one(make, seed: int, plain: bool = True) -> dict:
    problem = make()
    t0 = time.perf_counter()
    new = od.solve(problem, seed=seed, diagnose=False, ranges=False)
    t_new = time.perf_counter() - t0
    old, t_old = None, None
    if plain:
        problem = make()
        t0 = time.perf_counter()
        old = plain_multistart(problem, seed)
        t_old = time.perf_counter() - t0
    ms, odds = new.multistart, new.multistart.odds
    return {
        "value": new.objective if new.success else None,
        "status": new.status,
        "time_s": t_new,
        "starts": ms.n_starts,
        "counted": ms.counted,
        "optima": ms.optima,
        "stop": ms.stop,
        "p_better": None if odds is None else odds.p_better,
        "p_better_any": None if odds is None else odds.p_better_any,
        "plain_value": old.objective if old is not None and old.success else None,
        "plain_time_s": t_old,
    }


def compute(seeds: range, only: list[str] | None, plain: bool = True) -> None:
    done = set()
    if RESULTS.exists():
        for line in RESULTS.read_text().splitlines():
            rec = json.loads(line)
            done.add((rec["case"], rec["seed"]))
    for name, (make, _) in cases().items():
        if only and name not in only:
            continue
        for seed in seeds:
            if (name, seed) in done:
                continue
            rec = {"case": name, "seed": seed, **run_one(make, seed, plain)}
            with RESULTS.open("a") as fh:
                fh.write(json.dumps(rec) + "\n")
            print(name, seed, rec["value"], rec["stop"], f"{rec['time_s']:.2f}s", flush=True)


def _gap(value, ref) -> float:
    if value is None:
        return math.inf
    return (value - ref) / abs(ref)


def summary() -> str:
    recs = [json.loads(line) for line in RESULTS.read_text().splitlines()]
    refs = {name: ref for name, (_, ref) in cases().items()}
    lines = [
        "| case | seeds | global search at the reference | plain multistart at it | "
        "time ratio (median) | starts (median) | p_better (median) |",
        "|---|---|---|---|---|---|---|",
    ]
    calib = []
    for name in dict.fromkeys(r["case"] for r in recs):
        rows = [r for r in recs if r["case"] == name]
        ref = refs.get(name)
        if ref is None:  # a shipped problem: the best value any run found
            ref = min(v for r in rows for v in (r["value"], r["plain_value"]) if v is not None)
        hit = [_gap(r["value"], ref) <= GAP for r in rows]
        with_plain = [r for r in rows if r["plain_time_s"] is not None]
        plain = [_gap(r["plain_value"], ref) <= GAP for r in with_plain]
        ratios = [r["time_s"] / r["plain_time_s"] for r in with_plain]
        ratio = statistics.median(ratios) if ratios else float("nan")
        pb = [r["p_better"] for r in rows if r["p_better"] is not None]
        lines.append(
            f"| {name} | {len(rows)} | {sum(hit)}/{len(rows)} | {sum(plain)}/{len(with_plain)} | "
            f"{ratio:.2f} | {statistics.median(r['starts'] for r in rows):g} | "
            f"{statistics.median(pb) if pb else float('nan'):.3g} |"
        )
        calib += [(r["p_better"], r["p_better_any"], not h) for r, h in zip(rows, hit, strict=True)]
    lines += [
        "",
        "Calibration (all runs): runs reporting p below a threshold, and how many missed:",
        "",
    ]
    lines += ["| threshold | estimate | runs | missed | missed share |", "|---|---|---|---|---|"]
    for key, label in ((0, "p_better"), (1, "p_better_any")):
        for threshold in (0.01, 0.05, 0.1, 0.2):
            sel = [c for c in calib if c[key] is not None and c[key] < threshold]
            missed = sum(c[2] for c in sel)
            share = missed / len(sel) if sel else float("nan")
            lines.append(f"| {threshold:g} | {label} | {len(sel)} | {missed} | {share:.3f} |")
    mean_p = np.mean([c[0] for c in calib if c[0] is not None])
    lines.append("")
    lines.append(
        f"Mean reported p_better {mean_p:.4f} against the share of runs that missed the "
        f"reference {np.mean([c[2] for c in calib]):.4f} ({len(calib)} runs)."
    )
    return "\n".join(lines)


def main() -> None:
    global RESULTS
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--case", action="append", help="only these cases")
    parser.add_argument("--summary", action="store_true")
    parser.add_argument("--results", type=Path, help=f"the record (default {RESULTS.name})")
    parser.add_argument(
        "--no-plain", action="store_true", help="skip the plain multistart beside each run"
    )
    args = parser.parse_args()
    if args.results is not None:
        RESULTS = args.results.resolve()
    if args.summary:
        print(summary())
        return
    compute(range(args.first_seed, args.first_seed + args.seeds), args.case, not args.no_plain)
    print(summary())


if __name__ == "__main__":
    main()
