"""Cases run as real processes: signals inside a long solver call (class 3) and the same
result for any number of workers (class 1).

Signals: the command runs in its own process group (a job in a terminal) on a problem
whose single solver calls last seconds (1001 grid angles, Ipopt at tol 1e-14 with its
log on, so that the first iteration line shows the call is under way); once inside one,
SIGINT goes to the group (Ctrl-C), SIGTERM to the process (a supervisor), SIGHUP to the
group (the terminal closed). It must end within :data:`DEADLINE` s with exit 128 + n and
the one line ``optdesign: interrupted (SIG...)``, no traceback, no process of the group
left, nothing touched outside the output folder.

Determinism: ``pareto --deterministic`` and ``solve`` with 1 and with 2 workers must give
the same front / design (relative 1e-9), as ``--deterministic`` promises and "ties
decided by value and index" requires. They run with the default BLAS / OpenMP threads,
as a user's shell has them (with one thread each, the fork front of
tests/studies/pareto/test_pareto.py comes out equal; with the default two it does not).
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

from hostile_classes import workspace
from hostile_classes.common import base, sub
from hostile_classes.model import SUCCESS, Case, Expect, worst
from hostile_classes.server import child_env

#: Seconds from the signal to the end of the process.
DEADLINE = 1.0
#: Seconds waited after the signal before the process is killed.
WAIT = 3.0
SLOW_IPOPT = (
    "ipopt = { print_level = 5, max_iter = 3000, tol = 1e-14, acceptable_iter = 0, "
    'mu_strategy = "monotone" }'
)
_ITER = re.compile(rb"iter\s+objective\s+inf_pr")


def slow(text: str) -> str:
    """``text`` with 1001 grid angles, 8 starts and an Ipopt that takes its time (each
    call lasts seconds on this machine)."""
    text = re.sub(r"points = \d+", "points = 1001", text, count=1)
    return text + f"\n[solver]\nstarts = 8\nagree = 0\n{SLOW_IPOPT}\n"


class _Reader(threading.Thread):
    def __init__(self, stream):
        super().__init__(daemon=True)
        self.stream = stream
        self.data = b""

    def run(self) -> None:
        for chunk in iter(lambda: self.stream.read1(65536), b""):
            self.data += chunk


def _group_left(pgid: int) -> list[int]:
    try:
        import psutil
    except ImportError:
        return []
    left = []
    for proc in psutil.process_iter(["pid", "status"]):
        try:
            if os.getpgid(proc.pid) == pgid and proc.info["status"] != psutil.STATUS_ZOMBIE:
                left.append(proc.pid)
        except (ProcessLookupError, PermissionError, psutil.NoSuchProcess):
            pass
    return left


def _default_signals() -> None:
    # A runner started under nohup (or from a job that ignores SIGHUP) passes the ignored
    # disposition on through exec: the command must see the signals a terminal sends.
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)


def signal_run(
    root: Path, argv: list[str], text: str | None, sig: int, group: bool, marker: str, delay: float
) -> dict[str, Any]:
    """Run ``optdesign argv``, send ``sig`` inside a solver call, judge the end."""
    workspace.prepare(root, text)
    argv = [workspace.fill(a, root) for a in argv]
    folders = workspace.out_folders(root, argv)
    before = workspace.snapshot(root, folders)
    proc = subprocess.Popen(
        [sys.executable, "-m", "optdesign", *argv],
        cwd=root / "cwd",
        env=child_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
        preexec_fn=_default_signals,
    )
    readers = [_Reader(proc.stdout), _Reader(proc.stderr)]
    for r in readers:
        r.start()
    name = signal.Signals(sig).name
    problems: list[tuple[str, str]] = []
    staged = False
    end = time.monotonic() + 120
    while time.monotonic() < end and proc.poll() is None:
        if marker == "ipopt":
            staged = any(_ITER.search(r.data) for r in readers)
        else:
            staged = (root / marker).exists()
        if staged:
            break
        time.sleep(0.05)
    seconds = 0.0
    if staged and proc.poll() is None:
        time.sleep(delay)
        t0 = time.monotonic()
        try:
            if group:
                os.killpg(proc.pid, sig)
            else:
                os.kill(proc.pid, sig)
        except ProcessLookupError:
            pass
        try:
            proc.wait(WAIT)
        except subprocess.TimeoutExpired:
            problems.append(("signal_not_honoured", f"still running {WAIT:g} s after {name}"))
        seconds = time.monotonic() - t0
    elif proc.poll() is None:
        problems.append(("hang", "no solver call started within 120 s"))
    else:
        problems.append(
            ("wrong_refusal", f"ended (exit {proc.returncode}) before the signal could be sent")
        )
    time.sleep(0.3)
    left = _group_left(proc.pid)
    if left:
        problems.append(("signal_not_honoured", f"{len(left)} process(es) of the run left"))
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(proc.pid, signal.SIGKILL)
    try:
        proc.wait(10)
    except subprocess.TimeoutExpired:
        pass
    for r in readers:
        r.join(5)
    _out, err = readers[0].data, readers[1].data
    code = proc.returncode
    text_err = err.decode(errors="replace")
    if staged and not any(k == "signal_not_honoured" for k, _ in problems):
        # once (a worker killed mid-line may leave the line glued to its last output)
        lines = [ln for ln in text_err.splitlines() if f"optdesign: interrupted ({name})" in ln]
        if code != 128 + sig:
            problems.append(("signal_not_honoured", f"exit {code}, expected {128 + sig}"))
        elif seconds > DEADLINE:
            problems.append(("signal_not_honoured", f"ended {seconds:.2f} s after {name}"))
        if len(lines) != 1:
            problems.append(("signal_not_honoured", f"{len(lines)} 'interrupted ({name})' lines"))
    if "Traceback (most recent call last)" in text_err:
        problems.append(("traceback", text_err.strip().splitlines()[-1][:300]))
    if "internal error" in text_err:
        problems.append(("internal_error", text_err.strip().splitlines()[-1][:300]))
    touched = workspace.changes(before, workspace.snapshot(root, folders))
    if touched:
        problems.append(("files_touched", "; ".join(touched[:5])))
    last = text_err.strip().splitlines()[-1] if text_err.strip() else ""
    return {
        "mode": f"signal {name}",
        "verdict": worst(problems) if problems else "honoured",
        "seconds": round(seconds, 3),
        "code": code,
        "message": last[:300],
        "problems": [f"{k}: {w}" for k, w in problems],
    }


def _signal_case(
    what: str,
    argv: list[str],
    text: str | None,
    sig: int,
    marker: str = "ipopt",
    delay: float = 0.3,
    fast: bool = False,
) -> Case:
    group = sig != signal.SIGTERM

    def special(root: Path) -> list[dict[str, Any]]:
        return [signal_run(root, argv, text, sig, group, marker, delay)]

    name = signal.Signals(sig).name
    return Case(f"3:{what} {name}", "3", Expect("refuse"), special=special, fast=fast)


def signal_cases() -> list[Case]:
    solve = ["solve", "@FILE@", "--no-ranges", "--out", "@OUT@"]
    backlash = slow(base("cs_min_backlash"))
    catalogue = slow(base("cs_min_backlash_catalogue"))
    pareto = ["pareto", "@FILE@", "--objectives", "backlash,size", "--points", "4", "--workers", "1", "--no-progress", "--out", "@OUT@"]  # fmt: skip
    bench = ["bench", "--suite", "default", "--solvers", "trust-constr-fd", "--workers", "1", "--time-limit", "60", "--hard-timeout", "120", "--no-progress", "--out", "@OUT@"]  # fmt: skip
    c = []
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        json_flag = ["--json"] if sig == signal.SIGTERM else []
        c += [
            _signal_case(
                "solve, 1 worker,", [*solve, *json_flag], backlash, sig, fast=sig == signal.SIGTERM
            ),
            _signal_case(
                "solve, 2 workers,", [*solve, "--workers", "2", *json_flag], backlash, sig
            ),
            _signal_case("solve, a catalogue problem,", [*solve, *json_flag], catalogue, sig),
            _signal_case("pareto", pareto, backlash, sig, marker="out/epsilon.jsonl", delay=1.0),
            _signal_case("bench", bench, None, sig, marker="out/bench_runs.jsonl", delay=1.5),
        ]
    return c


# --- determinism ------------------------------------------------------------------------------------
def _run(root: Path, argv: list[str], timeout: float = 900) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "optdesign", *argv],
        cwd=root / "cwd",
        env=child_env(one_thread=False),
        capture_output=True,
        timeout=timeout,
    )


def _rel(a: float, b: float) -> float:
    return abs(a - b) / max(1e-300, abs(a), abs(b)) if a != b else 0.0


def _front(path: Path) -> list[dict[str, str]]:
    return [
        r
        for r in csv.DictReader(io.StringIO(path.read_text(), newline=""))
        if r.get("on_front") == "True"
    ]


def _compare_fronts(a: list[dict[str, str]], b: list[dict[str, str]]) -> list[str]:
    if len(a) != len(b):
        return [f"{len(a)} points with 1 worker, {len(b)} with 2"]
    skip = {"method", "id", "status", "verified", "on_front", "active"}
    worst_rel, where = 0.0, ""
    for ra, rb in zip(a, b, strict=True):
        for k in ra:
            if k in skip:
                continue
            r = _rel(float(ra[k]), float(rb[k]))
            if r > worst_rel:
                worst_rel, where = r, f"{ra['id']} {k}: {ra[k]} vs {rb[k]}"
    return [f"fronts differ by {worst_rel:.2g} relative ({where})"] if worst_rel > 1e-9 else []


def _compare_designs(a: dict[str, Any], b: dict[str, Any]) -> list[str]:
    out = []
    for k, va in a["design"].items():
        r = _rel(va["value"], b["design"][k]["value"])
        if r > 1e-9:
            out.append(f"design {k}: {va['value']} with 1 worker, {b['design'][k]['value']} with 2")
    r = _rel(a["objective"]["value"], b["objective"]["value"])
    if r > 1e-9:
        out.append(f"objective {a['objective']['value']} vs {b['objective']['value']}")
    return out


def determinism_run(root: Path, argv: list[str], text: str, kind: str) -> dict[str, Any]:
    workspace.prepare(root, text)
    t0 = time.monotonic()
    problems: list[tuple[str, str]] = []
    results = []
    for workers in ("1", "2"):
        args = [workspace.fill(a, root).replace("@N@", workers) for a in argv]
        if kind == "pareto":
            args += ["--out", str(root / f"out{workers}")]
        proc = _run(root, args)
        err = proc.stderr.decode(errors="replace")
        if proc.returncode != 0:
            problems.append(
                (
                    "wrong_refusal",
                    f"{workers} worker(s): exit {proc.returncode}: {err.strip()[-300:]}",
                )
            )
            break
        if "Traceback" in err:
            problems.append(("traceback", err.strip().splitlines()[-1]))
        if kind == "pareto":
            results.append(_front(root / f"out{workers}" / "front.csv"))
        else:
            results.append(json.loads(proc.stdout))
    if len(results) == 2:
        diff = _compare_fronts(*results) if kind == "pareto" else _compare_designs(*results)
        problems += [("not_deterministic", d) for d in diff]
    return {
        "mode": "workers 1 vs 2",
        "verdict": worst(problems) if problems else "verified",
        "seconds": round(time.monotonic() - t0, 3),
        "code": None,
        "message": problems[0][1][:300] if problems else "the same result",
        "problems": [f"{k}: {w}" for k, w in problems],
    }


_IN_ONE_PROCESS = """
import json, sys
import optdesign as od
problem = od.load(sys.argv[1])
fronts = []
for workers in (1, 2):
    f = od.pareto(problem, ["size", "backlash"], points=8, starts=2, deterministic=True,
                  workers=workers, out=sys.argv[2] + f"/out{workers}")
    fronts.append([[p.objectives[k] for k in ("size", "backlash")] for p in f.points])
print(json.dumps(fronts))
"""


def api_one_process(root: Path) -> dict[str, Any]:
    """od.pareto(deterministic=True) with 1 then 2 workers in one process (as
    tests/studies/pareto/test_pareto.py does): the same front."""
    workspace.prepare(root, base("fork_min_backlash"))
    t0 = time.monotonic()
    proc = subprocess.run(
        [sys.executable, "-c", _IN_ONE_PROCESS, str(root / "cwd" / "problem.toml"), str(root)],
        cwd=root / "cwd",
        env=child_env(one_thread=False),
        capture_output=True,
        timeout=900,
    )
    problems: list[tuple[str, str]] = []
    if proc.returncode != 0:
        err = proc.stderr.decode(errors="replace").strip()
        problems.append(("internal_error", err.splitlines()[-1][:300] if err else "no output"))
    else:
        one, two = json.loads(proc.stdout)
        if len(one) != len(two):
            problems.append(
                ("not_deterministic", f"{len(one)} points with 1 worker, {len(two)} with 2")
            )
        else:
            worst_rel = max(
                (
                    _rel(a, b)
                    for p, q in zip(one, two, strict=True)
                    for a, b in zip(p, q, strict=True)
                ),
                default=0.0,
            )
            if worst_rel > 1e-9:
                problems.append(("not_deterministic", f"fronts differ by {worst_rel:.2g} relative"))
    return {
        "mode": "api, one process",
        "verdict": worst(problems) if problems else "verified",
        "seconds": round(time.monotonic() - t0, 3),
        "code": proc.returncode,
        "message": problems[0][1] if problems else "the same result",
        "problems": [f"{k}: {w}" for k, w in problems],
    }


def _det_case(what: str, argv: list[str], text: str, kind: str, fast: bool = False) -> Case:
    def special(root: Path) -> list[dict[str, Any]]:
        return [determinism_run(root, argv, text, kind)]

    return Case(f"1:{what}", "1", SUCCESS, special=special, fast=fast)


def determinism_cases() -> list[Case]:
    def pareto(objectives: str, points: int, starts: int = 2) -> list[str]:
        return ["pareto", "@FILE@", "--objectives", objectives, "--points", str(points), "--starts", str(starts), "--workers", "@N@", "--deterministic", "--no-progress", "--no-plot", "--no-report"]  # fmt: skip

    solve = ["solve", "@FILE@", "--json", "--no-ranges", "--workers", "@N@"]
    ripple8 = base("cs_min_ripple") + "\n[solver]\nstarts = 8\n"
    return [
        _det_case("pareto --deterministic fork size,backlash (the README's failing test)", pareto("size,backlash", 8), base("fork_min_backlash"), "pareto"),
        Case("1:od.pareto deterministic fork, workers 1 then 2 in one process (the README's failing test)", "1", SUCCESS, special=lambda root: [api_one_process(root)], fast=True),
        _det_case("pareto --deterministic cs_min_ripple ripple,size", pareto("ripple,size", 6), base("cs_min_ripple"), "pareto"),
        _det_case("pareto --deterministic cs_min_backlash backlash,size", pareto("backlash,size", 6), base("cs_min_backlash"), "pareto"),
        _det_case("pareto --deterministic pivot backlash,size", pareto("backlash,size", 6), base("pivot_min_backlash"), "pareto"),
        _det_case("pareto --deterministic catalogue backlash,ripple", pareto("backlash,ripple", 4), base("cs_min_backlash_catalogue"), "pareto"),
        _det_case("pareto --deterministic three objectives", pareto("size,backlash,ripple", 6), base("fork_min_backlash"), "pareto"),
        _det_case("solve cs_min_ripple 8 starts, all run", [*solve, "--starts", "8"], sub(ripple8, "starts = 8", "starts = 8\nagree = 0"), "solve"),
        _det_case("solve cs_min_ripple 8 starts, agree 3", [*solve, "--starts", "8"], ripple8, "solve"),
        _det_case("solve cs_min_backlash 8 starts", [*solve, "--starts", "8"], base("cs_min_backlash"), "solve"),
        _det_case("solve pivot 8 starts", [*solve, "--starts", "8"], base("pivot_min_backlash"), "solve"),
        _det_case("solve catalogue", [*solve, "--starts", "4"], base("cs_min_backlash_catalogue"), "solve"),
        _det_case("solve duan2017_redesign", solve, base("duan2017_redesign"), "solve"),
    ]  # fmt: skip


def cases() -> list[Case]:
    return [*determinism_cases(), *signal_cases()]
