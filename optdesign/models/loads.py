"""Loads by virtual work (docs/loads.md): the hinge moment M_h at the output carried back
through the linkage and the screw to the motor.

With no losses in the linkage, F dx = M_h dphi for any member whose travel per output
radian is dx/dphi; the nut, the rod and the fork pin differ only in that rate.

Validity
--------
The virtual-work relations are exact for a rigid, lossless linkage: they hold wherever
the linkage assembles (its assembly rows) and need no range of their own. The pin the
loads size is a short, stiff cylinder in its bores:

pin diameter d : 0.1 ... 500 mm
    The ISO 286 tables and formulas of the pin's fit cover nominal sizes up to 500 mm;
    below 0.1 mm a pin is thinner than a hair, and its fit's tolerance grades and the
    roughness of its bore are of the order of the pin itself.
pin length over diameter L/d : 0.2 ... 5
    The bearing pressure F/(d L), the shear stress and the contact models spread the
    load evenly along L and ignore the pin's bending. A pin in double shear under an
    even load bends by about 0.11 (L/d)^4 times the flattening of [D17] eq. 11 (simply
    supported, uniform load): at L/d = 5 that is 70 times, and the load gathers at the
    lugs' edges instead of spreading. Below 0.2 the "line" contact is shorter than the
    contact strip is wide (plane strain fails) and the lug is a sheet (Huth's smallest
    t/d, :mod:`optdesign.models.lug_flexibility`).
pin length L : 0.02 ... 2500 mm
    The two ranges above together (0.2 x 0.1 mm to 5 x 500 mm), for a pin length
    declared on its own.
pin length over the linkage's size : <= 2
    A planar linkage model takes its links as lines in one plane and its joints as
    points; a pin is loaded over the thickness of the lugs around it, out of that plane,
    reaching L/2 to each side of it. Where L/2 exceeds the whole linkage's size (the sum
    of its lengths, R + l for the crank-slider, the arm R for the fork), the joint is
    wider out of the plane than the linkage is long in it: a block, whose out-of-plane
    offsets the planar model ignores. The bound is not 1: the size is a sum of lengths,
    not the linkage's extent (a fork also spans its stroke, 2 R tan 30 deg), and the
    fork's own box holds pins of 1.5 times its arm (45 mm on 30 mm) at the size end of
    its front, where the size objective leaves the pin free.
"""

from __future__ import annotations

from optdesign import math as m
from optdesign.models.validity import Validity

PIN_DIAMETER = Validity(
    "loads.pin_diameter",
    "pin model",
    "pin diameter d",
    0.1,
    500.0,
    "mm",
    "the ISO 286 fits of a pin cover sizes up to 500 mm; below 0.1 mm the fit's tolerance "
    "is of the order of the pin",
    checked=("file",),
)
PIN_SLENDERNESS = Validity(
    "loads.pin_slenderness",
    "pin model",
    "pin length over diameter L/d",
    0.2,
    5.0,
    "",
    "the pin is a short stiff cylinder loaded evenly over L; beyond L/d = 5 it bends 70 "
    "times more than it flattens",
    checked=("file", "design"),
)
PIN_LENGTH = Validity(
    "loads.pin_length",
    "pin model",
    "pin length L",
    0.02,
    2500.0,
    "mm",
    "L/d from 0.2 to 5 on pins of 0.1 to 500 mm",
    checked=("file",),
)
PIN_LENGTH_OVER_SIZE = Validity(
    "loads.pin_length_over_size",
    "planar linkage",
    "pin length over the linkage's size",
    0.0,
    2.0,
    "",
    "a planar linkage's lugs are thin against its links; a pin reaching further out of the "
    "plane on each side than the linkage is long is a block",
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (
    PIN_DIAMETER,
    PIN_SLENDERNESS,
    PIN_LENGTH,
    PIN_LENGTH_OVER_SIZE,
)


def force_from_rate(M_h, rate):
    """Force (N) that carries the moment M_h (N*mm) through a member moving ``rate`` mm/rad.

    Nut axial force: rate = dm/dphi (crank-slider) or R/cos^2 phi (fork).
    Rod force (both rod pins): rate = d|BC|/dphi.
    Fork pin normal force: rate = R/cos phi (the pin's lever arm).
    """
    return M_h / rate


def fork_pin_normal_force(M_h, R, phi, phi0=0.0):
    """Normal force between fork pin and slot, M_h cos(phi0 + phi) / R (N)."""
    return M_h * m.cos(phi0 + phi) / R


def motor_torque(F_a, p, i_a, eta_screw=1.0, eta_gear=1.0):
    """Motor torque (N*mm) to drive the nut against an axial force F_a (N).

    T_m = F_a p / (2 pi i_a eta_screw eta_gear).
    """
    return F_a * p / (2.0 * m.pi * i_a * eta_screw * eta_gear)


def backdriven_motor_torque(F_a, p, i_a, eta_screw_back=1.0, eta_gear_back=1.0):
    """Torque (N*mm) that an axial force F_a (N) on the nut exerts at the motor shaft when
    the load drives the screw backwards: F_a p eta' / (2 pi i_a)."""
    return F_a * p * eta_screw_back * eta_gear_back / (2.0 * m.pi * i_a)


def pin_bearing_pressure(F, d, L):
    """Projected bearing pressure F / (d L) of a pin (MPa)."""
    return F / (d * L)


def pin_shear_stress(F, d, shear_planes=2):
    """Mean shear stress of a pin in single (1) or double (2) shear, 4F/(k pi d^2) (MPa)."""
    return 4.0 * F / (shear_planes * m.pi * d**2)
