"""Which solver for catalogue (discrete) problems: a seeded instance family, every contender
checked against enumeration.

Instances (each reproducible from (family, seed)): variants of the shipped
``fin_actuator`` (catalogue screw d0 x lead, ISO 2338 pins) and
``cs_min_backlash_catalogue`` (ISO 3408 leads, ISO 2338 pins) with a random hinge moment
(+-20 %), deflection range (+-25..32 deg), top of the mean-ratio band (240..280) and a
window of the catalogues (consecutive items), small enough to enumerate.

Contenders, in-process one after another (1 core):

- ``enumerate``: every item combination's NLP (4-start multistart each): the reference;
- ``bnb``: optdesign's default catalogue search (branch and bound, warm nodes);
- ``bonmin-B-BB`` / ``bonmin-B-OA`` / ``bonmin-B-Hyb``: Bonmin through CasADi on the
  one-hot encoding (``od.solve(..., solver="bonmin", options={"algorithm": ...})``);
- ``de``: SciPy differential evolution with ``integrality`` on the NumPy path (the
  bench's ``de`` configuration; seed 0; ``--de-limit`` seconds);
- ``ga``: pymoo's mixed-variable genetic algorithm (``MixedVariableGA``: a catalogue
  variable is a ``Choice`` of its items, the others ``Real``; the violation of the
  NumPy path's requirements as its one constraint; population 40, seed 0, stopped at
  ``--de-limit`` seconds or 200 generations).

Every answer is compared with enumeration's: ``gap`` = (objective - enumeration's) /
|enumeration's|; "worse" beyond 1e-6. Rows go to ``--out`` (JSON lines) as they come; the
summary table (median seconds, worst gap, answers worse than enumeration) and a
Dolan-More time profile are written at the end (``--summary``, ``--plot``).

    .venv/bin/python benchmarks/bench_catalogue_solvers.py [--seeds 0 1 2 3]
        [--out benchmarks/results/bench_catalogue_solvers.jsonl]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
import tomllib
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from optdesign.formulations.catalogue.search import solve_catalogue
from optdesign.problem import problem_from_dict

ROOT = Path(__file__).resolve().parents[1]
ISO_2338 = (4, 5, 6, 8, 10, 12, 16)
ISO_3408 = (2, 2.5, 3, 4, 5, 6, 8, 10)
CONTENDERS = ("enumerate", "bnb", "bonmin-B-BB", "bonmin-B-OA", "bonmin-B-Hyb", "de", "ga")
WORSE = 1e-6


def _window(rng, items, n):
    k = int(rng.integers(0, len(items) - n + 1))
    return [f"{v} mm" for v in items[k : k + n]]


def _common(rng, data) -> str:
    req = data["requirements"]
    req["hinge_moment"] = f"{500 * rng.uniform(0.8, 1.2):.1f} N*m"
    top = float(rng.uniform(25.0, 32.0))
    req["deflection"] = {"min": f"{-top:.2f} deg", "max": f"{top:.2f} deg", "points": 61}
    req["mean_ratio"] = {"min": 200, "max": float(round(rng.uniform(240.0, 280.0), 1))}
    return f"M={req['hinge_moment']}, +-{top:.1f} deg, ratio<={req['mean_ratio']['max']}"


def instance(family: str, seed: int):
    """The problem of ``(family, seed)`` and a one-line description."""
    rng = np.random.default_rng([25, seed, 0 if family == "fin" else 1])
    if family == "fin":
        data = tomllib.loads((ROOT / "problems" / "fin_actuator.toml").read_text())
        what = _common(rng, data)
        d0_lo = float(rng.choice([14.0, 16.0, 20.0]))
        data["variables"]["d0"] = {"catalogue": "HIWIN", "lower": f"{d0_lo} mm", "upper": "25 mm"}
        data["variables"]["d"] = {"values": _window(rng, ISO_2338[1:], 3)}
        what += f", d0>={d0_lo:g}, d in {data['variables']['d']['values']}"
    else:
        data = tomllib.loads((ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text())
        what = _common(rng, data)
        data["variables"]["p"] = {"values": _window(rng, ISO_3408, 3)}
        data["variables"]["d"] = {"values": _window(rng, ISO_2338, 4)}
        what += (
            f", p in {data['variables']['p']['values']}, d in {data['variables']['d']['values']}"
        )
    data["name"] = f"{family}-{seed}"
    return problem_from_dict(data), what


def mixed_variable_ga(problem, objective: str, time_limit: float, seed: int = 0) -> dict:
    """pymoo's MixedVariableGA on the NumPy path: the best design it finds (no proof)."""
    from pymoo.core.mixed import MixedVariableGA
    from pymoo.core.problem import ElementwiseProblem
    from pymoo.core.variable import Choice, Real
    from pymoo.optimize import minimize
    from pymoo.termination.collection import TerminationCollection
    from pymoo.termination.max_gen import MaximumGenerationTermination
    from pymoo.termination.max_time import TimeBasedTermination

    free = problem.free
    variables = {
        v.name: Choice(options=list(v.values)) if v.discrete else Real(bounds=(v.lower, v.upper))
        for v in free
    }

    class Catalogue(ElementwiseProblem):
        def __init__(self):
            super().__init__(vars=variables, n_obj=1, n_ieq_constr=1)

        def _evaluate(self, X, out, *args, **kwargs):
            ev = problem.evaluate(np.array([float(X[v.name]) for v in free]))
            f = float(np.ravel(ev.objectives[objective])[0])
            out["F"] = f if math.isfinite(f) else 1e300
            viol = float(np.ravel(ev.violation)[0])
            out["G"] = viol if math.isfinite(viol) else 1e300

    termination = TerminationCollection(
        MaximumGenerationTermination(200), TimeBasedTermination(time_limit)
    )
    res = minimize(Catalogue(), MixedVariableGA(pop_size=40), termination, seed=seed)
    if res.X is None:  # no feasible member
        return {"success": False, "objective": math.nan, "design": {}}
    x = np.array([float(res.X[v.name]) for v in free])
    ev = problem.evaluate(x)
    return {
        "success": float(np.ravel(ev.violation)[0]) <= 0.0,
        "objective": float(np.ravel(ev.objectives[objective])[0]),
        "design": {v.name: float(xk) for v, xk in zip(free, x, strict=True)},
    }


def run(contender: str, problem, de_limit: float):
    t0 = time.perf_counter()
    if contender == "ga":
        found = mixed_variable_ga(problem, problem.objective_names[0], de_limit)
        items = {v.name: found["design"].get(v.name) for v in problem.free if v.discrete}
        return {
            "status": "feasible" if found["success"] else "infeasible",
            "success": found["success"],
            "objective": found["objective"] if found["success"] else None,
            "items": items if found["success"] else None,
            "nlp_solves": None,
            "bonmin_status": None,
            "wall_s": round(time.perf_counter() - t0, 3),
        }
    if contender == "enumerate":
        res = solve_catalogue(problem, method="enumerate", agree=0)  # the reference: every start
    elif contender == "bnb":
        res = solve_catalogue(problem, method="bnb")
    elif contender.startswith("bonmin-"):
        algorithm = contender.removeprefix("bonmin-")
        res = solve_catalogue(problem, solver="bonmin", options={"algorithm": algorithm})
    else:
        from optdesign.studies.bench.configs import get_config

        res = get_config("de").run(problem, problem.objective_names[0], de_limit)
    wall = time.perf_counter() - t0
    info = res.details.catalogue
    minlp = info.minlp if info is not None else None
    items = {v.name: res.design.get(v.name) for v in problem.free if v.discrete}
    return {
        "status": res.status,
        "success": bool(res.success),
        "objective": float(res.objective) if res.success else None,
        "items": items if res.success else None,
        "nlp_solves": info.nlp_solves if info is not None else None,
        "bonmin_status": minlp.status if minlp is not None else None,
        "wall_s": round(wall, 3),
    }


def summary(rows: list[dict]) -> str:
    by_inst: dict[str, dict[str, dict]] = {}
    for r in rows:
        by_inst.setdefault(r["instance"], {})[r["contender"]] = r
    lines = [
        "| contender | instances | median s | max s | answers as enumeration | worse | no answer | median NLP solves |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for c in CONTENDERS:
        times, same, worse, none, solves = [], 0, 0, 0, []
        for runs in by_inst.values():
            r, ref = runs.get(c), runs.get("enumerate")
            if r is None or ref is None:
                continue
            times.append(r["wall_s"])
            if r.get("nlp_solves") is not None:
                solves.append(r["nlp_solves"])
            if ref["objective"] is None:
                same += r["objective"] is None
                continue
            if r["objective"] is None:
                none += 1
                continue
            gap = (r["objective"] - ref["objective"]) / abs(ref["objective"])
            if gap > WORSE:
                worse += 1
            else:
                same += 1
        if not times:
            continue
        med_solves = f"{np.median(solves):.0f}" if solves else "-"
        lines.append(
            f"| {c} | {len(times)} | {np.median(times):.2f} | {max(times):.2f} | {same} | "
            f"{worse} | {none} | {med_solves} |"
        )
    return "\n".join(lines)


def profile(rows: list[dict], path: Path) -> None:
    """Dolan-More profile of time: a run counts as solved when its answer equals
    enumeration's (within 1e-6); the others are at infinity."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    by_inst: dict[str, dict[str, dict]] = {}
    for r in rows:
        by_inst.setdefault(r["instance"], {})[r["contender"]] = r
    ratios: dict[str, list[float]] = {c: [] for c in CONTENDERS if c != "enumerate"}
    for runs in by_inst.values():
        ref = runs.get("enumerate")
        if ref is None or ref["objective"] is None:
            continue
        t = {}
        for c in ratios:
            r = runs.get(c)
            ok = (
                r is not None
                and r["objective"] is not None
                and (r["objective"] - ref["objective"]) / abs(ref["objective"]) <= WORSE
            )
            t[c] = r["wall_s"] if ok else math.inf
        best = min(t.values())
        for c in ratios:
            ratios[c].append(t[c] / best if math.isfinite(best) else math.inf)
    fig, ax = plt.subplots(figsize=(6, 4))
    taus = np.logspace(0, 2, 200)
    for c, rs in ratios.items():
        rs = np.array(rs)
        ax.step(taus, [(rs <= tau).mean() if len(rs) else 0 for tau in taus], where="post", label=c)
    ax.set_xscale("log")
    ax.set_xlabel("time / best time on the instance")
    ax.set_ylabel("fraction of instances solved to enumeration's optimum")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3])
    ap.add_argument("--families", nargs="+", default=["fin", "cs"])
    ap.add_argument("--contenders", nargs="+", default=list(CONTENDERS))
    ap.add_argument("--de-limit", type=float, default=30.0, help="DE wall-time limit (s)")
    ap.add_argument(
        "--out",
        type=Path,
        default=ROOT / "benchmarks" / "results" / "bench_catalogue_solvers.jsonl",
    )
    ap.add_argument("--summary-only", action="store_true", help="table and plot of --out")
    ap.add_argument(
        "--plot", type=Path, default=ROOT / "benchmarks" / "results" / "bench_catalogue_profile.png"
    )
    args = ap.parse_args()
    if not args.summary_only:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        for family in args.families:
            for seed in args.seeds:
                problem, what = instance(family, seed)
                for c in args.contenders:
                    row = {"instance": f"{family}-{seed}", "what": what, "contender": c}
                    row.update(run(c, problem, args.de_limit))
                    with args.out.open("a") as fh:
                        fh.write(json.dumps(row) + "\n")
                    print(json.dumps(row), flush=True)
    rows = [json.loads(line) for line in args.out.read_text().splitlines() if line.strip()]
    print(summary(rows))
    profile(rows, args.plot)


if __name__ == "__main__":
    main()
