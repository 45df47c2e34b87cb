"""Interrupting a run: SIGINT and SIGHUP (to the whole process group, as a terminal's
Ctrl-C and hangup do), SIGTERM and SIGKILL at random moments of a 2-worker run_tasks,
then resume; and a signal inside a solver call, in library use, in native code that
never returns, or whose exception C code dropped.

Each case checks: exit code 130 / 143 / 129 and one line, no traceback; a reader of the
run's stdout pipe is not kept waiting (communicate with a timeout); no worker or isolated
task process left; the store readable, every record written before the signal kept, and
after resuming every task exactly once.
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
import threading
import time
from pathlib import Path

import pytest

psutil = pytest.importorskip("psutil")

from optdesign.runtime.runner import Isolation, read_store, run_tasks  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
N_TASKS = 16

SCRIPT = """
import os, sys, time
from optdesign.cli import run_guarded
from optdesign.runtime.runner import Isolation, run_tasks

def work(task, deps):
    time.sleep(task["sleep"])
    return {"value": 2 * task["n"]}

if __name__ == "__main__":
    store, sleep, isolated = sys.argv[1], float(sys.argv[2]), sys.argv[3] == "1"
    tasks = [{"id": f"t{i:03d}", "n": i, "sleep": sleep} for i in range(N_TASKS)]

    def run():
        done = run_tasks(
            tasks, work, store, workers=2, key="sig",
            isolate=Isolation(timeout=30) if isolated else None,
        )
        print("done", len(done), flush=True)
        return 0

    print("started", flush=True)
    sys.exit(run_guarded(run))
""".replace("N_TASKS", str(N_TASKS))


def _work(task, deps):
    # the script's task, for resuming in this process
    if "pidfile" in task:
        Path(task["pidfile"]).write_text(str(os.getpid()))
    time.sleep(task["sleep"])
    return {"value": 2 * task["n"]}


def _tasks(sleep: float) -> list[dict]:
    return [{"id": f"t{i:03d}", "n": i, "sleep": sleep} for i in range(N_TASKS)]


def _descendants(pid: int, wait: float = 3.0, want: int = 2) -> list[int]:
    """Pids of ``pid``'s descendants once ``want`` of them exist (or ``wait`` s passed)."""
    end = time.monotonic() + wait
    kids: list[int] = []
    while time.monotonic() < end:
        try:
            kids = [p.pid for p in psutil.Process(pid).children(recursive=True)]
        except psutil.NoSuchProcess:
            break
        if len(kids) >= want:
            break
        time.sleep(0.01)
    return kids


def _alive(pids: list[int], wait: float = 3.0) -> list[int]:
    """The pids still running (not gone, not a zombie) after up to ``wait`` s."""
    end = time.monotonic() + wait
    while True:
        alive = []
        for pid in pids:
            try:
                if psutil.Process(pid).status() != psutil.STATUS_ZOMBIE:
                    alive.append(pid)
            except psutil.NoSuchProcess:
                pass
        if not alive or time.monotonic() > end:
            return alive
        time.sleep(0.02)


def _group(pgid: int) -> list[int]:
    """Live (not zombie) processes of process group ``pgid``."""
    out = []
    for proc in psutil.process_iter(["pid", "status"]):
        try:
            if os.getpgid(proc.pid) == pgid and proc.info["status"] != psutil.STATUS_ZOMBIE:
                out.append(proc.pid)
        except (ProcessLookupError, psutil.NoSuchProcess, PermissionError):
            pass
    return out


def _env() -> dict[str, str]:
    path = os.environ.get("PYTHONPATH")
    return {
        **os.environ,
        "PYTHONPATH": str(ROOT) + (os.pathsep + path if path else ""),
        "MPLBACKEND": "Agg",
        "PYTHONUNBUFFERED": "1",  # a solver's log as it is written
    }


def signal_inside(command: list[str], sig: int, started, group: bool = False):
    """Run ``command``, send ``sig`` once ``started(output so far, pid)`` holds (e.g. the
    solver's log shows it running), and return (exit code, seconds from the signal to
    the exit, stdout, stderr, processes left). SIGINT goes to the process group
    (Ctrl-C), like SIGTERM with ``group`` (``timeout``, a service manager); otherwise
    the signal goes to the process alone."""
    proc = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=_env(),
        start_new_session=True,  # its own process group, as a job in a terminal
    )
    chunks: dict[str, list[bytes]] = {"out": [], "err": []}

    def pump(stream, key: str) -> None:
        for chunk in iter(lambda: stream.read1(1 << 16), b""):
            chunks[key].append(chunk)

    readers = [
        threading.Thread(target=pump, args=(proc.stdout, "out"), daemon=True),
        threading.Thread(target=pump, args=(proc.stderr, "err"), daemon=True),
    ]
    for r in readers:
        r.start()
    try:
        end = time.monotonic() + 180
        while not started(b"".join(chunks["out"] + chunks["err"]), proc.pid):
            assert proc.poll() is None, b"".join(chunks["err"]).decode()[-2000:]
            assert time.monotonic() < end, "the solver did not start"
            time.sleep(0.01)
        seen = [k.pid for k in psutil.Process(proc.pid).children(recursive=True)]
        t_signal = time.monotonic()
        if sig == signal.SIGINT or group:
            os.killpg(proc.pid, sig)
        else:
            os.kill(proc.pid, sig)
        try:
            code = proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            raise AssertionError(f"still running 30 s after {signal.Signals(sig).name}") from None
        seconds = time.monotonic() - t_signal
        for r in readers:  # a reader gets EOF: no orphan holds the pipes
            r.join(10)
            assert not r.is_alive(), "the output pipes are still open"
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    left = _alive(seen, wait=2.0) + [p for p in _group(proc.pid) if p not in seen]
    out = b"".join(chunks["out"]).decode(errors="replace")
    err = b"".join(chunks["err"]).decode(errors="replace")
    return code, seconds, out, err, left


def _interrupt_and_resume(tmp_path: Path, sig: int, seed: int, isolated: bool = False):
    rng = random.Random(seed)
    script = tmp_path / "run.py"
    script.write_text(SCRIPT)
    store = tmp_path / "out" / "s.jsonl"
    sleep = 0.1
    proc = subprocess.Popen(
        [sys.executable, str(script), str(store), str(sleep), "1" if isolated else "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        start_new_session=True,  # its own process group, like a job in a terminal
    )
    try:
        assert proc.stdout.readline().strip() == b"started"
        kids = _descendants(proc.pid, want=4 if isolated else 2)
        assert len(kids) >= 2, "the pool did not start"
        time.sleep(rng.uniform(0.0, 0.5))  # 16 tasks of 0.1 s on 2 workers: ~0.8 s
        kids = sorted(set(kids) | set(_descendants(proc.pid, wait=0)))
        if sig in (signal.SIGINT, signal.SIGHUP):
            # the terminal's Ctrl-C or hangup: every process of the job
            os.killpg(proc.pid, sig)
        else:
            os.kill(proc.pid, sig)
        # A reader of the run's output must get EOF: no orphan may hold the pipe.
        out, err = proc.communicate(timeout=10)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    out, err = out.decode(), err.decode()
    left = _alive(kids)
    assert left == [], f"processes left after {signal.Signals(sig).name}: {left}"
    assert "Traceback" not in err, err
    _, before = read_store(store)  # readable (a torn tail is only possible with SIGKILL)
    if proc.returncode == 0:  # finished before the signal: nothing to interrupt
        assert "done 16" in out and len(before) == N_TASKS
    elif sig == signal.SIGKILL:
        assert proc.returncode == -signal.SIGKILL
    else:
        assert proc.returncode == 128 + sig, (proc.returncode, err)
        name = signal.Signals(sig).name
        n = len(before)
        assert err.strip() == (
            f"optdesign: interrupted ({name}); {n} record{'' if n == 1 else 's'} saved in "
            f"{store}, --resume continues"
        )
        # an interrupt leaves no torn line
        assert store.read_bytes().endswith(b"\n")
    # resume (a new process: the dead run's lock is gone with it)
    done = run_tasks(_tasks(0.0), _work, store, workers=2, key="sig", resume=True)
    assert {k: r["value"] for k, r in done.items()} == {f"t{i:03d}": 2 * i for i in range(N_TASKS)}
    ids = [json.loads(line)["id"] for line in store.read_text().splitlines()[1:]]
    assert sorted(ids) == sorted(done)  # each record exactly once: none lost, none twice
    for k, rec in before.items():
        assert done[k] == rec  # what was saved before the signal is kept as it was
    return len(before)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGKILL])
def test_signal_then_resume(tmp_path, sig):
    _interrupt_and_resume(tmp_path, sig, seed=int(sig))


def test_sigkill_of_a_run_with_isolated_tasks_leaves_no_grandchild(tmp_path):
    _interrupt_and_resume(tmp_path, signal.SIGKILL, seed=3, isolated=True)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(1, 6))
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGKILL])
def test_signal_then_resume_more_seeds(tmp_path, sig, seed):
    _interrupt_and_resume(tmp_path, sig, seed=100 * seed + int(sig), isolated=seed % 2 == 0)


def test_isolated_task_is_killed_when_this_process_is_interrupted(tmp_path):
    # In-process isolation (workers=1): an interrupt while waiting for the forked child
    # kills the child; the record finished before it is in the store.
    def alarm(signum, frame):
        raise KeyboardInterrupt

    pidfile = tmp_path / "child.pid"
    tasks = [
        {"id": "t0", "n": 0, "sleep": 0.0},
        {"id": "t1", "n": 1, "sleep": 30.0, "pidfile": str(pidfile)},
    ]
    store = tmp_path / "s.jsonl"
    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, 0.5)
    t0 = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt) as info:
            run_tasks(tasks, _work, store, isolate=Isolation(timeout=60))
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert time.monotonic() - t0 < 5
    assert _alive([int(pidfile.read_text())], wait=1.0) == []
    assert info.value.run_store == {"path": str(store), "records": 1}
    assert list(read_store(store)[1]) == ["t0"]


def test_a_signal_inside_a_critical_section_is_raised_at_its_end_not_lost():
    from optdesign.interrupts import Interrupted, deferred, interrupts_as_exceptions

    before = signal.getsignal(signal.SIGINT)
    with interrupts_as_exceptions():
        reached = []
        with pytest.raises(Interrupted) as info:
            with deferred():
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(0.05)  # the handler has run by now: it only took note
                reached.append("end of section")
        assert reached == ["end of section"] and info.value.signum == signal.SIGTERM
        with deferred(drop=True):  # the cleanup of a run being interrupted already
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)
        with pytest.raises(Interrupted):  # outside a section: at once
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)
    assert signal.getsignal(signal.SIGINT) is before  # restored


def test_run_guarded_exit_codes_and_one_line(capsys):
    from optdesign.cli import run_guarded
    from optdesign.errors import InputError

    def terminated():
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)

    def bad_input():
        raise InputError("--points", "need at least 2 points")

    def hung_up():
        os.kill(os.getpid(), signal.SIGHUP)
        time.sleep(5)

    assert run_guarded(terminated) == 143
    assert capsys.readouterr().err == "optdesign: interrupted (SIGTERM)\n"
    assert run_guarded(hung_up) == 129
    assert capsys.readouterr().err == "optdesign: interrupted (SIGHUP)\n"
    assert run_guarded(bad_input) == 2
    assert capsys.readouterr().err == "optdesign: error: --points: need at least 2 points\n"
    assert run_guarded(lambda: 1) == 1


def test_an_interrupt_after_the_solving_still_names_the_saved_store(tmp_path, capsys):
    # Interrupted while the command writes its front (its store complete): the message
    # names the store and its count, as an interrupt during the solving does.
    from optdesign.cli import run_guarded

    store = tmp_path / "out" / "s.jsonl"

    def solved_then_terminated():
        run_tasks(_tasks(0.0)[:3], _work, store, workers=1, key="sig")
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)

    assert run_guarded(solved_then_terminated) == 143
    assert capsys.readouterr().err == (
        f"optdesign: interrupted (SIGTERM); 3 records saved in {store}, --resume continues\n"
    )
    # a new command starts with no store saved
    assert run_guarded(lambda: os.kill(os.getpid(), signal.SIGTERM) or time.sleep(5)) == 143
    assert capsys.readouterr().err == "optdesign: interrupted (SIGTERM)\n"


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_while_the_program_exits_gives_the_same_line(tmp_path, sig):
    # After the command (interpreter shutdown, a second or more with the solvers loaded)
    # a signal ends the program with the one line and 130/143, naming the saved store.
    store = tmp_path / "out" / "s.jsonl"
    code = f"""
import os, signal, sys, time
from optdesign.cli import _late_signals_exit, run_guarded
from optdesign.runtime.runner import run_tasks

def work(task, deps):
    return {{"value": task["n"]}}

_late_signals_exit()
assert run_guarded(lambda: len(run_tasks([{{"id": "a", "n": 1}}], work, {str(store)!r},
                                          workers=1, key="k"))) == 1
print("done", flush=True)
os.kill(os.getpid(), {int(sig)})
time.sleep(5)
"""
    res = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        timeout=60,
    )
    assert res.stdout == "done\n"
    assert res.returncode == 128 + sig
    name = signal.Signals(sig).name
    assert res.stderr == (
        f"optdesign: interrupted ({name}); 1 record saved in {store}, --resume continues\n"
    )


# --- solver calls, library use, native code (issue 21) ---------------------------------
LIBRARY_SCRIPT = """
import signal, sys
import optdesign as od

problem = od.load(sys.argv[1])
try:
    od.solve(problem)
except KeyboardInterrupt as exc:
    restored = signal.getsignal(signal.SIGINT) is signal.default_int_handler
    print(f"raised {type(exc).__name__} handler restored={restored}", file=sys.stderr)
    sys.exit(7)
print("returned a result", file=sys.stderr)
"""


def test_ctrl_c_during_od_solve_raises_keyboard_interrupt_in_library_use(tmp_path):
    # A notebook's Ctrl-C inside Ipopt: CasADi returned the start as failed and the
    # multistart went on; now KeyboardInterrupt, Python's own handler back afterwards.

    script = tmp_path / "use.py"
    script.write_text(LIBRARY_SCRIPT)
    problem = _slow_problem(tmp_path, "cs_min_backlash")
    code, seconds, out, err, left = signal_inside(
        [sys.executable, str(script), problem],
        signal.SIGINT,
        lambda output, _pid: IPOPT_RUNNING.search(output) is not None,
    )
    print(f"signal-inside od.solve SIGINT exit={code} after {seconds:.3f} s")
    assert code == 7, err[-2000:]
    assert seconds < 1.0, f"exit {seconds:.2f} s after Ctrl-C"
    assert err.splitlines()[-1] == "raised Interrupted handler restored=True"
    assert "KeyboardInterruptException" not in out + err  # CasADi's warning muted
    assert left == []


STUCK_SCRIPT = """
import ctypes, os, sys
from optdesign import cli, interrupts
from optdesign.solvers.casadi_nlp import CasadiNLPSolver

libc = ctypes.CDLL(None)
mutex = ctypes.create_string_buffer(64)  # a PTHREAD_MUTEX_INITIALIZER (zeros)


solve = CasadiNLPSolver.solve


def stuck(self, *args, **kwargs):
    if self.plugin != "ipopt":  # the sweep's primary (sqpmethod) solves the anchors
        return solve(self, *args, **kwargs)
    # native code that never returns nor looks at Python's signals (a mutex locked twice)
    with interrupts.solver_call():
        # one write: a signal sent on seeing the words must not split them from the
        # newline (the handler runs between two writes of print)
        os.write(2, b"inside the solver call\\n")
        libc.pthread_mutex_lock(mutex)
        libc.pthread_mutex_lock(mutex)


CasadiNLPSolver.solve = stuck
sys.argv = ["optdesign", *sys.argv[1:]]
cli.main()
"""


@pytest.mark.parametrize(
    "sig",
    [signal.SIGTERM, pytest.param(signal.SIGHUP, marks=pytest.mark.slow)],
    ids=lambda s: signal.Signals(s).name,
)
def test_a_signal_ends_the_program_stuck_in_native_solver_code(tmp_path, sig):
    # The main thread never comes back to Python: the watchdog ends the program with
    # the line and the code, naming the store and the records it holds (the front's
    # anchors, solved by the sweep's primary, are written; the first Ipopt call never
    # returns).
    script = tmp_path / "stuck.py"
    script.write_text(STUCK_SCRIPT)
    out = tmp_path / "out"
    args = ["pareto", str(ROOT / "problems" / "fork_min_backlash.toml"), "--objectives"]
    args += ["size,backlash", "--points", "6", "--workers", "1", "--no-plot", "--out", str(out)]
    code, seconds, _, err, left = signal_inside(
        [sys.executable, str(script), *args], sig, lambda o, _pid: b"inside the solver" in o
    )
    print(f"signal-inside native {signal.Signals(sig).name} exit={code} after {seconds:.3f} s")
    assert code == 128 + sig and seconds < 1.0, (code, seconds, err[-2000:])
    assert "Traceback" not in err and left == []
    store = out / "epsilon.jsonl"
    _, records = read_store(store)
    assert store.read_bytes().endswith(b"\n") and len(records) >= 1
    n = len(records)
    assert err.splitlines()[-1] == (
        f"optdesign: interrupted ({signal.Signals(sig).name}); {n} record"
        f"{'' if n == 1 else 's'} saved in {store}, --resume continues"
    )


DROPPED_SCRIPT = """
import sys, time
import numpy as np
import optdesign.reproduce
from optdesign import cli


class Sized:
    # NumPy asks an unknown object for its length and clears any error that raises
    def __getitem__(self, i):
        raise IndexError(i)

    def __len__(self):
        print("asked for the length", file=sys.stderr, flush=True)
        time.sleep(10)  # the signal's handler raises here; NumPy drops the exception
        return 0


def run(name, out):
    np.asarray(Sized(), dtype=object)
    print("numpy returned", file=sys.stderr, flush=True)
    end = time.monotonic() + 30
    while time.monotonic() < end:  # Python code that would hear a signal again
        time.sleep(0.01)
    return 0


optdesign.reproduce.run = run
sys.argv = ["optdesign", "reproduce", "duan2017", "--out", sys.argv[1]]
cli.main()
"""


def test_a_signal_whose_exception_c_code_dropped_is_raised_again(tmp_path):
    # reproduce prsm-contact ran on for 4.8 s and exited 0 after SIGTERM: NumPy cleared
    # the handler's exception while converting a CasADi object; the watchdog sees no
    # interrupt alive and signals the main thread again.
    script = tmp_path / "dropped.py"
    script.write_text(DROPPED_SCRIPT)
    code, seconds, _, err, left = signal_inside(
        [sys.executable, str(script), str(tmp_path / "out")],
        signal.SIGTERM,
        lambda output, _pid: b"asked for the length" in output,
    )
    print(f"signal-inside dropped SIGTERM exit={code} after {seconds:.3f} s")
    assert "numpy returned" in err  # the first exception was indeed dropped
    assert code == 143 and seconds < 1.0, (code, seconds, err[-2000:])
    assert err.splitlines()[-1] == "optdesign: interrupted (SIGTERM)" and left == []


def _after(seconds: float, sig: int) -> threading.Timer:
    timer = threading.Timer(seconds, os.kill, (os.getpid(), sig))
    timer.start()
    return timer


@pytest.mark.parametrize("library", ["swallows", "wraps"])
def test_solver_call_raises_the_signal_a_library_lost(library):
    # CasADi returns an interrupted Ipopt solve as failed, or raises RuntimeError from
    # its own KeyboardInterruptException: the signal is raised all the same.
    from optdesign.interrupts import Interrupted, interrupts_as_exceptions, solver_call

    def native():
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)  # the handler raises here
        except BaseException:
            if library == "wraps":
                raise RuntimeError("KeyboardInterrupt") from None
            return "failed"
        return "solved"

    with interrupts_as_exceptions():
        with pytest.raises(Interrupted) as info:
            with solver_call():
                native()
    assert info.value.signum == signal.SIGTERM


@pytest.mark.slow
def test_an_ipopt_solve_is_interrupted_not_returned_as_a_failed_start(capfd):
    # The root of issue 21's class 3, in this process: Ipopt (print_level 0) in a long
    # call, SIGTERM after 0.3 s; Interrupted within a second, CasADi's warning muted.

    import optdesign as od
    from optdesign.formulations.nlp.solve import solver_for
    from optdesign.interrupts import Interrupted, interrupts_as_exceptions

    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    backend = solver_for(problem, "ipopt", {**SLOW_IPOPT_OPTIONS, "max_iter": 20000})
    x0 = problem.start()
    with interrupts_as_exceptions():
        timer = _after(0.3, signal.SIGTERM)
        t0 = time.monotonic()
        with pytest.raises(Interrupted) as info:
            backend.solve(x0)
        timer.join()
    assert info.value.signum == signal.SIGTERM
    assert time.monotonic() - t0 < 1.3
    assert "KeyboardInterruptException" not in "".join(capfd.readouterr())


@pytest.mark.slow
def test_ctrl_c_in_a_solve_raises_keyboard_interrupt_without_the_cli():
    # library use: Python's own SIGINT handler, which the solve lends a recording twin

    import optdesign as od
    from optdesign.formulations.nlp.solve import solver_for

    problem = od.load(ROOT / "problems" / "cs_min_backlash.toml")
    backend = solver_for(problem, "ipopt", {**SLOW_IPOPT_OPTIONS, "max_iter": 20000})
    timer = _after(0.3, signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):
        backend.solve(problem.start())
    timer.join()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    # the interrupt is spent: the next solve runs to its end
    assert solver_for(problem, "ipopt").solve(problem.start()).success


# SIGINT, SIGTERM and SIGKILL of the real `optdesign pareto` and `optdesign bench` at
# seeded random moments, then `--resume` (issue 13).
#
# Each case checks: the run's stdout/stderr pipes reach EOF (no orphan holds them); no
# process of the run is left (its descendants, and anything else in its process group);
# exit 130 / 143 with the one-line message and no traceback (-9 for SIGKILL); every record
# saved before the signal is kept as it was after the resume, no record lost or written
# twice; the resumed front (pareto `--deterministic`) or the resumed bench rows equal an
# uninterrupted run's.


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


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL])
def test_pareto_signal_then_resume(tmp_path, pareto_reference, sig):
    _pareto_case(tmp_path, pareto_reference, sig, seed=100 + int(sig), early=True)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_pareto_signal_then_resume_more_moments(tmp_path, pareto_reference, sig, seed):
    _pareto_case(tmp_path, pareto_reference, sig, seed=1000 * seed + int(sig), early=False)


@pytest.mark.parametrize("sig", [signal.SIGTERM])
def test_bench_signal_then_resume(tmp_path, bench_reference, sig):
    _bench_case(tmp_path, bench_reference, sig, seed=200 + int(sig), early=True)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_bench_signal_then_resume_more_moments(tmp_path, bench_reference, sig, seed):
    _bench_case(tmp_path, bench_reference, sig, seed=1000 * seed + int(sig), early=False)


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
