"""Reduction ratio of a screw drive and its ripple over a deflection range ([D17]).

The ratio is motor angle per output angle, i = d(theta_motor)/d(phi). The nut moves
p/(2 pi) per screw radian and the gear pair divides by i_a, so for a nut velocity
v = dx/dphi (mm/rad), i = 2 pi i_a v / p.

Validity
--------
The exact ratio holds wherever the nut velocity is defined; the papers' finite-step
ratio lags it by about half a step (documented; a design problem uses the exact one).
The ratio must stay positive over the stroke (a dead point inside it is refused by the
row ``ratio_positive``).
"""

from __future__ import annotations

from collections.abc import Callable

from optdesign import math as m
from optdesign.models.validity import Validity

RATIO = Validity(
    "ratio.ratio",
    "reduction ratio",
    "reduction ratio i",
    1.0,
    None,
    "",
    "a dead point inside the stroke (i <= 0) is no transmission; a problem keeps i >= 1",
    checked=("design",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (RATIO,)


def ratio_from_nut_velocity(v, p, i_a):
    """Exact ratio i = 2 pi i_a v / p.

    Parameters
    ----------
    v
        Nut velocity dx/dphi (mm/rad).
    p
        Screw lead (mm).
    i_a
        Gear ratio between motor and screw.
    """
    return 2.0 * m.pi * i_a * v / p


def ratio_finite_step(position: Callable, phi, step, p, i_a):
    """The papers' finite-step ratio ([D17] eq. 5 and 9).

    i = 2 pi i_a [x(phi + step) - x(phi)] / (p step), a forward difference of the nut
    position ``position(phi)``; it tends to the exact ratio as ``step`` -> 0 and lags it
    by about half a step.
    """
    return 2.0 * m.pi * i_a * (position(phi + step) - position(phi)) / (p * step)


def ratio_ripple(i):
    """Ripple (i_max - i_min) / (i_max + i_min) of ratios over the grid ([D17], 1.3).

    This is the paper's "variation range": half the spread over the mean of the extremes.
    Non-smooth in the design; solvers use the epigraph form instead (see formulations).
    """
    return m.grid_spread(i)


def ripple_from_bounds(i_lo, i_hi):
    """Ripple from an enclosing band [i_lo, i_hi] (the smooth epigraph objective)."""
    return m.spread(i_lo, i_hi)
