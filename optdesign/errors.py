"""Exceptions raised at the boundaries of optdesign.

Every error names the field (or the angle, or the constraint) it is about, so that a
user can act on it without reading a traceback.
"""

from __future__ import annotations


class OptDesignError(Exception):
    """Base class of all errors that optdesign reports to a user (CLI prints, no traceback)."""


class InputError(OptDesignError, ValueError):
    """A non-physical or malformed input.

    Parameters
    ----------
    field
        Name of the offending field, e.g. ``"R"`` or ``"variables.l.lower"``.
    reason
        Why the value is rejected.
    """

    def __init__(self, field: str, reason: str):
        self.field = field
        self.reason = reason
        super().__init__(f"{field}: {reason}")


class AssemblyError(OptDesignError, ValueError):
    """The linkage cannot be assembled at some deflection angle (l^2 - u^2 <= 0).

    Parameters
    ----------
    angle_deg
        Output deflection angle (degrees) where assembly fails first.
    margin
        Assembly margin l^2 - u^2 at that angle (mm^2); non-positive.
    """

    def __init__(self, angle_deg: float, margin: float, detail: str = ""):
        self.angle_deg = float(angle_deg)
        self.margin = float(margin)
        msg = (
            f"linkage cannot assemble at deflection {self.angle_deg:+.3f} deg: "
            f"assembly margin l^2 - u^2 = {self.margin:.6g} mm^2 (must be > 0)"
        )
        if detail:
            msg += f"; {detail}"
        super().__init__(msg)


class ProblemError(OptDesignError):
    """A problem file that cannot be turned into a design problem."""


class InfeasibleRequirementsError(ProblemError):
    """Requirements that no design within the bounds can meet; names the conflicting ones."""
