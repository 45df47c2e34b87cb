"""Catalogue fronts of two versions of the code, point for point.

Writes the 6-point catalogue fronts of ``problems/fin_actuator.toml`` (backlash against
motor torque, docs/drive.md) and ``problems/cs_min_backlash_catalogue.toml`` (backlash
against motor torque), 1 worker, each from an empty solver cache: every record's
objectives, items and NLP solves, one JSON file per ``--tag``. ``--compare A B`` then
prints the largest relative difference of the two fronts' objectives, whether the items
and the binding rows are the same at every point, and the NLP solves of each (of an anchor's first stage,
which only gives its tie-break the least value of its objective, that value alone).

    # the code before, exported, and this tree:
    git archive <commit> | tar -x -C /tmp/before
    PYTHONPATH=/tmp/before .venv/bin/python benchmarks/catalogue_front_compare.py --tag before
    .venv/bin/python benchmarks/catalogue_front_compare.py --tag after
    .venv/bin/python benchmarks/catalogue_front_compare.py --compare before after
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

ROOT = Path(__file__).resolve().parents[1]
CASES = {
    "fin_actuator": ("fin_actuator.toml", ["backlash", "motor_torque"]),
    "cs_min_backlash_catalogue": ("cs_min_backlash_catalogue.toml", ["backlash", "motor_torque"]),
}
ITEMS = ("d0", "p", "d")


def run(tag: str, out: Path, points: int) -> None:
    import optdesign as od
    from optdesign.formulations.catalogue import bnb as catalogue_bnb
    from optdesign.formulations.nlp import solve as solve_study

    rows = {}
    for case, (file, objectives) in CASES.items():
        solve_study._NLPS.clear()
        solve_study._SOLVERS.clear()
        getattr(catalogue_bnb, "_MEMOS", {}).clear()
        records = {}

        def on_record(rec, records=records, objectives=objectives) -> None:
            rec = rec if isinstance(rec, dict) else rec.to_dict()
            records[rec["id"]] = {
                "status": rec.get("status"),
                "objectives": {k: rec["objectives"].get(k) for k in objectives},
                "items": {k: rec["design"][k] for k in ITEMS if k in (rec.get("design") or {})},
                "n_solves": rec.get("n_solves"),
                "active": rec.get("active"),
            }

        t0 = time.perf_counter()
        od.pareto(
            od.load(ROOT / "problems" / file),
            objectives,
            points=points,
            workers=1,
            out=Path(tempfile.mkdtemp(prefix="front-compare-")),
            on_record=on_record,
        )
        rows[case] = {"wall_s": round(time.perf_counter() - t0, 3), "records": records}
        print(case, rows[case]["wall_s"], sum(r["n_solves"] or 0 for r in records.values()))
    (out / f"catalogue_front_{tag}.json").write_text(json.dumps(rows, indent=1))


def compare(out: Path, a: str, b: str) -> None:
    fa = json.loads((out / f"catalogue_front_{a}.json").read_text())
    fb = json.loads((out / f"catalogue_front_{b}.json").read_text())
    for case in CASES:
        ra, rb = fa[case]["records"], fb[case]["records"]
        worst, same_items, same_active = 0.0, True, True
        for key in sorted(ra):
            # an anchor's first stage wants only its objective's least value (its
            # tie-break, the anchor, picks the design): its other values and items may
            # be any of the tied combinations'
            first_stage = key.endswith("-ms")
            names = [key[len("anchor-") : -len("-ms")]] if first_stage else ra[key]["objectives"]
            for k in names:
                va, vb = ra[key]["objectives"][k], rb[key]["objectives"][k]
                worst = max(worst, abs(va - vb) / max(abs(va), 1e-300))
            same_items &= first_stage or ra[key]["items"] == rb[key]["items"]
            same_active &= first_stage or ra[key].get("active") == rb[key].get("active")
        solves = [sum(r["n_solves"] or 0 for r in f.values()) for f in (ra, rb)]
        print(
            f"{case}: largest relative difference {worst:.3g}, same items: {same_items}, "
            f"same binding rows: {same_active}, "
            f"NLP solves {a} {solves[0]}, {b} {solves[1]}"
        )
        for key in sorted(ra):
            print(f"  {key:26s} {ra[key]['n_solves']:4d} {rb[key]['n_solves']:4d}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tag", default="run")
    ap.add_argument("--points", type=int, default=6)
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--compare", nargs=2, metavar=("A", "B"))
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.compare:
        compare(args.out, *args.compare)
    else:
        run(args.tag, args.out, args.points)


if __name__ == "__main__":
    main()
