"""A closed-form proof that some requirements cannot be met together by any design within
the variables' bounds: the record a mechanism's necessary conditions return
(:meth:`optdesign.mechanisms.base.Mechanism.impossible`), checked before any solve.

A proof is an argument from the geometry, not a search: e.g. the transmission angle of a
crank-slider sweeps at least the stroke less the rod's swing, whatever its lengths, so a
stroke wider than the transmission band plus twice the rod's inclination limit cannot be
turned. A solve of such a problem would only show a multistart that fails and relaxations
that do not each suffice; the proof says which requirements conflict and what would
lift it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: Angles (rad) closer than this count as equal in a proof: a stroke exactly as wide as
#: the geometry allows is not refused on rounding.
ANGLE_TOL = 1e-9


@dataclass(frozen=True)
class Impossibility:
    """Requirements that no design within the bounds can meet together, and why.

    Attributes
    ----------
    requirements
        The problem file's fields in the conflict (``"deflection"``,
        ``"transmission_angle"``, ``"variables.phi0"``), as written.
    reason
        The argument, with its numbers in the user's units (deg, mm).
    remedies
        Each change that alone lifts this proof (a necessary condition only: the
        changed problem may still be infeasible for other reasons); empty when none of
        the named requirements can lift it alone.
    """

    requirements: tuple[str, ...]
    reason: str
    remedies: tuple[str, ...] = ()

    def text(self) -> str:
        """One paragraph: the requirements, the argument, and the remedies."""
        head = f"{', '.join(self.requirements)}: {self.reason}"
        if not self.remedies:
            return head
        return f"{head}; any one of these lifts it: {'; '.join(self.remedies)}"

    def to_json(self) -> dict[str, object]:
        return {
            "requirements": list(self.requirements),
            "reason": self.reason,
            "remedies": list(self.remedies),
        }


def degrees_text(angle: float) -> str:
    """An angle in rad as the proofs write it: degrees to 4 significant digits."""
    return f"{math.degrees(angle):.4g}"


@dataclass(frozen=True)
class NutVelocityBounds:
    """Bounds of the nut velocity dx/dphi (mm/rad) that hold at every angle of the stroke
    for every design within the variables' bounds that meets the mechanism's own
    requirements: what a mechanism knows in closed form
    (:meth:`optdesign.mechanisms.base.Mechanism.nut_velocity_bounds`), from which the
    problem's proofs on the ratio and the loads follow (the ratio is 2 pi i_a v / p, the
    nut force M / v).

    Attributes
    ----------
    lower, upper
        ``lower <= dx/dphi <= upper`` (mm/rad); 0 and ``inf`` where nothing is known.
    reason
        Why, with its numbers (the proofs quote it).
    requirements
        The problem file's fields the bounds rest on (``"variables.R"``,
        ``"rod_inclination_max"``).
    """

    lower: float
    upper: float
    reason: str
    requirements: tuple[str, ...] = ()
