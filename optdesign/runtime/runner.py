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
  one ``write`` each), so a killed run loses at most the tasks in flight; an interrupted
  run (Ctrl-C, SIGTERM, SIGHUP through the CLI) writes every record it received before it
  stops its workers. The store and the folder lock live in :mod:`optdesign.storage`;
  the worker processes (which die with this process, whatever kills it) in
  :mod:`optdesign.runtime.processes`;
- ``expand(task, record, done)`` may add tasks as records come in (a computation that
  decides its next steps from results, e.g. two chains of a sweep meeting wherever they
  meet); on resume it sees the stored records too, so the same tasks are generated;
- ``resume=True`` reads the store first, skips every task with a record and hands the
  stored records to dependants as if just computed. The first line of the store holds
  the run's identity ``key`` (a string, or a mapping of everything the records depend
  on: problem, objectives, settings, solver options, version); resuming with another
  identity (the message names the components that changed), from a store without that
  line or in another store format is an error, so a resumed run cannot silently mix two
  configurations; ``check`` refuses stored records that cannot be trusted (a NaN, a
  design outside the bounds). Without ``resume``, a store holding records is not
  replaced unless ``overwrite=True``. The store's folder has one writer at a time;
- ``isolate=Isolation(timeout=...)`` runs each task in a forked child: a hang past the
  timeout is killed, a crash or exception becomes a failure record (the benchmark).

Records must be JSON-able. Floats survive the round trip exactly (``json`` writes
``repr``), so a resumed chain of warm starts is the same computation as an uninterrupted
one.
"""

from __future__ import annotations

import functools
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from optdesign.interrupts import deferred, note_active_store, note_store
from optdesign.runtime.processes import (
    WorkerPool,
    die_with_parent,
    fork_call,
    forks_workers,
    limit_blas_threads,
    process_pool,
)
from optdesign.solvers.blas import one_blas_thread
from optdesign.storage import StoreWriter, lock_folder, open_store, read_store
from optdesign.text import printable

__all__ = [
    "Isolation",
    "WorkerPool",
    "cached",
    "die_with_parent",
    "failure_record",
    "fork_call",
    "forks_workers",
    "limit_blas_threads",
    "process_pool",
    "read_store",
    "run_tasks",
]

Record = dict[str, Any]
TaskFn = Callable[[Mapping[str, Any], Mapping[str, Record]], Record]
ExpandFn = Callable[[Mapping[str, Any], Record, Mapping[str, Record]], Iterable[Mapping[str, Any]]]
FailureFn = Callable[[Mapping[str, Any], str, str, float], Record]


@dataclass(frozen=True)
class Isolation:
    """Run each task in a forked child of its worker: a hard timeout and crash isolation.

    A task that outlives ``timeout`` is killed, one that crashes its process (a segfault
    in a solver library, ``os._exit``) or raises becomes a *failure record* instead of
    stopping the run: ``failure(task, kind, reason, wall_s)`` with ``kind`` one of
    ``"timeout"``, ``"crash"``, ``"error"``. ``failure`` runs in the worker (the child's
    parent), so it may keep per-worker state (e.g. stop trying a solver that timed out
    repeatedly); the child inherits that state at its fork. POSIX only (``os.fork``).

    Parameters
    ----------
    timeout
        Seconds, or the name of a task field giving them; None: no time limit.
    failure
        Picklable module-level function making the failure record (default
        :func:`failure_record`).
    quiet
        Send the child's stdout and stderr to /dev/null (solver chatter would garble a
        progress bar).
    """

    timeout: float | str | None = None
    failure: FailureFn | None = None
    quiet: bool = False

    def timeout_for(self, task: Mapping[str, Any]) -> float | None:
        """The hard timeout of ``task`` in seconds (None: none)."""
        if self.timeout is None:
            return None
        return float(task[self.timeout] if isinstance(self.timeout, str) else self.timeout)


def failure_record(task: Mapping[str, Any], kind: str, reason: str, wall_s: float) -> Record:
    """Default record of an isolated task that failed: ``status``, ``reason``, ``time_s``."""
    return {"status": kind, "reason": reason, "success": False, "time_s": wall_s}


def run_tasks(
    tasks: Iterable[Mapping[str, Any]],
    fn: TaskFn,
    store_path: Path | str,
    workers: int = 1,
    scheduler: str | Any | None = None,
    resume: bool = False,
    progress: bool | str = False,
    key: str | Mapping[str, Any] | None = None,
    on_record: Callable[[Record], None] | None = None,
    known: Mapping[str, Record] | None = None,
    pool: WorkerPool | None = None,
    expand: ExpandFn | None = None,
    *,
    overwrite: bool = False,
    isolate: Isolation | None = None,
    check: Callable[[Record], str | None] | None = None,
    stop: Callable[[], bool] | None = None,
) -> dict[str, Record]:
    """Run ``tasks`` through ``fn``, storing each record as it finishes.

    Parameters
    ----------
    tasks
        Dicts with a unique ``"id"`` and optional ``"after"`` (ids this task needs).
    fn
        ``fn(task, deps) -> record``, picklable (module-level).
    store_path
        JSONL store. Its folder is locked for the run (one writer per folder, see
        :func:`optdesign.storage.lock_folder`).
    workers
        Local processes (1: in this process, no pool).
    scheduler
        Address of a Dask distributed scheduler (or a ``distributed.Client``); when given,
        tasks go to that cluster instead of local processes.
    resume
        Keep the store's records and run only the missing tasks. A store whose identity
        line is missing or carries another ``key``, or that is damaged, is refused
        (:class:`optdesign.storage.StoreError`); a torn last line is cut first.
    progress
        Show a tqdm bar (a string is used as its description).
    key
        Identity of the run written to / checked against the store on resume: a string,
        or a mapping of its components (JSON-able), stored one by one so that a refused
        resume names what changed.
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
    overwrite
        Without ``resume``, replace a store that holds records of an earlier run (by
        default that is refused rather than silently emptying it).
    isolate
        Run every task in a forked child with a hard timeout; a timeout, crash or
        exception becomes a failure record (see :class:`Isolation`) instead of an error.
    check
        ``check(record) -> None`` or why a stored record cannot be trusted; on resume
        every stored record is checked before any is used, and one that fails refuses
        the resume naming the store, its line and the reason.
    stop
        ``stop() -> bool``: once true, no further task begins (a study's time limit);
        the tasks running finish and are stored, the others are left out of the
        returned records (a resume runs them).

    Returns
    -------
    dict
        id -> record for every task (stored ones included when resuming), in the order
        the tasks joined the run.

    Raises
    ------
    optdesign.storage.FolderInUseError
        Another process writes into the store's folder.
    optdesign.storage.StoreError
        The store cannot be resumed (no identity, another key, another format, damaged,
        a record failing ``check``), or holds records and neither ``resume`` nor
        ``overwrite`` is given.
    KeyboardInterrupt
        Re-raised after the cleanup when the run is interrupted (Ctrl-C, or SIGTERM /
        SIGHUP turned into one by the CLI): workers stopped, every finished record
        written, the store closed. Its attribute ``run_store = {"path": ..., "records":
        n}`` tells the CLI what was saved.
    """
    path = Path(store_path)
    if check is not None and known:
        check = _unless_known(check, known)
    with lock_folder(path.parent):
        stored = open_store(path, key, resume, overwrite, check)
        return _run(
            tasks,
            fn,
            path,
            len(stored),
            dict(stored),
            workers,
            scheduler,
            progress,
            on_record,
            known,
            pool,
            expand,
            isolate,
            stop,
        )


def _unless_known(check: Callable[[Record], str | None], known: Mapping[str, Record]):
    """``check`` for the stored records that are not the caller's own: a record equal to
    one in ``known`` (computed by this process in an earlier phase of the same run, and
    checked when it was resumed or computed) is not checked again."""

    def checked(record: Record) -> str | None:
        rid = record.get("id") if isinstance(record, Mapping) else None
        if rid is not None and known.get(rid) == record:
            return None
        return check(record)

    return checked


def _run(
    tasks,
    fn,
    path,
    n_stored,
    done,
    workers,
    scheduler,
    progress,
    on_record,
    known,
    pool,
    expand,
    isolate,
    stop=None,
) -> dict[str, Record]:
    # run_tasks once the store is open: the scheduling loop.
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
    store: StoreWriter | None = None
    # Records computed but not yet written; written on the way out of an interrupted run
    # too (they are finished work), unless on_record itself stopped the run.
    pending: deque[Record] = deque()
    stopped_by_callback = False
    try:
        add(tasks)
        expand_replayed()

        def ready(t: Mapping[str, Any]) -> bool:
            return all(a in done for a in t.get("after", []))

        # The workers start (fork) before the store's fsync thread and the progress bar's
        # monitor thread exist: a process forked while other threads run inherits only
        # the forking one, and whatever locks the others held.
        with _executor(fn, workers, scheduler, pool, isolate) as ex:
            store = StoreWriter(path, n_stored)
            # what an interrupt that ends the process from the watchdog names as saved
            note_active_store(str(path), lambda: store.count)
            if progress:
                from tqdm.auto import tqdm

                bar = tqdm(
                    total=len(by_id),
                    initial=sum(1 for i in by_id if i in done),
                    desc=printable(progress) if isinstance(progress, str) else None,
                    leave=False,
                    disable=None,  # no bar outside a terminal: its redraws would fill logs
                )

            def submit_ready() -> None:
                while ex.has_room() and not (stop is not None and stop()):
                    t = next((t for t in queue if ready(t)), None)
                    if t is None:
                        break
                    queue.remove(t)
                    ex.submit(t, {a: done[a] for a in t.get("after", [])})

            while True:
                submit_ready()
                if not ex.running():
                    if queue and not (stop is not None and stop()):
                        raise ValueError("run_tasks: dependency cycle")
                    break
                results = ex.wait()
                for _, record in results:
                    done[record["id"]] = record
                    pending.append(record)
                for t, record in results:
                    if expand is not None:
                        add(expand(t, record, done))
                        expand_replayed()
                # The next tasks of the chains go out before the store writes (an fsync
                # each was serial latency on every step of every chain); a run
                # killed in between just recomputes the unstored records on resume.
                submit_ready()
                while pending:
                    with deferred():  # written and off the list, or neither
                        record = pending.popleft()
                        store.write(record)
                    if bar is not None:
                        bar.update(1)
                    if on_record is not None:
                        try:
                            on_record(record)
                        except BaseException:
                            stopped_by_callback = True
                            raise
    except BaseException as exc:
        with deferred(drop=True):  # the run is ending already: a second Ctrl-C waits
            if store is not None and not stopped_by_callback:
                while pending:
                    store.write(pending.popleft())
            if isinstance(exc, KeyboardInterrupt):
                exc.run_store = {  # type: ignore[attr-defined]
                    "path": str(path),
                    "records": store.count if store is not None else n_stored,
                }
        raise
    finally:
        # An interrupt while the store closes waits for the close, and finds the store
        # noted for the CLI's message (it may come after the last record is written).
        with deferred():
            if store is not None:
                store.close()
            if bar is not None:
                bar.close()
            note_active_store(None)
            note_store(str(path), store.count if store is not None else n_stored)
    return {i: done[i] for i in by_id if i in done}


def _call(
    fn: TaskFn,
    task: Mapping[str, Any],
    deps: Mapping[str, Record],
    isolate: Isolation | None = None,
) -> Record:
    # One BLAS thread for the task wherever it runs (this process or a worker): the same
    # arithmetic, and so the same record, for any number of workers.
    with one_blas_thread():
        if isolate is None:
            record = dict(fn(task, deps))
        else:
            t0 = time.perf_counter()
            kind, value = fork_call(
                functools.partial(fn, task, deps), isolate.timeout_for(task), isolate.quiet
            )
            if kind == "ok":
                record = dict(value)
            else:
                failure = isolate.failure or failure_record
                record = dict(failure(task, kind, value, time.perf_counter() - t0))
    record["id"] = task["id"]
    return record


class _Serial:
    """Runs each task in this process when asked for a result (one at a time)."""

    def __init__(self, fn: TaskFn, isolate: Isolation | None):
        self.fn, self.isolate = fn, isolate
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
        return [(task, _call(self.fn, task, deps, self.isolate))]


class _Pool:
    """Local worker processes: never more tasks in flight than workers, so that a chain's
    next point goes to a free worker as soon as its neighbour is done."""

    def __init__(self, fn: TaskFn, pool: WorkerPool, isolate: Isolation | None):
        self.fn, self.pool, self.isolate = fn, pool, isolate
        self.tasks: dict[int, dict] = {}

    def has_room(self) -> bool:
        return len(self.tasks) < self.pool.size

    def running(self) -> bool:
        return bool(self.tasks)

    def submit(self, task: dict, deps: dict) -> None:
        self.tasks[self.pool.submit(_call, (self.fn, task, deps, self.isolate))] = task

    def wait(self) -> list[tuple[dict, Record]]:
        return [(self.tasks.pop(i), record) for i, record in self.pool.wait()]


class _Dask:
    """A Dask distributed cluster: every ready task is submitted at once."""

    def __init__(self, fn: TaskFn, client: Any, isolate: Isolation | None):
        from distributed import as_completed

        self.fn, self.client, self.isolate = fn, client, isolate
        self.ac = as_completed(with_results=False)
        self.tasks: dict[str, dict] = {}

    def has_room(self) -> bool:
        return True

    def running(self) -> bool:
        return bool(self.tasks)

    def submit(self, task: dict, deps: dict) -> None:
        fut = self.client.submit(_call, self.fn, task, deps, self.isolate, pure=False)
        self.tasks[fut.key] = task
        self.ac.add(fut)

    def wait(self) -> list[tuple[dict, Record]]:
        fut = next(self.ac)
        return [(self.tasks.pop(fut.key), fut.result())]


@contextmanager
def _executor(
    fn: TaskFn, workers: int, scheduler: Any, pool: WorkerPool | None, isolate: Isolation | None
):
    if scheduler is not None:
        from distributed import Client

        own = not hasattr(scheduler, "submit")
        client = _connect(Client, scheduler) if own else scheduler
        try:
            yield _Dask(fn, client, isolate)
        finally:
            if own:
                client.close()
    elif workers > 1 and pool is not None:
        yield _Pool(fn, pool, isolate)
    elif workers > 1:
        with process_pool(workers) as own_pool:
            yield _Pool(fn, own_pool, isolate)
    else:
        yield _Serial(fn, isolate)


def _connect(client_class: Any, scheduler: Any) -> Any:
    """A Client of the scheduler at ``scheduler`` (an address, or a cluster); a scheduler
    that does not answer in distributed's connect timeout, or a transport that cannot be
    set up (TLS without its configuration, UCX not installed), is an
    :class:`~optdesign.argument_checks.ArgumentError` naming the address, not a traceback."""
    from optdesign.argument_checks import ArgumentError, shown

    try:
        return client_class(scheduler)
    except (OSError, TypeError, ValueError, ImportError) as exc:
        where = shown(scheduler, 200) if isinstance(scheduler, str) else type(scheduler).__name__
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise ArgumentError(
            "scheduler", f"cannot connect to the Dask scheduler at {where}: {reason}"
        ) from exc


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
