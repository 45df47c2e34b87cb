"""Safe output: atomic result files, one writer per output folder, the JSONL task store.

Long runs write into an output folder that a user may reuse, interrupt, share between
two runs by mistake, or receive from someone else. This module makes each of those safe:

- :func:`atomic_write_text` / :func:`atomic_write_bytes` / :func:`atomic_output`: a
  result file is either the old one or the complete new one, never a partial file (a
  new temporary file in the same folder, created with ``O_EXCL``, fsynced, then
  ``os.replace``: a link planted at the result's name is replaced, never followed);
- :func:`lock_folder`: an advisory lock (``flock`` on ``.optdesign.lock`` in the folder),
  non-blocking, so a second run into the same folder is refused at once with the pid of
  the first. The kernel drops the lock with the process, whatever ends it: no stale
  locks. The lock is re-entrant within a process (a command holds it for the whole run,
  the task runner takes it again for each store);
- :func:`open_store` / :class:`StoreWriter` / :func:`read_store`: the append-only JSON
  Lines store of :func:`optdesign.studies.runner.run_tasks`. Its first line is the run's
  identity ``{"__store__": 2, "key": ..., "identity": {...}}``, written with the file's
  creation (the file appears complete with it, atomically), so a store without its
  identity is never ours. Resuming checks the format version, the identity (naming the
  component that changed, :mod:`optdesign.store_identity`) and every record, refuses
  damaged or foreign stores, and cuts a torn last line (a run killed while writing)
  before appending.

The lock file and the stores are opened without following links, and must be regular
files with one link (:mod:`optdesign.safe_io`): nothing outside the folder is truncated,
appended to or read through them. An ``--out`` that is itself a link, given on the
command line, is the user's choice and is used as given.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
import threading
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from optdesign.errors import OptDesignError
from optdesign.interrupts import deferred
from optdesign.safe_io import CLOEXEC, NOFOLLOW, open_file, read_file

try:  # POSIX; elsewhere folders are not locked
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

Record = dict[str, Any]

#: Name of the lock file in a locked output folder.
LOCK_NAME = ".optdesign.lock"

#: Store format version (the identity line's ``__store__``): 2 stores the identity's
#: components; a store of another format is refused, naming its version.
STORE_VERSION = 2

_EMPTY = "it is empty (no identity line)"


class StoreError(OptDesignError):
    """An output folder or store that cannot be used safely (damaged, foreign, busy)."""


class FolderInUseError(StoreError):
    """Another process holds the lock of an output folder."""


# --- atomic files ------------------------------------------------------------------------
def _umask() -> int:
    # os.umask can only be read by setting it; do it once (at first use, not at import).
    global _UMASK
    if _UMASK is None:
        old = os.umask(0o022)
        os.umask(old)
        _UMASK = old
    return _UMASK


_UMASK: int | None = None


def _fsync_dir(folder: Path) -> None:
    # The rename itself is durable only once the directory entry is on disk.
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _temp_file(path: Path) -> tuple[int, Path]:
    # Hidden, in the same folder (os.replace must not cross file systems), keeping the
    # suffix so that writers choosing the format by extension (matplotlib) still work.
    # mkstemp creates it with O_EXCL | O_NOFOLLOW: a new file, never a planted one.
    try:
        fd, tmp = tempfile.mkstemp(
            prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}", dir=path.parent
        )
    except OSError as exc:
        raise StoreError(f"cannot write {path}: {exc.strerror}") from None
    return fd, Path(tmp)


def _commit(fd: int, tmp: Path, path: Path) -> None:
    # The temporary file's content is complete: make it durable and put it in place.
    # os.replace swaps the directory entry: a link planted at ``path`` is replaced, its
    # target never opened.
    os.fchmod(fd, 0o666 & ~_umask())  # mkstemp made it 0600
    os.fsync(fd)
    os.replace(tmp, path)


@contextlib.contextmanager
def atomic_output(path: Path | str) -> Iterator[Path]:
    """A temporary path to write ``path``'s new content to; it replaces ``path`` on exit.

    For writers that want a file name (``savefig``). On an exception (an interrupt too)
    the temporary file is removed and ``path`` is unchanged. A symbolic link at ``path``
    is replaced by the new file, never followed.

    Examples
    --------
    >>> with atomic_output(out / "front.png") as tmp:  # doctest: +SKIP
    ...     fig.savefig(tmp)
    """
    path = Path(path)
    _make_folder(path.parent)
    fd, tmp = _temp_file(path)
    os.close(fd)
    try:
        yield tmp
        # The writer wrote by name (it may even have replaced the file, atomically):
        # reopened without following a link, made durable, put in place.
        fd = os.open(tmp, os.O_RDWR | NOFOLLOW | CLOEXEC)
        try:
            _commit(fd, tmp, path)
        finally:
            os.close(fd)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    _fsync_dir(path.parent)


def atomic_write_bytes(path: Path | str, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically: readers see the old file or the whole new one.

    The data goes through the descriptor of the new temporary file (created with
    ``O_EXCL``), never through a name: a link at ``path`` is replaced, not followed.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    _make_folder(path.parent)
    fd, tmp = _temp_file(path)
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view) :]
        _commit(fd, tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    finally:
        os.close(fd)
    _fsync_dir(path.parent)
    return path


def atomic_write_text(path: Path | str, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically (see :func:`atomic_write_bytes`)."""
    return atomic_write_bytes(path, text.encode(encoding))


def _make_folder(folder: Path) -> None:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise StoreError(f"cannot create the output folder {folder}: {exc.strerror}") from None


def ensure_writable(folder: Path | str) -> Path:
    """Create ``folder`` if needed and check that files can be created in it.

    Done before a long computation, so that a read-only or full output folder is
    reported at once rather than after an hour of solving.

    Raises
    ------
    StoreError
        Naming the folder and the reason.
    """
    folder = Path(folder)
    _make_folder(folder)
    try:
        fd, tmp = tempfile.mkstemp(prefix=".optdesign-write-test.", dir=folder)
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise StoreError(f"cannot write to the output folder {folder}: {exc.strerror}") from None
    return folder


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


# --- the JSONL store --------------------------------------------------------------------
#: Largest store read back (a pareto record with its multipliers is ~10 kB, a bench row
#: ~1 kB: 10 000 points are ~100 MB).
STORE_MAX_BYTES = 1 << 30


@dataclass
class StoreScan:
    """What a store file holds (see :func:`scan_store`)."""

    path: Path
    exists: bool = False
    key: str | None = None
    has_identity: bool = False
    #: The identity line's ``__store__`` (the store format version).
    version: Any = None
    #: The identity line's components (what the run's records depend on), if stored.
    identity: dict[str, Any] | None = None
    records: dict[str, Record] = field(default_factory=dict)
    #: Line number of each record (for messages).
    lines: dict[str, int] = field(default_factory=dict)
    #: Length of the part made of complete lines (a torn tail starts there).
    good_bytes: int = 0
    #: The file's bytes after the last newline (a record being written when killed).
    torn: bytes = b""
    #: The torn tail is a complete record that only lacks its newline.
    torn_record: Record | None = None
    #: Why the file cannot be used as a store (None: it can).
    problem: str | None = None


def scan_store(path: Path | str) -> StoreScan:
    """Read a store without trusting it: the identity, the records, a torn tail, damage.

    Never raises for content (an unreadable file gives ``problem``); only for a file that
    cannot be opened, or that is a symbolic link, not a regular file, or larger than
    :data:`STORE_MAX_BYTES` (:class:`~optdesign.safe_io.UnsafeFileError`).
    """
    path = Path(path)
    scan = StoreScan(path)
    try:
        data = read_file(path, what="the store", limit=STORE_MAX_BYTES)
    except OSError as exc:
        raise StoreError(f"cannot read the store {path}: {exc.strerror}") from None
    if data is None:
        return scan
    scan.exists = True
    end = data.rfind(b"\n") + 1
    scan.good_bytes, scan.torn = end, data[end:]
    if not data:
        scan.problem = _EMPTY
        return scan
    lines = data[:end].split(b"\n")[:-1]
    for n, raw in enumerate(lines, start=1):
        obj, why = _parse_line(raw)
        if why is not None:
            scan.problem = f"line {n} {why}"
            return scan
        if obj is None:
            continue  # blank line
        if "__store__" in obj:
            if n != 1:
                scan.problem = f"line {n} is a second identity line (two runs wrote into it)"
                return scan
            scan.has_identity, scan.key = True, obj.get("key")
            scan.version = obj["__store__"]
            ident = obj.get("identity")
            scan.identity = ident if isinstance(ident, dict) else None
            continue
        if n == 1:
            scan.problem = "its first line is not the identity of an optdesign run"
            return scan
        rid = obj.get("id")
        if not isinstance(rid, str):
            scan.problem = f"line {n} is not a record (no string 'id')"
            return scan
        if rid in scan.records:
            scan.problem = f"record {rid!r} appears twice (line {n}): two runs wrote into it"
            return scan
        scan.records[rid] = obj
        scan.lines[rid] = n
    if not scan.has_identity:
        scan.problem = "it has no identity line"
    elif scan.torn:
        obj, why = _parse_line(scan.torn)
        if why is None and obj is not None and isinstance(obj.get("id"), str):
            if obj["id"] not in scan.records and "__store__" not in obj:
                scan.torn_record = obj
                scan.lines[obj["id"]] = len(lines) + 1
    return scan


def _parse_line(raw: bytes) -> tuple[dict | None, str | None]:
    """(object, None), (None, None) for a blank line, or (None, why it is unreadable)."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        return None, "is not text (binary data)"
    if not text.strip():
        return None, None
    try:
        obj = json.loads(text)
    except (json.JSONDecodeError, RecursionError):
        return None, "is not JSON"
    if not isinstance(obj, dict):
        return None, "is not a JSON object"
    return obj, None


def _version_problem(scan: StoreScan) -> str | None:
    from optdesign.store_identity import version_problem

    return version_problem(scan.has_identity, scan.version, STORE_VERSION)


def read_store(store_path: Path | str) -> tuple[str | None, dict[str, Record]]:
    """The key and the records (id -> record) of a JSONL store.

    A torn last line (a run killed while writing it) is ignored - that task runs again on
    resume - unless it is a whole record that only lacks its newline. A missing file
    gives ``(None, {})``.

    Raises
    ------
    StoreError
        If the file is not a readable store (damaged, binary, two runs interleaved, or
        in another store format).
    """
    scan = scan_store(store_path)
    problem = scan.problem if scan.problem not in (None, _EMPTY) else _version_problem(scan)
    if problem is not None:
        raise StoreError(f"{scan.path} is not a usable optdesign store: {problem}")
    if scan.torn_record is not None:
        scan.records[scan.torn_record["id"]] = scan.torn_record
    return scan.key, scan.records


#: ``check(record) -> None`` or why a stored record cannot be trusted.
RecordCheck = Callable[[Record], "str | None"]


def open_store(
    path: Path | str,
    key: str | Mapping[str, Any] | None,
    resume: bool,
    overwrite: bool = False,
    check: RecordCheck | None = None,
) -> dict[str, Record]:
    """Make ``path`` ready for appending the records of run ``key``; return its records.

    ``key`` is the run's identity: a string, or a mapping of its components (what the
    records depend on: the problem, the objectives, the method's and the solver's
    settings, the code's version...), stored component by component so that a refused
    resume can say which one changed (:mod:`optdesign.store_identity`).

    - ``resume`` and the store exists: it must be in this store format, its identity
      must equal ``key``, every line must be readable and every record must pass
      ``check``; a torn last line is completed (a whole record that only lacks its
      newline) or cut. Returns the stored records.
    - otherwise a new store holding only the identity replaces ``path``, atomically.
      An existing store with records (or unreadable content) is not replaced unless
      ``overwrite``: a run without ``resume`` must not silently empty an earlier one.

    The caller holds the folder's lock (:func:`lock_folder`).

    Raises
    ------
    StoreError
        Naming the file and the reason (the changed component, the line of a record
        that fails ``check`` and why), and what to do.
    """
    from optdesign.store_identity import describe_difference, identity_key

    path = Path(path)
    key_text = identity_key(key)
    components = dict(key) if isinstance(key, Mapping) else None
    scan = scan_store(path) if resume or not overwrite else StoreScan(path)
    if resume and scan.exists:
        problem = scan.problem or _version_problem(scan)
        if problem is not None:
            raise StoreError(f"--resume: {path} cannot be resumed: {problem}; {_START_OVER}")
        if scan.key != key_text:
            diff = describe_difference(scan.identity, scan.key, components, key_text)
            raise StoreError(
                f"--resume: the store {path} belongs to another run: {diff}; resume with the "
                f"same settings, or {_START_OVER}"
            )
        if scan.torn_record is not None:
            scan.records[scan.torn_record["id"]] = scan.torn_record
        if check is not None:
            _check_records(scan, check)
        if scan.torn:
            _repair_tail(path, scan)
        return scan.records
    if not overwrite:
        _refuse_replacing(scan)
    identity: dict[str, Any] = {"__store__": STORE_VERSION, "key": key_text}
    if components is not None:
        identity["identity"] = components
    atomic_write_text(path, json.dumps(identity, sort_keys=True, default=str) + "\n")
    return {}


_START_OVER = "start over with --overwrite or use another output folder"


def _check_records(scan: StoreScan, check: RecordCheck) -> None:
    from optdesign.store_identity import check_records

    bad = check_records(scan.records, scan.lines, check)
    if bad is not None:
        rid, line, why = bad
        raise StoreError(
            f"--resume: {scan.path} line {line}: record {rid!r} {why}; it cannot be "
            f"trusted: {_START_OVER}"
        )


def _refuse_replacing(scan: StoreScan) -> None:
    if scan.exists and (scan.records or scan.problem not in (None, _EMPTY)):
        what = (
            f"holds {len(scan.records)} records of an earlier run"
            if scan.problem is None
            else f"holds data that is not a usable store ({scan.problem})"
        )
        raise StoreError(
            f"{scan.path} {what}; continue it with --resume, start over with --overwrite, "
            "or use another output folder"
        )


def check_new_store(path: Path | str) -> None:
    """Refuse, before any work, to start a new run over ``path`` if it holds records.

    The check :func:`open_store` makes without ``resume`` and ``overwrite``, for a
    command to make it for all its stores up front.
    """
    _refuse_replacing(scan_store(path))


def _repair_tail(path: Path, scan: StoreScan) -> None:
    # The next record must start on a line of its own: appended onto the partial line,
    # it would make that line unreadable and be lost with it.
    fd = open_file(path, os.O_RDWR, what="the store", single_link=True)
    try:
        if scan.torn_record is not None:
            os.lseek(fd, 0, os.SEEK_END)
            os.write(fd, b"\n")
        else:
            os.ftruncate(fd, scan.good_bytes)
        os.fsync(fd)
    finally:
        os.close(fd)


def discard_store(path: Path | str) -> None:
    """Remove a store (``--overwrite``); the caller holds the folder's lock."""
    with contextlib.suppress(FileNotFoundError):
        os.unlink(path)


class StoreWriter:
    """Append records to a store made ready by :func:`open_store`.

    One ``os.write`` of the whole line per record (``O_APPEND``): a record is on disk
    complete or, if the process is killed inside that one system call, as a torn tail
    that the next resume cuts. No user-space buffer, so an interrupt between two records
    loses nothing already handed to :meth:`write`. A background thread fsyncs, so a
    crash of the machine loses at most the last few milliseconds; the fsync (~1 ms) used
    to delay the next task of every chain when it ran in the scheduling loop.

    Parameters
    ----------
    path
        The store.
    count
        Records already in it (for :attr:`count`).
    """

    def __init__(self, path: Path | str, count: int = 0):
        self.path = Path(path)
        self.count = count
        # Not through a link, nor into a file with other hard links (see safe_io).
        self.fd = open_file(
            self.path, os.O_WRONLY | os.O_APPEND, what="the store", single_link=True
        )
        self._dirty = threading.Event()
        self._closing = False
        self._syncer = threading.Thread(target=self._sync_loop, daemon=True)
        self._syncer.start()

    def write(self, obj: Mapping[str, Any]) -> None:
        """Append one record (a JSON-able mapping with an ``id``)."""
        data = (json.dumps(obj, allow_nan=True) + "\n").encode()
        with deferred():  # the whole line, and counted (the CLI reports the count)
            view = memoryview(data)
            while view:
                view = view[os.write(self.fd, view) :]
            self.count += 1
        self._dirty.set()

    def _sync_loop(self) -> None:
        while True:
            self._dirty.wait()
            self._dirty.clear()
            if self._closing:
                return
            try:
                os.fsync(self.fd)
            except (OSError, ValueError):
                return  # closed underneath us: close() syncs itself

    def close(self) -> None:
        """Stop the fsync thread, fsync and close (idempotent)."""
        if self.fd < 0:
            return
        with deferred():
            self._close()

    def _close(self) -> None:
        self._closing = True
        self._dirty.set()
        self._syncer.join()
        with contextlib.suppress(OSError):
            os.fsync(self.fd)
        os.close(self.fd)
        self.fd = -1
