"""What ``optdesign solve`` costs as a whole against a plain CasADi script of the same
8-start multistart (issue 36: the command's fixed cost).

The peer: a fresh interpreter that imports CasADi and NumPy, loads the problem's NLP
(exported once from optdesign as a serialized CasADi Function with its bounds: what a
hand-written script would build in a few milliseconds), runs Ipopt from 8 scrambled
Sobol starts in the box, and writes the best point as JSON. Ours, each in a fresh
interpreter with ``PYTHONPATH`` set to the tree:

* ``optdesign solve FILE --out DIR``: the default command (result.json, solution.png,
  report.html, the ranges of the optimal set and the sensitivities);
* the same with ``--no-plot --no-report`` (result.json alone);
* with ``--baseline TREE``, the default command of another tree (e.g. ``git worktree
  add /tmp/prev HEAD~1``).

Rounds are interleaved (each round runs every variant once) so that all see the same
machine; the medians and their ratios to the peer are printed and appended to
``benchmarks/results/command_cost.jsonl`` (one line a run).

    python benchmarks/command_cost.py [--problem cs_min_ripple] [--rounds 7] [--baseline TREE]

With ``--pareto``, the same for ``optdesign pareto FILE --objectives ripple,backlash
--points 50`` (default problem cs_min_backlash) against the NSGA-II script of part (c) of
``benchmarks/bench_overhead.py`` (pymoo, population 100, 500 generations, NumPy path):
the default command (front.csv, front.json, front.png, report.html), the front alone
(``--no-plot --no-report``), the front alone on one worker, and with ``--baseline`` the
first two of another tree; then the command's phases from ``--phase-runs`` runs of
``benchmarks/pareto_phases.py`` (a timestamp at each phase, in the parent and in the
forked workers), the NLP solves of the front, and every command's front compared with
the first default run's (objectives and designs, relative 1e-9).

    python benchmarks/command_cost.py --pareto [--rounds 5] [--phase-runs 3] [--baseline TREE] [--bytecode]
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

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "command_cost.jsonl"

PEER = r"""
import json, sys
import casadi as ca
import numpy as np
folder = sys.argv[1]
F = ca.Function.load(folder + "/nlp.casadi")
d = np.load(folder + "/nlp.npz")
z = ca.MX.sym("z", F.size1_in(0)); p = ca.MX.sym("p", F.size1_in(1))
f, g = F(z, p)
solver = ca.nlpsol("s", "ipopt", {"x": z, "p": p, "f": f, "g": g},
                   {"ipopt.print_level": 0, "print_time": False})
best = None
for z0 in d["starts"]:
    sol = solver(x0=z0, p=d["p"], lbx=d["lbz"], ubx=d["ubz"], lbg=d["lbg"], ubg=d["ubg"])
    ok = solver.stats()["success"]
    if ok and (best is None or float(sol["f"]) < best[0]):
        best = (float(sol["f"]), np.asarray(sol["x"]).ravel().tolist())
with open(folder + "/peer.json", "w") as out:
    json.dump({"f": None if best is None else best[0], "z": None if best is None else best[1]}, out)
"""


def export_nlp(problem_name: str, folder: Path, starts: int = 8, seed: int = 0) -> None:
    """Write the problem's NLP (its default objective) as a CasADi Function and its
    bounds, parameter vector and ``starts`` Sobol starts, for the peer script."""
    import casadi as ca
    import numpy as np
    from scipy.stats import qmc

    import optdesign as od
    from optdesign.formulations.nlp.solve import formulation_for

    problem = od.load(problem_name)
    nlp = formulation_for(problem)
    bounds = nlp.bounds()
    p = nlp.params(nlp.target())
    ca.Function("nlp", [nlp.z, nlp.p], [nlp.f, nlp.g]).save(str(folder / "nlp.casadi"))
    unit = qmc.Sobol(nlp.n_design, scramble=True, seed=seed).random(starts)
    lo, hi = bounds.lbz[: nlp.n_design], bounds.ubz[: nlp.n_design]
    design = lo + unit * (hi - lo)
    z0 = np.array([nlp.z_from_x(nlp.x_lo + nlp.x_span * d) for d in design])
    np.savez(
        folder / "nlp.npz",
        p=p,
        lbz=bounds.lbz,
        ubz=bounds.ubz,
        lbg=bounds.lbg,
        ubg=bounds.ubg,
        starts=z0,
        scale=nlp.target_scales[nlp.targets.index(nlp.default_target)],
    )


def _wall(cmd: list[str], env: dict[str, str], cwd: Path) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if proc.returncode not in (0, 1):
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}): {proc.stderr[-800:]}")
    return dt


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--problem", default=None, help="default cs_min_ripple (solve)")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--baseline", type=Path, help="another tree's default command")
    parser.add_argument("--label", default="")
    parser.add_argument("--pareto", action="store_true", help="the pareto command")
    parser.add_argument("--phase-runs", type=int, default=3, help="--pareto: phase runs")
    parser.add_argument(
        "--bytecode",
        action="store_true",
        help="--pareto: keep compiled bytecode (as an installed package does), after a warm-up",
    )
    args = parser.parse_args(argv)
    if args.pareto:
        from pareto_cost import pareto_cost

        return pareto_cost(args, RESULTS, _wall)
    args.problem = args.problem or "cs_min_ripple"
    work = Path(tempfile.mkdtemp(prefix="command_cost_"))
    export_nlp(args.problem, work)
    file = ROOT / "problems" / f"{args.problem}.toml"
    base_env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    ours = {**base_env, "PYTHONPATH": str(ROOT)}
    command = [sys.executable, "-m", "optdesign", "solve", str(file)]
    variants: dict[str, tuple[list[str], dict[str, str]]] = {
        "plain CasADi, 8 starts": ([sys.executable, "-c", PEER, str(work)], base_env),
        "optdesign solve (default)": (command, ours),
        "optdesign solve --no-plot --no-report": ([*command, "--no-plot", "--no-report"], ours),
    }
    if args.baseline is not None:
        theirs = {**base_env, "PYTHONPATH": str(args.baseline.resolve())}
        variants["baseline tree: optdesign solve (default)"] = (command, theirs)
    times: dict[str, list[float]] = {name: [] for name in variants}
    for r in range(args.rounds):
        for name, (cmd, env) in variants.items():
            out = work / f"out{r}-{len(times[name])}-{abs(hash(name))}"
            full = cmd if name.startswith("plain") else [*cmd, "--out", str(out)]
            times[name].append(_wall(full, env, work))
    peer = statistics.median(times["plain CasADi, 8 starts"])
    import numpy as np

    peer_f = json.loads((work / "peer.json").read_text())["f"]
    peer_value = None if peer_f is None else peer_f * float(np.load(work / "nlp.npz")["scale"])
    last = work / f"out{args.rounds - 1}-{args.rounds - 1}-{abs(hash('optdesign solve (default)'))}"
    ours_value = json.loads((last / "result.json").read_text())["objective"]["value"]
    row = {
        "label": args.label,
        "problem": args.problem,
        "rounds": args.rounds,
        "median_s": {k: statistics.median(v) for k, v in times.items()},
        "over_peer": {k: statistics.median(v) / peer for k, v in times.items()},
        "objective": {"peer": peer_value, "optdesign": ours_value},
        "when": time.strftime("%Y-%m-%d %H:%M"),
    }
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    with RESULTS.open("a") as fh:
        fh.write(json.dumps(row) + "\n")
    print(f"{'work':45s} {'median (s)':>10s} {'/ peer':>7s}")
    for k in times:
        print(f"{k:45s} {row['median_s'][k]:10.3f} {row['over_peer'][k]:7.2f}")
    print(f"objective: peer {peer_value}, optdesign {ours_value}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
