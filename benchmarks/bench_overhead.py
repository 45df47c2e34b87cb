"""What a user waits for: one solve, the whole commands, and where the time goes (issue 15).

Measures in one run, as ratios between things timed on the same machine in the same run
(interleaved repeats, medians):

(a) one in-process solve of each shipped NLP problem (solver built once, declared start)
    against a plain CasADi script of the same NLP (``nlpsol`` with Ipopt's defaults), same
    optimum to 1e-6; with each solve's floor: iterations x (evaluations of one iteration
    + one sparse LDL factorisation of its KKT matrix by CasADi's own ``ldl``);
(b) the whole ``optdesign solve problems/cs_min_backlash.toml --json`` command against
    ``python -c "import casadi"`` plus the in-process multistart, with the phases of the
    command (imports, load, build, multistart, ranges, report) timed in a fresh process;
(c) the whole ``optdesign pareto problems/cs_min_backlash.toml --objectives
    ripple,backlash --points 50`` command against a plain pymoo NSGA-II script
    (population 100, 500 generations, on the NumPy path of the same problem), with the
    command's hypervolume as a fraction of the dense reference front's;
(d) with ``--suite``, the wall time of the default ``optdesign bench`` suite.

    PYTHONPATH=$PWD python benchmarks/bench_overhead.py --label after [--suite] [--bytecode]

The commands run with this interpreter and this environment (``PYTHONPATH`` picks the
source tree, an absolute path, so ``PYTHONPATH=/path/to/old/tree`` measures an older version with this
same script). Results go to ``benchmarks/results/overhead.json`` under ``--label``, one
part at a time (a rerun skips the parts already there; ``--redo`` measures again).
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
PROBLEMS = ROOT / "problems"
OUT = ROOT / "benchmarks" / "results" / "overhead.json"
REFERENCE = ROOT / "benchmarks" / "data" / "cs_min_backlash_reference_front.csv"
SHIPPED = ["cs_min_ripple", "cs_min_backlash", "fork_min_backlash", "pivot_min_backlash"]
OBJECTIVES = ["ripple", "backlash"]

PHASES = r"""
import json, sys, time
t = [time.perf_counter()]
import casadi  # noqa: F401
t.append(time.perf_counter())
from optdesign.problem import load_problem
from optdesign.formulations.nlp.solve import formulation_for, solver_for, solve_nlp, optimal_ranges, finish
t.append(time.perf_counter())
problem = load_problem(sys.argv[1])
t.append(time.perf_counter())
formulation_for(problem)
t.append(time.perf_counter())
solver_for(problem)
t.append(time.perf_counter())
result = solve_nlp(problem)
t.append(time.perf_counter())
result.ranges = optimal_ranges(problem, result)
t.append(time.perf_counter())
from optdesign.reports.result_json import result_json  # what the command prints
text = result_json(result)
t.append(time.perf_counter())
names = ["import casadi", "import optdesign", "load file", "build NLP", "build solver",
         "multistart", "ranges", "report JSON"]
print(json.dumps({
    "phases_s": dict(zip(names, [b - a for a, b in zip(t, t[1:])])),
    "starts": result.multistart.n_starts,
    "modules": sorted(m for m in ("scipy.stats", "pint", "dask", "matplotlib", "pymoo", "cvxpy")
                      if m in sys.modules),
}))
"""

NSGA2_SCRIPT = r"""
import sys
from optdesign.problem import load_problem
from optdesign.studies.pareto import NSGA2, compute_front
problem = load_problem(sys.argv[1])
compute_front(problem, ["ripple", "backlash"], method=NSGA2(100, 500, seed=0))
"""


#: Commands run from a neutral folder: ``python -m``/``-c`` put the working folder first on
#: sys.path, and PYTHONPATH alone must decide which optdesign is measured.
NEUTRAL = Path(tempfile.gettempdir())


#: The environment of every command: this one, or with ``--bytecode`` one that keeps
#: compiled bytecode (in a temporary folder) as an installed package does.
ENV = os.environ.copy()


def use_bytecode(folder: str) -> None:
    """Let the commands write and reuse bytecode under ``folder`` (PYTHONDONTWRITEBYTECODE
    makes every run compile optdesign's ~100 modules from source, ~0.1 s; ``pip install``
    compiles them once)."""
    ENV.pop("PYTHONDONTWRITEBYTECODE", None)
    ENV["PYTHONPYCACHEPREFIX"] = folder


def wall(cmd: list[str], cwd: Path = NEUTRAL) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=ENV)
    dt = time.perf_counter() - t0
    if proc.returncode not in (0, 1):
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}): {proc.stderr[-500:]}")
    return dt


def kkt_ldl_time(solver, z, p, lam_g, repeats: int = 200) -> float:
    """Seconds of one numeric LDL factorisation + solve of the KKT matrix at ``z`` with
    CasADi's own sparse ``ldl`` (symbolic analysis done once, as a solver would)."""
    import casadi as ca
    import numpy as np

    hess = solver.get_function("nlp_hess_l")
    jac = solver.get_function("nlp_jac_g")
    H = hess(z, p, 1.0, lam_g)
    H = ca.DM(H[0] if isinstance(H, list | tuple) else H)
    J = jac(z, p)
    J = ca.DM(J[1] if isinstance(J, list | tuple) else J)
    n, m = H.shape[0], J.shape[0]
    H = ca.triu(H) + ca.triu(H, False).T  # Ipopt's Hessian is the upper triangle
    K = ca.blockcat([[H + 1e-8 * ca.DM.eye(n), J.T], [J, -1e-8 * ca.DM.eye(m)]])
    lin = ca.Linsol("kkt", "ldl", K.sparsity())
    rhs = np.ones(n + m)
    lin.sfact(K)
    t0 = time.perf_counter()
    for _ in range(repeats):
        lin.nfact(K)
        lin.solve(K, rhs)
    return (time.perf_counter() - t0) / repeats


def part_a(repeats: int) -> dict:
    import casadi as ca

    from optdesign.formulations.nlp.solve import solver_for
    from optdesign.problem import load_problem

    out = {}
    for name in SHIPPED:
        problem = load_problem(PROBLEMS / f"{name}.toml")
        ours = solver_for(problem)
        nlp = ours.nlp
        target = nlp.target(None)
        b = nlp.bounds()
        p = nlp.params(target, b.parameters)
        z0 = nlp.z_from_x(problem.start())
        plain = ca.nlpsol(
            "plain",
            "ipopt",
            {"x": nlp.z, "p": nlp.p, "f": nlp.f, "g": nlp.g},
            {"print_time": False, "ipopt": {"print_level": 0, "sb": "yes"}},
        )
        args = {"x0": z0, "p": p, "lbx": b.lbz, "ubx": b.ubz, "lbg": b.lbg, "ubg": b.ubg}
        t_ours, t_plain = [], []
        for _ in range(repeats):
            t0 = time.perf_counter()
            r = ours.solve(nlp.start(z0=z0), target, b)
            t_ours.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            sol = plain(**args)
            t_plain.append(time.perf_counter() - t0)
        f_plain = float(sol["f"])
        # the same objective value from both (f is the weighted, scaled objective)
        zo = r.raw["z"]
        f_ours = float(ca.Function("f", [nlp.z, nlp.p], [nlp.f])(zo, p))
        stats = ours.solver.stats()
        iters = int(stats["iter_count"])
        t_eval = sum(
            v for k, v in stats.items() if k.startswith("t_wall_nlp_") and isinstance(v, float)
        )
        ldl = kkt_ldl_time(ours.solver, zo, p, r.raw["lam_g"])
        med_o, med_p = statistics.median(t_ours), statistics.median(t_plain)
        out[name] = {
            "ours_s": med_o,
            "plain_casadi_s": med_p,
            "ratio_ours_over_plain": med_o / med_p,
            "objective": r.objective,
            "same_optimum": abs(f_ours - f_plain) <= 1e-6 * max(abs(f_plain), 1e-12),
            "f_ours": f_ours,
            "f_plain": f_plain,
            "iterations": iters,
            "plain_iterations": int(plain.stats()["iter_count"]),
            "eval_per_iteration_s": t_eval / max(iters, 1),
            "ldl_kkt_s": ldl,
            "kkt_size": int(len(zo) + len(r.raw["lam_g"])),
            "floor_s": iters * (t_eval / max(iters, 1) + ldl),
            "per_iteration_s": med_o / max(iters, 1),
        }
        print(name, json.dumps(out[name]), flush=True)
    return out


def part_b(repeats: int) -> dict:
    from optdesign.formulations.nlp.solve import solve_nlp
    from optdesign.problem import load_problem

    file = str(PROBLEMS / "cs_min_backlash.toml")
    cmd = [sys.executable, "-m", "optdesign", "solve", file, "--json"]
    imp = [sys.executable, "-c", "import casadi"]
    problem = load_problem(file)
    solve_nlp(problem)  # build once
    t_cmd, t_imp, t_ms = [], [], []
    for _ in range(repeats):
        t_cmd.append(wall(cmd))
        t_imp.append(wall(imp))
        t0 = time.perf_counter()
        res = solve_nlp(problem)
        t_ms.append(time.perf_counter() - t0)
    phases = [
        json.loads(
            subprocess.run(
                [sys.executable, "-c", PHASES, file],
                cwd=NEUTRAL,
                capture_output=True,
                text=True,
                check=True,
                env=ENV,
            )
            .stdout.strip()
            .splitlines()[-1]
        )
        for _ in range(max(1, repeats // 2))
    ]
    phase_med = {
        k: statistics.median(ph["phases_s"][k] for ph in phases) for k in phases[0]["phases_s"]
    }
    help_t = [wall([sys.executable, "-m", "optdesign", "--help"]) for _ in range(repeats)]
    c, i, m = (statistics.median(x) for x in (t_cmd, t_imp, t_ms))
    out = {
        "command_s": c,
        "import_casadi_s": i,
        "multistart_s": m,
        "starts_run": res.multistart.n_starts,
        "ratio_command_over_floor": c / (i + m),
        "help_s": statistics.median(help_t),
        "phases_s": phase_med,
        "modules_imported": phases[0]["modules"],
    }
    print("solve command", json.dumps(out), flush=True)
    return out


def part_c(repeats: int) -> dict:
    import numpy as np

    from optdesign.problem import load_problem
    from optdesign.reports.front_files import read_front_csv
    from optdesign.studies.pareto.metrics import hypervolume, non_dominated, reference_point

    problem = load_problem(PROBLEMS / "cs_min_backlash.toml")  # front.csv: ripple in %
    R = read_front_csv(REFERENCE, OBJECTIVES, problem)
    R = R[non_dominated(R)]
    ref = reference_point(R)
    hv_ref = hypervolume(R, ref)
    file = str(PROBLEMS / "cs_min_backlash.toml")
    t_cmd, t_ns, hv = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeats):
            out = Path(tmp) / f"front{k}"
            cmd = [sys.executable, "-m", "optdesign", "pareto", file, "--objectives"]
            cmd += ["ripple,backlash", "--points", "50", "--out", str(out), "--no-progress"]
            t_cmd.append(wall(cmd))
            F = read_front_csv(out / "front.csv", OBJECTIVES, problem)
            hv.append(hypervolume(F[non_dominated(F)], ref) / hv_ref)
            t_ns.append(wall([sys.executable, "-c", NSGA2_SCRIPT, file]))
    c, n = statistics.median(t_cmd), statistics.median(t_ns)
    res = {
        "command_s": c,
        "nsga2_script_s": n,
        "ratio_command_over_nsga2": c / n,
        "hv_ratio": float(np.min(hv)),
        "command_runs_s": t_cmd,
        "nsga2_runs_s": t_ns,
    }
    print("pareto command", json.dumps(res), flush=True)
    return res


def part_d() -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        t = wall([sys.executable, "-m", "optdesign", "bench", "--out", tmp, "--no-progress"])
    res = {"suite_wall_s": t}
    print("bench suite", json.dumps(res), flush=True)
    return res


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--label", default="after", help="key of this run in the results")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--parts", default="a,b,c", help="comma list of a, b, c, d")
    ap.add_argument("--suite", action="store_true", help="also part d (minutes)")
    ap.add_argument("--redo", action="store_true", help="measure parts already stored")
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument(
        "--bytecode",
        action="store_true",
        help="commands keep compiled bytecode (as installed), after one warm-up run each",
    )
    args = ap.parse_args()
    if args.bytecode:
        use_bytecode(tempfile.mkdtemp(prefix="overhead-pyc-"))
        file = str(PROBLEMS / "cs_min_backlash.toml")
        with tempfile.TemporaryDirectory() as tmp:
            wall([sys.executable, "-m", "optdesign", "solve", file, "--json"])
            wall([sys.executable, "-c", NSGA2_SCRIPT.replace("500", "1"), file])
            cmd = [sys.executable, "-m", "optdesign", "pareto", file, "--objectives"]
            wall([*cmd, "ripple,backlash", "--points", "4", "--out", tmp, "--no-progress"])
    parts = [p for p in args.parts.split(",") if p] + (["d"] if args.suite else [])
    data = json.loads(args.out.read_text()) if args.out.exists() else {}
    run = data.setdefault(args.label, {})
    for part in parts:
        if part in run and not args.redo:
            print(f"part {part}: stored, skipped (--redo to measure again)")
            continue
        t0 = time.perf_counter()
        if part == "a":
            run["a"] = part_a(args.repeats)
        elif part == "b":
            run["b"] = part_b(args.repeats)
        elif part == "c":
            run["c"] = part_c(max(1, args.repeats // 2))
        elif part == "d":
            run["d"] = part_d()
        run[part]["measured"] = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
        run[part]["took_s"] = time.perf_counter() - t0
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(data, indent=1, sort_keys=True))  # after every part


if __name__ == "__main__":
    main()
