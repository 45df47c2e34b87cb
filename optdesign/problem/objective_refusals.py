"""Why a problem or a formulation lacks an objective, in words a user can act on: what a
problem must give for the objective ``motor_mass``, the error for an objective the
problem's expressions lack, and the refusal of an objective with no smooth form by a
formulation that needs one (:attr:`~optdesign.problem.objectives.ObjectiveInfo.
numeric_only`).
"""

from __future__ import annotations

from typing import Any

from optdesign.errors import ProblemError


def motor_mass_needs(problem: Any) -> str:
    """What a problem must give for the objective motor_mass (``""``: it gives it)."""
    from optdesign.problem import motor_catalogue_variable as mcv

    motor = problem.spec.motor
    if motor is None:
        return "needs a [motor] section with the motor's mass"
    catalogue = mcv.spec_catalogue(motor)
    if catalogue is not None:
        missing = mcv.masses_missing(catalogue)
        if missing:
            more = f" and {len(missing) - 3} more" if len(missing) > 3 else ""
            return (
                f"the motor catalogue {catalogue.name!r} prints no mass for "
                f"{', '.join(missing[:3])}{more}: give a catalogue CSV whose mass_kg column "
                "is filled (catalogue = FILE)"
            )
        return ""
    if motor.designation is not None:
        from optdesign.models.motor_catalogue import by_designation

        if by_designation(motor.designation).mass is None:
            return (
                f"the shipped catalogue prints no mass for {motor.designation}: give the "
                "motor's data with its mass, or a catalogue CSV with mass_kg"
            )
        return ""
    return "" if motor.mass is not None else "give [motor] mass"


def unavailable_objective(problem: Any, name: str, available: Any) -> ProblemError:
    """The error for objective ``name`` that the problem's expressions lack: its own
    reason where the objective declares one, and the objectives the problem has."""
    info = problem.objectives.get(name)
    reason = info.needs(problem) if info is not None and info.needs is not None else ""
    why = f": {reason}" if reason else ""
    return ProblemError(
        f"objective {name!r} is not available for this problem{why} "
        f"(available: {', '.join(available)})"
    )


def smooth_form_refusal(problem: Any, objectives: Any, who: str) -> str:
    """Why ``who`` (a formulation needing a smooth form: the NLP, the catalogue search,
    the GP, the robust design, an epsilon front) cannot pose one of ``objectives`` (a
    name or names), naming it, or ``""``."""
    names = [objectives] if isinstance(objectives, str) else list(objectives or ())
    for name in filter(None, names):
        info = problem.objectives.get(name)
        if info is not None and info.numeric_only:
            return f"{who} needs a smooth form of objective {name!r}: {info.numeric_only}"
    return ""
