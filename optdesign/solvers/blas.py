"""OpenBLAS thread counts: one BLAS thread while solving, in every process alike.

Why: the libraries an NLP solve calls (CasADi's bundled OpenBLAS under MUMPS, SciPy's
under SLSQP, NumPy's) split some reductions among their threads, and the split changes
the rounding. A solve in the main process (as many BLAS threads as cores) and the same
solve in a worker process (one thread, :func:`optdesign.studies.processes` sets it) then
differ in the last bits, and a chain of warm-started solves (a Pareto front) carries the
difference to ~1e-5. With the same thread count everywhere, one worker and several do the
same arithmetic, bit for bit; one thread is also the faster choice for these small
problems (the processes are the parallelism).

:func:`one_blas_thread` gives a context manager (and decorator) that sets every OpenBLAS
loaded in this process to one thread and restores each library's own count on the way
out, so that a program that imports optdesign keeps its NumPy threading outside the
solver calls. It nests and is shared by threads (the outermost exit restores), and it
also limits a library loaded inside it (CasADi loads its OpenBLAS with the first Ipopt
solver). The loaded libraries are found with ``dl_iterate_phdr`` and rescanned only when
the dynamic loader reports a new object, so a solve pays a few microseconds. Where that
call or OpenBLAS is missing (macOS, an MKL NumPy) nothing changes.
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


class _PhdrInfo(ctypes.Structure):
    # struct dl_phdr_info (glibc, musl, the BSDs): only the fields read here.
    _fields_ = (
        ("addr", ctypes.c_void_p),
        ("name", ctypes.c_char_p),
        ("phdr", ctypes.c_void_p),
        ("phnum", ctypes.c_uint16),
        ("adds", ctypes.c_ulonglong),
        ("subs", ctypes.c_ulonglong),
    )


_CALLBACK = ctypes.CFUNCTYPE(
    ctypes.c_int, ctypes.POINTER(_PhdrInfo), ctypes.c_size_t, ctypes.c_void_p
)
_COUNTERS_END = _PhdrInfo.subs.offset + ctypes.sizeof(ctypes.c_ulonglong)


def _dl_iterate_phdr():
    try:
        fn = ctypes.CDLL(None).dl_iterate_phdr
    except (OSError, AttributeError):
        return None
    fn.argtypes = (_CALLBACK, ctypes.c_void_p)
    fn.restype = ctypes.c_int
    return fn


_ITERATE = _dl_iterate_phdr()


def _loaded(names: list[str] | None) -> int:
    """The loader's count of objects loaded so far; with ``names``, the path of every
    loaded object is appended to it (without, the walk stops at the first object)."""
    if _ITERATE is None:
        return 0
    seen = [0]

    def visit(info, size, _data) -> int:
        if size >= _COUNTERS_END:
            seen[0] = info.contents.adds
        if names is None:
            return 1
        if info.contents.name:
            names.append(os.fsdecode(info.contents.name))
        return 0

    _ITERATE(_CALLBACK(visit), None)
    return seen[0]


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
_SCAN: dict[str, object] = {"adds": -1, "libraries": ()}


def blas_libraries() -> tuple[BlasLibrary, ...]:
    """The OpenBLAS libraries loaded in this process (rescanned when the loader has
    loaded something since the last call)."""
    with _LOCK:
        adds = _loaded(None)
        if adds != _SCAN["adds"] or adds == 0:
            names: list[str] = []
            adds = _loaded(names)
            found, addresses = [], set()
            for path in sorted(set(names)):
                if "blas" in os.path.basename(path).lower():
                    lib = _probe(path)
                    # a module linked to an OpenBLAS (SciPy's _fblas) finds its symbols
                    # too: one entry per library, by the function's address
                    address = (
                        None if lib is None else ctypes.cast(lib.set_threads, ctypes.c_void_p).value
                    )
                    if lib is not None and address not in addresses:
                        addresses.add(address)
                        found.append(lib)
            _SCAN.update(adds=adds, libraries=tuple(found))
        return _SCAN["libraries"]  # type: ignore[return-value]


def blas_thread_counts() -> dict[str, int]:
    """Thread count of each loaded OpenBLAS, by the library's file name."""
    return {os.path.basename(lib.path): int(lib.get_threads()) for lib in blas_libraries()}


def limit_blas_threads(n: int = 1) -> int:
    """Set the thread count of every OpenBLAS loaded in this process to ``n`` (for good:
    a worker process's setting). Returns how many libraries were set."""
    libs = blas_libraries()
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
            for lib in blas_libraries():
                if lib.path not in cls.saved:  # new, or loaded since the outermost entry
                    count = int(lib.get_threads())
                    cls.saved[lib.path] = (lib, count)
                    if count != 1:
                        lib.set_threads(1)
            cls.depth += 1
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
