"""OpenBLAS thread counts: one BLAS thread while solving, in every process alike.

Why: the libraries an NLP solve calls (CasADi's bundled OpenBLAS under MUMPS, SciPy's
under SLSQP, NumPy's) split some reductions among their threads, and the split changes
the rounding. A solve in the main process (as many BLAS threads as cores) and the same
solve in a worker process (one thread, :func:`optdesign.runtime.processes` sets it) then
differ in the last bits, and a chain of warm-started solves (a Pareto front) carries the
difference to ~1e-5. With the same thread count everywhere, one worker and several do the
same arithmetic, bit for bit; one thread is also the faster choice for these small
problems (the processes are the parallelism).

:func:`one_blas_thread` gives a context manager (and decorator) that sets every OpenBLAS
loaded in this process to one thread and restores each library's own count on the way
out, so that a program that imports optdesign keeps its NumPy threading outside the
solver calls. It nests and is shared by threads (the outermost exit restores). The loaded
libraries are read from ``/proc/self/maps`` once, and again by :func:`rescan_blas` when a
solver is built (CasADi loads its OpenBLAS with the first Ipopt solver), so a solve pays
a few microseconds. (Not ``dl_iterate_phdr``: its Python callback would swallow a Ctrl-C
that lands inside it.) Where ``/proc`` or OpenBLAS is missing (macOS, an MKL NumPy)
nothing changes.
"""

from __future__ import annotations

import ctypes
import os
import threading
from collections.abc import Callable
from contextlib import ContextDecorator
from dataclasses import dataclass

#: (set, get) symbol pairs of the OpenBLAS builds met in the wild: the reference names,
#: 64-bit-integer builds, and the prefixed ones SciPy and NumPy wheels bundle.
_SYMBOLS = (
    ("openblas_set_num_threads", "openblas_get_num_threads"),
    ("openblas_set_num_threads64_", "openblas_get_num_threads64_"),
    ("scipy_openblas_set_num_threads", "scipy_openblas_get_num_threads"),
    ("scipy_openblas_set_num_threads64_", "scipy_openblas_get_num_threads64_"),
)


@dataclass(frozen=True, eq=False)
class BlasLibrary:
    """One loaded OpenBLAS: its path and its thread-count functions."""

    path: str
    set_threads: Callable[[int], None]
    get_threads: Callable[[], int]


def _probe(path: str) -> BlasLibrary | None:
    try:
        handle = ctypes.CDLL(path)
    except OSError:
        return None
    for set_name, get_name in _SYMBOLS:
        setter, getter = getattr(handle, set_name, None), getattr(handle, get_name, None)
        if setter is not None and getter is not None:
            setter.argtypes, setter.restype = (ctypes.c_int,), None
            getter.argtypes, getter.restype = (), ctypes.c_int
            return BlasLibrary(path, setter, getter)
    return None


_LOCK = threading.RLock()
_FOUND: list[tuple[BlasLibrary, ...]] = []  # the last scan (empty: none yet)


def rescan_blas() -> tuple[BlasLibrary, ...]:
    """Find the OpenBLAS libraries loaded in this process now (call it after loading one,
    e.g. once a solver is built); :func:`blas_libraries` returns them until the next scan."""
    try:
        with open("/proc/self/maps") as fh:
            paths = {line.split()[-1] for line in fh if "blas" in line.lower()}
    except OSError:
        paths = set()
    found, addresses = [], set()
    for path in sorted(paths):
        if "blas" not in os.path.basename(path).lower():
            continue
        lib = _probe(path)
        if lib is None:
            continue
        # a module linked to an OpenBLAS (SciPy's _fblas) finds its symbols too: one
        # entry per library, by the function's address
        address = ctypes.cast(lib.set_threads, ctypes.c_void_p).value
        if address not in addresses:
            addresses.add(address)
            found.append(lib)
    with _LOCK:
        _FOUND[:] = [tuple(found)]
    return tuple(found)


def blas_libraries() -> tuple[BlasLibrary, ...]:
    """The OpenBLAS libraries of the last :func:`rescan_blas` (one is made the first time)."""
    with _LOCK:
        if _FOUND:
            return _FOUND[0]
    return rescan_blas()


def blas_thread_counts() -> dict[str, int]:
    """Thread count of each loaded OpenBLAS, by the library's file name."""
    return {os.path.basename(lib.path): int(lib.get_threads()) for lib in blas_libraries()}


def limit_blas_threads(n: int = 1) -> int:
    """Set the thread count of every OpenBLAS loaded in this process to ``n`` (for good:
    a worker process's setting). Returns how many libraries were set."""
    libs = rescan_blas()
    for lib in libs:
        lib.set_threads(n)
    return len(libs)


class _OneThread(ContextDecorator):
    # Process-wide state: the count applies to the whole process, so contexts in several
    # threads share one activation; the last one out restores the saved counts.
    depth = 0
    saved: dict[str, tuple[BlasLibrary, int]] = {}  # noqa: RUF012

    def __enter__(self):
        with _LOCK:
            cls = type(self)
            cls.depth += 1
            try:
                for lib in blas_libraries():
                    if lib.path not in cls.saved:  # new, or found since the outermost entry
                        count = int(lib.get_threads())
                        cls.saved[lib.path] = (lib, count)
                        if count != 1:
                            lib.set_threads(1)
            except BaseException:  # e.g. Ctrl-C here: no __exit__ will come, restore now
                self.__exit__()
                raise
        return self

    def __exit__(self, *exc) -> None:
        with _LOCK:
            cls = type(self)
            cls.depth -= 1
            if cls.depth == 0:
                # a library loaded inside the context is limited too (it was saved then);
                # restoring it gives back the count it was loaded with
                for lib, count in cls.saved.values():
                    if count != 1:
                        lib.set_threads(count)
                cls.saved.clear()


def one_blas_thread() -> ContextDecorator:
    """Every OpenBLAS of this process at one thread inside, each library's own count
    restored after: ``with one_blas_thread(): ...`` or ``@one_blas_thread()`` (see the
    module's doc)."""
    return _OneThread()


def _after_fork_in_child() -> None:
    # A lock held by another thread at the fork would never be released in the child.
    global _LOCK
    _LOCK = threading.RLock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork_in_child)
