"""The append-only JSON Lines store of :func:`optdesign.runtime.runner.run_tasks`
(:mod:`optdesign.storage`).

Its first line is the run's identity ``{"__store__": 2, "key": ..., "identity": {...}}``,
written with the file's creation (the file appears complete with it, atomically), so a
store without its identity is never ours. Resuming checks the format version, the
identity (naming the component that changed, :mod:`optdesign.store_identity`) and every
record, refuses damaged or foreign stores, and cuts a torn last line (a run killed while
writing) before appending.
"""

from __future__ import annotations

import contextlib
import json
import os
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from optdesign.interrupts import deferred
from optdesign.safe_io import open_file, read_file
from optdesign.storage.files import StoreError, atomic_write_text, write_error

Record = dict[str, Any]

#: Store format version (the identity line's ``__store__``): 2 stores the identity's
#: components; a store of another format is refused, naming its version.
STORE_VERSION = 2

_EMPTY = "it is empty (no identity line)"


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
            raise StoreError(f"resume=True: {path} cannot be resumed: {problem}; {_START_OVER}")
        if scan.key != key_text:
            diff = describe_difference(scan.identity, scan.key, components, key_text)
            raise StoreError(
                f"resume=True: the store {path} belongs to another run: {diff}; resume with the "
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


_START_OVER = "start over with overwrite=True or use another output folder"


def _check_records(scan: StoreScan, check: RecordCheck) -> None:
    from optdesign.store_identity import check_records

    bad = check_records(scan.records, scan.lines, check)
    if bad is not None:
        rid, line, why = bad
        raise StoreError(
            f"resume=True: {scan.path} line {line}: record {rid!r} {why}; it cannot be "
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
            f"{scan.path} {what}; continue it with resume=True, start over with overwrite=True, "
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
    except OSError as exc:
        raise write_error(path, exc) from exc
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
            try:
                while view:
                    view = view[os.write(self.fd, view) :]
            except OSError as exc:  # a full disk: the message names the store
                raise write_error(self.path, exc) from exc
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
