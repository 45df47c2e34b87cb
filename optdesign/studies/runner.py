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
- ``expand(task, record, done)`` may add tasks as records come in (a computation that
  decides its next steps from results, e.g. two chains of a sweep meeting wherever they
  meet); on resume it sees the stored records too, so the same tasks are generated;
- ``resume=True`` reads the store first, skips every task with a record and hands the
  stored records to dependants as if just computed. The first line of the store holds a
  ``key`` (e.g. a hash of the run's settings); resuming with another key is an error, so
  a resumed run cannot silently mix two configurations.

Records must be JSON-able. Floats survive the round trip exactly (``json`` writes
``repr``), so a resumed chain of warm starts is the same computation as an uninterrupted
one.
"""

from __future__ import annotations

import gc
import json
import multiprocessing
import os
import sys
import threading
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from optdesign.errors import OptDesignError

Record = dict[str, Any]
TaskFn = Callable[[Mapping[str, Any], Mapping[str, Record]], Record]
ExpandFn = Callable[[Mapping[str, Any], Record, Mapping[str, Record]], Iterable[Mapping[str, Any]]]


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
    """Append-only JSONL writer: one line per record, flushed at once (a killed run keeps
    every record written so far) and fsynced by a background thread (so that a crash of
    the machine loses at most the records of the last few milliseconds).

    The fsync (~1 ms here) used to run in the scheduling loop, where it delayed the next
    task of every chain; in a thread it releases the GIL and overlaps the solves.
    """

    def __init__(self, path: Path, key: str | None, fresh: bool):
        self.path = path
        path.parent.mkdir(parents=True, exist_ok=True)
        self.fh = path.open("w" if fresh else "a")
        self._dirty = threading.Event()
        self._closing = False
        self._syncer = threading.Thread(target=self._sync_loop, daemon=True)
        self._syncer.start()
        if fresh:
            self.write({"__store__": 1, "key": key})

    def write(self, obj: Mapping[str, Any]) -> None:
        self.fh.write(json.dumps(obj, allow_nan=True) + "\n")
        self.fh.flush()
        self._dirty.set()

    def _sync_loop(self) -> None:
        while True:
            self._dirty.wait()
            self._dirty.clear()
            if self._closing:
                return
            try:
                os.fsync(self.fh.fileno())
            except (OSError, ValueError):
                return  # closed underneath us: close() syncs itself

    def close(self) -> None:
        self._closing = True
        self._dirty.set()
        self._syncer.join()
        self.fh.flush()
        os.fsync(self.fh.fileno())
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
    pool: WorkerPool | None = None,
    expand: ExpandFn | None = None,
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
    expand
        ``expand(task, record, done) -> tasks``, called in this process for every task
        of the run once its record is in (computed, or read from the store when
        resuming); the tasks it returns join the run. A computation can so decide its
        next tasks from results - e.g. two chains of a sweep that meet wherever they
        meet. ``done`` maps every id finished so far to its record.

    Returns
    -------
    dict
        id -> record for every task (stored ones included when resuming), in the order
        the tasks joined the run.
    """
    path = Path(store_path)
    done: dict[str, Record] = {}
    if resume and path.exists():
        stored_key, done = read_store(path)
        if key is not None and stored_key is not None and stored_key != key:
            raise OptDesignError(
                f"--resume: the store {path} belongs to another run (key {stored_key!r}, "
                f"this run {key!r}); use a new output folder or the same settings"
            )
    for k, rec in (known or {}).items():
        done.setdefault(k, rec)
    by_id: dict[str, dict[str, Any]] = {}
    queue: list[dict[str, Any]] = []
    replay: deque[dict[str, Any]] = deque()

    def add(new: Iterable[Mapping[str, Any]]) -> None:
        new = [dict(t) for t in new]
        for t in new:
            if t["id"] in by_id:
                raise ValueError(f"run_tasks: task id {t['id']!r} is not unique")
            by_id[t["id"]] = t
        missing = [i for t in new for i in t.get("after", []) if i not in by_id and i not in done]
        if missing:
            raise ValueError(f"run_tasks: unknown dependencies {sorted(set(missing))}")
        for t in new:
            if t["id"] in done:
                replay.append(t)  # finished in an earlier run: only its expansion is due
            else:
                queue.append(t)
        if bar is not None:
            bar.total = len(by_id)
            bar.refresh()

    def expand_replayed() -> None:
        while expand is not None and replay:
            t = replay.popleft()
            add(expand(t, done[t["id"]], done))

    bar = None
    store: _Store | None = None
    try:
        add(tasks)
        expand_replayed()

        def ready(t: Mapping[str, Any]) -> bool:
            return all(a in done for a in t.get("after", []))

        # The workers start (fork) before the store's fsync thread and the progress bar's
        # monitor thread exist: a process forked while other threads run inherits only
        # the forking one, and whatever locks the others held.
        with _executor(fn, workers, scheduler, pool) as ex:
            store = _Store(path, key, fresh=not (resume and path.exists()))
            if progress:
                from tqdm.auto import tqdm

                bar = tqdm(
                    total=len(by_id),
                    initial=sum(1 for i in by_id if i in done),
                    desc=progress if isinstance(progress, str) else None,
                    leave=False,
                )

            def submit_ready() -> None:
                while ex.has_room():
                    t = next((t for t in queue if ready(t)), None)
                    if t is None:
                        break
                    queue.remove(t)
                    ex.submit(t, {a: done[a] for a in t.get("after", [])})

            while True:
                submit_ready()
                if not ex.running():
                    if queue:
                        raise ValueError("run_tasks: dependency cycle")
                    break
                results = ex.wait()
                for _, record in results:
                    done[record["id"]] = record
                for t, record in results:
                    if expand is not None:
                        add(expand(t, record, done))
                        expand_replayed()
                # The next tasks of the chains go out before the store writes (an fsync
                # each, ~1 ms, was serial latency on every step of every chain); a run
                # killed in between just recomputes the unstored records on resume.
                submit_ready()
                for _, record in results:
                    store.write(record)
                    if bar is not None:
                        bar.update(1)
                    if on_record is not None:
                        on_record(record)
    finally:
        if store is not None:
            store.close()
        if bar is not None:
            bar.close()
    return {i: done[i] for i in by_id if i in done}


class _Serial:
    """Runs each task in this process when asked for a result (one at a time)."""

    def __init__(self, fn: TaskFn):
        self.fn = fn
        self.next: tuple[dict, dict] | None = None

    def has_room(self) -> bool:
        return self.next is None

    def running(self) -> bool:
        return self.next is not None

    def submit(self, task: dict, deps: dict) -> None:
        self.next = (task, deps)

    def wait(self) -> list[tuple[dict, Record]]:
        assert self.next is not None
        task, deps = self.next
        self.next = None
        return [(task, _call(self.fn, task, deps))]


class _Pool:
    """Local worker processes: never more tasks in flight than workers, so that a chain's
    next point goes to a free worker as soon as its neighbour is done."""

    def __init__(self, fn: TaskFn, pool: WorkerPool):
        self.fn, self.pool = fn, pool
        self.tasks: dict[int, dict] = {}

    def has_room(self) -> bool:
        return len(self.tasks) < self.pool.size

    def running(self) -> bool:
        return bool(self.tasks)

    def submit(self, task: dict, deps: dict) -> None:
        self.tasks[self.pool.submit(_call, (self.fn, task, deps))] = task

    def wait(self) -> list[tuple[dict, Record]]:
        return [(self.tasks.pop(i), record) for i, record in self.pool.wait()]


class _Dask:
    """A Dask distributed cluster: every ready task is submitted at once."""

    def __init__(self, fn: TaskFn, client: Any):
        from distributed import as_completed

        self.fn, self.client = fn, client
        self.ac = as_completed(with_results=False)
        self.tasks: dict[str, dict] = {}

    def has_room(self) -> bool:
        return True

    def running(self) -> bool:
        return bool(self.tasks)

    def submit(self, task: dict, deps: dict) -> None:
        fut = self.client.submit(_call, self.fn, task, deps, pure=False)
        self.tasks[fut.key] = task
        self.ac.add(fut)

    def wait(self) -> list[tuple[dict, Record]]:
        fut = next(self.ac)
        return [(self.tasks.pop(fut.key), fut.result())]


@contextmanager
def _executor(fn: TaskFn, workers: int, scheduler: Any, pool: WorkerPool | None):
    if scheduler is not None:
        from distributed import Client

        own = not hasattr(scheduler, "submit")
        client = Client(scheduler) if own else scheduler
        try:
            yield _Dask(fn, client)
        finally:
            if own:
                client.close()
    elif workers > 1 and pool is not None:
        yield _Pool(fn, pool)
    elif workers > 1:
        with process_pool(workers) as own_pool:
            yield _Pool(fn, own_pool)
    else:
        yield _Serial(fn)


@contextmanager
def process_pool(workers: int) -> Iterator[WorkerPool | None]:
    """A pool of ``workers`` local processes (None for ``workers <= 1``).

    Pass it to several :func:`run_tasks` calls (``pool=``) to keep the same worker
    processes, and so their caches, across phases; it is shut down on exit.
    """
    if workers <= 1:
        yield None
        return
    pool = WorkerPool(workers)
    try:
        yield pool
    finally:
        pool.close()


class WorkerPool:
    """Local worker processes, each fed through its own pipe.

    Why not :class:`concurrent.futures.ProcessPoolExecutor`: a task there passes through
    two helper threads on its way to a worker; for the ~10 ms points of a Pareto chain
    that cost 1.6 ms median (3.5 ms at the 90th percentile) between submitting a point
    and its worker starting it, and 0.7 ms back - a fifth of a 2-worker front's chain
    time. One pipe per worker, written from the scheduling thread, costs ~0.3 ms for
    the round trip (measured with the same ~29 kB task).

    A task that raises re-raises in :meth:`wait` (the same exception when it pickles, a
    :class:`OptDesignError` with the worker's traceback otherwise); a worker that dies is
    reported with its exit code.
    """

    def __init__(self, size: int):
        ctx = multiprocessing.get_context("fork" if forks_workers() else "spawn")
        self.size = size
        self.conns: list[Any] = []
        self.procs: list[Any] = []
        # Objects of this process that a forked worker inherits are frozen out of the
        # garbage collector while forking: a collection in the worker would otherwise
        # write to every inherited object and copy its memory page (copy-on-write).
        gc.freeze()
        for _ in range(size):
            parent, child = ctx.Pipe()
            proc = ctx.Process(target=_worker_loop, args=(child,), daemon=True)
            proc.start()
            child.close()
            self.conns.append(parent)
            self.procs.append(proc)
        gc.unfreeze()
        self.idle = list(range(size))[::-1]
        self.busy: set[int] = set()

    def submit(self, fn: Callable, args: tuple) -> int:
        """Send ``fn(*args)`` to an idle worker; returns the worker's index."""
        i = self.idle.pop()
        self.conns[i].send((fn, args))
        self.busy.add(i)
        return i

    def wait(self) -> list[tuple[int, Any]]:
        """Block until at least one busy worker answers; ``(worker index, result)`` each."""
        from multiprocessing.connection import wait as wait_any

        ready = wait_any([self.conns[i] for i in self.busy])
        out = []
        for i in sorted(self.busy):
            if self.conns[i] not in ready:
                continue
            try:
                ok, value = self.conns[i].recv()
            except EOFError:
                self.procs[i].join(1.0)
                raise OptDesignError(
                    f"worker process {self.procs[i].pid} died "
                    f"(exit code {self.procs[i].exitcode}) while running a task"
                ) from None
            self.busy.discard(i)
            self.idle.append(i)
            if not ok:
                raise value
            out.append((i, value))
        return out

    def close(self) -> None:
        """Stop the workers: idle ones are asked to exit, busy ones (an interrupted run:
        their results are not wanted any more) are terminated."""
        for i, (conn, proc) in enumerate(zip(self.conns, self.procs, strict=True)):
            if i in self.busy:
                proc.terminate()
            else:
                try:
                    conn.send(None)
                except OSError:
                    pass
        for proc in self.procs:
            proc.join(2.0)
            if proc.is_alive():
                proc.kill()
                proc.join(1.0)
        for conn in self.conns:
            conn.close()


def _worker_loop(conn) -> None:
    _init_process()
    while True:
        try:
            msg = conn.recv()
        except (EOFError, KeyboardInterrupt):
            return
        if msg is None:
            return
        fn, args = msg
        try:
            reply = (True, fn(*args))
        except BaseException as exc:  # every failure goes back to the parent
            reply = (False, _portable(exc))
        try:
            conn.send(reply)
        except Exception as exc:  # e.g. a result that does not pickle
            conn.send((False, _portable(exc)))


def _portable(exc: BaseException) -> BaseException:
    """``exc`` if it survives pickling, else an OptDesignError carrying its traceback."""
    import pickle
    import traceback

    try:
        pickle.loads(pickle.dumps(exc))
        return exc
    except Exception:
        text = "".join(traceback.format_exception(exc))
        return OptDesignError(f"a worker process failed:\n{text}")


def forks_workers() -> bool:
    """Whether local workers are forked from this process (Linux), and so inherit what it
    built before starting them. Elsewhere the platform's default (spawn) is used."""
    return sys.platform.startswith("linux")


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


#: Per-process (and per-thread, for threaded Dask workers) cache of expensive objects.
_CACHE: dict[tuple, Any] = {}
_CACHE_LOCK = threading.Lock()


def cached(key: tuple, build: Callable[[], Any]) -> Any:
    """``build()`` once per process and thread for ``key`` (e.g. a solver per worker).

    CasADi solvers are not thread-safe, so threaded workers each get their own copy. The
    main thread's entries carry no thread id: a process forked from it (a local worker)
    inherits them, so what the parent built before starting its pool (see
    :func:`optdesign.studies.pareto.prebuild_solvers`) is not built again in every worker.
    """
    owner = (
        "main" if threading.current_thread() is threading.main_thread() else threading.get_ident()
    )
    full = (owner, *key)
    with _CACHE_LOCK:
        if full in _CACHE:
            return _CACHE[full]
    value = build()
    with _CACHE_LOCK:
        _CACHE[full] = value
    return value


#: Callables handed to forked workers by inheritance (see :func:`map_inherited`).
_INHERITED: dict[int, Callable[[Any], Any]] = {}


def _call_inherited(key: int, item: Any) -> Any:
    return _INHERITED[key](item)


def map_inherited(
    fn: Callable[[Any], Any],
    items: list[Any],
    workers: int,
    stop: Callable[[list[Any]], bool] | None = None,
) -> list[Any]:
    """``[fn(item) for item in items]`` on ``workers`` forked processes that inherit
    ``fn`` (e.g. a solver's bound ``solve``: built once here, never pickled).

    Results come back in the order of ``items``; with ``stop``, no new item is started
    once ``stop(results so far, in order)`` holds. Off Linux (no fork) it runs here.
    """
    if workers <= 1 or not forks_workers() or len(items) <= 1:
        out: list[Any] = []
        for item in items:
            out.append(fn(item))
            if stop is not None and stop(out):
                break
        return out
    key = id(fn)
    _INHERITED[key] = fn
    try:
        pool = WorkerPool(min(workers, len(items)))
        try:
            results: dict[int, Any] = {}
            running: dict[int, int] = {}  # worker -> item index
            nxt = 0
            stopped = False
            while nxt < len(items) or running:
                while not stopped and nxt < len(items) and pool.idle:
                    running[pool.submit(_call_inherited, (key, items[nxt]))] = nxt
                    nxt += 1
                for worker, value in pool.wait():
                    results[running.pop(worker)] = value
                done = [results[k] for k in sorted(results)]
                if stop is not None and stop(done):
                    stopped = True
                    nxt = len(items)
            return [results[k] for k in sorted(results)]
        finally:
            pool.close()
    finally:
        _INHERITED.pop(key, None)
