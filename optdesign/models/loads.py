"""Loads by virtual work (docs/loads.md): the hinge moment M_h at the output carried back
through the linkage and the screw to the motor.

With no losses in the linkage, F dx = M_h dphi for any member whose travel per output
radian is dx/dphi; the nut, the rod and the fork pin differ only in that rate.
"""

from __future__ import annotations

from optdesign import math as m


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
