"""One writer per output folder (:mod:`optdesign.storage`): an advisory lock (``flock``
on ``.optdesign.lock`` in the folder), non-blocking, so a second run into the same folder
is refused at once with the pid of the first. The kernel drops the lock with the process,
whatever ends it: no stale locks. The lock is re-entrant within a process (a command holds
it for the whole run, the task runner takes it again for each store).
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Iterator
from pathlib import Path

from optdesign.errors import OptDesignError
from optdesign.safe_io import open_file, read_file
from optdesign.storage.files import FolderInUseError, StoreError, _make_folder

try:  # POSIX; elsewhere folders are not locked
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

#: Name of the lock file in a locked output folder.
LOCK_NAME = ".optdesign.lock"


# --- one writer per folder ------------------------------------------------------------------
#: realpath of a folder -> [lock file descriptor, depth] for the locks this process holds.
_HELD: dict[str, list[int]] = {}
_HELD_LOCK = threading.Lock()


def _forget_locks_in_child() -> None:
    # A forked child (worker, isolated task) inherits the lock's file descriptor; it
    # must not keep the lock alive after the parent is gone, nor believe it holds it.
    # Closing the inherited descriptor leaves the parent's lock in place (flock locks
    # belong to the open file, which the parent still has open).
    global _HELD_LOCK
    _HELD_LOCK = threading.Lock()
    for fd, _ in _HELD.values():
        with contextlib.suppress(OSError):
            os.close(fd)
    _HELD.clear()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_locks_in_child)


def _lock_holder(path: Path) -> str:
    try:
        pid = (read_file(path, what="the lock file", limit=64) or b"").decode().strip()
    except (OSError, OptDesignError, UnicodeDecodeError):
        pid = ""
    return f"pid {pid}" if pid.isdigit() else "pid unknown"


def _acquire(folder: Path) -> int:
    path = folder / LOCK_NAME
    # A lock file planted as a link (to ~/.bashrc) is refused, never truncated; so is
    # a hard link, a FIFO or a device.
    try:
        fd = open_file(path, os.O_RDWR | os.O_CREAT, 0o644, what="the lock file", single_link=True)
    except OSError as exc:
        raise StoreError(f"cannot write to the output folder {folder}: {exc.strerror}") from None
    if fcntl is None:  # pragma: no cover - no advisory locks on this platform
        return fd
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        raise FolderInUseError(
            f"folder {folder} is in use by another optdesign run ({_lock_holder(path)}); "
            "wait for it to finish or use another output folder"
        ) from None
    # The pid is for the message of a run refused by this one.
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
    return fd


@contextlib.contextmanager
def lock_folder(folder: Path | str) -> Iterator[Path]:
    """Hold the output folder ``folder`` (created if needed) for this process.

    Non-blocking: if another process holds it, :class:`FolderInUseError` says so with
    its pid. Re-entrant within a process. The lock is released on exit, or by the kernel
    when the process ends, however it ends.
    """
    folder = Path(folder)
    _make_folder(folder)
    key = os.path.realpath(folder)
    with _HELD_LOCK:
        entry = _HELD.get(key)
        if entry is not None:
            entry[1] += 1
        else:
            _HELD[key] = [_acquire(folder), 1]
    try:
        yield folder
    finally:
        with _HELD_LOCK:
            entry = _HELD.get(key)
            if entry is not None:  # absent in a forked child: nothing to release
                entry[1] -= 1
                if entry[1] == 0:
                    del _HELD[key]
                    with contextlib.suppress(OSError):
                        os.close(entry[0])  # closing releases the flock


def holds_lock(folder: Path | str) -> bool:
    """Whether this process holds the lock of ``folder``."""
    return os.path.realpath(folder) in _HELD
