"""A function mapped over items on forked workers that inherit it, in the serial order.

The function (e.g. a solver's bound ``solve``, built once in this process) is never
pickled: the workers are forked after it is registered and find it by key. Only the
items and the results cross the pipes. The answer is the one a serial loop gives: the
results in the order of the items, and with a ``stop`` rule the shortest prefix on
which it holds, whatever the number of workers and whichever finishes first.

:func:`map_inherited` forks its workers for one call. :class:`InheritedWorkers` keeps
them for many calls (the nodes of a catalogue search: a pool per node would cost a fork
per node); after a call that stopped early it waits for the items still running, whose
results are dropped, so that the next call starts with idle workers.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from optdesign.runtime.processes import WorkerPool, forks_workers

#: Callables handed to forked workers by inheritance.
_INHERITED: dict[int, Callable[[Any], Any]] = {}


def _call_inherited(key: int, item: Any) -> Any:
    return _INHERITED[key](item)


def map_serial(
    fn: Callable[[Any], Any], items: list[Any], stop: Callable[[list[Any]], bool] | None = None
) -> list[Any]:
    """The serial answer itself: ``fn`` over ``items`` here, in order, up to ``stop``."""
    out: list[Any] = []
    for item in items:
        out.append(fn(item))
        if stop is not None and stop(out):
            break
    return out


def _prefix_map(pool: WorkerPool, key: int, items: list[Any], stop) -> list[Any]:
    """The serial answer of ``items`` on ``pool``; items past it may still be running."""
    results: dict[int, Any] = {}
    running: dict[int, int] = {}  # worker -> item index
    nxt = 0
    prefix = 0  # results[0:prefix] are in, and stop() was asked at each length
    while prefix < len(items):
        while nxt < len(items) and pool.idle:
            running[pool.submit(_call_inherited, (key, items[nxt]))] = nxt
            nxt += 1
        for worker, value in pool.wait():
            results[running.pop(worker)] = value
        while prefix in results:
            prefix += 1
            if stop is not None and stop([results[k] for k in range(prefix)]):
                return [results[k] for k in range(prefix)]
    return [results[k] for k in range(len(items))]


def map_inherited(
    fn: Callable[[Any], Any],
    items: list[Any],
    workers: int,
    stop: Callable[[list[Any]], bool] | None = None,
) -> list[Any]:
    """``[fn(item) for item in items]`` on ``workers`` forked processes that inherit
    ``fn`` (e.g. a solver's bound ``solve``: built once here, never pickled).

    Results come back in the order of ``items``. With ``stop``, the answer is the
    shortest prefix ``results[:k]`` for which ``stop(results[:k])`` holds (all of them if
    none): the list a serial run returns, whatever the number of workers and the order in
    which they finish. Results of later items that finished first are dropped, items
    still running are stopped. Off Linux (no fork) it runs here.
    """
    if workers <= 1 or not forks_workers() or len(items) <= 1:
        return map_serial(fn, items, stop)
    key = id(fn)
    _INHERITED[key] = fn
    try:
        pool = WorkerPool(min(workers, len(items)))
        try:
            return _prefix_map(pool, key, items, stop)
        finally:
            pool.close()  # terminates the workers still running items past the prefix
    finally:
        _INHERITED.pop(key, None)


class InheritedWorkers:
    """``workers`` forked processes that inherit ``fn``, kept for many :meth:`map` calls.

    Create it once ``fn`` can run (what it uses is built: the workers copy this process
    as it is), use it as a context manager (the workers stop on exit). With one worker,
    or where processes cannot be forked, :meth:`map` runs here.
    """

    def __init__(self, fn: Callable[[Any], Any], workers: int):
        self.fn = fn
        self.key = id(fn)
        self.pool: WorkerPool | None = None
        if workers > 1 and forks_workers():
            _INHERITED[self.key] = fn
            try:
                self.pool = WorkerPool(workers)
            except BaseException:
                _INHERITED.pop(self.key, None)
                raise

    def map(self, items: list[Any], stop: Callable[[list[Any]], bool] | None = None) -> list[Any]:
        """The serial answer of ``fn`` over ``items`` (see :func:`map_inherited`)."""
        if self.pool is None or len(items) <= 1:
            return map_serial(self.fn, items, stop)
        out = _prefix_map(self.pool, self.key, items, stop)
        while self.pool.busy:  # the items past the answer: finished, and dropped
            self.pool.wait()
        return out

    def close(self) -> None:
        if self.pool is not None:
            try:
                self.pool.close()
            finally:
                self.pool = None
                _INHERITED.pop(self.key, None)

    def __enter__(self) -> InheritedWorkers:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
