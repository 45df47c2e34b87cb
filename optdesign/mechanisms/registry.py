"""The mechanism registry: name -> plug-in class.

Built-in mechanisms register on import of :mod:`optdesign.mechanisms`; a notebook or
script registers its own with :func:`register_mechanism`; a separate package adds one
through the entry-point group ``optdesign.mechanisms`` (``name = "pkg.module:Class"`` in
its ``pyproject.toml`` under ``[project.entry-points."optdesign.mechanisms"]``), loaded
the first time a name is not found. Problem files name a mechanism by its key; the
problem schema (variables, requirements, clearances) is derived from the class.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, TypeVar, overload

from optdesign.errors import InputError

if TYPE_CHECKING:
    from optdesign.mechanisms.base import Mechanism

ENTRY_POINT_GROUP = "optdesign.mechanisms"

_REGISTRY: dict[str, type[Mechanism]] = {}
_ENTRY_POINTS_LOADED = False

M = TypeVar("M", bound="type[Mechanism]")


@overload
def register_mechanism(cls: M, /) -> M: ...
@overload
def register_mechanism(
    name: str | None = None, /, *, replace: bool = False
) -> Callable[[M], M]: ...


def register_mechanism(arg=None, /, *, replace: bool = False):
    """Register a :class:`~optdesign.mechanisms.Mechanism` subclass under its ``name``.

    Use as ``@register_mechanism`` (the key is the class's ``name``), as
    ``@register_mechanism("key")``, or call ``register_mechanism(Cls)``. Registering a
    name twice replaces the first class only with ``replace=True`` (or when it is the
    same class, e.g. a module reloaded in a notebook).
    """

    def add(cls, key: str | None):
        from optdesign.mechanisms.base import Mechanism

        if not (isinstance(cls, type) and issubclass(cls, Mechanism)):
            raise InputError("register_mechanism", f"{cls!r} is not a Mechanism subclass")
        key = key or cls.name
        if not key or not isinstance(key, str):
            raise InputError("mechanism", f"{cls.__name__} has no name; set name = '...'")
        if key != cls.name:
            cls.name = key
        old = _REGISTRY.get(key)
        if (
            old is not None
            and old is not cls
            and not replace
            and old.__qualname__ != cls.__qualname__
        ):
            raise InputError(
                "mechanism",
                f"{key!r} is registered already ({old.__module__}.{old.__qualname__}); "
                "pass replace=True to replace it",
            )
        _check_declarations(cls, key)  # now, not at first use
        _REGISTRY[key] = cls
        return cls

    if isinstance(arg, type):
        return add(arg, None)
    if arg is not None and not isinstance(arg, str):
        raise InputError("register_mechanism", f"{arg!r} is not a Mechanism subclass (or a name)")

    def deco(cls):
        return add(cls, arg)

    return deco


def _check_declarations(cls: type[Mechanism], key: str) -> None:
    """The class's variables are valid declarations and it writes nut_position; a
    refusal names the class and points at its file and line."""
    from optdesign.mechanisms.base import Mechanism
    from optdesign.user_code import UserCodeError, describe_class

    subject = f"mechanism {key!r} ({describe_class(cls)})"  # cls.name is set after the checks
    try:
        cls.variable_table()
    except Exception as exc:
        raise UserCodeError(
            f"{subject}: its variables: {type(exc).__name__}: {exc}", subject
        ) from exc
    if cls.nut_position is Mechanism.nut_position:
        raise UserCodeError(f"{subject}: define nut_position(self, phi)", subject)
    pins = cls.pin_joints
    if pins is None and cls.joints is Mechanism.joints:
        # The default chain would have to guess where the pins are and what loads them;
        # a wrong guess is a silently wrong backlash, so the class says it.
        raise UserCodeError(
            f"{subject}: its pins are undeclared: set pin_joints = ('crank pin',) for "
            "pins on the screw's line of action carrying the nut force (a Scotch yoke's), "
            "pin_joints = () for none, or write joints(self, phi, M_h, pin) "
            "(docs/mechanisms.md)",
            subject,
        )
    if pins is not None and (
        not isinstance(pins, tuple)
        or not all(isinstance(n, str) and n.strip() for n in pins)
        or len(set(pins)) != len(pins)
    ):
        raise UserCodeError(
            f"{subject}: pin_joints must be a tuple of distinct names, got {pins!r}", subject
        )


def _load_entry_points() -> None:
    global _ENTRY_POINTS_LOADED
    if _ENTRY_POINTS_LOADED:
        return
    _ENTRY_POINTS_LOADED = True
    # Imported here: importlib.metadata (with the email package) is a measurable part of
    # the CLI's start-up, and a shipped mechanism never needs it.
    from importlib.metadata import entry_points

    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name in _REGISTRY:
            continue
        try:
            cls = ep.load()
        except Exception as exc:  # a broken plug-in must not break the others
            raise InputError(
                "mechanism", f"plug-in {ep.name!r} ({ep.value}) failed to load: {exc}"
            ) from None
        register_mechanism(ep.name)(cls)


def get_mechanism(name: str) -> type[Mechanism]:
    """The class registered as ``name``; InputError listing the registered ones if none.

    The built-ins are registered already: importing this module runs the package's
    ``__init__`` first, which imports them (and they register on import)."""
    cls = _REGISTRY.get(name)
    if cls is None:
        _load_entry_points()
        cls = _REGISTRY.get(name)
    if cls is None:
        from difflib import get_close_matches

        known = registered()
        close = get_close_matches(str(name), known, n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise InputError(
            "mechanism",
            f"unknown mechanism {name!r} (registered: {', '.join(known)}); {hint}a mechanism "
            "of your own is registered by @od.register_mechanism(NAME) on its class, in "
            f"Python, or by an entry point of the group {ENTRY_POINT_GROUP!r} in its "
            "package's pyproject.toml (docs/mechanisms.md)",
        )
    return cls


def registered() -> list[str]:
    """Names of the registered mechanisms (entry points included)."""
    _load_entry_points()
    return list(_REGISTRY)
