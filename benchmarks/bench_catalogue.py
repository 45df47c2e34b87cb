"""Catalogue searches of fin_actuator: the single solve and the 6-point front, in one run.

- (a) the shipped ``problems/fin_actuator.toml`` solved as users solve it
  (``od.solve(problem)``: the catalogue branch and bound with its relaxation bound),
  ``--repeats`` times: the first from an empty solver cache (formulation and Ipopt
  builds included), the others with the built solver (``--workers N``: each node's
  starts on N local processes);
- (b) the catalogue front backlash vs motor torque of docs/drive.md
  (``optdesign pareto problems/fin_actuator.toml --objectives backlash,motor_torque
  --points 6 --workers 1``), in-process with 1 worker from an empty solver cache: its
  wall time, the NLP solves of every anchor and point, and the points themselves.

- (c) ``--only ratio``: the catalogue front of (b) against a 50-point continuous front
  of the same problem, alternated ``--repeats`` times in one process (each from an empty
  solver cache): the NLP solves per point of each and the ratio of their wall times (and
  of their CPU times, one thread: less moved by the other jobs of a shared machine). The
  continuous problem is fin_actuator.toml with d0, p and d continuous over the same
  ranges; the catalogue's item data go with them (the nut stiffness is the fixed 270
  N/um of tests/hostile_classes/data/drive_continuous.toml, and the requirements that need a
  catalogue screw's load ratings - static safety, life and its duty cycle - are left
  out). The 50-point front of the shipped continuous cs_min_backlash (ripple against
  backlash, as in global_search/cost.py) runs beside them. The fronts alone are timed
  (``files=False``: no figure or report, which cost the same for either).

Every figure is written as one JSON line to ``--out`` as soon as it is measured, so a
killed run keeps what it measured. Seconds are wall-clock on a shared machine: read them
beside the NLP solve counts, which do not depend on the load.

    .venv/bin/python benchmarks/bench_catalogue.py [--repeats 2] [--points 6] [--workers 1]
        [--no-evidence] [--only single|front|ratio]
        [--out benchmarks/results/bench_catalogue.jsonl] [--tag before]
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
import tomllib
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import optdesign as od
from optdesign.formulations.catalogue import bnb as catalogue_bnb
from optdesign.formulations.nlp import solve as solve_study

ROOT = Path(__file__).resolve().parents[1]
FIN = ROOT / "problems" / "fin_actuator.toml"


def _clear_caches() -> None:
    solve_study._NLPS.clear()
    solve_study._SOLVERS.clear()
    # a front's memo of proofs and node bounds lives as long as the process: a second
    # front of the same problem would start from the first one's knowledge
    getattr(catalogue_bnb, "_MEMOS", {}).clear()


def _write(path: Path, row: dict) -> None:
    with path.open("a") as fh:
        fh.write(json.dumps(row) + "\n")
    print(json.dumps(row), flush=True)


def _catalogue_info(result) -> dict:
    """The catalogue search's counts of ``result`` (its typed ``details.catalogue``)."""
    info = result.details.catalogue
    if info is None:
        return {}
    return {
        "method": info.method,
        "nlp_solves": info.nlp_solves,
        "nodes": info.nodes,
        "pruned": info.pruned,
        "infeasible": info.infeasible,
        "leaves": info.leaves,
        "items": info.items,
    }


def single(path: Path, tag: str, repeats: int, workers: int = 1, evidence: bool = True) -> None:
    problem = od.load(FIN)
    _clear_caches()
    for i in range(repeats):
        t0 = time.perf_counter()
        if not evidence:
            # the solve without the optimum's sensitivities and neighbouring items, which
            # od.solve adds since issue 24: the work the code did
            from optdesign.problem.request import SolveRequest
            from optdesign.studies.solve import solve as solve_study

            request = SolveRequest.for_problem(problem, workers=workers, sensitivities=False)
            res = solve_study(problem, request)
        elif workers > 1:
            res = od.solve(problem, workers=workers)
        else:  # the default, called as the code was
            res = od.solve(problem)
        wall = time.perf_counter() - t0
        _write(
            path,
            {
                "tag": tag,
                "case": "single",
                "workers": workers,
                "evidence": evidence,
                "repeat": i,
                "cold": i == 0,
                "wall_s": round(wall, 3),
                "status": res.status,
                "objective": res.objective,
                "bound": res.bound,
                **_catalogue_info(res),
            },
        )


def front(path: Path, tag: str, points: int) -> None:
    problem = od.load(FIN)
    _clear_caches()
    t0 = time.perf_counter()

    def on_record(rec) -> None:
        rec = rec if isinstance(rec, dict) else rec.to_dict()
        _write(
            path,
            {
                "tag": tag,
                "case": "front-record",
                "id": rec.get("id"),
                "kind": rec.get("kind"),
                "status": rec.get("status"),
                "objectives": rec.get("objectives"),
                "n_solves": rec.get("n_solves"),
                "wall_s": rec.get("wall_time_s"),
                "elapsed_s": round(time.perf_counter() - t0, 3),
            },
        )

    out = Path(tempfile.mkdtemp(prefix="bench-catalogue-"))
    fr = od.pareto(
        problem,
        ["backlash", "motor_torque"],
        points=points,
        workers=1,
        out=out,
        on_record=on_record,
    )
    wall = time.perf_counter() - t0
    frame = fr.to_frame()
    cols = [
        c for c in frame.columns if c.split(" ")[0] in ("backlash", "motor_torque", "d0", "p", "d")
    ]
    _write(
        path,
        {
            "tag": tag,
            "case": "front",
            "points": points,
            "wall_s": round(wall, 3),
            "nlp_solves": fr.n_solves,
            "front": frame[cols].to_dict(orient="records"),
        },
    )


#: The requirements of fin_actuator that need a catalogue screw's load ratings.
RATED = ("static_safety_min", "life_min", "duty_cycle", "f_w")


def continuous_fin():
    """fin_actuator with continuous d0, p and d (see the module's text, (c))."""
    from optdesign.problem import problem_from_dict

    data = tomllib.loads(FIN.read_text())
    for name in ("d0", "p", "d"):
        data["variables"][name].pop("catalogue")
    screw = data["screw"]
    screw.pop("catalogue")
    screw.pop("nut_stiffness_rule")
    screw["nut_stiffness"] = "270 N/um"
    for name in RATED:
        data["requirements"].pop(name)
    data["name"] = "fin_actuator_continuous"
    return problem_from_dict(data, source=str(FIN), bare="refuse", folder=str(FIN.parent))


def timed_front(path: Path, tag: str, case: str, problem, objectives, points: int) -> dict:
    """One front from an empty solver cache, 1 worker: wall time, NLP solves (all, and
    those of the points between the anchors, per point)."""
    _clear_caches()
    solves: dict[str, int] = {}

    def on_record(rec) -> None:
        rec = rec if isinstance(rec, dict) else rec.to_dict()
        solves[rec["id"]] = rec.get("n_solves") or 0

    t0, c0 = time.perf_counter(), time.process_time()
    fr = od.pareto(
        problem,
        objectives,
        points=points,
        workers=1,
        out=Path(tempfile.mkdtemp(prefix="bench-ratio-")),
        on_record=on_record,
        files=False,  # the fronts alone: no figure or report (the same cost for both)
    )
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    points_solves = [n for k, n in solves.items() if not k.startswith("anchor")]
    row = {
        "tag": tag,
        "case": case,
        "points": points,
        "wall_s": round(wall, 3),
        # this process's CPU time (one worker, one thread): less moved by the other
        # jobs on a shared machine than the wall time
        "cpu_s": round(cpu, 3),
        "nlp_solves": fr.n_solves,
        "anchor_solves": fr.n_solves - sum(points_solves),
        "point_solves": sum(points_solves),
        "solves_per_point": round(sum(points_solves) / max(len(points_solves), 1), 3),
        "front": [
            {k: v for k, v in r.items() if k.split(" ")[0] in (*objectives, "d0", "p", "d")}
            for r in fr.to_frame().to_dict(orient="records")
        ],
    }
    _write(path, row)
    return row


def ratio(path: Path, tag: str, points: int, repeats: int) -> None:
    """(c): the catalogue front against the continuous ones, alternated in one process,
    after a first untimed 3-point front of each: the imports a front makes the first
    time (SciPy's SLSQP for the continuous fronts, ~0.3 s; the catalogue search's
    modules) are then paid by neither."""
    objectives = ["backlash", "motor_torque"]
    fin, cont = od.load(FIN), continuous_fin()
    cs = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    for problem, names in ((fin, objectives), (cont, objectives), (cs, ["ripple", "backlash"])):
        od.pareto(problem, names, points=3, workers=1, files=False)
    for i in range(repeats):
        cat = timed_front(path, tag, "ratio-catalogue", fin, objectives, points)
        con = timed_front(path, tag, "ratio-continuous", cont, objectives, 50)
        ref = timed_front(path, tag, "ratio-cs_min_backlash", cs, ["ripple", "backlash"], 50)
        _write(
            path,
            {
                "tag": tag,
                "case": "ratio",
                "repeat": i,
                "catalogue_over_continuous": round(cat["wall_s"] / con["wall_s"], 3),
                "catalogue_over_cs_min_backlash": round(cat["wall_s"] / ref["wall_s"], 3),
                "cpu_catalogue_over_continuous": round(cat["cpu_s"] / con["cpu_s"], 3),
                "cpu_catalogue_over_cs_min_backlash": round(cat["cpu_s"] / ref["cpu_s"], 3),
                "solves_per_point": {
                    "catalogue": cat["solves_per_point"],
                    "continuous": con["solves_per_point"],
                    "cs_min_backlash": ref["solves_per_point"],
                },
            },
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=2, help="single solves (first one cold)")
    ap.add_argument("--points", type=int, default=6)
    ap.add_argument("--tag", default="run", help="label written on every line")
    ap.add_argument(
        "--out", type=Path, default=ROOT / "benchmarks" / "results" / "bench_catalogue.jsonl"
    )
    ap.add_argument("--only", choices=("single", "front", "ratio"), default=None)
    ap.add_argument(
        "--workers", type=int, default=1, help="local processes of the single solve's nodes"
    )
    ap.add_argument(
        "--no-evidence",
        action="store_true",
        help="the single solve without the sensitivities and neighbouring items",
    )
    args = ap.parse_args()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    _write(args.out, {"tag": args.tag, "case": "start", "load": os.getloadavg()})
    if args.only in (None, "single"):
        single(args.out, args.tag, args.repeats, args.workers, not args.no_evidence)
    if args.only in (None, "front"):
        front(args.out, args.tag, args.points)
    if args.only == "ratio":
        ratio(args.out, args.tag, args.points, args.repeats)


if __name__ == "__main__":
    main()
