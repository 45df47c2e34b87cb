"""Files opened without trusting what is on disk: no links followed, regular files only.

An output folder may be reused, shared, or prepared by someone else: a symbolic link
planted in it (``.optdesign.lock -> ~/.bashrc``), a FIFO or ``/dev/zero`` where a store
should be, a hard link to a file elsewhere. Everything optdesign changes in place or
reads back from an output folder goes through :func:`open_file` / :func:`read_file`:

- ``O_NOFOLLOW``: a symbolic link is refused, naming the file; its target is never
  opened, truncated or read;
- a file that is not a regular file (FIFO, device, socket, folder) is refused, and never
  blocks the open (``O_NONBLOCK``);
- a file changed in place (the lock, a store appended to) must have one link only: a
  hard link would carry the change to another name, possibly outside the folder;
- reads are capped: nothing reads "until the kernel kills it".

Files written whole are replaced atomically by a new file (:mod:`optdesign.storage`):
``os.replace`` swaps the directory entry, so a planted link is replaced, not followed.

:func:`slug` turns any text (a problem's name) into a safe file-name part.
"""

from __future__ import annotations

import errno
import hashlib
import os
import re
import stat
import unicodedata
from collections.abc import Mapping
from pathlib import Path

from optdesign.errors import OptDesignError

NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
NONBLOCK = getattr(os, "O_NONBLOCK", 0)
CLOEXEC = getattr(os, "O_CLOEXEC", 0)


class UnsafeFileError(OptDesignError):
    """A file optdesign will not open: a symbolic link, not a regular file, too large.

    ``path`` and ``reason`` (e.g. ``"is a FIFO, not a regular file"``) let a caller
    word the message for its own option."""

    def __init__(self, message: str, path: Path | None = None, reason: str = ""):
        super().__init__(message)
        self.path = path
        self.reason = reason or message


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "a special file"


def _refuse(what: str, path: Path, reason: str) -> UnsafeFileError:
    return UnsafeFileError(
        f"{what} {path} {reason}; remove it or use another output folder", path, reason
    )


def open_file(
    path: Path | str,
    flags: int,
    mode: int = 0o644,
    *,
    what: str = "the file",
    single_link: bool = False,
    follow: bool = False,
) -> int:
    """``os.open`` that refuses a symbolic link, a non-regular file and (``single_link``)
    a file with other hard links; returns the descriptor.

    Parameters
    ----------
    flags
        ``os.O_*`` flags; ``O_NOFOLLOW``, ``O_NONBLOCK`` and ``O_CLOEXEC`` are added.
    what
        How messages name the file (``"the lock file"``).
    single_link
        Refuse a file with more than one hard link (for files changed in place).
    follow
        Follow a symbolic link (only for a path the user named on the command line).

    Raises
    ------
    UnsafeFileError
        Naming the file and why it is refused.
    OSError
        Any other failure of the open (missing, no permission).
    """
    path = Path(path)
    try:
        fd = os.open(path, flags | (0 if follow else NOFOLLOW) | NONBLOCK | CLOEXEC, mode)
    except OSError as exc:
        if exc.errno == errno.ELOOP or (exc.errno == errno.EMLINK and path.is_symlink()):
            raise _refuse(
                what, path, "is a symbolic link (optdesign does not follow links there)"
            ) from None
        if exc.errno in (errno.EISDIR, errno.ENXIO, errno.ENODEV, errno.EOPNOTSUPP):
            try:
                kind = _kind(os.lstat(path).st_mode)
            except OSError:
                kind = "a special file"
            raise _refuse(what, path, f"is {kind}, not a regular file") from None
        raise
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise _refuse(what, path, f"is {_kind(st.st_mode)}, not a regular file")
        if single_link and st.st_nlink > 1:
            raise _refuse(
                what,
                path,
                f"has {st.st_nlink} hard links (changing it would change another file too)",
            )
    except BaseException:
        os.close(fd)
        raise
    return fd


def read_file(
    path: Path | str, *, what: str = "the file", limit: int | None = None, follow: bool = False
) -> bytes | None:
    """The bytes of the regular file ``path``, or None if it does not exist.

    Refuses (see :func:`open_file`) a symbolic link or a file that is not regular, and
    a file larger than ``limit`` bytes, naming it.
    """
    path = Path(path)
    try:
        fd = open_file(path, os.O_RDONLY, what=what, follow=follow)
    except FileNotFoundError:
        return None
    try:
        size = os.fstat(fd).st_size
        if limit is not None and size > limit:
            reason = f"holds {size} bytes, more than the {limit} it may hold"
            raise UnsafeFileError(f"{what} {path} {reason}", path, reason)
        chunks, total = [], 0
        while True:  # a file growing while read is read up to the limit only
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if limit is not None and total > limit:
                reason = f"holds more than the {limit} bytes it may hold"
                raise UnsafeFileError(f"{what} {path} {reason}", path, reason)
        return b"".join(chunks)
    finally:
        os.close(fd)


#: Longest slug :func:`slug` returns (a file name must stay well under 255 bytes with the
#: command's prefix and the time stamp).
SLUG_MAX = 60


def slug(text: str, max_len: int = SLUG_MAX) -> str:
    """``text`` as a safe part of a file name: ASCII letters, digits, ``.``, ``_``, ``-``.

    No ``/``, no NUL or control character, never ``.`` or ``..`` nor a leading dot or
    dash, at most ``max_len`` characters. Accents are dropped (``Ölpumpe`` ->
    ``Olpumpe``); a name with nothing left (or cut short) keeps a short hash of the
    original, so that two different names stay two different folders.

    Examples
    --------
    >>> slug("cs_min_backlash")
    'cs_min_backlash'
    """
    text = str(text)
    ascii_text = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode()
    s = re.sub(r"[^A-Za-z0-9._-]+", "-", ascii_text)
    s = re.sub(r"\.{2,}", "-", s)  # "..": never a path step, even inside a name
    s = re.sub(r"[-.]*-[-.]*", "-", s).strip(".-")
    if s == text and 0 < len(s) <= max_len:
        return s
    digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:8]
    s = s[: max_len - len(digest) - 1].rstrip(".-")
    return f"{s}-{digest}" if s else f"problem-{digest}"


# --- solver options that touch files ------------------------------------------------------
#: Solver options that read or write a file, or load code, by name: refused wherever
#: they come from (a problem file's ``[solver] ipopt = {...}``, ``options=`` in Python),
#: at any depth of nested option tables. Ipopt's log is on the terminal with
#: ``print_level`` (stderr with ``--json``).
FILE_OPTIONS: dict[str, str] = {
    "output_file": "would write Ipopt's log to a file (and truncate any file of that name); "
    "print_level = 5 shows the log on the terminal",
    "file_print_level": "only sets the level of Ipopt's output_file, which is refused",
    "file_append": "only concerns Ipopt's output_file, which is refused",
    "option_file_name": "would read an Ipopt options file",
    "hsllib": "would load a shared library (code) from a file",
    "pardisolib": "would load a shared library (code) from a file",
    "ma77_file_size": "only concerns MA77's out-of-core files, which are refused",
    "dump": "would make CasADi write files into the working directory",
    "dump_in": "would make CasADi write files into the working directory",
    "dump_out": "would make CasADi write files into the working directory",
    "dump_dir": "would make CasADi write files into a folder",
    "dump_format": "only concerns CasADi's dump files, which are refused",
    "jit": "would make CasADi write C code, compile it and load it",
    "jit_name": "would make CasADi write C code, compile it and load it",
    "jit_options": "would make CasADi write C code, compile it and load it",
    "jit_serialize": "would make CasADi write C code, compile it and load it",
    "jit_cleanup": "only concerns CasADi's jit files, which are refused",
    "jit_temp_suffix": "only concerns CasADi's jit files, which are refused",
    "compiler": "would make CasADi compile C code and load it",
    "codegen_options": "only concerns CasADi's generated code, which is refused",
    "external_transform": "would make CasADi load a shared library (code)",
    "write_data_filename": "would make the conic solver write the problem to a file",
    "log_csv_filename": "would make the conic solver write its log to a file",
    "save_file": "would make the conic solver write the problem to a file",
}

#: Option values refused whatever the option: linear solvers that write files.
FILE_VALUES: dict[str, str] = {
    "ma77": "selects HSL_MA77, which writes its out-of-core files into the working directory",
}

#: A key that names a file, a folder, a path or a library (``*_file``, ``logdir``...).
_FILE_KEY = re.compile(r"(^|_)(file|filename|dir|directory|path|lib|library)s?(_|$)|(lib|dir)$")


def file_option_problem(options: object, field: str) -> tuple[str, str] | None:
    """The first solver option in ``options`` (nested tables and lists too) that would
    read or write a file or load code, as ``(field.path, reason)``; None if there is none.

    Refused: the options of :data:`FILE_OPTIONS`, any other whose name says it is about
    a file, a folder, a path or a library, the values of :data:`FILE_VALUES`, and any
    text value holding a path separator, a NUL or a control character.
    """
    if isinstance(options, Mapping):
        for key, value in options.items():
            where = f"{field}.{key}"
            name = str(key)
            if name in FILE_OPTIONS:
                return where, FILE_OPTIONS[name]
            if _FILE_KEY.search(name.lower()):
                return where, "is about a file, a folder or a library, which optdesign refuses"
            found = file_option_problem(value, where)
            if found:
                return found
    elif isinstance(options, list | tuple):
        for k, value in enumerate(options):
            found = file_option_problem(value, f"{field}[{k}]")
            if found:
                return found
    elif isinstance(options, str):
        if options.lower() in FILE_VALUES:
            return field, FILE_VALUES[options.lower()]
        if any(c in options for c in "/\\") or any(ord(c) < 32 or ord(c) == 127 for c in options):
            return field, f"looks like a path or holds control characters ({options[:60]!r})"
    return None


def refuse_file_options(options: object, field: str) -> None:
    """Raise :class:`~optdesign.errors.InputError` naming the first option of
    :func:`file_option_problem`: optdesign writes nothing outside its output folder."""
    from optdesign.errors import InputError

    found = file_option_problem(options, field)
    if found:
        where, reason = found
        raise InputError(where, f"refused: it {reason}")


def without_option_files(options: dict) -> dict:
    """A copy of CasADi ``options`` in which every Ipopt (the plugin's own ``ipopt``
    table, or one nested, e.g. an ``nlpsol = "ipopt"`` inside a QP solver's options)
    reads no options file: Ipopt reads ``ipopt.opt`` from the working directory by
    default, a file anyone able to write there could plant (``option_file_name = ""``
    turns that off)."""
    out = {k: without_option_files(v) if isinstance(v, dict) else v for k, v in options.items()}
    if isinstance(out.get("ipopt"), dict):
        out["ipopt"] = {**out["ipopt"], "option_file_name": ""}
    if out.get("nlpsol") == "ipopt":
        nested = dict(out.get("nlpsol_options") or {})
        nested["ipopt"] = {**(nested.get("ipopt") or {}), "option_file_name": ""}
        out["nlpsol_options"] = nested
    return out
