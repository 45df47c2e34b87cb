"""The generic task runner: JSONL store, dependencies, resume, local processes, Dask."""

import json
import os

import pytest

from optdesign.errors import OptDesignError
from optdesign.runtime.runner import read_store, run_tasks
from optdesign.storage import STORE_VERSION


def _chain_fn(task, deps):
    # value = previous value * 2 + increment: any order or resume mistake changes the sum.
    prev = deps[task["after"][0]]["value"] if task.get("after") else 1
    return {"value": prev * 2 + task["inc"]}


def _tasks(n=8):
    tasks = []
    for i in range(n):
        t = {"id": f"t{i}", "inc": i}
        if i > 0 and i != 4:  # two chains: t0..t3 and t4..t7
            t["after"] = [f"t{i - 1}"]
        tasks.append(t)
    return tasks


def _expected(n=8):
    out, v = {}, None
    for i in range(n):
        v = (1 if i in (0, 4) else v) * 2 + i
        out[f"t{i}"] = v
    return out


def test_chains_are_computed_in_order_and_stored(tmp_path):
    store = tmp_path / "s.jsonl"
    done = run_tasks(_tasks(), _chain_fn, store, key="k1")
    assert {k: r["value"] for k, r in done.items()} == _expected()
    assert done["t3"]["value"] == 27  # by hand: 2, 5, 12, 27
    assert done["t7"]["value"] == 2 * (2 * (2 * 6 + 5) + 6) + 7
    lines = store.read_text().splitlines()
    assert json.loads(lines[0]) == {"__store__": STORE_VERSION, "key": "k1"}
    assert len(lines) == 9


def test_resume_after_interruption_does_not_recompute(tmp_path):
    store = tmp_path / "s.jsonl"
    seen = []

    def stop_after_three(rec):
        seen.append(rec["id"])
        if len(seen) == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_tasks(_tasks(), _chain_fn, store, key="k", on_record=stop_after_three)
    assert len(read_store(store)[1]) == 3
    computed = []
    done = run_tasks(
        _tasks(), _chain_fn, store, resume=True, key="k", on_record=lambda r: computed.append(r)
    )
    assert len(computed) == 5  # only the missing ones
    assert {k: r["value"] for k, r in done.items()} == _expected()
    # A different run must not resume from this store.
    with pytest.raises(OptDesignError, match="another run"):
        run_tasks(_tasks(), _chain_fn, store, resume=True, key="other")


def test_torn_last_line_is_ignored(tmp_path):
    store = tmp_path / "s.jsonl"
    run_tasks(_tasks(4), _chain_fn, store, key="k")
    text = store.read_text()
    store.write_text(text[: len(text) - 5])  # killed while writing the last record
    _, records = read_store(store)
    assert sorted(records) == ["t0", "t1", "t2"]
    done = run_tasks(_tasks(4), _chain_fn, store, resume=True, key="k")
    assert done["t3"]["value"] == _expected(4)["t3"]


def test_local_processes_give_the_same_records(tmp_path):
    done = run_tasks(_tasks(), _chain_fn, tmp_path / "p.jsonl", workers=2)
    assert {k: r["value"] for k, r in done.items()} == _expected()


def test_dask_local_cluster(tmp_path):
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        done = run_tasks(
            _tasks(), _chain_fn, tmp_path / "d.jsonl", scheduler=client.scheduler.address
        )
    assert {k: r["value"] for k, r in done.items()} == _expected()
    assert len(read_store(tmp_path / "d.jsonl")[1]) == 8


def test_unknown_dependency_is_an_error(tmp_path):
    with pytest.raises(ValueError, match="unknown dependencies"):
        run_tasks([{"id": "a", "after": ["zz"]}], _chain_fn, tmp_path / "x.jsonl")


def _step_fn(task, deps):
    # A point's value depends on the neighbour it started from: 10 * index + side, so a
    # test sees from which side each point was computed.
    if task.get("fail"):
        raise ValueError(f"task {task['id']} fails on purpose")
    if task.get("die"):
        import os

        os._exit(3)
    return {"index": task["index"], "side": task["dir"]}


class _Meet:
    """Two chains from both ends of 0..n-1 that stop where they meet (expand)."""

    def __init__(self, n):
        self.n, self.claimed, self.calls = n, set(), 0

    def task(self, i, d, after):
        self.claimed.add(i)
        return {"id": f"p{i:02d}", "index": i, "dir": d, "after": after}

    def __call__(self, task, record, done):
        self.calls += 1
        if task["id"] == "start":
            return [self.task(0, 1, ["start"]), self.task(self.n - 1, -1, ["start"])]
        j = task["index"] + task["dir"]
        if 0 <= j < self.n and j not in self.claimed:
            return [self.task(j, task["dir"], [task["id"]])]
        return []


@pytest.mark.parametrize("workers", [1, 2])
def test_expand_adds_tasks_as_records_come_in(tmp_path, workers):
    meet = _Meet(9)
    done = run_tasks(
        [{"id": "start", "index": -1, "dir": 0}],
        _step_fn,
        tmp_path / "m.jsonl",
        workers=workers,
        expand=meet,
    )
    points = sorted(r["index"] for k, r in done.items() if k != "start")
    assert points == list(range(9))  # every point once, none twice
    sides = [done[f"p{i:02d}"]["side"] for i in range(9)]
    # Each chain is contiguous from its end: +1 on the left, -1 on the right.
    k = sides.index(-1)
    assert sides == [1] * k + [-1] * (9 - k)
    if workers == 1:
        assert k == 5  # one worker: the chains alternate and meet in the middle
    assert len(read_store(tmp_path / "m.jsonl")[1]) == 10


@pytest.mark.parametrize("workers", [1, 2])
def test_expand_replays_stored_records_on_resume(tmp_path, workers):
    store = tmp_path / "m.jsonl"
    seen = []

    def stop(rec):
        seen.append(rec["id"])
        if len(seen) == 4:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_tasks(
            [{"id": "start", "index": -1, "dir": 0}],
            _step_fn,
            store,
            workers=workers,
            expand=_Meet(9),
            on_record=stop,
        )
    assert len(read_store(store)[1]) == 4
    computed = []
    meet = _Meet(9)
    done = run_tasks(
        [{"id": "start", "index": -1, "dir": 0}],
        _step_fn,
        store,
        resume=True,
        workers=workers,
        expand=meet,
        on_record=lambda r: computed.append(r["id"]),
    )
    assert len(computed) == 6  # 10 tasks, 4 stored
    assert sorted(k for k in done if k != "start") == [f"p{i:02d}" for i in range(9)]
    assert meet.calls == 10  # stored records were expanded too


def test_worker_errors_reach_the_caller(tmp_path):
    with pytest.raises(ValueError, match="p01 fails on purpose"):
        run_tasks(
            [
                {"id": "p00", "index": 0, "dir": 1},
                {"id": "p01", "index": 1, "dir": 1, "fail": True},
            ],
            _step_fn,
            tmp_path / "e.jsonl",
            workers=2,
        )
    with pytest.raises(OptDesignError, match="exit code 3"):
        run_tasks(
            [{"id": "p00", "index": 0, "dir": 1, "die": True}, {"id": "p01", "index": 1, "dir": 1}],
            _step_fn,
            tmp_path / "d.jsonl",
            workers=2,
        )


def _misbehave(task, deps):
    import signal
    import time

    if task["do"] == "hang":
        time.sleep(60)
    elif task["do"] == "segfault":  # what a crashing solver library does
        os.kill(os.getpid(), signal.SIGSEGV)
    elif task["do"] == "exit":
        os._exit(7)
    elif task["do"] == "raise":
        raise RuntimeError("deliberate failure")
    return {"status": "ok", "pid": os.getpid()}


def _my_failure(task, kind, reason, wall_s):
    return {"status": f"failed:{kind}", "why": reason, "t": wall_s}


@pytest.mark.parametrize("workers", [1, 2])
def test_isolated_tasks_hard_timeout_and_crashes_become_failure_records(tmp_path, workers):
    import time

    from optdesign.runtime.runner import Isolation

    kinds = ["ok", "hang", "segfault", "exit", "raise", "ok"]
    tasks = [{"id": f"t{i}", "do": d, "limit": 0.5} for i, d in enumerate(kinds)]
    store = tmp_path / "i.jsonl"
    t0 = time.monotonic()
    done = run_tasks(
        tasks, _misbehave, store, workers=workers, isolate=Isolation(timeout="limit", quiet=True)
    )
    assert time.monotonic() - t0 < 10  # the hang was killed after its 0.5 s
    status = {k: r["status"] for k, r in done.items()}
    assert status == {
        "t0": "ok",
        "t1": "timeout",
        "t2": "crash",
        "t3": "crash",
        "t4": "error",
        "t5": "ok",
    }
    assert "hard timeout of 0.5 s" in done["t1"]["reason"]
    assert 0.5 <= done["t1"]["time_s"] < 5
    assert "wait status" in done["t2"]["reason"]
    assert done["t4"]["reason"] == "RuntimeError: deliberate failure"
    assert not any(done[k]["success"] for k in ("t1", "t2", "t3", "t4"))
    assert done["t0"]["pid"] != os.getpid()  # ran in a child
    assert len(read_store(store)[1]) == 6  # failures are records like any other
    # a custom failure record (e.g. the benchmark's row), with a fixed timeout
    done = run_tasks(
        tasks[1:3],
        _misbehave,
        tmp_path / "j.jsonl",
        workers=workers,
        isolate=Isolation(timeout=0.3, failure=_my_failure, quiet=True),
    )
    assert done["t1"]["status"] == "failed:timeout" and done["t1"]["id"] == "t1"
    assert done["t2"]["status"] == "failed:crash"


def test_fork_call_returns_values_and_kinds():
    from optdesign.runtime.runner import fork_call

    assert fork_call(lambda: {"a": [1.5]}) == ("ok", {"a": [1.5]})
    assert fork_call(lambda: 1 / 0)[0] == "error"
    kind, reason = fork_call(lambda: __import__("time").sleep(5), timeout=0.2)
    assert kind == "timeout" and "0.2 s" in reason
    assert fork_call(lambda: os._exit(0))[0] == "crash"
    assert fork_call(lambda: b"x" * 3_000_000) == ("ok", b"x" * 3_000_000)  # > a pipe buffer


def test_a_scheduler_that_does_not_answer_is_an_input_error_naming_its_address(tmp_path):
    """optdesign.runtime.runner._connect: a well-formed address where no scheduler
    answers is refused naming the address (it was distributed's traceback)."""
    pytest.importorskip("distributed")
    import dask

    from optdesign.errors import InputError

    with (
        dask.config.set({"distributed.comm.timeouts.connect": "1s"}),
        pytest.raises(InputError) as err,
    ):
        run_tasks(_tasks(), _chain_fn, tmp_path / "s.jsonl", scheduler="tcp://127.0.0.1:1")
    assert err.value.field == "scheduler"
    assert str(err.value).startswith(
        "scheduler: cannot connect to the Dask scheduler at 'tcp://127.0.0.1:1': "
    )
