"""Hertz line contact of a pin: contact half-width and flattening ([D17] eq. 10-11).

The paper treats a pin of diameter D, length L, under a normal force F as a cylinder on
a flat of the same material:

    b     = sqrt(4 D (F/L) (1 - nu^2) / (pi E))        contact half-width   (eq. 10)
    Delta = D/2 - sqrt(D^2/4 - b^2)                    flattening           (eq. 11)

**Reading implemented.** Delta is the equation's value for *one* body (0.00552 mm for the
paper's 10 mm pin, 20 mm long, 20 kN). The paper prints 0.012 mm; flattening of both the
pin and its bore, 2 Delta = 0.0110 mm, comes close to it, and the clearance chains of
optdesign count 2 Delta per pin joint for that reason (see models.clearance).

Delta is evaluated in the algebraically identical form b^2 / (D/2 + sqrt(D^2/4 - b^2)),
which does not lose digits to cancellation when b << D. First-order form: b^2 / D
(a monomial in D, F, L: what the geometric-programming formulation uses).

Limits: eq. 10 is a cylinder on a flat; a pin in a bore with small clearance is a
conforming contact where the half-width grows and Hertz stops holding once the arc is
wide (docs/clearance_and_backlash.md). Where b approaches D/2 the formula has no real value.

Validity
--------
b / (D/2) : <= 0.25
    Hertz's solution treats each body as an elastic half-space, which needs a contact
    strip narrow against the radius of curvature. At b = D/8 the strip subtends
    +-14.5 deg of the pin, where the conforming-contact module finds Hertz's formulas
    within 3 % of the exact solution (15 deg, :mod:`optdesign.models.pin_contact`), and
    the sagitta (11) departs by 1.6 % from its first-order form b^2/D; at b = D/2 (11)
    has no real value at all. A steel pin at its usual bearing limit (100 MPa) has
    b/(D/2) = 0.047.
E, nu : :data:`~optdesign.models.validity.ELASTIC_MODULUS`, :data:`~optdesign.models.validity.POISSON_RATIO`
    Linear elasticity of a real solid.
"""

from __future__ import annotations

from optdesign import math as m
from optdesign.models.validity import ELASTIC_MODULUS, POISSON_RATIO, Validity

HALF_WIDTH_RATIO = Validity(
    "hertz_line.half_width_ratio",
    "Hertz line contact",
    "contact half-width over the pin radius b/(d/2)",
    0.0,
    0.25,
    "",
    "Hertz's half-space needs a contact strip narrow against the radius (within 3 % up to b = d/8)",
)

#: The ranges of validity of this model.
VALIDITY: tuple[Validity, ...] = (HALF_WIDTH_RATIO, ELASTIC_MODULUS, POISSON_RATIO)


def contact_half_width(D, F, L, E, nu):
    """Contact half-width b (mm), eq. 10. D, L in mm; F in N; E in MPa."""
    return m.sqrt(4.0 * D * (F / L) * (1.0 - nu**2) / (m.pi * E))


def pin_flattening(D, F, L, E, nu):
    """Flattening Delta (mm) of one body, eq. 11 (cancellation-free form)."""
    b2 = 4.0 * D * (F / L) * (1.0 - nu**2) / (m.pi * E)
    return b2 / (0.5 * D + m.sqrt_domain(0.25 * D**2 - b2))


def pin_flattening_first_order(D, F, L, E, nu):
    """First-order flattening b^2 / D = 4 (F/L)(1 - nu^2)/(pi E) (mm); independent of D."""
    return 4.0 * (F / L) * (1.0 - nu**2) / (m.pi * E)
