"""Mechanisms: plug-ins that own all mechanism knowledge.

Each mechanism (:class:`Mechanism` subclass) declares its variables and computes its
kinematics, loads and clearance chain from the pure models; the problem, formulations,
solvers and studies see only what the contract exposes. Built-ins: the crank-slider and
the shifting fork of [D17], and the trunnion-mounted pivoting screw. Register your
own with :func:`register_mechanism`.
"""

from optdesign.mechanisms.base import (
    DRIVE_VARIABLES,
    Mechanism,
    RequirementInfo,
    Rows,
    Sketch,
    VariableInfo,
)

# The built-in plug-ins register themselves on import.
from optdesign.mechanisms.crank_slider import CrankSlider
from optdesign.mechanisms.fork import ShiftingFork
from optdesign.mechanisms.joints import Backlash, Joint, PinJoint
from optdesign.mechanisms.pivoting_screw import PivotingScrew
from optdesign.mechanisms.registry import get_mechanism, register_mechanism, registered

__all__ = [
    "DRIVE_VARIABLES",
    "Backlash",
    "CrankSlider",
    "Joint",
    "Mechanism",
    "PinJoint",
    "PivotingScrew",
    "RequirementInfo",
    "Rows",
    "ShiftingFork",
    "Sketch",
    "VariableInfo",
    "get_mechanism",
    "register_mechanism",
    "registered",
]
