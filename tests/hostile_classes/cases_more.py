"""Class 8: resume that mixes runs. Each case starts from a finished run (a front, a
benchmark) copied into its output folder, changes the problem, the settings or the store,
and resumes. A resume must refuse a store that is not this run's (other solver options,
other content, another store version), and must not trust a record it cannot check (NaN
objectives, a design outside the bounds): refused, or computed again."""

from __future__ import annotations

import atexit
import csv
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from hostile_classes.common import base, sub
from hostile_classes.model import SUCCESS, Case, either, refuse
from hostile_classes.server import child_env

#: The front every resume case starts from: cs_min_ripple with its solver settings written.
PARETO_TEXT = base("cs_min_ripple") + "\n[solver]\nstarts = 2\nipopt = { tol = 1e-8 }\n"
PARETO = ["pareto", "@FILE@", "--objectives", "ripple,size", "--points", "4", "--workers", "1"]
PARETO += ["--deterministic", "--no-progress", "--no-plot", "--no-report"]
BENCH = ["bench", "--suite", "quick", "--solvers", "ipopt-exact", "--workers", "1", "--no-progress"]
#: Bounds of cs_min_ripple's free variables under front.csv's headings (in the file's
#: units, as the summary shows them).
BOUNDS = {
    "R [mm]": (30, 120),
    "l [mm]": (40, 200),
    "n [mm]": (0, 150),
    "p [mm]": (2, 10),
    "phi0 [rad]": (-0.6, 0.6),
}

_BASES: dict[str, Path] = {}


def _base_run(kind: str) -> Path:
    """The finished run ``kind`` ("pareto" or "bench"), made once per process."""
    if kind in _BASES:
        return _BASES[kind]
    top = Path(tempfile.mkdtemp(prefix="hostile-classes-base-"))
    atexit.register(shutil.rmtree, top, True)
    out = top / "out"
    if kind == "pareto":
        (top / "problem.toml").write_text(PARETO_TEXT)
        argv = [a.replace("@FILE@", str(top / "problem.toml")) for a in PARETO]
    else:
        argv = list(BENCH)
    proc = subprocess.run(
        [sys.executable, "-m", "optdesign", *argv, "--out", str(out)],
        capture_output=True,
        text=True,
        env=child_env(),
        cwd=top,
        timeout=600,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"the base {kind} run failed: {proc.stderr[-2000:]}")
    (out / ".optdesign.lock").unlink(missing_ok=True)
    _BASES[kind] = out
    return out


def _lines(path: Path) -> list[dict[str, Any]]:
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def _write(path: Path, rows: list[dict[str, Any]]) -> None:
    path.write_text("".join(json.dumps(r, allow_nan=True) + "\n" for r in rows))


def _from(kind: str, edit: Callable[[Path], None] | None = None):
    """A setup: the finished run copied to ``root/out``, then ``edit(store)``."""

    def setup(root: Path) -> None:
        shutil.copytree(_base_run(kind), root / "out")
        store = root / "out" / ("epsilon.jsonl" if kind == "pareto" else "bench_runs.jsonl")
        if edit is not None:
            edit(store)

    return setup


def _identity(**changes: Any):
    def edit(store: Path) -> None:
        rows = _lines(store)
        rows[0].update(changes)
        _write(store, rows)

    return edit


def _record(rid: str, change: Callable[[dict[str, Any]], None]):
    def edit(store: Path) -> None:
        rows = _lines(store)
        hits = [r for r in rows if r.get("id") == rid]
        assert hits, rid
        change(hits[0])
        _write(store, rows)

    return edit


def _nan_objectives(rec: dict[str, Any]) -> None:
    rec["objectives"] = {k: float("nan") for k in rec["objectives"]}


def _outside(rec: dict[str, Any]) -> None:
    rec["design"]["R"] = 1e6
    rec["x"][0] = 1e6


def _front_inside(root: Path, stdout: str, stderr: str) -> list[str]:
    """front.csv's rows on the front or shown as verified: finite and inside
    cs_min_ripple's bounds."""
    path = root / "out" / "front.csv"
    if not path.exists():
        return []
    out = []
    for row in csv.DictReader(io.StringIO(path.read_text(), newline="")):
        if row.get("on_front") != "True" and row.get("verified") != "True":
            continue
        for k, (lo, hi) in BOUNDS.items():
            try:
                v = float(row[k])
            except (KeyError, ValueError):
                out.append(f"front.csv {row.get('id')}: {k} = {row.get(k)!r}")
                continue
            if not lo - 1e-6 <= v <= hi + 1e-6:
                out.append(f"front.csv {row.get('id')}: {k} = {v} outside [{lo}, {hi}] shown")
        for k in ("ripple [%]", "size [mm]"):
            try:
                ok = float(row[k]) == float(row[k]) and abs(float(row[k])) < 1e300
            except (KeyError, ValueError):
                ok = False
            if not ok:
                out.append(f"front.csv {row.get('id')}: {k} = {row.get(k)!r} shown")
    return out


def _bench_finite(root: Path, stdout: str, stderr: str) -> list[str]:
    path = root / "out" / "bench_runs.csv"
    if not path.exists():
        return []
    out = []
    for row in csv.DictReader(io.StringIO(path.read_text(), newline="")):
        if row.get("verified") == "True" and row.get("objective", "") in ("nan", "NaN", ""):
            out.append(
                f"bench_runs.csv {row.get('id')}: verified with objective {row.get('objective')!r}"
            )
    return out


def cases() -> list[Case]:
    resume = [*PARETO, "--resume", "--out", "@OUT@"]
    store = ("epsilon.jsonl", "another run", "store")
    changed = [
        ("ipopt tol changed", "ipopt = { tol = 1e-8 }", "ipopt = { tol = 1e-4 }", ("ipopt", "solver", *store)),
        ("ipopt max_iter added", "ipopt = { tol = 1e-8 }", "ipopt = { tol = 1e-8, max_iter = 7 }", ("ipopt", "solver", *store)),
        ("ipopt mu_strategy added", "ipopt = { tol = 1e-8 }", 'ipopt = { tol = 1e-8, mu_strategy = "monotone" }', ("ipopt", "solver", *store)),
        ("solver starts changed", "starts = 2", "starts = 3", ("starts", *store)),
        ("solver seed added", "starts = 2", "starts = 2\nseed = 5", ("seed", *store)),
        ("hinge moment changed", 'hinge_moment = "500 N*m"', 'hinge_moment = "400 N*m"', ("hinge_moment", *store)),
        ("ratio band changed", "min = 200, max = 260", "min = 205, max = 260", ("mean_ratio", *store)),
        ("an upper bound changed", 'R = { lower = "30 mm", upper = "120 mm" }', 'R = { lower = "30 mm", upper = "110 mm" }', ("R", *store)),
        ("the mechanism's neutral angle fixed", 'phi0 = { lower = "-0.6 rad", upper = "0.6 rad" }', 'phi0 = "0.2 rad"', ("phi0", *store)),
    ]  # fmt: skip
    c: list[Case] = []
    for what, old, new, names in changed:
        c.append(
            Case(f"8:{what}", "8", refuse(*names), argv=resume, text=sub(PARETO_TEXT, old, new), json=False, setup=_from("pareto"), fast=what == "solver starts changed")
        )  # fmt: skip
    c += [
        Case("8:--starts changed", "8", refuse("starts", *store), argv=[*resume, "--starts", "5"], text=PARETO_TEXT, json=False, setup=_from("pareto")),
        Case("8:--points changed", "8", refuse("points", *store), argv=[*resume[:5], "6", *resume[6:]], text=PARETO_TEXT, json=False, setup=_from("pareto")),
        Case("8:unchanged resume", "8", SUCCESS, argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto"), cli_check=_front_inside),
        Case("8:store version 99", "8", refuse("version", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _identity(__store__=99)), fast=True),
        Case("8:store version 0", "8", refuse("version", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _identity(__store__=0))),
        Case("8:store version a string", "8", refuse("version", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _identity(__store__="1"))),
        Case("8:store key null", "8", refuse("key", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _identity(key=None))),
        Case("8:record with NaN objectives", "8", either("epsilon-0001", "record", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _record("epsilon-0001", _nan_objectives)), cli_check=_front_inside, fast=True),
        Case("8:record outside the bounds", "8", either("epsilon-0001", "record", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _record("epsilon-0001", _outside)), cli_check=_front_inside),
        Case("8:anchor outside the bounds", "8", either("anchor-size", "record", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _record("anchor-size", _outside)), cli_check=_front_inside),
        Case("8:record without its design", "8", either("epsilon-0002", "record", "design", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _record("epsilon-0002", lambda r: r.pop("design"))), cli_check=_front_inside),
        Case("8:record objectives as text", "8", either("epsilon-0002", "record", "objectives", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _record("epsilon-0002", lambda r: r.update(objectives={"ripple": "low", "size": "big"}))), cli_check=_front_inside),
        Case("8:record status bogus", "8", either("epsilon-0002", "record", "status", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _record("epsilon-0002", lambda r: r.update(status="splendid"))), cli_check=_front_inside),
        Case("8:record x of the wrong length", "8", either("epsilon-0002", "record", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_from("pareto", _record("epsilon-0002", lambda r: r.update(x=[1.0]))), cli_check=_front_inside),
        Case("8:store a link to a store outside", "8", either("epsilon.jsonl", "link", *store), argv=resume, text=PARETO_TEXT, json=False, setup=_linked_store),
    ]  # fmt: skip
    bench_resume = [*BENCH, "--resume", "--out", "@OUT@"]
    bstore = ("bench_runs.jsonl", "another run", "store")
    c += [
        Case("8:bench store version 99", "8", refuse("version", *bstore), argv=bench_resume, json=False, setup=_from("bench", _identity(__store__=99)), timeout=120),
        Case("8:bench time limit changed", "8", refuse("time", *bstore), argv=[*bench_resume, "--time-limit", "2"], json=False, setup=_from("bench"), timeout=120),
        Case("8:bench row with a NaN objective", "8", either("cs_ripple-000", "record", *bstore), argv=bench_resume, json=False, setup=_from("bench", _record("cs_ripple-000|ipopt-exact", lambda r: r.update(objective=float("nan")))), cli_check=_bench_finite, timeout=120),
        Case("8:bench row outside the bounds", "8", either("cs_ripple-000", "record", *bstore), argv=bench_resume, json=False, setup=_from("bench", _record("cs_ripple-000|ipopt-exact", lambda r: r["design"].update(R=1e6))), timeout=120),
    ]  # fmt: skip
    c += _api_resume()
    return c


def _linked_store(root: Path) -> None:
    shutil.copytree(_base_run("pareto"), root / "out")
    store = root / "out" / "epsilon.jsonl"
    rows = _lines(store)
    # outside: a copy of the store missing its last point, so that a resume appends to it
    _write(root / "outside" / "epsilon.jsonl", rows[:-1])
    store.unlink()
    os.symlink("../outside/epsilon.jsonl", store)


def _api_resume() -> list[Case]:
    """od.pareto(resume=True) after the problem changed in Python."""

    def run(change: Callable[[Any], None], **kw: Any):
        def api(ctx: Any) -> Any:
            import optdesign as od

            problem = od.load(ctx.data())
            change(problem)
            return od.pareto(
                problem,
                ["ripple", "size"],
                points=4,
                workers=1,
                out=ctx.out,
                resume=True,
                deterministic=True,
                **kw,
            )

        return api

    def constraint(problem: Any) -> None:
        problem.add_constraint("arm_cap", lambda q: q.R, upper="40 mm", unit="mm", over="design")

    def ipopt(problem: Any) -> None:
        problem.spec.solver.ipopt["tol"] = 1e-3

    store = ("epsilon.jsonl", "another run", "store")
    return [
        Case("8:API resume after add_constraint", "8", refuse("arm_cap", *store), text=PARETO_TEXT, api=run(constraint), setup=_from("pareto")),
        Case("8:API resume with other solver options", "8", refuse("ipopt", "solver", *store), text=PARETO_TEXT, api=run(lambda p: None, solver="ipopt"), setup=_from("pareto")),
        Case("8:API resume after the spec's ipopt changed", "8", refuse("ipopt", "tol", *store), text=PARETO_TEXT, api=run(ipopt), setup=_from("pareto")),
    ]  # fmt: skip
