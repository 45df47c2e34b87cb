"""A catalogue sweep point against a single catalogue solve, in one process (CPU s).

- *single*: ``od.solve`` of ``fin_actuator`` at 400 N*m, a problem this process has not
  built yet (its NLP and solvers are built, as each sweep point's are); the imports are
  paid before by an untimed solve of the shipped file;
- *warm single*: the shipped file solved again (its solvers cached: no build);
- *sweep*: ``od.sweep`` of the hinge moment, 200 to 600 N*m, 5 points (the last one
  infeasible: its diagnosis included), ``files=False``.

Issue 36's target: a sweep point at most 2x a single solve. It runs the optdesign found on
``PYTHONPATH``, so two trees are measured with the same script:

    PYTHONPATH=/tmp/base python benchmarks/catalogue_sweep_cost.py --tag before
    PYTHONPATH=. python benchmarks/catalogue_sweep_cost.py --tag after
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIN = ROOT / "problems" / "fin_actuator.toml"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tag", default="run")
    ap.add_argument(
        "--out", type=Path, default=ROOT / "benchmarks" / "results" / "catalogue_sweep_cost.jsonl"
    )
    args = ap.parse_args()

    import optdesign as od
    from optdesign.problem import problem_from_dict

    fin = od.load(FIN)
    od.solve(fin, ranges=False)  # the imports and the shipped file's solvers
    data = tomllib.loads(FIN.read_text())
    data["requirements"]["hinge_moment"] = "400 N*m"
    point = problem_from_dict(data, source=str(FIN), folder=str(FIN.parent))
    c0 = time.process_time()
    single = od.solve(point)
    single_cpu = time.process_time() - c0
    c0 = time.process_time()
    od.solve(fin)
    warm_cpu = time.process_time() - c0
    c0 = time.process_time()
    vary = {"requirements.hinge_moment": ("200 N*m", "600 N*m", 5)}
    od.sweep(fin, vary, out=tempfile.mkdtemp(prefix="bench-sweep-"), files=False)
    sweep_cpu = time.process_time() - c0
    row = {
        "tag": args.tag,
        "single_cpu_s": round(single_cpu, 3),
        "single_objective": single.objective,
        "warm_single_cpu_s": round(warm_cpu, 3),
        "sweep_cpu_s": round(sweep_cpu, 3),
        "point_over_single": round(sweep_cpu / 5 / single_cpu, 3),
        "point_over_warm_single": round(sweep_cpu / 5 / warm_cpu, 3),
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with args.out.open("a") as fh:
        fh.write(json.dumps(row) + "\n")
    print(json.dumps(row))


if __name__ == "__main__":
    main()
