"""The mechanism's necessary conditions, checked on a problem before any solve: the
stroke, the mechanism's own requirements and the variables' bounds handed to
:meth:`~optdesign.mechanisms.base.Mechanism.impossible`.

From the mechanism's closed-form bounds of the nut velocity
(:meth:`~optdesign.mechanisms.base.Mechanism.nut_velocity_bounds`) follow two proofs that
need no mechanism knowledge here: the ratio 2 pi i_a v / p at every angle, hence its mean,
lies inside the bounds p and i_a and v allow (a band beyond them is out of reach), and the
nut force M / v at every angle is at least M over the velocity's bound (a static safety
no catalogue screw within the bounds can give).

A proof found here is the verdict of the solve (``od.solve``, ``optdesign solve``): no
multistart runs and no relaxation is searched, and the summary names the requirements in
the conflict and what would lift it. No proof says nothing: the problem may still be
infeasible, which the search then finds.
"""

from __future__ import annotations

import math
from typing import Any

from optdesign.errors import ProblemError
from optdesign.models.impossibility import Impossibility, NutVelocityBounds
from optdesign.problem import drive
from optdesign.user_code import call_method

#: A bound met within this relative margin is not refused (rounding).
RELATIVE_TOL = 1e-9


def impossibilities(problem: Any) -> list[Impossibility]:
    """The proofs of :meth:`Mechanism.impossible` for ``problem`` (a
    :class:`~optdesign.problem.design_problem.DesignProblem`): empty when none holds."""
    req = problem.spec.requirements
    stroke = (float(req.deflection.min), float(req.deflection.max))
    own = {
        name: getattr(req, name)
        for name in problem.mechanism.requirements
        if getattr(req, name, None) is not None
    }
    # a variable the file omits holds its declared default
    bounds = {
        name: (float(info.default), float(info.default))
        for name, info in problem.mechanism.variable_table().items()
        if info.default is not None
    }
    bounds.update({v.name: _range(v) for v in problem.variables})
    found = call_method(
        problem.mechanism, "impossible", stroke, own, bounds, doing="checking the stroke"
    )
    if not isinstance(found, list | tuple) or not all(isinstance(f, Impossibility) for f in found):
        raise ProblemError(
            f"mechanism {problem.mechanism.label()!r}: impossible() must return a list of "
            f"Impossibility records, got {type(found).__name__}"
        )
    velocity = call_method(
        problem.mechanism,
        "nut_velocity_bounds",
        stroke,
        own,
        bounds,
        doing="bounding the nut velocity",
    )
    if velocity is None:
        return list(found)
    if not isinstance(velocity, NutVelocityBounds):
        raise ProblemError(
            f"mechanism {problem.mechanism.label()!r}: nut_velocity_bounds() must return a "
            f"NutVelocityBounds record or None, got {type(velocity).__name__}"
        )
    return [
        *found,
        *ratio_band_proofs(problem, velocity, bounds),
        *static_safety_proofs(problem, velocity, bounds),
    ]


def ratio_band_proofs(
    problem: Any, velocity: NutVelocityBounds, bounds: dict[str, tuple[float, float]]
) -> list[Impossibility]:
    """``mean_ratio`` beyond every ratio 2 pi i_a v / p the bounds allow: the ratio at
    each angle lies in that range, so the mean over the grid does too."""
    band = problem.spec.requirements.mean_ratio
    if band is None:
        return []
    (p_lo, p_hi), (ia_lo, ia_hi) = bounds["p"], bounds["i_a"]
    i_lo = 2 * math.pi * ia_lo * velocity.lower / p_hi
    i_hi = 2 * math.pi * ia_hi * velocity.upper / p_lo
    named = ("mean_ratio", *velocity.requirements, "variables.p", "variables.i_a")
    if band.min is not None and band.min > i_hi * (1 + RELATIVE_TOL):
        reason = (
            f"the ratio 2 pi i_a v / p is at most 2 pi x {ia_hi:.4g} x {velocity.upper:.4g} / "
            f"{p_lo:.4g} = {i_hi:.4g} at every angle, so its mean cannot reach "
            f"{band.min:.4g}; {velocity.reason}"
        )
        remedies = (
            f"mean_ratio.min of at most {i_hi:.4g}",
            f"a lower bound of p below {2 * math.pi * ia_hi * velocity.upper / band.min:.4g} mm",
            f"i_a above {band.min * p_lo / (2 * math.pi * velocity.upper):.4g}",
        )
        return [Impossibility(named, reason, remedies)]
    if band.max is not None and band.max < i_lo * (1 - RELATIVE_TOL):
        reason = (
            f"the ratio 2 pi i_a v / p is at least 2 pi x {ia_lo:.4g} x {velocity.lower:.4g} / "
            f"{p_hi:.4g} = {i_lo:.4g} at every angle, so its mean cannot stay below "
            f"{band.max:.4g}; {velocity.reason}"
        )
        remedies = (
            f"mean_ratio.max of at least {i_lo:.4g}",
            f"an upper bound of p above {2 * math.pi * ia_lo * velocity.lower / band.max:.4g} mm",
            f"i_a below {band.max * p_hi / (2 * math.pi * velocity.lower):.4g}",
        )
        return [Impossibility(named, reason, remedies)]
    return []


def static_safety_proofs(
    problem: Any, velocity: NutVelocityBounds, bounds: dict[str, tuple[float, float]]
) -> list[Impossibility]:
    """``static_safety_min`` no catalogue screw within the bounds of d0 and p can give:
    the nut force M / v at every angle is at least M over the velocity's upper bound, and
    the row asks f_s x force <= C0a of the screw."""
    spec = problem.spec
    req, screw = spec.requirements, spec.screw
    if req.static_safety_min is None or screw is None or screw.catalogue is None:
        return []
    moment = abs(float(req.hinge_moment))
    if moment == 0.0 or not math.isfinite(velocity.upper):
        return []
    (d_lo, d_hi), (p_lo, p_hi) = bounds.get("d0", (0.0, math.inf)), bounds["p"]
    rated = [
        float(item.C0a)
        for (d0, p), item in drive.catalogue_items(screw.catalogue, screw.nut).items()
        if d_lo <= d0 <= d_hi and p_lo <= p <= p_hi and item.C0a is not None
    ]
    if not rated:
        return []
    force = moment / velocity.upper
    best = max(rated)
    if req.static_safety_min * force <= best * (1 + RELATIVE_TOL):
        return []
    reason = (
        f"the nut force M / v is at least {moment:.4g} N*mm / {velocity.upper:.4g} "
        f"mm/rad = {force:.4g} N at every angle, and f_s = {req.static_safety_min:g} times "
        f"it exceeds the largest static rating C0a = {best:.4g} N of the {screw.catalogue} "
        f"screws with d0 in [{d_lo:g}, {d_hi:g}] mm and p in [{p_lo:g}, {p_hi:g}] mm; "
        f"{velocity.reason}"
    )
    remedies = (
        f"hinge_moment of at most {best * velocity.upper / req.static_safety_min / 1e3:.4g} N*m",
        f"static_safety_min of at most {best / force:.4g}",
        f"a screw rated C0a >= {req.static_safety_min * force:.4g} N within the bounds of d0 and p",
    )
    named = ("hinge_moment", "static_safety_min", "variables.d0", *velocity.requirements)
    return [Impossibility(named, reason, remedies)]


def _range(var: Any) -> tuple[float, float]:
    """A variable's (lower, upper): its bounds, its catalogue's items, or its value."""
    if var.lower is not None and var.upper is not None:
        return float(var.lower), float(var.upper)
    if var.values:
        return float(min(var.values)), float(max(var.values))
    return float(var.value), float(var.value)
