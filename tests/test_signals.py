"""Interrupting a run: SIGINT (to the whole process group, as a terminal's Ctrl-C does),
SIGTERM and SIGKILL at random moments of a 2-worker run_tasks, then resume.

Each case checks: exit code 130 / 143 and one line, no traceback; a reader of the run's
stdout pipe is not kept waiting (communicate with a timeout); no worker or isolated task
process left; the store readable, every record written before the signal kept, and after
resuming every task exactly once.
"""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

psutil = pytest.importorskip("psutil")

from optdesign.studies.runner import Isolation, read_store, run_tasks  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
N_TASKS = 16

SCRIPT = """
import os, sys, time
from optdesign.cli import run_guarded
from optdesign.studies.runner import Isolation, run_tasks

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
        if sig == signal.SIGINT:
            os.killpg(proc.pid, sig)  # the terminal's Ctrl-C: every process of the job
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


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_signal_then_resume(tmp_path, sig):
    _interrupt_and_resume(tmp_path, sig, seed=int(sig))


def test_sigkill_of_a_run_with_isolated_tasks_leaves_no_grandchild(tmp_path):
    _interrupt_and_resume(tmp_path, signal.SIGKILL, seed=3, isolated=True)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(1, 6))
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
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
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored


def test_run_guarded_exit_codes_and_one_line(capsys):
    from optdesign.cli import run_guarded
    from optdesign.errors import InputError

    def terminated():
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)

    def bad_input():
        raise InputError("--points", "need at least 2 points")

    assert run_guarded(terminated) == 143
    assert capsys.readouterr().err == "optdesign: interrupted (SIGTERM)\n"
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


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_the_program_exits_gives_the_same_line(tmp_path, sig):
    # After the command (interpreter shutdown, a second or more with the solvers loaded)
    # a signal ends the program with the one line and 130/143, naming the saved store.
    store = tmp_path / "out" / "s.jsonl"
    code = f"""
import os, signal, sys, time
from optdesign.cli import _late_signals_exit, run_guarded
from optdesign.studies.runner import run_tasks

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
