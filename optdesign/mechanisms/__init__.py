"""Mechanisms: geometry + loads + clearance chain, built on the pure models.

:class:`CrankSlider` and :class:`ShiftingFork` share one interface (:class:`Mechanism`),
so problems and studies treat them alike. Their parameters may be floats, NumPy arrays
(a population of designs, broadcast against the angle grid) or CasADi symbols.
"""

from optdesign.mechanisms.base import Backlash, Joint, Mechanism, PinJoint
from optdesign.mechanisms.crank_slider import CrankSlider
from optdesign.mechanisms.fork import ShiftingFork

__all__ = ["Backlash", "CrankSlider", "Joint", "Mechanism", "PinJoint", "ShiftingFork"]
