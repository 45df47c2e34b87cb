"""``benchmarks/command_cost.py --pareto``: what ``optdesign pareto`` costs as a whole,
against the NSGA-II script of ``benchmarks/bench_overhead.py`` part (c), phase by phase.

See the docstring of ``command_cost.py`` for what is measured; the figures and the
command are in ``benchmarks/README.md`` ("The pareto command's fixed cost").
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from bench_overhead import NSGA2_SCRIPT

ROOT = Path(__file__).resolve().parents[1]
PHASES = ROOT / "benchmarks" / "pareto_phases.py"
OBJECTIVES = "ripple,backlash"
POINTS = "50"


def _front(folder: Path) -> tuple[list[dict], int]:
    """The first front's points (objectives and design) and its NLP solves."""
    front = json.loads((folder / "front.json").read_text())["fronts"][0]
    points = [{**p["objectives"], **p["design"]} for p in front["points"]]
    return points, int(front["n_solves"])


def _difference(a: list[dict], b: list[dict]) -> float:
    """Largest relative difference between two fronts' points (inf: not the same count)."""
    if len(a) != len(b):
        return float("inf")
    worst = 0.0
    for pa, pb in zip(a, b, strict=True):
        for k, v in pa.items():
            worst = max(worst, abs(v - pb[k]) / max(1.0, abs(v)))
    return worst


def _busiest(events: list[dict], name: str, until: float) -> float:
    """The largest sum over one process of the ``name`` spans that end by ``until``."""
    per: dict[int, float] = {}
    for e in events:
        if e["name"] == name and e["b"] <= until:
            per[e["pid"]] = per.get(e["pid"], 0.0) + e["b"] - e["a"]
    return max(per.values(), default=0.0)


def summarise(events: list[dict], wall: float) -> dict[str, float]:
    """The phases of one run (seconds) from its events (see pareto_phases.py)."""

    def ends(prefix: str) -> list[float]:
        return [e["b"] for e in events if e["name"].startswith(prefix)]

    def spans(prefix: str) -> list[float]:
        return [e["b"] - e["a"] for e in events if e["name"].startswith(prefix)]

    def one(name: str) -> dict:
        return next(e for e in events if e["name"] == name)

    main = one("command (cli.main)")
    pools = [
        e for e in events if e["name"].startswith("worker pool of") and "of 1 " not in e["name"]
    ]
    forked = pools[0]["b"] if pools else main["a"]
    anchors_end = max(ends("task anchor"))
    eps_end = max(ends("task eps"), default=anchors_end)
    tasks_end = max(ends("task "))
    front = one("the front (optdesign.pareto)")
    out = {
        "start-up: interpreter, imports to the command": main["a"],
        "file, checks, formulation: to the workers' fork": forked - main["a"],
        "anchors (multistarts, tie-breaks)": anchors_end - forked,
        "  anchor multistarts (each)": statistics.mean(spans("task anchor-multistart")),
        "  anchor tie-breaks (each)": statistics.mean(spans("task anchor ")),
        "  solver builds in the workers (sum)": sum(spans("solver build")),
        "  NLP solves in the anchors, busiest worker (builds included)": _busiest(
            events, "NLP solve", anchors_end
        ),
        "chain points": eps_end - anchors_end,
        "  per point (mean of a worker's task)": statistics.mean(spans("task eps") or [0.0]),
        "  NLP solve per point (mean)": statistics.mean(
            [e["b"] - e["a"] for e in events if e["name"] == "NLP solve" and e["a"] >= anchors_end]
            or [0.0]
        ),
        "polish": tasks_end - eps_end,
        "front's end (records, metrics, workers stopped)": front["b"] - tasks_end,
        "front.csv + front.json": sum(spans("front.csv")) + sum(spans("front.json")),
        "report.html (the page, parent)": sum(spans("report.html")),
        "front.png drawn (figure worker)": sum(spans("front.png: drawn in")),
        "figure warm-up (imports; off the critical path when done in time)": sum(
            spans("figure worker: warm-up")
        ),
        "files: after the front to the command's end": main["b"] - front["b"],
        "exit": wall - main["b"],
        "whole run": wall,
    }
    warm = [e for e in events if e["name"].startswith("figure worker: warm-up")]
    if warm:
        out["figure warm-up starts after the fork"] = warm[0]["a"] - forked
    return out


def phase_run(file: Path, env: dict[str, str], work: Path, k: int, extra: list[str]) -> dict:
    events = work / f"events{k}.jsonl"
    out = work / f"phases{k}"
    launched = time.time()
    cmd = [sys.executable, str(PHASES), str(events), repr(launched), "--", "pareto", str(file)]
    cmd += ["--objectives", OBJECTIVES, "--points", POINTS, "--no-progress", "--out", str(out)]
    done = subprocess.run([*cmd, *extra], cwd=work, env=env, capture_output=True, text=True)
    wall = time.time() - launched
    if done.returncode != 0:
        raise RuntimeError(f"phase run failed: {done.stderr[-800:]}")
    lines = [json.loads(line) for line in events.read_text().splitlines()]
    return summarise(lines, wall)


def pareto_cost(args, results: Path, wall: Callable[..., float]) -> int:
    """Time the variants in interleaved rounds, then the phases; print and store."""
    problem = args.problem or "cs_min_backlash"
    file = ROOT / "problems" / f"{problem}.toml"
    work = Path(tempfile.mkdtemp(prefix="pareto_cost_"))
    base_env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    if args.bytecode:
        # compiled once and reused, as an installed package's modules are (the agents'
        # environment sets PYTHONDONTWRITEBYTECODE: every run compiles from source)
        base_env.pop("PYTHONDONTWRITEBYTECODE", None)
        base_env["PYTHONPYCACHEPREFIX"] = str(work / "pyc")
    ours = {**base_env, "PYTHONPATH": str(ROOT)}
    command = [sys.executable, "-m", "optdesign", "pareto", str(file), "--objectives"]
    command += [OBJECTIVES, "--points", POINTS, "--no-progress"]
    alone = ["--no-plot", "--no-report"]
    variants: dict[str, tuple[list[str] | None, dict[str, str]]] = {
        "NSGA-II script (pymoo 100 x 500)": (None, ours),
        "optdesign pareto (default)": (command, ours),
        "optdesign pareto --no-plot --no-report": ([*command, *alone], ours),
        "the same, --workers 1": ([*command, *alone, "--workers", "1"], ours),
    }
    if args.baseline is not None:
        theirs = {**base_env, "PYTHONPATH": str(args.baseline.resolve())}
        variants["baseline tree: default"] = (command, theirs)
        variants["baseline tree: --no-plot --no-report"] = ([*command, *alone], theirs)
    if args.bytecode:  # one short run of each, to compile
        for k, (cmd, env) in enumerate(variants.values()):
            short = NSGA2_SCRIPT.replace("500", "1")
            first = [sys.executable, "-c", short, str(file)] if cmd is None else cmd
            wall([*first, *(["--out", str(work / f"warm{k}")] if cmd else [])], env, work)
    times: dict[str, list[float]] = {name: [] for name in variants}
    fronts: dict[str, tuple[list[dict], int]] = {}
    for r in range(args.rounds):
        for k, (name, (cmd, env)) in enumerate(variants.items()):
            if cmd is None:
                times[name].append(wall([sys.executable, "-c", NSGA2_SCRIPT, str(file)], env, work))
                continue
            out = work / f"out{r}-{k}"
            times[name].append(wall([*cmd, "--out", str(out)], env, work))
            fronts.setdefault(name, _front(out))
    # interleaved as the rounds are: ours, ours alone, the baseline's (the same probes)
    runs: dict[str, list[dict[str, float]]] = {"phases_default_s": [], "phases_alone_s": []}
    if args.baseline is not None:
        runs["phases_baseline_default_s"] = []
    for k in range(args.phase_runs):
        runs["phases_default_s"].append(phase_run(file, ours, work, k, []))
        runs["phases_alone_s"].append(phase_run(file, ours, work, 100 + k, alone))
        if args.baseline is not None:
            runs["phases_baseline_default_s"].append(phase_run(file, theirs, work, 200 + k, []))
    peer = statistics.median(times["NSGA-II script (pymoo 100 x 500)"])
    reference, _ = fronts["optdesign pareto (default)"]
    row = {
        "label": args.label,
        "problem": problem,
        "rounds": args.rounds,
        "bytecode": bool(args.bytecode),
        "load_at_end": os.getloadavg()[0],
        "median_s": {k: statistics.median(v) for k, v in times.items()},
        "over_nsga2": {k: statistics.median(v) / peer for k, v in times.items()},
        "front_difference": {k: _difference(reference, f[0]) for k, f in fronts.items()},
        "nlp_solves": {k: f[1] for k, f in fronts.items()},
        **{
            key: {k: statistics.median(p.get(k, 0.0) for p in ps) for k in ps[0]}
            for key, ps in runs.items()
        },
        "when": time.strftime("%Y-%m-%d %H:%M"),
    }
    results.parent.mkdir(parents=True, exist_ok=True)
    with results.open("a") as fh:
        fh.write(json.dumps(row) + "\n")
    print(f"{'work':45s} {'median (s)':>10s} {'/ NSGA-II':>9s} {'solves':>6s} {'front diff':>10s}")
    for k in times:
        solves = row["nlp_solves"].get(k, "")
        diff = row["front_difference"].get(k)
        shown = "" if diff is None else f"{diff:.1e}"
        print(
            f"{k:45s} {row['median_s'][k]:10.3f} {row['over_nsga2'][k]:9.2f} {solves!s:>6s} {shown:>10s}"
        )
    for key in runs:
        title = key.removeprefix("phases_").removesuffix("_s").replace("_", " ")
        print(f"\nphases, {title} (medians of {args.phase_runs} runs, s):")
        for k, v in row[key].items():
            print(f"  {k:70s} {v:7.3f}")
    return 0
