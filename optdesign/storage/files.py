"""Atomic result files and a writable output folder (:mod:`optdesign.storage`).

A result file is either the old one or the complete new one, never a partial file: a new
temporary file in the same folder, created with ``O_EXCL``, fsynced, then ``os.replace``
(a link planted at the result's name is replaced, never followed).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

from optdesign.errors import OptDesignError
from optdesign.safe_io import CLOEXEC, NOFOLLOW


class StoreError(OptDesignError):
    """An output folder or store that cannot be used safely (damaged, foreign, busy)."""


class FolderInUseError(StoreError):
    """Another process holds the lock of an output folder."""


class WriteError(StoreError, OSError):
    """A file that could not be written (a full disk, no permission, a quota): its
    message names the file, ``cannot write out/sweep.csv: No space left on device``.

    Also an :class:`OSError` with the failure's ``errno``, ``strerror`` and the file as
    ``filename``, so that code treating I/O errors apart (a figure's failure is a note,
    a full disk is not) still does. Built by :func:`write_error`.
    """

    def __str__(self) -> str:
        return f"cannot write {self.filename}: {self.strerror}"


def write_error(path: Path | str, exc: OSError) -> WriteError:
    """``exc`` (raised while writing ``path``) as a :class:`WriteError` naming ``path``
    (also one naming a temporary file of ``path``: a writer that writes atomically
    itself, inside :func:`atomic_output`)."""
    return WriteError(exc.errno, exc.strerror or str(exc) or type(exc).__name__, str(path))


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
        raise write_error(path, exc) from None
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
        try:
            yield tmp
            # The writer wrote by name (it may even have replaced the file, atomically):
            # reopened without following a link, made durable, put in place.
            fd = os.open(tmp, os.O_RDWR | NOFOLLOW | CLOEXEC)
            try:
                _commit(fd, tmp, path)
            finally:
                os.close(fd)
        except OSError as exc:  # the writer's too: it names the temporary file, or none
            raise write_error(path, exc) from exc
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
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view) :]
            _commit(fd, tmp, path)
        except OSError as exc:  # "[Errno 28] No space left on device" names no file
            raise write_error(path, exc) from exc
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
