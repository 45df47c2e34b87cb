"""runtime.processes.when_a_worker_idles: the callback runs once, when a pool is waited on
while one of its workers has nothing to do, and never while every worker is busy or
after its block."""

from __future__ import annotations

import os
import time

import pytest

from optdesign.runtime.processes import WorkerPool, forks_workers, when_a_worker_idles

pytestmark = pytest.mark.skipif(not forks_workers(), reason="local workers are forked")


def test_the_callback_waits_for_an_idle_worker_and_runs_once():
    calls: list[int] = []
    pool = WorkerPool(2)
    try:
        pool.submit(time.sleep, (0.05,))
        pool.submit(time.sleep, (0.05,))
        with when_a_worker_idles(lambda: calls.append(len(pool.busy))):
            pool.wait()  # waited on with both workers busy: no core left idle
            assert calls == []
        while pool.busy:
            pool.wait()
        with when_a_worker_idles(lambda: calls.append(len(pool.busy))):
            pool.submit(os.getpid, ())  # one task for two workers: the other idles
            pool.wait()
            assert calls == [1]
            pool.submit(os.getpid, ())
            pool.wait()
            assert calls == [1]  # once
    finally:
        pool.close()


def test_no_callback_after_its_block():
    calls: list[str] = []
    pool = WorkerPool(2)
    try:
        with when_a_worker_idles(lambda: calls.append("idle")):
            pass
        pool.submit(os.getpid, ())
        pool.wait()
    finally:
        pool.close()
    assert calls == []


def _callbacks_here() -> int:
    from optdesign.runtime import processes

    return len(processes._ON_IDLE)


def test_a_forked_worker_inherits_no_callback():
    # a worker's own pools are not the run's: the callback acts on this process's objects
    with when_a_worker_idles(lambda: None):
        assert _callbacks_here() == 1
        pool = WorkerPool(1)
        try:
            pool.submit(_callbacks_here, ())
            ((_, inherited),) = pool.wait()
        finally:
            pool.close()
    assert inherited == 0
