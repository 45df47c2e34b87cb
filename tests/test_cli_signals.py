"""SIGINT, SIGTERM and SIGKILL of the real `optdesign pareto` and `optdesign bench` at
seeded random moments, then `--resume` (issue 13).

Each case checks: the run's stdout/stderr pipes reach EOF (no orphan holds them); no
process of the run is left (its descendants, and anything else in its process group);
exit 130 / 143 with the one-line message and no traceback (-9 for SIGKILL); every record
saved before the signal is kept as it was after the resume, no record lost or written
twice; the resumed front (pareto `--deterministic`) or the resumed bench rows equal an
uninterrupted run's.
"""

from __future__ import annotations

import csv
import json
import os
import random
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

psutil = pytest.importorskip("psutil")

from test_interrupts import _alive, _env, _group, signal_inside  # noqa: E402  (shared helpers)

from optdesign.storage import read_store  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FORK = ROOT / "problems" / "fork_min_backlash.toml"
PARETO = [
    "pareto",
    str(FORK),
    "--objectives",
    "size,backlash",
    "--points",
    "12",
    "--workers",
    "2",
    "--starts",
    "2",
    "--deterministic",
    "--no-plot",
    "--no-progress",
]
BENCH = [
    "bench",
    "--suite",
    "quick",
    "--solvers",
    "slsqp-exact",
    "ipopt-exact",
    "--workers",
    "2",
    "--time-limit",
    "30",
    "--hard-timeout",
    "60",
    "--no-progress",
]


def _cli(args: list[str]) -> list[str]:
    """The command line of ``optdesign ARGS`` run from this tree."""
    return [sys.executable, "-m", "optdesign", *args]


def _run_cli(args: list[str], timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run(
        _cli(args),
        capture_output=True,
        text=True,
        env=_env(),
        timeout=timeout,
    )


def _store_lines(store: Path) -> list[dict]:
    if not store.exists():
        return []
    data = store.read_bytes()
    if not data.endswith(b"\n"):  # a torn tail (SIGKILL mid-write) is cut on resume
        data = data[: data.rfind(b"\n") + 1]
    return [json.loads(line) for line in data.decode().splitlines()[1:] if line.strip()]


def _interrupt(
    args: list[str], store: Path, sig: int, rng: random.Random, k_max: int, delay_max: float
):
    """Run the CLI and send ``sig`` at a seeded random moment: once the store holds a
    random number k <= k_max of records, after a further random delay of up to
    ``delay_max`` s (late moments may find the run finished). Returns (returncode, stderr, records
    before, processes left)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "optdesign", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=_env(),
        start_new_session=True,  # its own process group, as a job in a terminal
    )
    seen: set[int] = set()
    try:
        end = time.monotonic() + 60
        while time.monotonic() < end and proc.poll() is None:
            try:
                kids = psutil.Process(proc.pid).children(recursive=True)
            except psutil.NoSuchProcess:
                break
            seen |= {k.pid for k in kids}
            if kids:
                break
            time.sleep(0.01)
        k = rng.randint(0, k_max)
        delay = rng.uniform(0.0, delay_max)
        while len(_store_lines(store)) < k and proc.poll() is None:
            try:
                seen |= {c.pid for c in psutil.Process(proc.pid).children(recursive=True)}
            except psutil.NoSuchProcess:
                break
            time.sleep(0.005)
        t_sig = time.monotonic() + delay
        while time.monotonic() < t_sig and proc.poll() is None:
            try:
                seen |= {k.pid for k in psutil.Process(proc.pid).children(recursive=True)}
            except psutil.NoSuchProcess:
                break
            time.sleep(0.02)
        if proc.poll() is None:
            if sig == signal.SIGINT:
                os.killpg(proc.pid, sig)  # Ctrl-C reaches every process of the job
            else:
                os.kill(proc.pid, sig)
        # a reader of the output must get EOF: no orphan may hold the pipes
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    left = _alive(sorted(seen), wait=5.0) + [p for p in _group(proc.pid) if p not in seen]
    return proc.returncode, err.decode(), _store_lines(store), left


def _check_exit(code: int, err: str, sig: int, store: Path, n_before: int) -> None:
    assert "Traceback" not in err, err
    if code == 0:  # it finished before the signal
        return
    if sig == signal.SIGKILL:
        assert code == -signal.SIGKILL
        return
    assert code == 128 + sig, (code, err)
    name = signal.Signals(sig).name
    s = "" if n_before == 1 else "s"
    assert err.strip() == (
        f"optdesign: interrupted ({name}); {n_before} record{s} saved in {store}, "
        "--resume continues"
    )
    assert store.read_bytes().endswith(b"\n")  # an interrupt leaves no torn line


def _check_records(before: list[dict], after: list[dict]) -> None:
    ids = [r["id"] for r in after]
    assert len(ids) == len(set(ids)), "a record written twice"
    by_id = {r["id"]: r for r in after}
    for rec in before:
        assert by_id.get(rec["id"]) == rec, f"record {rec['id']} lost or changed"


def _front_rows(path: Path) -> list[dict]:
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def _same_front(a: list[dict], b: list[dict]) -> None:
    assert len(a) == len(b) and len(a) >= 10
    for ra, rb in zip(a, b, strict=True):
        assert ra.keys() == rb.keys()
        for k in ra:
            try:
                assert float(ra[k]) == pytest.approx(float(rb[k]), rel=1e-8, abs=1e-12), k
            except ValueError:
                assert ra[k] == rb[k], k


# --- pareto -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def pareto_reference(tmp_path_factory) -> tuple[list[dict], list[dict]]:
    out = tmp_path_factory.mktemp("pareto_ref") / "run"
    res = _run_cli([*PARETO, "--out", str(out)])
    assert res.returncode == 0, res.stderr
    return _front_rows(out / "front.csv"), _store_lines(out / "epsilon.jsonl")


def _pareto_case(tmp_path: Path, reference, sig: int, seed: int, early: bool) -> None:
    front_ref, store_ref = reference
    out = tmp_path / "run"
    store = out / "epsilon.jsonl"
    rng = random.Random(seed)
    code, err, before, left = _interrupt(
        [*PARETO, "--out", str(out)],
        store,
        sig,
        rng,
        len(store_ref) // 3 if early else len(store_ref) - 2,
        0.02 if early else 0.05,  # the 12-point front takes about 1 s once started
    )
    assert left == [], f"processes left after {signal.Signals(sig).name}: {left}"
    assert code != 0 or not early, "the run ended before the signal"
    _check_exit(code, err, sig, store, len(before))
    res = _run_cli([*PARETO, "--out", str(out), "--resume"])
    assert res.returncode == 0 and "Traceback" not in res.stderr, res.stderr
    after = _store_lines(store)
    _check_records(before, after)
    assert sorted(r["id"] for r in after) == sorted(r["id"] for r in store_ref)
    _same_front(_front_rows(out / "front.csv"), front_ref)
    # one line per case for the record (pytest -s): figures of the closing note
    print(f"signal-case pareto {signal.Signals(sig).name} exit={code} saved={len(before)}")


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL])
def test_pareto_signal_then_resume(tmp_path, pareto_reference, sig):
    _pareto_case(tmp_path, pareto_reference, sig, seed=100 + int(sig), early=True)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_pareto_signal_then_resume_more_moments(tmp_path, pareto_reference, sig, seed):
    _pareto_case(tmp_path, pareto_reference, sig, seed=1000 * seed + int(sig), early=False)


# --- bench --------------------------------------------------------------------------------
_BENCH_FIELDS = ("status", "objective", "verified", "violation", "design", "applicable")


@pytest.fixture(scope="module")
def bench_reference(tmp_path_factory) -> dict[str, dict]:
    out = tmp_path_factory.mktemp("bench_ref") / "run"
    res = _run_cli([*BENCH, "--out", str(out)])
    assert res.returncode == 0, res.stderr
    return {r["id"]: r for r in _store_lines(out / "bench_runs.jsonl")}


def _bench_case(
    tmp_path: Path, reference: dict[str, dict], sig: int, seed: int, early: bool
) -> None:
    out = tmp_path / "run"
    store = out / "bench_runs.jsonl"
    rng = random.Random(seed)
    code, err, before, left = _interrupt(
        [*BENCH, "--out", str(out)],
        store,
        sig,
        rng,
        len(reference) // (3 if early else 1),
        0.02 if early else 0.3,
    )
    assert left == [], f"processes left after {signal.Signals(sig).name}: {left}"
    assert code != 0 or not early, "the run ended before the signal"
    _check_exit(code, err, sig, store, len(before))
    res = _run_cli([*BENCH, "--out", str(out), "--resume"])
    assert res.returncode == 0 and "Traceback" not in res.stderr, res.stderr
    after = _store_lines(store)
    _check_records(before, after)
    assert sorted(r["id"] for r in after) == sorted(reference)
    for r in after:
        ref = reference[r["id"]]
        for k in _BENCH_FIELDS:
            if isinstance(ref.get(k), float):
                assert r[k] == pytest.approx(ref[k], rel=1e-6, abs=1e-9), (r["id"], k)
            elif isinstance(ref.get(k), dict):
                assert r[k] == pytest.approx(ref[k], rel=1e-6, abs=1e-9), (r["id"], k)
            else:
                assert r.get(k) == ref.get(k), (r["id"], k)
    print(f"signal-case bench {signal.Signals(sig).name} exit={code} saved={len(before)}")


@pytest.mark.parametrize("sig", [signal.SIGTERM])
def test_bench_signal_then_resume(tmp_path, bench_reference, sig):
    _bench_case(tmp_path, bench_reference, sig, seed=200 + int(sig), early=True)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_bench_signal_then_resume_more_moments(tmp_path, bench_reference, sig, seed):
    _bench_case(tmp_path, bench_reference, sig, seed=1000 * seed + int(sig), early=False)


# --- a signal inside one long solver call (issue 21) -------------------------------------
# Ipopt options that keep one call going for minutes: the tolerances cannot be met, so
# Ipopt iterates (tiny steps) until max_iter, checking for Python signals between its
# function evaluations; print_level 5 shows when it has started.
SLOW_IPOPT_OPTIONS = {
    "max_iter": 100000,
    "tol": 1e-300,
    "acceptable_tol": 1e-300,
    "acceptable_iter": 1000000000,
    "constr_viol_tol": 1e-300,
    "dual_inf_tol": 1e-300,
    "compl_inf_tol": 1e-300,
    "acceptable_constr_viol_tol": 1e-300,
    "acceptable_dual_inf_tol": 1e-300,
    "acceptable_compl_inf_tol": 1e-300,
    "tiny_step_tol": 0,
}
SLOW_IPOPT = (
    "\n[solver]\nstarts = 4\nagree = 0\nipopt = { print_level = 5, "
    + ", ".join(f"{k} = {v}" for k, v in SLOW_IPOPT_OPTIONS.items())
    + " }\n"
)
IPOPT_RUNNING = re.compile(rb"^iter\s+objective\s+inf_pr", re.MULTILINE)


SIGNALS = [signal.SIGINT, signal.SIGTERM, signal.SIGHUP]


def _signame(sig: int) -> str:
    return signal.Signals(sig).name


def _slow_problem(tmp_path: Path, name: str) -> str:
    path = tmp_path / f"{name}_slow.toml"
    path.write_text((ROOT / "problems" / f"{name}.toml").read_text() + SLOW_IPOPT)
    return str(path)


def _bench_run_started(pid: int, workers: int) -> bool:
    # A bench run is a forked child (of this process with 1 worker, of a worker with 2)
    # that lives exactly as long as the run's solve.
    try:
        kids = psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return False
    return any(k.ppid() != pid for k in kids) if workers > 1 else bool(kids)


def _check_inside(case, sig: int, store: Path | None, label: str) -> None:
    code, seconds, out, err, left = case
    # one line per case for the record (pytest -s)
    print(f"signal-inside {label} {_signame(sig)} exit={code} after {seconds:.3f} s")
    assert code == 128 + sig, (code, err[-2000:])
    assert seconds < 1.0, f"exit {seconds:.2f} s after the signal"
    assert left == [], f"processes left: {left}"
    both = out + err
    assert "Traceback" not in both and "internal error" not in both, err[-2000:]
    assert "KeyboardInterruptException" not in both  # CasADi's warning: not for the user
    line = err.rstrip("\n").splitlines()[-1]
    name = signal.Signals(sig).name
    if store is None:
        assert line == f"optdesign: interrupted ({name})"
        return
    key, records = read_store(store)  # a store --resume accepts: identity, whole lines
    lines = _store_lines(store)
    assert key and store.read_bytes().endswith(b"\n")
    assert len({r["id"] for r in lines}) == len(lines) == len(records)  # none twice
    n = len(records)
    assert line == (
        f"optdesign: interrupted ({name}); {n} record{'' if n == 1 else 's'} saved in "
        f"{store}, --resume continues"
    )


def _ipopt_running(output: bytes, pid: int) -> bool:
    return IPOPT_RUNNING.search(output) is not None


def _inside_a_solve(output: str) -> None:
    # the interrupted call never finished: one more Ipopt solve began than ended
    assert output.count("This is Ipopt version") > output.count("EXIT:"), output[-1000:]


_SOLVE_CASES = {
    # name: (problem, extra arguments)
    "nlp-1-worker": ("cs_min_backlash", []),
    "nlp-2-workers": ("cs_min_backlash", ["--workers", "2", "--json"]),
    "catalogue": ("cs_min_backlash_catalogue", ["--json"]),
    "robust": ("cs_min_backlash_robust", ["--formulation", "robust"]),
    "gp": ("fork_min_backlash", ["--formulation", "gp", "--json"]),
}


def _solve_inside(tmp_path: Path, case: str, sig: int, group: bool = False) -> None:
    name, extra = _SOLVE_CASES[case]
    args = ["solve", _slow_problem(tmp_path, name), "--out", str(tmp_path / "out"), *extra]
    result = signal_inside(_cli(args), sig, _ipopt_running, group)
    _check_inside(result, sig, None, f"solve-{case}")
    _inside_a_solve(result[2] + result[3])
    assert not (tmp_path / "out" / "result.json").exists()  # no result of a half solve


def _pareto_inside(tmp_path: Path, workers: int, sig: int, group: bool = False) -> None:
    out = tmp_path / "out"
    args = [
        "pareto", _slow_problem(tmp_path, "fork_min_backlash"), "--objectives",
        "size,backlash", "--points", "6", "--workers", str(workers), "--no-plot",
        "--no-progress", "--out", str(out),
    ]  # fmt: skip
    result = signal_inside(_cli(args), sig, _ipopt_running, group)
    _check_inside(result, sig, out / "epsilon.jsonl", f"pareto-{workers}w")
    _inside_a_solve(result[2] + result[3])


def _bench_inside(tmp_path: Path, workers: int, sig: int, group: bool = False) -> None:
    # differential evolution with a 60 s limit: each run is one long solver call
    out = tmp_path / "out"
    args = [
        "bench", "--suite", "quick", "--solvers", "de", "--workers", str(workers),
        "--time-limit", "60", "--hard-timeout", "120", "--no-progress", "--out", str(out),
    ]  # fmt: skip
    result = signal_inside(_cli(args), sig, lambda _o, pid: _bench_run_started(pid, workers), group)
    _check_inside(result, sig, out / "bench_runs.jsonl", f"bench-{workers}w")


def _reproduce_inside(tmp_path: Path, sig: int) -> None:
    # the PRSM contact sweeps: Newton solves of the contact equations, one after another
    args = ["reproduce", "prsm-contact", "--out", str(tmp_path / "out")]
    result = signal_inside(_cli(args), sig, lambda o, _pid: b"\n1. Hertz" in b"\n" + o)
    _check_inside(result, sig, None, "reproduce")


def test_ctrl_c_inside_the_solver_call_of_a_one_worker_solve(tmp_path):
    # the case: SIGINT used to be lost inside CasADi (the next start ran, exit 0)
    _solve_inside(tmp_path, "nlp-1-worker", signal.SIGINT)


@pytest.mark.slow
@pytest.mark.parametrize("sig", SIGNALS, ids=_signame)
@pytest.mark.parametrize("case", list(_SOLVE_CASES))
def test_signal_inside_a_solver_call_of_solve(tmp_path, case, sig):
    _solve_inside(tmp_path, case, sig)


@pytest.mark.slow
@pytest.mark.parametrize("sig", SIGNALS, ids=_signame)
@pytest.mark.parametrize("workers", [1, 2])
def test_signal_inside_a_solver_call_of_pareto(tmp_path, workers, sig):
    _pareto_inside(tmp_path, workers, sig)


@pytest.mark.slow
@pytest.mark.parametrize("sig", SIGNALS, ids=_signame)
@pytest.mark.parametrize("workers", [1, 2])
def test_signal_inside_a_solver_call_of_bench(tmp_path, workers, sig):
    _bench_inside(tmp_path, workers, sig)


@pytest.mark.slow
@pytest.mark.parametrize("sig", SIGNALS, ids=_signame)
def test_signal_inside_a_solver_call_of_reproduce(tmp_path, sig):
    _reproduce_inside(tmp_path, sig)


@pytest.mark.slow
@pytest.mark.parametrize("command", ["solve", "pareto", "bench"])
def test_sigterm_to_the_whole_process_group_with_two_workers(tmp_path, command):
    # `timeout`, a service manager: the workers get SIGTERM too and die at once; the
    # run still ends as interrupted (143), not as "a worker died" or a crash record
    if command == "solve":
        _solve_inside(tmp_path, "nlp-2-workers", signal.SIGTERM, group=True)
    elif command == "pareto":
        _pareto_inside(tmp_path, 2, signal.SIGTERM, group=True)
    else:
        _bench_inside(tmp_path, 2, signal.SIGTERM, group=True)
