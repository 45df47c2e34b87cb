"""A user's own code - an objective, a constraint, a mechanism's method - that fails,
reported as such.

optdesign calls a user's functions while it builds a solver's model (on CasADi
symbols), evaluates a design (on NumPy arrays) or traces the GP form. When one raises,
or returns what no formulation can use (None, a string, NaN where only a constant could
be, an array of the wrong shape), the error names the function (its name and qualified
name) or the mechanism class and method, says what optdesign was doing, and points at
the user's own file and line; the original exception is chained (``raise ... from
exc``). It is an :class:`~optdesign.errors.OptDesignError`, so the command line prints
one line (``OPTDESIGN_DEBUG=1`` adds the traceback down to that line). Errors of
optdesign's own code are not wrapped: they stay internal errors.
"""

from __future__ import annotations

import inspect
import os
import re
import sys
import sysconfig
import traceback
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from optdesign.errors import OptDesignError


@dataclass(frozen=True)
class Location:
    """Where in a user's file: the file, the line and the function's qualified name."""

    file: str
    line: int
    function: str = ""

    def __str__(self) -> str:
        return f"{self.file}:{self.line}"


class UserCodeError(OptDesignError):
    """A user's function or mechanism method raised, or returned an unusable value.

    Attributes
    ----------
    subject
        What failed, as a user declared it: ``objective 'peak'``, ``mechanism 'yoke'``.
    location
        The user's file and line (None when unknown).
    """

    def __init__(self, message: str, subject: str = "", location: Location | None = None):
        self.subject = subject
        self.location = location
        super().__init__(message)

    def __reduce__(self):  # raised in a worker process, re-raised in the caller
        return (type(self), (str(self), self.subject, self.location))


@lru_cache(maxsize=1)
def _library_dirs() -> tuple[str, ...]:
    """Folders whose code is not the user's: optdesign itself, the standard library and
    the installed packages (numpy, CasADi ...)."""
    dirs = {str(Path(__file__).resolve().parent)}
    for key in ("stdlib", "platstdlib", "purelib", "platlib"):
        with_key = sysconfig.get_paths().get(key)
        if with_key:
            dirs.add(str(Path(with_key).resolve()))
    return tuple(sorted(dirs))


def is_library_file(filename: str) -> bool:
    """True for a file of optdesign, the standard library or an installed package."""
    if filename.startswith("<frozen "):
        return True
    try:
        full = str(Path(filename).resolve())
    except (OSError, ValueError):
        return False
    return any(full == d or full.startswith(d + os.sep) for d in _library_dirs())


def is_users(obj: Any) -> bool:
    """True for a function or class written outside optdesign (a user's, a plug-in's)."""
    module = getattr(obj, "__module__", None) or ""
    return not (module == "optdesign" or module.startswith("optdesign."))


def location_in(exc: BaseException) -> Location | None:
    """The last frame of ``exc``'s traceback in a user's file (outside optdesign, the
    standard library and the installed packages), else the last outside optdesign."""
    frames = [
        (f.f_code.co_filename, line, f.f_code.co_qualname)
        for f, line in traceback.walk_tb(exc.__traceback__)
    ]
    ours = str(Path(__file__).resolve().parent)
    for keep in (lambda f: not is_library_file(f), lambda f: not f.startswith(ours)):
        for file, line, qualname in reversed(frames):
            if keep(file):
                return Location(file, line or 0, qualname)
    return None


def location_of(obj: Any) -> Location | None:
    """Where a function (or a class, or a callable object) is defined."""
    target = getattr(obj, "func", obj)  # functools.partial
    code = getattr(target, "__code__", None)
    if code is None and not inspect.isclass(target):
        call = inspect.getattr_static(type(target), "__call__", None)  # a callable object
        code = getattr(call, "__code__", None)
    if code is not None:
        return Location(code.co_filename, code.co_firstlineno, code.co_qualname)
    try:
        file = inspect.getsourcefile(target) or inspect.getfile(target)
        line = inspect.getsourcelines(target)[1]
    except (OSError, TypeError):
        return None
    return Location(file, line, getattr(target, "__qualname__", ""))


def describe_function(fn: Any) -> str:
    """``name (module.qualified.name)`` of a user's function."""
    target = getattr(fn, "func", fn)
    name = getattr(target, "__name__", None) or type(target).__name__
    qual = getattr(target, "__qualname__", None) or name
    module = getattr(target, "__module__", None)
    full = f"{module}.{qual}" if module else qual
    return f"{name} ({full})"


_BUILDING = "while building the solver's model"


def stage(values: Any) -> str:
    """What optdesign is doing with values like ``values`` (a design's): building the
    solver's model (CasADi), tracing the GP form (signomial tracers) or evaluating."""
    from optdesign import math as m

    items = list(values.values()) if isinstance(values, Mapping) else list(values)
    if any(m.is_symbolic(v) for v in items):
        return _BUILDING
    if any(type(v).__name__ in ("Signomial", "NotGP") for v in items):
        return "while tracing the GP form"
    return "while evaluating a design"


#: CasADi's own source location at the head of its messages (".../casadi/core/x.cpp:166: ")
_CASADI_SOURCE = re.compile(r"(?:\.\.\./|/)?casadi/core/[\w/]+\.(?:cpp|hpp):\d+:\s*")


def _exception_text(exc: BaseException) -> str:
    text = _CASADI_SOURCE.sub("", " ".join(str(exc).split()))
    if "not iterable by design" in text:  # CasADi's own text goes on about m.nz
        text = "CasADi matrices are not iterable"
    return text if len(text) <= 300 else text[:297] + "..."


def hint(exc: BaseException) -> str:
    """What to write instead, for the mistakes that CasADi symbols make visible."""
    text = str(exc)
    if "not iterable" in text or "has no len()" in text:
        return (
            "; the quantities are CasADi expressions while the model is built: use "
            "od.math.grid_max / grid_min / grid_sum over the stroke and od.math.fmax / "
            "fmin of two values, not Python's max, min, sum or a loop"
        )
    if "__round__" in text:
        return (
            "; the quantities are arrays over the stroke (CasADi expressions while the model"
            " is built): Python's round() does not apply to them, and a rounded value gives"
            " the solver no gradient"
        )
    if "bad operand type for abs()" in text:
        return (
            "; the quantities are CasADi expressions while the model is built, and this "
            "CasADi release has no abs() for them: use od.math.fabs"
        )
    if "truth value" in text:
        return (
            "; a CasADi expression has no truth value: use od.math.where(cond, a, b) or "
            "od.math.fmax / fmin instead of if, and, or"
        )
    return ""


def raised(subject: str, who: str, exc: Exception, doing: str, fallback: Any = None):
    """The :class:`UserCodeError` for ``exc`` raised by the user's ``who``."""
    where = location_in(exc) or (location_of(fallback) if fallback is not None else None)
    message = f"{subject}: {who} raised {type(exc).__name__}: {_exception_text(exc)}"
    message += (f" at {where}" if where else "") + (f", {doing}" if doing else "") + hint(exc)
    return UserCodeError(message, subject, where)


def returned(
    subject: str,
    who: str,
    fn: Any,
    reason: str,
    doing: str,
    advice: str,
    at: Location | None = None,
) -> UserCodeError:
    """The :class:`UserCodeError` for an unusable value returned by ``fn`` (``at``: the
    line of the ``return`` that gave it, when known)."""
    where = location_of(fn)
    message = f"{subject}: {who}" + (f" (defined at {where})" if where else "") + f" {reason}"
    if at is not None:
        message += f" at {at}"
        where = at
    message += (f" {doing}" if doing else "") + f"; {advice}"
    return UserCodeError(message, subject, where)


def return_line(fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Location | None:
    """The line of the ``return`` of ``fn`` (the user's own code object) when called with
    these arguments again, found by a profile hook: an unusable value has no traceback to
    point at. Only on the error path; the call's own failure (a second run may differ)
    gives None."""
    target = getattr(fn, "__func__", getattr(fn, "func", fn))
    code = getattr(target, "__code__", None)
    if code is None:
        return None
    seen: list[int] = []

    def hook(frame: Any, event: str, arg: Any) -> None:
        if event == "return" and frame.f_code is code:
            seen.append(frame.f_lineno)

    previous = sys.getprofile()
    sys.setprofile(hook)
    try:
        fn(*args, **kwargs)
    except Exception:
        return None
    finally:
        sys.setprofile(previous)
    if not seen:
        return None
    return Location(code.co_filename, seen[-1], code.co_qualname)


def unusable(value: Any) -> str:
    """Why ``value`` cannot be a quantity (empty when it can): None, text, a bool, a
    dict, an array of non-numbers."""
    from optdesign import math as m

    if m.is_symbolic(value) or type(value).__name__ in ("Signomial", "NotGP"):
        return ""
    if value is None:
        return "returned None"
    if isinstance(value, str | bytes | bool | np.bool_ | Mapping):
        return f"returned a {type(value).__name__} ({_short(value)})"
    try:
        array = np.asarray(value)
    except Exception:
        return f"returned a {type(value).__name__}"
    if array.dtype.kind not in "iuf":
        return f"returned a {type(value).__name__} of {array.dtype} values"
    return ""


def wrong_shape(value: Any, n_phi: int, per_angle: bool, design: Mapping[str, Any]) -> str:
    """Why ``value`` has the wrong size for one design's quantity (empty when it has the
    right one): one value, or one per grid angle when ``per_angle``. Checked on CasADi
    expressions and on one numeric design (a population's shapes are the caller's)."""
    from optdesign import math as m

    if m.is_symbolic(value):
        size = int(value.numel())
    elif type(value).__name__ in ("Signomial", "NotGP") or any(
        np.ndim(v) > 0 for v in design.values() if not m.is_symbolic(v)
    ):
        return ""
    else:
        array = np.asarray(value)
        if array.ndim > 2 or (array.ndim == 2 and array.shape[0] != 1):
            return f"returned an array of shape {array.shape}"
        size = int(array.size)
    allowed = (1, n_phi) if per_angle else (1,)
    if size in allowed:
        return ""
    expected = f"one value or one per grid angle ({n_phi})" if per_angle else "one value"
    return f"returned {size} values (expected {expected})"


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def call_function(fn: Callable[[Any], Any], q: Any, subject: str, doing: str | None = None) -> Any:
    """``fn(q)``: a user's objective or constraint function; its failure (an exception,
    or a value no formulation can use) as a :class:`UserCodeError`."""
    doing = doing or stage(q.design)
    who = f"its function {describe_function(fn)}"
    try:
        value = fn(q)
    except OptDesignError:
        raise
    except Exception as exc:
        raise raised(subject, who, exc, doing, fn) from exc
    reason = unusable(value)
    if reason:
        advice = "return a number or an expression of q"
        raise returned(subject, who, fn, reason, doing, advice, return_line(fn, q))
    return value


def call_method(mechanism: Any, method: str, *args: Any, doing: str = "", **kwargs: Any) -> Any:
    """``mechanism.method(*args, **kwargs)`` (``mechanism`` an instance, or a class for
    its construction with ``method="__init__"``); a user's mechanism that fails -
    raises, or returns None or text for a quantity - gives a :class:`UserCodeError`
    naming its class and method. The built-in mechanisms' errors pass unchanged
    (internal errors). Every mechanism's method runs with NumPy's invalid-value and
    divide-by-zero warnings off: its NaN is reported, not warned about."""
    cls = mechanism if inspect.isclass(mechanism) else type(mechanism)
    fn = cls if method == "__init__" else getattr(mechanism, method)
    # On the NumPy path a linkage that does not assemble at some design or angle gives
    # NaN (a root of a negative, a division by zero): that is its answer, which the
    # checks report ("cannot assemble", not verified), so NumPy's RuntimeWarning is not
    # printed. CasADi is not affected.
    quiet = np.errstate(invalid="ignore", divide="ignore")
    if not is_users(cls):
        with quiet:
            return fn(*args, **kwargs)
    try:
        with quiet:
            value = fn(*args, **kwargs)
    except OptDesignError:
        raise
    except Exception as exc:
        where = location_in(exc)
        who = where.function if where and where.function else f"{cls.__name__}.{method}"
        raise raised(mechanism_subject(cls), who, exc, doing, getattr(cls, method, cls)) from exc
    if method in _VALUE_METHODS:
        reason = unusable(value)
        if reason:
            raise returned(
                mechanism_subject(cls),
                f"{cls.__name__}.{method}",
                getattr(cls, method),
                reason,
                doing,
                "return a number or an expression of phi (optdesign.math)",
                return_line(fn, *args, **kwargs),
            )
    return value


def quantity_of(
    fn: Callable[[Any], Any], q: Any, subject: str, per_angle: bool, doing: str | None = None
) -> Any:
    """``fn(q)`` checked as a quantity (see :func:`call_function`) of the right size
    (one value, or one per grid angle when ``per_angle``) and, on the solver's path,
    not a constant NaN (what Python's math functions and float() make of a CasADi
    expression)."""
    from optdesign import math as m

    doing = doing or q.doing
    value = call_function(fn, q, subject, doing)
    reason = wrong_shape(value, len(q.phi), per_angle, q.design)
    advice = "return one value" + (" or one per grid angle" if per_angle else " per design")
    if not reason and not m.is_symbolic(value) and q.doing == _BUILDING:
        with np.errstate(invalid="ignore"):
            if np.isnan(np.asarray(value, dtype=float)).any():
                reason = "returned NaN, a constant"
                advice = (
                    "Python's math functions and float() turn a CasADi expression into "
                    "NaN: write the function with optdesign.math"
                )
    if reason:
        who = f"its function {describe_function(fn)}"
        raise returned(subject, who, fn, reason, doing, advice, return_line(fn, q))
    return value


#: Mechanism methods that return a quantity (a number, an array or an expression).
_VALUE_METHODS = frozenset(
    {"nut_position", "nut_velocity", "ratio", "nut_travel", "nut_force", "motor_torque"}
    | {"pin_force", "size", "sensitivity_axial"}
)


def mechanism_subject(cls: type) -> str:
    """``mechanism 'key' (class module.Name at file:line)``."""
    return f"mechanism {getattr(cls, 'name', '') or cls.__name__!r} ({describe_class(cls)})"


def describe_class(cls: type) -> str:
    """``class module.Qualified`` with its file and line when known."""
    where = location_of(cls)
    at = f" at {where}" if where else ""
    return f"class {cls.__module__}.{cls.__qualname__}{at}"


__all__ = [
    "Location",
    "UserCodeError",
    "call_function",
    "call_method",
    "describe_function",
    "is_users",
    "location_in",
    "location_of",
    "quantity_of",
    "stage",
    "unusable",
]
