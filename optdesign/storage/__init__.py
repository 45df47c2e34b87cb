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
  Lines store of :func:`optdesign.runtime.runner.run_tasks`. Its first line is the run's
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

One job a module: :mod:`optdesign.storage.files` (atomic files, a writable folder),
:mod:`optdesign.storage.folder_lock` (one writer per folder), :mod:`optdesign.storage.store`
(the JSONL store); every name is imported from ``optdesign.storage`` as before.
"""

from optdesign.storage.files import (
    FolderInUseError,
    StoreError,
    WriteError,
    atomic_output,
    atomic_write_bytes,
    atomic_write_text,
    ensure_writable,
)
from optdesign.storage.folder_lock import LOCK_NAME, _lock_holder, holds_lock, lock_folder
from optdesign.storage.store import (
    STORE_MAX_BYTES,
    STORE_VERSION,
    Record,
    RecordCheck,
    StoreScan,
    StoreWriter,
    check_new_store,
    discard_store,
    open_store,
    read_store,
    scan_store,
)

__all__ = [
    "LOCK_NAME",
    "STORE_MAX_BYTES",
    "STORE_VERSION",
    "FolderInUseError",
    "Record",
    "RecordCheck",
    "StoreError",
    "StoreScan",
    "StoreWriter",
    "WriteError",
    "_lock_holder",
    "atomic_output",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_new_store",
    "discard_store",
    "ensure_writable",
    "holds_lock",
    "lock_folder",
    "open_store",
    "read_store",
    "scan_store",
]
