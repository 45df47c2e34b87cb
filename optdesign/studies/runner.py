"""Run a list of tasks with a checkpoint store: local processes or a Dask cluster, resumable.

The one entry point is :func:`run_tasks`. It is generic (the Pareto fronts use it; the
benchmark command can reuse it):

- a *task* is a JSON-able dict with a unique ``"id"`` and optionally ``"after"``, a list
  of ids of tasks whose records it needs (e.g. the neighbour point a sweep warm-starts
  from). Tasks form chains or any DAG; a task runs once all its ``after`` tasks finished;
- ``fn(task, deps) -> record`` does the work; ``deps`` maps each ``after`` id to its
  record. ``fn`` must be a picklable module-level function; per-process state (a solver
  built once per worker) belongs in a module-level cache inside ``fn``'s module;
- every finished record is appended to ``store_path`` (JSON Lines, one record a line,
  flushed at once), so a killed run loses at most the tasks in flight;
- ``resume=True`` reads the store first, skips every task with a record and hands the
  stored records to dependants as if just computed. The first line of the store holds a
  ``key`` (e.g. a hash of the run's settings); resuming with another key is an error, so
  a resumed run cannot silently mix two configurations.

Records must be JSON-able. Floats survive the round trip exactly (``json`` writes
``repr``), so a resumed chain of warm starts is the same computation as an uninterrupted
one.
"""

from __future__ import annotations

import json
import os
import threading
from collections.abc import Callable, Iterable, Iterator, Mapping
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from optdesign.errors import OptDesignError

Record = dict[str, Any]
TaskFn = Callable[[Mapping[str, Any], Mapping[str, Record]], Record]


def read_store(store_path: Path | str) -> tuple[str | None, dict[str, Record]]:
    """The key and the records (id -> record) of a JSONL store; a torn last line is ignored.

    A run killed while writing can leave a partial last line; it is dropped (that task
    simply runs again on resume).
    """
    path = Path(store_path)
    key: str | None = None
    records: dict[str, Record] = {}
    if not path.exists():
        return key, records
    with path.open() as fh:
        for line in fh:
            line = line.strip()
            if not line:
                continue
            try:
                obj = json.loads(line)
            except json.JSONDecodeError:
                continue
            if "__store__" in obj:
                key = obj.get("key")
            elif "id" in obj:
                records[obj["id"]] = obj
    return key, records


class _Store:
    """Append-only JSONL writer (one line per record, flushed and fsynced)."""

    def __init__(self, path: Path, key: str | None, fresh: bool):
        self.path = path
        path.parent.mkdir(parents=True, exist_ok=True)
        self.fh = path.open("w" if fresh else "a")
        if fresh:
            self.write({"__store__": 1, "key": key})

    def write(self, obj: Mapping[str, Any]) -> None:
        self.fh.write(json.dumps(obj, allow_nan=True) + "\n")
        self.fh.flush()
        os.fsync(self.fh.fileno())

    def close(self) -> None:
        self.fh.close()


def _call(fn: TaskFn, task: Mapping[str, Any], deps: Mapping[str, Record]) -> Record:
    record = dict(fn(task, deps))
    record["id"] = task["id"]
    return record


def run_tasks(
    tasks: Iterable[Mapping[str, Any]],
    fn: TaskFn,
    store_path: Path | str,
    workers: int = 1,
    scheduler: str | Any | None = None,
    resume: bool = False,
    progress: bool | str = False,
    key: str | None = None,
    on_record: Callable[[Record], None] | None = None,
    known: Mapping[str, Record] | None = None,
    pool: ProcessPoolExecutor | None = None,
) -> dict[str, Record]:
    """Run ``tasks`` through ``fn``, storing each record as it finishes.

    Parameters
    ----------
    tasks
        Dicts with a unique ``"id"`` and optional ``"after"`` (ids this task needs).
    fn
        ``fn(task, deps) -> record``, picklable (module-level).
    store_path
        JSONL file; created (or truncated unless ``resume``).
    workers
        Local processes (1: in this process, no pool).
    scheduler
        Address of a Dask distributed scheduler (or a ``distributed.Client``); when given,
        tasks go to that cluster instead of local processes.
    resume
        Keep the store's records and run only the missing tasks.
    progress
        Show a tqdm bar (a string is used as its description).
    key
        Identity of the run written to / checked against the store on resume.
    on_record
        Called in this process with each new record after it is stored (for example to
        stop a run in a test by raising).
    known
        Records computed elsewhere (id -> record) that tasks may name in ``after``; they
        are not written to this store.
    pool
        An open process pool (see :func:`process_pool`) to run local tasks on instead of
        a new one, so that consecutive phases of one computation share the workers and
        their per-process caches (solvers built once per worker, not once per phase).

    Returns
    -------
    dict
        id -> record for every task (stored ones included when resuming).
    """
    tasks = [dict(t) for t in tasks]
    ids = [t["id"] for t in tasks]
    if len(set(ids)) != len(ids):
        raise ValueError("run_tasks: task ids must be unique")
    path = Path(store_path)
    done: dict[str, Record] = {}
    if resume and path.exists():
        stored_key, done = read_store(path)
        if key is not None and stored_key is not None and stored_key != key:
            raise OptDesignError(
                f"--resume: the store {path} belongs to another run (key {stored_key!r}, "
                f"this run {key!r}); use a new output folder or the same settings"
            )
    store = _Store(path, key, fresh=not (resume and path.exists()))
    for k, rec in (known or {}).items():
        done.setdefault(k, rec)
    by_id = {t["id"]: t for t in tasks}
    missing = [i for t in tasks for i in t.get("after", []) if i not in by_id and i not in done]
    if missing:
        raise ValueError(f"run_tasks: unknown dependencies {sorted(set(missing))}")
    pending = [t for t in tasks if t["id"] not in done]
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(
            total=len(tasks),
            initial=len(tasks) - len(pending),
            desc=progress if isinstance(progress, str) else None,
            leave=False,
        )

    def finished(record: Record) -> None:
        done[record["id"]] = record
        store.write(record)
        if bar is not None:
            bar.update(1)
        if on_record is not None:
            on_record(record)

    def mark(record: Record) -> None:
        done[record["id"]] = record

    def ready(t: Mapping[str, Any]) -> bool:
        return all(a in done for a in t.get("after", []))

    def deps_of(t: Mapping[str, Any]) -> dict[str, Record]:
        return {a: done[a] for a in t.get("after", [])}

    try:
        if scheduler is not None:
            _run_dask(pending, fn, scheduler, ready, deps_of, finished)
        elif workers > 1 and len(pending) > 1:
            if pool is not None:
                _run_on(pool, pending, fn, workers, ready, deps_of, finished, mark)
            else:
                with process_pool(workers) as own:
                    _run_on(own, pending, fn, workers, ready, deps_of, finished, mark)
        else:
            queue = list(pending)
            while queue:
                t = next((t for t in queue if ready(t)), None)
                if t is None:
                    raise ValueError("run_tasks: dependency cycle")
                queue.remove(t)
                finished(_call(fn, t, deps_of(t)))
    finally:
        store.close()
        if bar is not None:
            bar.close()
    return {i: done[i] for i in ids if i in done}


@contextmanager
def process_pool(workers: int) -> Iterator[ProcessPoolExecutor | None]:
    """A local process pool of ``workers`` processes (None for ``workers <= 1``).

    Pass it to several :func:`run_tasks` calls (``pool=``) to keep the same worker
    processes, and so their caches, across phases; it is shut down on exit.
    """
    if workers <= 1:
        yield None
        return
    with ProcessPoolExecutor(max_workers=workers, initializer=_init_process) as pool:
        yield pool


def _run_on(pool, pending, fn, workers, ready, deps_of, finished, mark) -> None:
    # Submit a task as soon as its dependencies are in; never more in flight than workers,
    # so that a chain's next point goes to a free worker as soon as its neighbour is done.
    queue = list(pending)
    running: dict[Any, dict] = {}

    def submit_ready() -> None:
        while len(running) < workers:
            t = next((t for t in queue if ready(t)), None)
            if t is None:
                break
            queue.remove(t)
            running[pool.submit(_call, fn, t, deps_of(t))] = t

    while queue or running:
        submit_ready()
        if not running:
            raise ValueError("run_tasks: dependency cycle")
        finished_futs, _ = wait(running, return_when=FIRST_COMPLETED)
        records = []
        for fut in finished_futs:
            running.pop(fut)
            records.append(fut.result())
            mark(records[-1])
        # The next tasks of the chains go out before the store write (an fsync each,
        # ~1 ms, was serial latency on every step of every chain); a run killed in
        # between just recomputes the unstored records on resume.
        submit_ready()
        for record in records:
            finished(record)


def _init_process() -> None:
    # One solver thread per process: the processes are the parallelism.
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    # The environment variable is read when a BLAS library loads; forked workers inherit
    # NumPy's and SciPy's OpenBLAS already loaded with one thread per core. Two workers
    # each running two BLAS threads (SLSQP's QP) on 2 cores ran ~3x slower per point.
    limit_blas_threads(1)


def limit_blas_threads(n: int = 1) -> int:
    """Set the thread count of every OpenBLAS already loaded in this process.

    Returns how many libraries were limited (0 where there is no OpenBLAS or no
    ``/proc``; nothing else changes then).
    """
    import ctypes

    try:
        with open("/proc/self/maps") as fh:
            libs = {line.split()[-1] for line in fh if "openblas" in line.lower()}
    except OSError:
        return 0
    count = 0
    for lib in sorted(libs):
        try:
            handle = ctypes.CDLL(lib)
        except OSError:
            continue
        for symbol in (
            "openblas_set_num_threads",
            "openblas_set_num_threads64_",
            "scipy_openblas_set_num_threads",
            "scipy_openblas_set_num_threads64_",
        ):
            fn = getattr(handle, symbol, None)
            if fn is not None:
                fn(ctypes.c_int(n))
                count += 1
                break
    return count


def _run_dask(pending, fn, scheduler, ready, deps_of, finished) -> None:
    from distributed import Client, as_completed

    own = not hasattr(scheduler, "submit")
    client = Client(scheduler) if own else scheduler
    try:
        queue = list(pending)
        ac = as_completed()
        n_running = 0

        def submit_ready() -> int:
            k = 0
            for t in [t for t in queue if ready(t)]:
                queue.remove(t)
                ac.add(client.submit(_call, fn, t, deps_of(t), pure=False))
                k += 1
            return k

        n_running += submit_ready()
        if n_running == 0 and queue:
            raise ValueError("run_tasks: dependency cycle")
        for fut in ac:
            n_running -= 1
            finished(fut.result())
            n_running += submit_ready()
            if n_running == 0 and queue:
                raise ValueError("run_tasks: dependency cycle")
    finally:
        if own:
            client.close()


#: Per-process (and per-thread, for threaded Dask workers) cache of expensive objects.
_CACHE: dict[tuple, Any] = {}
_CACHE_LOCK = threading.Lock()


def cached(key: tuple, build: Callable[[], Any]) -> Any:
    """``build()`` once per process and thread for ``key`` (e.g. a solver per worker).

    CasADi solvers are not thread-safe, so threaded workers each get their own copy.
    """
    full = (threading.get_ident(), *key)
    with _CACHE_LOCK:
        if full in _CACHE:
            return _CACHE[full]
    value = build()
    with _CACHE_LOCK:
        _CACHE[full] = value
    return value
