"""What limits a design, in the quantities the user wrote.

The solver reports constraint rows as it sees them: one row per deflection angle, some
rows on a transformed quantity (the sine of a rod inclination, the cosine of a
transmission angle), some internal (the epigraph rows ``backlash_envelope[...]`` that
carry the objective). Here rows become :class:`Limit` records, one per requirement,
shown through the block's own ``display`` map (an inclination in degrees, not its sine)
and in the units a user reads; active variable bounds are limits too.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optdesign.display.shown import Shown, angle_unit, shown
from optdesign.text import printable
from optdesign.tolerances import FEASIBILITY_TOL

#: Row names never shown as limits: the objective's epigraph rows, and membership checks
#: (a design is a catalogue item: met with equality by every catalogue design).
INTERNAL_MARKERS = ("_envelope", "_membership")


def is_internal(row_name: str) -> bool:
    """True for a formulation's own rows (the objective's epigraph rows, membership checks)."""
    base = row_name.split("[", 1)[0]
    return any(m in base for m in INTERNAL_MARKERS)


@dataclass
class Limit:
    """One requirement or variable bound at a design, as a user reads it.

    Attributes
    ----------
    name, description
        Requirement (or variable) name and what it is.
    kind
        ``"requirement"`` or ``"bound"`` (a design variable at its bound).
    side
        ``"max"`` or ``"min"``: which side of the requirement binds; ``"number"``: a row
        without bounds, violated because its value is NaN.
    value, limit
        The worst value over the binding angles, and the limit, in ``value.unit``.
    where
        Deflection angles where it binds (empty for one-value requirements).
    violation
        Amount by which it is exceeded (0 when it holds), same unit.
    """

    name: str
    description: str
    kind: str
    side: str
    value: Shown
    limit: Shown
    where: list[str] = field(default_factory=list)
    violation: float = 0.0

    def text(self) -> str:
        """One line: ``rod inclination (rod_inclination) = 25 deg, max 25 deg at phi=...``."""
        what = _what(self)
        if self.kind == "bound":
            return f"{what} = {self.value.text()}, at its {self.side} bound"
        if self.side == "number":
            return f"{what} is not a number (NaN)"
        line = f"{what} = {self.value.text()}, {self.side} {self.limit.text()}"
        if self.where:
            shown_where = ", ".join(self.where[:4]) + (" ..." if len(self.where) > 4 else "")
            line += f" at {shown_where}"
        if self.violation > 0:
            unit = "" if self.value.unit in ("", "%") else " " + self.value.unit
            pct = " %" if self.value.unit == "%" else ""
            word = "short by" if self.side == "min" else "exceeded by"
            line += f": {word} {self.violation:.3g}{pct}{unit}"
        return line

    def to_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "description": self.description,
            "kind": self.kind,
            "side": self.side,
            "value": self.value.to_json(),
            "limit": self.limit.to_json(),
            "where": list(self.where),
            "violation": {"value": float(self.violation), "unit": self.value.unit},
        }


@dataclass(frozen=True)
class BlockInfo:
    """How one constraint block is shown: its map to the user's quantity and unit."""

    description: str
    unit: str
    display: Callable[[Any], Any] | None
    display_unit: str


#: :func:`block_infos` of the last problems asked, by their state's token (a front's page
#: shows every point's limits; the declarations are the same for all of them).
_BLOCK_INFOS: OrderedDict[str, dict[str, BlockInfo]] = OrderedDict()
_BLOCK_INFOS_SIZE = 8


def block_infos(problem: Any) -> dict[str, BlockInfo]:
    """Name -> :class:`BlockInfo` of every constraint block of ``problem`` (NumPy path,
    at its start design: only the declarations are read). Remembered per problem state:
    the caller must not change the mapping it gets."""
    token = getattr(problem, "token", None)
    if token is not None and token in _BLOCK_INFOS:
        _BLOCK_INFOS.move_to_end(token)
        return _BLOCK_INFOS[token]
    infos = _block_infos(problem)
    if token is not None:
        _BLOCK_INFOS[token] = infos
        while len(_BLOCK_INFOS) > _BLOCK_INFOS_SIZE:
            _BLOCK_INFOS.popitem(last=False)
    return infos


def _block_infos(problem: Any) -> dict[str, BlockInfo]:
    design = problem.design_dict(problem.start()[None, :])
    with np.errstate(all="ignore"):
        ex = problem.expressions(design)
    infos = {
        b.name: BlockInfo(b.description, b.unit, b.display, b.display_unit) for b in ex.constraints
    }
    for name in problem.objective_limits():
        info = problem.objectives[name]
        infos[f"{name}_max"] = BlockInfo(
            f"{info.description} (limit)", info.unit, _scaled(info.display_scale), info.shown_unit
        )
    return infos


def _scaled(scale: float) -> Callable[[Any], Any] | None:
    return None if scale == 1.0 else (lambda v: v * scale)


def _label(row_name: str) -> str:
    return row_name.split("[", 1)[1].rstrip("]") if "[" in row_name else ""


def limits_of(problem: Any, rows: Sequence[Any], infos: dict[str, BlockInfo] | None = None):
    """:class:`Limit` records of constraint reports ``rows`` (one per requirement, the
    worst row first), internal rows left out."""
    if problem is None:
        return []
    infos = infos if infos is not None else block_infos(problem)
    groups: dict[str, list[Any]] = {}
    for r in rows:
        if not is_internal(r.name):
            groups.setdefault(r.name.split("[", 1)[0], []).append(r)
    return [_limit(problem, name, group, infos.get(name)) for name, group in groups.items()]


def _limit(problem: Any, name: str, group: list[Any], info: BlockInfo | None) -> Limit:
    worst = max(group, key=lambda r: r.amount)
    if worst.lower is None and worst.upper is None:  # violated because it is not a number
        nan = Shown(math.nan, info.unit if info is not None else worst.unit)
        where = [_label(r.name) for r in group if _label(r.name)]
        description = info.description if info is not None else ""
        return Limit(name, description, "requirement", "number", nan, nan, where, 0.0)
    bound_hi = worst.upper is not None and (
        worst.lower is None or abs(worst.value - worst.upper) <= abs(worst.value - worst.lower)
    )
    raw_limit = worst.upper if bound_hi else worst.lower
    side = "max" if bound_hi else "min"
    unit = info.unit if info is not None else worst.unit
    where = [_label(r.name) for r in group if _label(r.name)]
    if info is not None and info.display is not None:
        f = info.display
        worst_value = worst.value
        if symmetric(f, worst.lower, worst.upper):
            # |x| <= a written as -a <= x <= a: the user wrote the magnitude's limit
            worst_value, raw_limit, side = abs(worst_value), worst.upper, "max"
        value = Shown(float(f(worst_value)), info.display_unit)
        limit = Shown(float(f(raw_limit)), info.display_unit)
        # a decreasing map (an angle from its cosine) turns an upper row bound into a min
        probe = raw_limit if np.isfinite(raw_limit) else worst.value
        if _decreasing(f, probe):
            side = "min" if side == "max" else "max"
        violation = abs(value.value - limit.value) if worst.amount > 0 else 0.0
        return Limit(name, info.description, "requirement", side, value, limit, where, violation)
    angle = angle_unit(problem)
    value = shown(worst.value, unit, angle)
    limit = shown(raw_limit, unit, angle)
    violation = abs(shown(worst.amount, unit, angle).value) if worst.amount > 0 else 0.0
    description = info.description if info is not None else ""
    return Limit(name, description, "requirement", side, value, limit, where, violation)


def symmetric(f: Callable[[Any], Any], lower: float | None, upper: float | None) -> bool:
    """A band -a <= x <= a whose display map is odd (shows as |f(x)| <= f(a))."""
    if lower is None or upper is None or upper <= 0 or abs(lower + upper) > 1e-12 * upper:
        return False
    return abs(float(f(lower)) + float(f(upper))) <= 1e-9 * max(1.0, abs(float(f(upper))))


def at_bound(var: Any, value: float, rel: float = FEASIBILITY_TOL) -> str | None:
    """``"lower"`` or ``"upper"`` when free variable ``var`` is within ``rel`` (relative
    to max(1, its bound range)) of that bound at ``value``, else None: the test of a
    variable at its bound (:data:`optdesign.tolerances.FEASIBILITY_TOL`)."""
    tol = rel * max(1.0, abs(var.upper - var.lower))
    for side, bound in (("lower", var.lower), ("upper", var.upper)):
        if abs(value - bound) < tol:
            return side
    return None


def bound_limits(
    problem: Any, design: dict[str, float], rel: float = FEASIBILITY_TOL
) -> list[Limit]:
    """Free variables of ``design`` at a bound (:func:`at_bound`)."""
    from optdesign.display.shown import variable_shown

    out = []
    for var in problem.free:
        value = design.get(var.name)
        if value is None:
            continue
        side = at_bound(var, value, rel)
        if side is not None:
            bound = var.lower if side == "lower" else var.upper
            out.append(
                Limit(
                    var.name,
                    var.description,
                    "bound",
                    side,
                    variable_shown(problem, var, value),
                    variable_shown(problem, var, bound),
                )
            )
    return out


def objective_where(rows: Iterable[Any]) -> list[str]:
    """Angles where the objective is attained (from its internal epigraph rows)."""
    return sorted({_label(r.name) for r in rows if is_internal(r.name) and _label(r.name)})


def relaxation_limits(problem: Any, items: Sequence[Any]) -> list[Limit]:
    """:class:`~optdesign.formulations.nlp.relaxation.Relaxation` records as limits a user reads:
    ``limit`` as written, ``value`` the limit that makes the problem feasible (None:
    relaxing it alone is not enough), ``where`` the catalogue items it needs when they
    are not the diagnosis' basis."""
    infos = block_infos(problem)
    out = []
    for r in items:
        info = infos.get(r.name)
        side = "max" if r.upper else "min"
        written, needed = r.written, r.needed
        unit = info.unit if info is not None else ""
        f = info.display if info is not None else None
        if f is not None:
            if symmetric(f, r.lower_row, r.upper_row):
                side, written = "max", r.upper_row
                needed = None if needed is None else r.upper_row + abs(r.needed - r.written)
            elif _decreasing(f, written):
                side = "min" if side == "max" else "max"
            lim = Shown(float(f(written)), info.display_unit)
            need = None if needed is None else Shown(float(f(needed)), info.display_unit)
        else:
            angle = angle_unit(problem)
            lim = shown(written, unit, angle)
            need = None if needed is None else shown(needed, unit, angle)
        description = info.description if info is not None else ""
        at = [r.at] if getattr(r, "at", "") else []  # other catalogue items than the basis
        out.append(Limit(r.name, description, "relaxation", side, need or Shown(math.nan), lim, at))
    return out


def relaxation_text(lim: Limit) -> str:
    """``nut travel (nut_travel): max 25 mm -> 33.4 mm`` (or why there is no answer)."""
    what = _what(lim)
    if math.isnan(lim.value.value):
        return f"{what}: relaxing it alone gave no feasible design (it conflicts with others too)"
    at = f" (with {', '.join(lim.where)})" if lim.where else ""
    return f"{what}: {lim.side} {lim.limit.text()} -> {lim.value.text()}{at}"


def _what(lim: Limit) -> str:
    """``description (name)`` of a limit, one printable line (both may come from a user's
    plug-in or :meth:`add_constraint`)."""
    name = printable(lim.name)
    return f"{printable(lim.description)} ({name})" if lim.description else name


def _decreasing(f: Callable[[Any], Any], x: float) -> bool:
    step = 1e-7 * max(1.0, abs(x))
    return float(f(x + step)) < float(f(x))


def binding_angles(rows: Iterable[Any]) -> dict[str, list[float]]:
    """Requirement name -> deflection angles (deg) where its rows bind (internal rows
    left out)."""
    out: dict[str, list[float]] = {}
    for r in rows:
        if "[phi=" in r.name and not is_internal(r.name):
            base, label = r.name.split("[", 1)
            out.setdefault(base, []).append(float(label[4:].rstrip("]").removesuffix("deg")))
    return out
