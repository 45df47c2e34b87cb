"""A sweep's grid: the swept parameters (:class:`Axis`), checked against the problem -
each path names a requirement or a variable's bound, each range has the parameter's
dimension, the grid stays within its caps - the parameters linked to them (which move
with a swept one, :func:`point_settings`) and the order in which its points are visited.
:mod:`optdesign.studies.sweep` solves the points."""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from optdesign.errors import InputError, OptDesignError
from optdesign.problem.design_problem import SETTING_SECTIONS, DesignProblem
from optdesign.problem.parameters import at_values, linked_values

#: Most parameters of one sweep, and most points along one parameter.
MAX_AXES = 2
MAX_POINTS = 1000
#: Most points of a sweep's grid (the product of its axes' counts). Every point gets its
#: own global search (about 1 to 2 s on the shipped problems) and then its polish
#: rounds' warm starts, so 2 500 points are an hour or two on one process, and 50 x 50
#: is finer than a design chart shows; a 1000 x 1000 grid (a typo, or a count meant for
#: one axis) would be weeks. One axis keeps its MAX_POINTS.
MAX_GRID = 2500


@dataclass(frozen=True)
class Axis:
    """One swept parameter.

    Attributes
    ----------
    path
        Where the file states it: ``"requirements.hinge_moment"``,
        ``"requirements.mean_ratio.min"``, ``"variables.R.upper"``, ``"variables.i_a"``.
    values
        The values, internal units.
    unit, shown
        The unit the values are shown in and the values in it.
    linked
        The paths that move with this one: at every point each is set to the same value
        (``("loop.bandwidth",)`` on ``requirements.bandwidth_min``: the loop's gains are
        placed for the bandwidth the requirement asks).
    """

    path: str
    values: tuple[float, ...]
    unit: str
    shown: tuple[float, ...]
    linked: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        name = self.path.split(".", 1)[1] if "." in self.path else self.path
        return f"{name} [{self.unit}]" if self.unit else name


#: What a sweep may vary, as its refusals say it.
WHAT_TO_VARY = (
    "requirements.NAME, motion.NAME, load.NAME, loop.NAME or variables.NAME[.lower|.upper]"
)


def check_path_names(path: str) -> None:
    """InputError ``vary`` when a name of the dotted ``path`` is empty: a dot at its start
    or its end, or two dots in a row (``requirements.hinge_moment.``)."""
    names = path.split(".")
    empty = next((k for k, name in enumerate(names) if not name.strip()), None)
    if empty is None:
        return
    if empty == 0:
        at = "before its first dot" if len(names) > 1 else "(no name at all)"
    elif empty == len(names) - 1:
        at = "after its last dot"
    else:
        at = f"between two dots (after {'.'.join(names[:empty])})"
    raise InputError(
        "vary",
        f"{path!r}: an empty name {at}; give {WHAT_TO_VARY}",
    )


def parameter_dimension(problem: DesignProblem, path: str) -> str:
    """The dimension of the parameter at ``path`` (InputError ``vary`` when unknown)."""
    from optdesign.display.shown import _dimension

    check_path_names(path)
    head, _, rest = path.partition(".")
    if head == "variables":
        name, _, side = rest.partition(".")
        var = problem.by_name.get(name)
        if var is None:
            raise InputError("vary", f"{path}: no variable {name!r} ({_known(problem)})")
        if var.discrete:
            raise InputError("vary", f"{path}: {name} takes catalogue values; sweep a requirement")
        if side not in (("lower", "upper") if var.free else ("",)):
            want = f"{name}.lower or {name}.upper" if var.free else name
            raise InputError(
                "vary",
                f"{path}: {name} is {'free' if var.free else 'fixed'}: sweep variables.{want}",
            )
        return var.dimension
    if head not in SETTING_SECTIONS or not rest:
        raise InputError("vary", f"{path!r}: give {WHAT_TO_VARY}")
    model: Any = getattr(problem.spec, head)
    if model is None:
        raise InputError("vary", f"{path}: the problem has no [{head}] section")
    what = "requirement" if head == "requirements" else f"field of [{head}]"
    keys = rest.split(".")
    for depth, key in enumerate(keys):
        fields = type(model).model_fields
        if key not in fields:
            close = difflib.get_close_matches(key, list(fields), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise InputError("vary", f"{path}: unknown {what}{hint}")
        value = getattr(model, key)
        if depth < len(keys) - 1:
            if value is None:
                raise InputError("vary", f"{path}: {head}.{key} is not set in the problem")
            if not hasattr(type(value), "model_fields"):
                inner = ".".join(keys[: depth + 1])
                raise InputError("vary", f"{path}: {head}.{inner} is a value, not a table")
            model = value
            continue
        info = fields[key]
        if hasattr(type(value), "model_fields"):
            raise InputError(
                "vary",
                f"{path}: a table; sweep one of its numbers "
                f"({', '.join(type(value).model_fields)})",
            )
        if not isinstance(value, float) and not (value is None and _numeric(info)):
            raise InputError("vary", f"{path}: not a number (a {type(value).__name__})")
        return _dimension(info) or "dimensionless"
    raise AssertionError("unreachable")


def _numeric(info: Any) -> bool:
    import typing

    stack, seen = [info.annotation], []
    while stack:
        t = stack.pop()
        seen.append(t)
        stack += list(typing.get_args(t))
    return float in seen


def _known(problem: DesignProblem) -> str:
    return "known: " + ", ".join(v.name for v in problem.variables)


def sweep_axes(
    problem: DesignProblem, vary: Any, linked: Mapping[str, str] | None = None
) -> list[Axis]:
    """The axes of ``vary`` (``{path: (start, stop, count)}``), checked: a known parameter
    path, quantities of its dimension (a bare number only for a plain number), a range
    that is not empty, a problem that validates at both ends. ``linked``: ``{path: swept
    path}``, parameters that take the value of a swept one at every point (checked by
    :func:`linked_paths`; the ends are checked with them). InputError naming the field."""
    from optdesign.display.shown import Shown, _value, variable_shown
    from optdesign.units import to_internal

    if not isinstance(vary, Mapping) or not vary:
        raise InputError(
            "vary",
            "give {parameter path: (start, stop, count)}, e.g. "
            '{"requirements.hinge_moment": ("200 N*m", "1000 N*m", 20)}',
        )
    if len(vary) > MAX_AXES:
        raise InputError("vary", f"{len(vary)} parameters; at most {MAX_AXES}")
    axes = []
    ranges: dict[str, tuple[Any, Any, str]] = {}  # path -> start, stop as given, dimension
    for path, spec in vary.items():
        if not isinstance(path, str):
            raise InputError("vary", f"a parameter path is text, got {path!r}")
        where = f"vary.{path}"
        dim = parameter_dimension(problem, path)
        if not isinstance(spec, Sequence) or isinstance(spec, str) or len(spec) != 3:
            raise InputError(where, f"give (start, stop, count), got {spec!r}")
        start, stop, count = spec
        if isinstance(count, bool) or not isinstance(count, int | np.integer):
            raise InputError(where, f"count: an integer, got {count!r}")
        if not 2 <= count <= MAX_POINTS:
            raise InputError(where, f"count: {count} is outside 2..{MAX_POINTS}")
        lo = to_internal(start, dim, f"{where} start", bare="refuse")
        hi = to_internal(stop, dim, f"{where} stop", bare="refuse")
        if lo == hi:
            raise InputError(where, f"an empty range: start and stop are both {start}")
        values = tuple(float(v) for v in np.linspace(lo, hi, int(count)))
        ranges[path] = (start, stop, dim)
        head, _, rest = path.partition(".")
        if head == "variables":
            var = problem.by_name[rest.partition(".")[0]]
            shown = [variable_shown(problem, var, v) for v in values]
        else:
            shown = [
                _value(problem, path, v, None if dim == "dimensionless" else dim) for v in values
            ]
            shown = [s if isinstance(s, Shown) else Shown(float(s), "") for s in shown]
        axes.append(Axis(path, values, shown[0].unit, tuple(float(s.value) for s in shown)))
    if len({a.path for a in axes}) < len(axes):
        raise InputError("vary", "the same parameter twice")
    links = linked_paths(problem, {p: dim for p, (_, _, dim) in ranges.items()}, linked)
    axes = [
        replace(a, linked=tuple(p for p, swept in links.items() if swept == a.path)) for a in axes
    ]
    for a in axes:
        start, stop, _ = ranges[a.path]
        for end in (a.values[0], a.values[-1]):
            try:
                at_values(problem, point_settings([a], (end,)))
            except InputError as exc:
                if exc.field.startswith("vary.") and exc.field[5:] in a.linked:
                    raise InputError("linked." + exc.field[5:], exc.reason) from None
                raise
            except OptDesignError as exc:
                with_ = f" (with {', '.join(a.linked)})" if a.linked else ""
                raise InputError(f"vary.{a.path}", f"{start}..{stop}{with_}: {exc}") from None
    total = math.prod(len(a.values) for a in axes)
    if total > MAX_GRID:
        counts = " x ".join(str(len(a.values)) for a in axes)
        raise InputError(
            "vary",
            f"{counts} = {total} points; a sweep's grid has at most {MAX_GRID} (each point "
            "is a global search): give fewer points",
        )
    return axes


def linked_paths(
    problem: DesignProblem, swept: Mapping[str, str], linked: Mapping[str, str] | None
) -> dict[str, str]:
    """``linked`` (``{path: swept path}``) checked against the swept paths and their
    dimensions (``swept``: path -> dimension): each path a parameter a sweep could vary,
    not swept itself, following a swept path of its own dimension (it takes that path's
    value, in internal units). InputError ``linked`` or ``linked.PATH`` naming the
    reason."""
    if linked is None:
        return {}
    if not isinstance(linked, Mapping):
        raise InputError(
            "linked",
            "give {path: swept path}, e.g. "
            '{"loop.bandwidth": "requirements.bandwidth_min"}, got ' + repr(linked),
        )
    out: dict[str, str] = {}
    for path, follows in linked.items():
        if not isinstance(path, str) or not isinstance(follows, str):
            raise InputError("linked", f"paths are text, got {path!r}: {follows!r}")
        where = f"linked.{path}"
        try:
            dim = parameter_dimension(problem, path)
        except InputError as exc:
            raise InputError(where, exc.reason) from None
        if path in swept:
            raise InputError(
                where, "is swept itself: a parameter has its own range or follows a swept one"
            )
        if follows not in swept:
            raise InputError(
                where, f"follows {follows!r}, which is not swept (swept: {', '.join(swept)})"
            )
        if dim != swept[follows]:
            raise InputError(
                where,
                f"a {dim.replace('_', ' ')} cannot follow {follows} "
                f"(a {swept[follows].replace('_', ' ')}): it takes that parameter's value",
            )
        out[path] = follows
    return out


def point_settings(axes: Sequence[Axis], values: Sequence[float]) -> dict[str, float]:
    """The parameters of the point at ``values`` (one per axis, internal units): each
    swept path at its value, each path linked to it at the same value - what
    :func:`~optdesign.problem.parameters.at_values` makes the point's problem of."""
    swept = {axis.path: value for axis, value in zip(axes, values, strict=True)}
    return linked_values(swept, {path: a.path for a in axes for path in a.linked})


def grid_order(axes: Sequence[Axis]) -> list[tuple[int, ...]]:
    """Index tuples of the grid, the first parameter fastest."""
    if len(axes) == 1:
        return [(i,) for i in range(len(axes[0].values))]
    return [(i, j) for j in range(len(axes[1].values)) for i in range(len(axes[0].values))]


def neighbour(idx: tuple[int, ...]) -> tuple[int, ...] | None:
    """The point a point would continue from in a plain chain of warm starts: the one
    before it along the first parameter; the first point of a row continues from the
    first point of the row before. A point's ``jump`` compares its optimum with the warm
    start from it."""
    if idx[0] > 0:
        return (idx[0] - 1, *idx[1:])
    if len(idx) == 2 and idx[1] > 0:
        return (0, idx[1] - 1)
    return None
