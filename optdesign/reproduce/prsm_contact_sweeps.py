"""The sweeps behind the PRSM thread-contact reproduction ([C-PRSM], Fig. 7-11).

* omega along the contact position (Fig. 7; the paper: constant);
* omega and the eccentricity with and without omega against the pitch and the flank
  half-angle (Fig. 8-10);
* contact-ellipse area against the load (Fig. 11).

The paper's parameter table was lost in extraction; :func:`reference_geometry` states
the geometry used here (a 30 mm, 5-start screw, as the paper's Fig. 8 mentions).
Every study returns NumPy arrays; printing and plotting live in
:mod:`optdesign.reproduce.prsm_contact`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from optdesign.models.prsm import PRSMContact, PRSMGeometry

SIDES = ("screw", "nut")


def reference_geometry(**changes) -> PRSMGeometry:
    """The stated geometry: d_s = 30 mm, 5 starts, p = 2 mm, beta = 45 deg, spherical roller.

    Keyword arguments override fields (e.g. ``pitch=3.0`` or ``roller_arc=10.0``).
    """
    return replace(
        PRSMGeometry(d_s=30.0, n_starts=5, pitch=2.0, beta=math.radians(45.0)), **changes
    )


@dataclass(frozen=True)
class ContactSweep:
    """Results of a sweep over geometries, one entry per geometry, per side.

    Arrays keyed by side (``"screw"`` or ``"nut"``): omega (rad, index convention),
    e (eccentricity with omega), e0 (omega = 0, index pairing), e0_nearest (omega = 0,
    nearest-plane pairing), area and area0 (mm^2, at load Q).
    """

    x: np.ndarray  #: swept parameter values
    omega: dict[str, np.ndarray]
    e: dict[str, np.ndarray]
    e0: dict[str, np.ndarray]
    e0_nearest: dict[str, np.ndarray]
    area: dict[str, np.ndarray]
    area0: dict[str, np.ndarray]

    def relative_difference(self, side: str, nearest: bool = False) -> np.ndarray:
        """(e - e0)/e0 along the sweep."""
        e0 = self.e0_nearest[side] if nearest else self.e0[side]
        return self.e[side] / e0 - 1.0

    def max_relative_difference(self, side: str, nearest: bool = False) -> float:
        """Signed relative difference of largest magnitude along the sweep."""
        r = self.relative_difference(side, nearest)
        return float(r[np.argmax(np.abs(r))])


def sweep_geometries(
    x: Sequence[float], geometries: Sequence[PRSMGeometry], Q: float = 1000.0, psi: float = 0.0
) -> ContactSweep:
    """Contact at both sides for each geometry, at load Q (N) and position psi (rad)."""
    keys = ("omega", "e", "e0", "e0_nearest", "area", "area0")
    out = {k: {s: np.empty(len(geometries)) for s in SIDES} for k in keys}
    for i, g in enumerate(geometries):
        solver = PRSMContact(g)
        for s in SIDES:
            c = solver.contact(s, psi)
            h, h0 = c.hertz(Q), c.hertz_aligned(Q)
            out["omega"][s][i] = c.omega
            out["e"][s][i] = h.eccentricity
            out["e0"][s][i] = h0.eccentricity
            out["e0_nearest"][s][i] = c.hertz_aligned(Q, pairing="nearest").eccentricity
            out["area"][s][i] = h.area
            out["area0"][s][i] = h0.area
    return ContactSweep(np.asarray(x, dtype=float), **out)


def _with_arc(g: PRSMGeometry, arc_ratio: float | None) -> PRSMGeometry:
    # The roller arc as a multiple of the spherical radius r_r/sin(beta): keeps the
    # roller equally far from spherical when beta is swept.
    if arc_ratio is None:
        return g
    return replace(g, roller_arc=arc_ratio * g.r_r / math.sin(g.beta))


def sweep_pitch(
    pitches: Sequence[float],
    base: PRSMGeometry | None = None,
    Q: float = 1000.0,
    arc_ratio: float | None = None,
) -> ContactSweep:
    """omega and eccentricity against the pitch (mm), other fields from ``base``.

    ``arc_ratio``: if given, the roller arc radius is ``arc_ratio * r_r / sin(beta)``.
    """
    base = reference_geometry() if base is None else base
    geoms = [_with_arc(replace(base, pitch=float(p)), arc_ratio) for p in pitches]
    return sweep_geometries(pitches, geoms, Q)


def sweep_flank_angle(
    betas_deg: Sequence[float],
    base: PRSMGeometry | None = None,
    Q: float = 1000.0,
    arc_ratio: float | None = None,
) -> ContactSweep:
    """omega and eccentricity against the flank half-angle (deg); ``arc_ratio`` as above."""
    base = reference_geometry() if base is None else base
    geoms = [_with_arc(replace(base, beta=math.radians(float(b))), arc_ratio) for b in betas_deg]
    return sweep_geometries(betas_deg, geoms, Q)


def omega_vs_position(psi: Sequence[float], geometry: PRSMGeometry | None = None):
    """omega (rad) at the screw and nut contacts for each contact position psi (rad).

    Returns
    -------
    dict
        ``{"screw": array, "nut": array}``.
    """
    g = reference_geometry() if geometry is None else geometry
    solver = PRSMContact(g)
    return {s: np.array([solver.contact(s, float(p)).omega for p in psi]) for s in SIDES}


def area_vs_load(loads: Sequence[float], geometry: PRSMGeometry | None = None):
    """Contact-ellipse area (mm^2) with and without omega against the normal load (N).

    Returns
    -------
    dict
        ``{"screw": (area, area0), "nut": (area, area0)}`` arrays over ``loads``.
    """
    g = reference_geometry() if geometry is None else geometry
    solver = PRSMContact(g)
    out = {}
    for s in SIDES:
        c = solver.contact(s)
        out[s] = (
            np.array([c.hertz(float(Q)).area for Q in loads]),
            np.array([c.hertz_aligned(float(Q)).area for Q in loads]),
        )
    return out
