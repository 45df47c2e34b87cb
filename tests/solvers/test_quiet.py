"""optdesign.solvers.quiet: a solver library's printing is silenced, on file descriptor 1
and on ``sys.stdout``, and stdout is whole again after any number of nested or
concurrent windows."""

from __future__ import annotations

import os
import sys
import threading

from optdesign.solvers.quiet import quiet_stdout


def _fd1() -> tuple[int, int]:
    st = os.fstat(1)
    return st.st_dev, st.st_ino


def test_what_is_printed_inside_the_window_is_lost_and_nothing_else(capfd):
    print("before", flush=True)
    with quiet_stdout():
        print("python inside")  # CasADi's output (qpOASES's banner) comes this way
        os.write(1, b"c inside\n")  # a C library's, on the descriptor
        with quiet_stdout():  # nested: the outer window stays
            print("nested inside")
        os.write(1, b"after the nested one\n")
    print("after", flush=True)
    assert capfd.readouterr().out == "before\nafter\n"


def test_interleaved_windows_of_two_threads_leave_stdout_as_it_was():
    """Thread A opens, B opens, A closes, B closes: windows that each saved and restored
    on their own left fd 1 on /dev/null and ``sys.stdout`` on a sink."""
    stdout, fd1 = sys.stdout, _fd1()
    a_in, b_in, a_out = threading.Event(), threading.Event(), threading.Event()
    seen = {}

    def a():
        with quiet_stdout():
            a_in.set()
            b_in.wait(5)
        a_out.set()

    def b():
        a_in.wait(5)
        with quiet_stdout():
            b_in.set()
            a_out.wait(5)
            seen["inside, after A left"] = sys.stdout is stdout or _fd1() == fd1

    threads = [threading.Thread(target=a), threading.Thread(target=b)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(10)
    assert seen == {"inside, after A left": False}  # B's window still holds
    assert sys.stdout is stdout and _fd1() == fd1
