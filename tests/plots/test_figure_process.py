"""plots.figure_process: a command's figure drawn in a forked child gives the file the
command drew in process before, and every way the child can fail is a note."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

import optdesign as od
from optdesign.plots import write_figure
from optdesign.plots.figure_process import FigureProcess
from optdesign.plots.solution import draw_solution, result_figure

pytestmark = pytest.mark.skipif(
    not hasattr(os, "fork"), reason="the figure process forks (elsewhere: in process)"
)


@pytest.fixture(scope="module")
def solved():
    return od.solve("cs_min_backlash", starts=1, ranges=False)


def test_the_child_writes_the_png_the_process_draws(solved, tmp_path):
    record = result_figure(solved)
    assert write_figure(lambda: draw_solution(record), tmp_path / "here.png") is None
    with FigureProcess() as figures:
        if threading.active_count() != 1:
            pytest.skip("the test process runs threads: no fork (drawn in process)")
        assert figures.forked
        figures.submit("optdesign.plots.solution:draw_solution", tmp_path / "a.png", lambda: record)
        figures.submit("optdesign.plots.solution:draw_solution", tmp_path / "b.png", lambda: record)
        assert figures.outcome() is None and figures.outcome() is None
    here = (tmp_path / "here.png").read_bytes()
    assert len(here) > 10_000
    assert (tmp_path / "a.png").read_bytes() == here == (tmp_path / "b.png").read_bytes()


def test_a_drawing_that_fails_in_the_child_is_a_note(solved, tmp_path):
    with FigureProcess() as figures:
        figures.submit(
            "optdesign.plots.solution:draw_solution", tmp_path / "x.png", lambda: "not a record"
        )
        note = figures.outcome()
    assert note.startswith("x.png not written: AttributeError:")
    assert not (tmp_path / "x.png").exists()


def test_a_child_killed_while_drawing_is_a_note(tmp_path):
    with FigureProcess() as figures:
        if not figures.forked:
            pytest.skip("no fork here")
        figures.submit("time:sleep", tmp_path / "a.png", lambda: 30.0)  # a drawing that hangs
        os.kill(figures.pid, signal.SIGKILL)
        note = figures.outcome()
        assert note == "a.png not written: the figure process ended (exit code -9)"
        assert not figures.forked
    assert not (tmp_path / "a.png").exists()


def _gone(pid: int) -> bool:
    """Whether process ``pid`` has exited (a zombie: its pipe ends are closed)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except FileNotFoundError:
        return True


def test_after_the_child_is_gone_figures_are_drawn_in_process(solved, tmp_path):
    record = result_figure(solved)
    with FigureProcess() as figures:
        if not figures.forked or not os.path.exists(f"/proc/{figures.pid}/stat"):
            pytest.skip("no fork here, or no /proc to see the child exit")
        os.kill(figures.pid, signal.SIGKILL)
        deadline = time.monotonic() + 10.0
        while not _gone(figures.pid) and time.monotonic() < deadline:
            time.sleep(0.01)
        figures.submit("optdesign.plots.solution:draw_solution", tmp_path / "b.png", lambda: record)
        assert not figures.forked and figures.outcome() is None
    assert (tmp_path / "b.png").stat().st_size > 10_000


def test_no_child_is_forked_beside_another_thread(tmp_path):
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        with FigureProcess() as figures:
            assert not figures.forked
    finally:
        stop.set()
        other.join()


def _no_design():
    raise ValueError("plot: no design")


def test_a_figure_that_cannot_be_prepared_is_its_note(tmp_path):
    with FigureProcess() as figures:
        figures.submit("optdesign.plots.solution:draw_solution", tmp_path / "s.png", _no_design)
        assert figures.outcome() == "s.png not written: ValueError: plot: no design"
    with pytest.raises(RuntimeError, match="no figure was submitted"):
        FigureProcess().outcome()


def _as_a_user(tmp_path, argv: list[str], prelude: str = "", shown: str = "") -> str:
    """The last line ``optdesign ARGV`` prints, run as a user runs it (its signal
    watchdog running), followed by ``exit CODE MATPLOTLIB_IMPORTED[ SHOWN]`` printed by
    the command's own process as it ends (with os._exit: the check runs there, in the
    command's process only). ``prelude``: code run first; ``shown``: an expression
    printed after it."""
    import subprocess
    import sys

    printed = "'exit', code, 'matplotlib' in sys.modules" + (f", {shown}" if shown else "")
    script = (
        "import os, runpy, sys\n"
        f"{prelude}"
        "me, real_exit = os.getpid(), os._exit\n"
        "def checked_exit(code):\n"
        "    if os.getpid() == me:\n"
        f"        print({printed}, flush=True)\n"
        "    real_exit(code)\n"
        "os._exit = checked_exit\n"
        f"sys.argv = {['optdesign', *argv]!r}\n"
        "try:\n"
        "    runpy.run_module('optdesign', run_name='__main__')\n"
        "except SystemExit as end:\n"
        "    checked_exit(end.code)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, cwd=tmp_path, timeout=300
    )
    lines = done.stdout.strip().splitlines()
    assert lines, done.stderr[-2000:]
    return lines[-1]


def test_the_command_draws_its_figure_in_the_worker_beside_its_watchdog(tmp_path):
    """``optdesign solve`` as a user runs it: the PNG is written and matplotlib is never
    imported by the command's own process."""
    argv = ["solve", "cs_min_backlash", "--starts", "1", "--no-ranges"]
    assert _as_a_user(tmp_path, [*argv, "--out", str(tmp_path / "out")]) == "exit 0 False"
    assert (tmp_path / "out" / "solution.png").stat().st_size > 10_000


def test_only_the_watchdog_may_run_beside_a_fork():
    from optdesign.interrupts import WATCHDOG_THREAD, fork_safe_threads

    # the verdict of this process as it runs (pytest-xdist's workers run threads of
    # their own); the watchdog never changes it, any other thread makes it False
    before = fork_safe_threads()
    for name, safe in ((WATCHDOG_THREAD, before), ("a user's thread", False)):
        stop = threading.Event()
        other = threading.Thread(target=stop.wait, name=name)
        other.start()
        try:
            assert fork_safe_threads() is safe
        finally:
            stop.set()
            other.join()
    assert fork_safe_threads() is before


def test_a_warm_up_asked_for_later_draws_the_png_the_process_draws(solved, tmp_path):
    record = result_figure(solved)
    assert write_figure(lambda: draw_solution(record), tmp_path / "here.png") is None
    draw = "optdesign.plots.solution:draw_solution"
    with FigureProcess(warm=False, draws=(draw,)) as figures:
        if not figures.forked:
            pytest.skip("no fork here")
        figures.warm_up()
        figures.warm_up()  # once: the second finds it sent
        figures.submit(draw, tmp_path / "a.png", lambda: record)
        assert figures.outcome() is None
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "here.png").read_bytes()


def test_the_pareto_command_warms_its_figure_worker_when_a_front_worker_idles(tmp_path):
    """``optdesign pareto`` as a user runs it, on two cores with two workers: the figure
    worker is warmed before front.png is submitted (when a chain first waits for the
    other's anchor, not beside two busy workers), the command's own process never
    imports matplotlib, and front.png is byte for byte what this process draws of the
    same record."""
    import pickle

    from optdesign.plots.front import draw_front

    record_file = tmp_path / "record.pickle"
    prelude = (
        "import pickle\n"
        "os.cpu_count = lambda: 2  # two workers hold every core: warmed when one idles\n"
        "import optdesign.plots.figure_process as fp\n"
        "events = []\n"
        "warm, submit = fp.FigureProcess.warm_up, fp.FigureProcess.submit\n"
        "def warm_up(self):\n"
        "    events.append('warm-up' if self._pool is not None else 'no worker')\n"
        "    warm(self)\n"
        "def keep(self, draw, path, prepare):\n"
        "    record = prepare()\n"
        f"    pickle.dump(record, open({str(record_file)!r}, 'wb'))\n"
        "    events.append('figure')\n"
        "    submit(self, draw, path, lambda: record)\n"
        "fp.FigureProcess.warm_up, fp.FigureProcess.submit = warm_up, keep\n"
    )
    argv = ["pareto", "cs_min_backlash", "--objectives", "ripple,backlash", "--points", "6"]
    argv += ["--workers", "2", "--no-progress", "--out", str(tmp_path / "out")]
    last = _as_a_user(tmp_path, argv, prelude, shown="events")
    assert last == "exit 0 False ['warm-up', 'figure']"
    record = pickle.loads(record_file.read_bytes())
    assert write_figure(lambda: draw_front(record), tmp_path / "here.png") is None
    assert (tmp_path / "out" / "front.png").read_bytes() == (tmp_path / "here.png").read_bytes()
