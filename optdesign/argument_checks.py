"""The checks of one argument, shared by every layer: its type (``True`` is not an
integer, nor is ``2.5``; NumPy integers are), its range (the caps below, the same as the
command line's) and a name with the nearest valid one. A refusal is an
:class:`ArgumentError` (an :class:`~optdesign.errors.InputError`) naming the argument:
``starts: 0 is outside 1..10000``.

The checks that know the registered formulations, solvers, methods and suites, and the
entry points' argument sets, are :mod:`optdesign.validation` (the API's layer); this
module knows nothing above the errors and the unit grammar, so the problem layer (the
loader, ``add_objective``) uses it without importing the studies.
"""

from __future__ import annotations

import difflib
import numbers
import os
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

from optdesign.errors import InputError

#: Caps of the sizes (a front of 10^7 points or 10^9 starts is a typo, not a study).
MAX_WORKERS = 256
MAX_STARTS = 10_000
MAX_POINTS = 10_000
#: Points of a front when the caller gives none (od.pareto, the command line, the bench).
DEFAULT_FRONT_POINTS = 50
MAX_SEED = 2**32 - 1
MAX_POP = 100_000
MAX_GENERATIONS = 100_000
#: Longest time limit (s) of a benchmark run: a day.
MAX_SECONDS = 86_400.0
#: Longest name of an objective or a constraint (it becomes a column header).
MAX_NAME = 64


class ArgumentError(InputError):
    """An argument of a public entry point refused before any work.

    ``argument`` is the API's name of the argument; ``reason`` may name other arguments
    as ``{name}`` for each ``name`` in ``mentions``, so that the command line can show
    them as its options (:meth:`render`).
    """

    def __init__(self, argument: str, reason: str, mentions: Sequence[str] = ()):
        self.argument = argument
        self.template = reason
        self.mentions = tuple(mentions)
        super().__init__(argument, self.render(str))

    def render(self, name: Callable[[str], str]) -> str:
        """The reason with every mentioned argument shown as ``name(argument)``."""
        text = self.template
        for other in self.mentions:
            text = text.replace("{" + other + "}", name(other))
        return text

    def __reduce__(self):  # raised in a worker process, re-raised in the caller
        return (type(self), (self.argument, self.template, self.mentions))


# --- values -----------------------------------------------------------------------------
def shown(value: Any, limit: int = 60) -> str:
    """``repr(value)`` short enough for a one-line message."""
    if isinstance(value, int) and not isinstance(value, bool):
        digits = len(str(abs(value))) if abs(value) < 10**100 else 101
        if digits > 20:
            return f"an integer of {'more than 100' if digits > 100 else digits} digits"
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def is_integer(value: Any) -> bool:
    """An int or a NumPy integer; not a bool, not a float with an integer value."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool | _np_bool())


def is_number(value: Any) -> bool:
    """A real number (int, float, NumPy scalar); not a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool | _np_bool())


def _np_bool() -> type:
    import numpy as np

    return np.bool_


def integer(argument: str, value: Any, lo: int, hi: int, *, optional: bool = False) -> int | None:
    """``value`` as an int with ``lo <= value <= hi`` (None passes when ``optional``)."""
    if value is None and optional:
        return None
    if not is_integer(value):
        raise ArgumentError(argument, f"{shown(value)} is not an integer")
    value = int(value)
    if not lo <= value <= hi:
        raise ArgumentError(argument, f"{shown(value)} is outside {lo}..{hi}")
    return value


def number(
    argument: str, value: Any, lo: float, hi: float, *, optional: bool = False
) -> float | None:
    """``value`` as a finite float with ``lo < value <= hi`` (None passes when
    ``optional``)."""
    if value is None and optional:
        return None
    if not is_number(value):
        raise ArgumentError(argument, f"{shown(value)} is not a number")
    try:
        number_ = float(value)
    except OverflowError:  # an int of hundreds of digits
        raise ArgumentError(argument, f"{shown(value)} is outside ({lo:g}, {hi:g}]") from None
    if not lo < number_ <= hi:  # also refuses nan
        raise ArgumentError(argument, f"{number_:g} is outside ({lo:g}, {hi:g}]")
    return number_


def flag(argument: str, value: Any) -> bool:
    """``value`` as a bool: True or False (a NumPy bool too), nothing else."""
    if isinstance(value, bool | _np_bool()):
        return bool(value)
    raise ArgumentError(argument, f"{shown(value)} is not True or False")


def text(argument: str, value: Any, *, optional: bool = False) -> str | None:
    """A string (None passes when ``optional``)."""
    if value is None and optional:
        return None
    if not isinstance(value, str):
        raise ArgumentError(argument, f"expected a string, got {shown(value)}")
    return value


def nearest(value: str, known: Iterable[str]) -> str:
    """``"did you mean 'x'? "`` for the closest of ``known``, or ``""``."""
    close = difflib.get_close_matches(value, list(known), n=1, cutoff=0.6)
    return f"did you mean {close[0]!r}? " if close else ""


def choice(
    argument: str, value: Any, known: Iterable[str], what: str = "", *, optional: bool = False
) -> str | None:
    """One of ``known``; the refusal names the nearest (``what``: the kind of name,
    default the argument)."""
    if value is None and optional:
        return None
    known = list(known)
    what = what or argument
    if not isinstance(value, str):
        raise ArgumentError(
            argument,
            f"expected the name of a {what}, got {shown(value)} (known: {', '.join(known)})",
        )
    if value not in known:
        raise ArgumentError(
            argument,
            f"unknown {what} {shown(value)} ({nearest(value, known)}known: {', '.join(known)})",
        )
    return value


_NAME = re.compile(r"[^\W\d]\w*")


def name(argument: str, value: Any) -> str:
    """A name that can be a column header, a JSON key and part of a file name: letters,
    digits and underscores, not starting with a digit, at most :data:`MAX_NAME` long."""
    if not isinstance(value, str):
        raise ArgumentError(argument, f"expected a name (a string), got {shown(value)}")
    if not (_NAME.fullmatch(value) and len(value) <= MAX_NAME):
        raise ArgumentError(
            argument,
            f"{shown(value)} is not a name: use letters, digits and underscores, not "
            f"starting with a digit, at most {MAX_NAME} characters (it becomes a column "
            "header, a JSON key and a file label)",
        )
    return value


def names(argument: str, value: Any) -> list[str]:
    """A list of names: a sequence of strings, or one string of comma-separated names
    (the command line's form)."""
    if isinstance(value, str):
        return [s.strip() for s in value.split(",") if s.strip()]
    if isinstance(value, Mapping) or not isinstance(value, Iterable):
        raise ArgumentError(argument, f"expected a list of names, got {shown(value)}")
    items = list(value)
    for item in items:
        if not isinstance(item, str):
            raise ArgumentError(argument, f"expected names (strings), got {shown(item)}")
    return items


def path(argument: str, value: Any, *, optional: bool = False):
    """A file system path (str or os.PathLike; None passes when ``optional``)."""
    from pathlib import Path

    if value is None and optional:
        return None
    if not isinstance(value, str | os.PathLike) or isinstance(value, bytes):
        raise ArgumentError(argument, f"expected a folder or file path, got {shown(value)}")
    text_ = os.fspath(value)
    if not isinstance(text_, str) or not text_ or "\x00" in text_:
        raise ArgumentError(argument, f"{shown(value)} is not a usable path")
    return Path(text_)


def function(argument: str, value: Any, *, optional: bool = False):
    """A callable (None passes when ``optional``)."""
    if value is None and optional:
        return None
    if not callable(value):
        raise ArgumentError(argument, f"expected a function, got {shown(value)}")
    return value


def unit(argument: str, value: Any) -> str:
    """A unit expression of the restricted grammar of :mod:`optdesign.units` ("" for a
    dimensionless value)."""
    value = text(argument, value)
    if value.strip():
        from optdesign.units import parse_quantity

        try:
            parse_quantity(f"1 {value}")
        except InputError as exc:
            detail = re.sub(r"^cannot read .* as a quantity: ", "", exc.reason)
            detail = re.sub(r" \(write a number and a unit.*\)$", "", detail)
            raise ArgumentError(argument, f"{shown(value)} is not a unit ({detail})") from None
    return value


# --- the arguments (one check each, the API's and the command line's) -----------------
def starts(argument: str, value: Any) -> int | None:
    """Multistart size (None: the problem file's)."""
    return integer(argument, value, 1, MAX_STARTS, optional=True)


def seed(argument: str, value: Any) -> int | None:
    """Sobol / random seed (None: the problem file's)."""
    return integer(argument, value, 0, MAX_SEED, optional=True)


def workers(argument: str, value: Any) -> int:
    """Local processes."""
    return integer(argument, value, 1, MAX_WORKERS)


def agree(argument: str, value: Any) -> int | None:
    """Starts that must agree before a multistart stops (0: all run; None: the file's)."""
    return integer(argument, value, 0, MAX_STARTS, optional=True)


def points(argument: str, value: Any) -> int:
    """Points of a front."""
    return integer(argument, value, 2, MAX_POINTS)


def pop_size(argument: str, value: Any) -> int:
    """NSGA-II population."""
    return integer(argument, value, 4, MAX_POP)


def generations(argument: str, value: Any) -> int:
    """NSGA-II generations."""
    return integer(argument, value, 1, MAX_GENERATIONS)


def odds(argument: str, value: Any) -> float | None:
    """A probability the global search may stop at, in (0, 0.5] (None: the default)."""
    return number(argument, value, 0.0, 0.5, optional=True)


def seconds(argument: str, value: Any) -> float | None:
    """A time limit in seconds, at most a day (None: the default)."""
    return number(argument, value, 0.0, MAX_SECONDS, optional=True)


#: Transports of a Dask scheduler's address (those distributed registers; ``inproc``: a
#: scheduler inside this process, ``inproc://HOST/PID/N``).
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx", "inproc")
_HOST = re.compile(r"[A-Za-z0-9](?:[A-Za-z0-9._-]*[A-Za-z0-9])?|\[[0-9A-Fa-f:.]+(?:%\w+)?\]")
_INPROC = re.compile(r"[^\s/]+/\d+/\d+")


def scheduler(argument: str, value: Any) -> Any:
    """A Dask distributed scheduler: its address ``SCHEME://HOST:PORT`` (``HOST:PORT``
    is ``tcp://HOST:PORT``, as distributed reads it; an IPv6 host in brackets; an
    in-process scheduler's ``inproc://HOST/PID/N``) or, from Python, a
    ``distributed.Client``; None: local processes. Only the form is checked
    here; a scheduler that does not answer is refused when the run connects to it
    (:func:`optdesign.runtime.runner.run_tasks`)."""
    if value is None:
        return None
    if not isinstance(value, str):
        if hasattr(value, "submit") or hasattr(value, "scheduler_address"):  # a Client
            return value  # (or a cluster, which the run makes its Client of)
        raise ArgumentError(
            argument,
            f"expected a scheduler's address (e.g. 'tcp://127.0.0.1:8786') or a "
            f"distributed.Client, got {shown(value)}",
        )
    form = "write SCHEME://HOST:PORT, e.g. tcp://127.0.0.1:8786"
    scheme, sep, rest = value.partition("://")
    if not sep:
        scheme, rest = "tcp", value
    if scheme not in SCHEDULER_SCHEMES:
        raise ArgumentError(
            argument,
            f"{shown(value)} is not a scheduler's address: unknown transport {shown(scheme)} "
            f"(known: {', '.join(SCHEDULER_SCHEMES)}; {form})",
        )
    if scheme == "inproc":
        if not _INPROC.fullmatch(rest):
            raise ArgumentError(
                argument,
                f"{shown(value)} is not a scheduler's address: an in-process scheduler's is "
                "inproc://HOST/PID/N (its Client's scheduler.address)",
            )
        return value
    host, colon, port = rest.rpartition(":")
    if not colon or not port.isascii() or not port.isdigit() or not 1 <= int(port) <= 65535:
        raise ArgumentError(
            argument, f"{shown(value)} is not a scheduler's address: no port 1..65535 ({form})"
        )
    if not _HOST.fullmatch(host):
        raise ArgumentError(
            argument,
            f"{shown(value)} is not a scheduler's address: {shown(host)} is not a host name "
            f"({form})",
        )
    return value
