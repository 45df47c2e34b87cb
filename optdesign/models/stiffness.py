"""Stiffness chain from the motor to the output shaft ([Z00]; docs/screw.md and 8).

Members and their stiffness (all through :mod:`optdesign.math`, CasADi or NumPy):

- screw shaft, axial: :func:`optdesign.models.screw_sizing.shaft_stiffness` (by mounting
  and nut position);
- screw shaft, torsional: :func:`shaft_torsional_stiffness` G J / L, seen at the nut as an
  axial stiffness through the lead, :func:`torsion_to_axial` K_theta (2 pi / p)^2
  ([Z00] eq. 7, :func:`optdesign.models.screw.axial_stiffness`, carries a friction
  factor eta in addition; for an elastic member the lossless form is the energy-consistent
  one; the two differ by the factor eta, 3.7 % at eta = 0.963);
- nut, support bearings, housing: numbers from the catalogue (e.g.
  :class:`optdesign.models.screw_catalogue.BallScrew` ``K_nut``) or the bearing maker;
- series along one load path: :func:`optdesign.models.screw.series_stiffness`.

Reflection to the output. A member of linear stiffness K (N/mm) whose length changes at
the rate r = dL/dphi (mm/rad) with the output angle phi carries F = M / r for an output
moment M (virtual work, :mod:`optdesign.models.loads`) and stretches F / K, which turns
the output by F / (K r): its stiffness seen at the output is K r^2 (N*mm/rad). Members in
series along the load path (screw chain, rod pins, ...) add their compliances there:

    1 / K_out = sum_k 1 / (K_k r_k^2)                       (:func:`output_stiffness`)

For the crank-slider the axial chain (shaft, nut, bearings) acts with r = dm/dphi and
the rod with its pins with r = d|BC|/dphi (:mod:`optdesign.models.crank_slider`); for the
fork the nut rate is R / cos^2(phi). tests/test_stiffness.py checks the formula against
the equilibrium of the crank-slider with springs, solved without it.

Validity
--------
stiffness of a member (nut, bearings) : 1 ... 1e9 N/mm
    A member of the chain is a steel part or a preloaded rolling contact: preloaded
    nuts and angular-contact bearing pairs are 1e5-2e6 N/mm (100-2000 N/um); below
    1 N/mm a part is a soft spring, and 1e9 N/mm is stiffer than a steel cylinder 100 mm
    across and 10 mm long (E A / L = 1.6e8 N/mm). The reflection to the output itself is
    exact (linear elasticity, small deflections).

Units: mm, N, MPa, N*mm/rad.
"""

from __future__ import annotations

from collections.abc import Iterable

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.models._checks import require_positive
from optdesign.models.screw_sizing import E_STEEL
from optdesign.models.validity import Validity

MEMBER_STIFFNESS = Validity(
    "stiffness.member",
    "stiffness chain",
    "axial stiffness of a member",
    1.0,
    1.0e9,
    "N/mm",
    "the parts of a screw drive are 1e5-2e6 N/mm; 1e9 N/mm is stiffer than any steel part "
    "of its size",
    checked=("file",),
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (MEMBER_STIFFNESS,)

#: Poisson's ratio of steel assumed for the shear modulus.
NU_STEEL = 0.3
#: Shear modulus of screw steel, E / (2 (1 + nu)) = 79 231 MPa with E = 2.06e5 MPa.
G_STEEL = E_STEEL / (2.0 * (1.0 + NU_STEEL))


def polar_moment(d1):
    """Polar second moment of the root circle, J = pi d1^4 / 32 (mm^4)."""
    return m.pi * d1**4 / 32.0


def shaft_torsional_stiffness(d1, L, G=G_STEEL):
    """Torsional stiffness G J / L of a shaft length L (N*mm/rad); d1 root diameter (mm)."""
    require_positive("d1", d1)
    require_positive("L", L)
    return G * polar_moment(d1) / L


def torsion_to_axial(K_theta, p):
    """Axial stiffness at the nut (N/mm) equivalent to a torsional stiffness at the screw.

    A screw twist dtheta moves the nut p dtheta / (2 pi): K = K_theta (2 pi / p)^2.
    """
    require_positive("p", p)
    return K_theta * (2.0 * m.pi / p) ** 2


def axial_to_torsion(K, p):
    """Torsional stiffness at the screw (N*mm/rad) of an axial stiffness K at the nut,
    K (p / (2 pi))^2: the inverse of :func:`torsion_to_axial`."""
    require_positive("p", p)
    return K * (p / (2.0 * m.pi)) ** 2


def reflected_stiffness(K, rate):
    """Stiffness at the output (N*mm/rad) of a member of stiffness K (N/mm) whose length
    changes by ``rate`` = dL/dphi (mm/rad) per radian of output: K rate^2."""
    return K * rate**2


def output_stiffness(terms: Iterable[tuple]):
    """Output stiffness (N*mm/rad) of members in series along the load path.

    Parameters
    ----------
    terms
        Pairs (K, rate): member stiffness (N/mm, or N*mm/rad for a rotary member with rate
        = its angle per output angle) and its rate (mm/rad or rad/rad). Arrays broadcast
        (a grid of phi), CasADi expressions stay symbolic.

    Returns
    -------
    K_out
        1 / sum_k 1 / (K_k rate_k^2).
    """
    total = 0.0
    count = 0
    for K, rate in terms:
        total = total + 1.0 / reflected_stiffness(K, rate)
        count += 1
    if count == 0:
        raise InputError("terms", "output_stiffness needs at least one (K, rate) pair")
    return 1.0 / total
