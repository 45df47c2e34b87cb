"""Stop the mutants whose test process hangs without using the CPU.

mutmut 3 runs each mutant in a process forked from its own (threaded) process and limits
it by CPU time only: a child that deadlocks on a lock a thread held at the fork (the
process-pool and Dask tests of the fronts and the runner) waits forever at 0 % CPU. This
watchdog sends SIGTERM to a mutant's process that, with every process it started, has
used under 5 % of a core over IDLE seconds;
mutmut records it as "suspicious" (exit -15), which summary.py counts apart - neither
killed nor survived.

Usage: python benchmarks/mutation/watchdog.py LOGFILE [IDLE_SECONDS]   (runs until killed)
"""

from __future__ import annotations

import os
import signal
import sys
import time


def _processes() -> dict[int, tuple[str, int, int]]:
    """pid -> (command, parent pid, CPU ticks used by it and its waited-for children)."""
    out = {}
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as fh:
                cmd = fh.read().split(b"\0")[0].decode(errors="replace")
            with open(f"/proc/{pid}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        ticks = sum(int(f) for f in fields[11:15])  # utime stime cutime cstime
        out[int(pid)] = (cmd, int(fields[1]), ticks)
    return out


def _mutants() -> dict[int, tuple[str, int]]:
    """A mutant's test process -> (mutant, CPU ticks of it and all its descendants): a
    test waiting for a command it started is not idle while the command works."""
    procs = _processes()
    children: dict[int, list[int]] = {}
    for pid, (_, ppid, _) in procs.items():
        children.setdefault(ppid, []).append(pid)
    out = {}
    for pid, (cmd, _, _) in procs.items():
        if not cmd.startswith("mutmut: "):
            continue
        total, stack = 0, [pid]
        while stack:
            p = stack.pop()
            total += procs[p][2]
            stack += children.get(p, [])
        out[pid] = (cmd[len("mutmut: ") :], total)
    return out


def main(log: str, idle: float = 120.0) -> int:
    hz = os.sysconf("SC_CLK_TCK")
    window: dict[int, tuple[int, float]] = {}  # pid -> (CPU ticks, time) at its start
    while True:
        now = time.monotonic()
        current = _mutants()
        for pid, (name, ticks) in current.items():
            t0, since = window.setdefault(pid, (ticks, now))
            if now - since < idle:
                continue
            # under 5 % of one core over the window: waiting, not computing (a thread's
            # event loop still ticks now and then)
            if (ticks - t0) / hz < 0.05 * (now - since):
                try:
                    os.kill(pid, signal.SIGTERM)
                except OSError:
                    continue
                with open(log, "a", encoding="utf-8") as fh:
                    fh.write(f"{time.strftime('%H:%M:%S')} hung {name}\n")
            window[pid] = (ticks, now)
        for pid in set(window) - set(current):
            window.pop(pid)
        time.sleep(10)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], float(sys.argv[2]) if len(sys.argv) > 2 else 120.0))
