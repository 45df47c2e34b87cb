"""A screw-driven double rocker, written from docs/mechanisms.md with public names only:
the nut, on a screw whose axis is offset and inclined, pushes a connecting rod onto one
arm of an input rocker pivoted on the frame; the rocker's other arm drives the output
rocker (the horn, turning about the origin) through a coupler.

Geometry (mm, rad; output axis O at the origin, angles from +x, counter-clockwise):

- horn pin H = R (cos a, sin a), a = phi0 + phi;
- input rocker about K = (k_x, k_y): its coupler arm ends at C (|C - K| = r_c,
  |C - H| = l_c, the branch left of H -> K), its rod arm at Q, turned gamma from the
  coupler arm (|Q - K| = r_q);
- screw axis: direction u = (cos beta, sin beta), at the signed distance e from O along
  n = (-sin beta, cos beta); the nut pin N = e n + x u, behind Q: |Q - N| = l_r,
  x = u.Q - sqrt(l_r^2 - (n.Q - e)^2). x is the nut position.

Rates by virtual work (w, v the unit vectors H -> C and N -> Q; turn(p) the velocity of
a point p about its pivot per unit rotation, p turned by +90 deg):

  g_c = -w . turn(H)          coupler length rate as the horn turns, rocker held
  h_c =  w . turn(C - K)      coupler length rate as the rocker turns, horn held
  g_r =  v . turn(Q - K)      rod length rate as the rocker turns, nut held
  dpsi/dphi = -g_c / h_c,     dx/dphi = g_r dpsi/dphi / (v . u)

Coupler tension T_c = -M_h / g_c, rod tension T_r = -M_h / (g_r dpsi/dphi) (the horn's
and the rocker's moment balances); the frame holds the rocker at K with
F_K = T_c w + T_r v. A clearance delta of a joint, opened along the force it carries,
turns the horn by delta |F| / M_h with the nut held: the sensitivities are 1/|g_c| (both
coupler pins), 1/|g_r dpsi/dphi| (both rod pins) and |F_K| / M_h (the rocker's pivot).
Five pins of one size: the rod's two, the rocker's pivot, the coupler's two.
"""

from __future__ import annotations

import numpy as np

import optdesign as od
from optdesign import math as m

LENGTH, ANGLE = "length", "angle"


def _dot(u, v):
    return u[0] * v[0] + u[1] * v[1]


def _cross(u, v):
    return u[0] * v[1] - u[1] * v[0]


def _turn(v):  # v turned by +90 deg: the velocity of a point at v about its pivot
    return (-v[1], v[0])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def degrees_of_cosine(value):
    """The angle in degrees whose cosine a row bounds (how a transmission angle reads)."""
    return np.degrees(np.arccos(np.clip(value, -1.0, 1.0)))


def degrees_of_sine(value):
    """The angle in degrees whose sine a row bounds (how the rod's inclination reads)."""
    return np.degrees(np.arcsin(np.clip(value, -1.0, 1.0)))


class DoubleRocker(od.Mechanism):
    name = "double_rocker"
    title = "screw-driven double rocker"
    variables = {  # noqa: RUF012 - a plug-in declares its variables as a plain dict
        "R": od.VariableInfo(LENGTH, "horn radius (output rocker, O to H)"),
        "l_c": od.VariableInfo(LENGTH, "coupler length (H to C)"),
        "r_c": od.VariableInfo(LENGTH, "input rocker's coupler arm (K to C)"),
        "r_q": od.VariableInfo(LENGTH, "input rocker's rod arm (K to Q)"),
        "gamma": od.VariableInfo(
            ANGLE, "angle from the coupler arm to the rod arm", positive=False, default=-np.pi / 2
        ),
        "l_r": od.VariableInfo(LENGTH, "connecting rod length (N to Q)"),
        "k_x": od.VariableInfo(LENGTH, "input rocker pivot abscissa", positive=False),
        "k_y": od.VariableInfo(LENGTH, "input rocker pivot ordinate", positive=False),
        "e": od.VariableInfo(LENGTH, "screw axis offset from O (signed)", positive=False),
        "beta": od.VariableInfo(ANGLE, "screw axis inclination to +x", positive=False, default=0.0),
        "phi0": od.VariableInfo(ANGLE, "neutral horn angle from +x", positive=False, default=0.0),
    }
    requirements = {  # noqa: RUF012
        "transmission_angle": od.RequirementInfo(
            "band",
            ANGLE,
            "coupler to horn (at H) and rod to rocker arm (at Q)",
            valid=(0.0, np.pi),
        ),
        "rod_inclination_max": od.RequirementInfo(
            "value", ANGLE, "connecting rod to the screw axis", valid=(0.0, np.pi / 3)
        ),
    }
    pin_shear_planes = 2
    size_description = "sum of the links R + l_c + r_c + r_q + l_r"
    bench_families = {"double_rocker_backlash": ("backlash",)}  # noqa: RUF012

    # --- positions -------------------------------------------------------------------
    def solve_chain(self, phi):
        """H, K, C, Q, N (pairs (x, y), mm) and the two reaches: sin^2 of the angle at H
        between H -> K and H -> C (0: the four-bar at a toggle), cos^2 of the rod's
        inclination to the screw axis."""
        a = self.phi0 + phi
        H = (self.R * m.cos(a), self.R * m.sin(a))
        K = (self.k_x + 0.0 * phi, self.k_y + 0.0 * phi)
        D = _sub(K, H)
        d2 = self._safe(_dot(D, D))  # K on H: no division by zero on the solver's path
        along = (self.l_c**2 - self.r_c**2 + d2) / (2.0 * d2)  # H -> C along D, over |D|
        four_bar_reach = 1.0 - along**2 * d2 / self.l_c**2
        across = self.l_c / m.sqrt(d2) * m.sqrt_domain(four_bar_reach)
        T = _turn(D)
        C = (H[0] + along * D[0] + across * T[0], H[1] + along * D[1] + across * T[1])
        c, s, q = m.cos(self.gamma), m.sin(self.gamma), self.r_q / self.r_c
        KC = _sub(C, K)
        Q = (K[0] + q * (c * KC[0] - s * KC[1]), K[1] + q * (s * KC[0] + c * KC[1]))
        u, n = self.axis()
        height = _dot(n, Q) - self.e  # Q above the screw axis
        rod_reach = 1.0 - (height / self.l_r) ** 2
        x = _dot(u, Q) - self.l_r * m.sqrt_domain(rod_reach)
        N = (self.e * n[0] + x * u[0], self.e * n[1] + x * u[1])
        return H, K, C, Q, N, x, four_bar_reach, rod_reach

    def axis(self):
        """Unit vectors along (u) and across (n) the screw axis."""
        cb, sb = m.cos(self.beta), m.sin(self.beta)
        return (cb, sb), (-sb, cb)

    def points(self, phi):
        """H, K, C, Q, N: each a pair (x, y) in mm."""
        return self.solve_chain(phi)[:5]

    def nut_position(self, phi):
        return self.solve_chain(phi)[5]

    def _safe(self, rate):
        return m.away_from_zero(rate) if self.guarded else rate

    def rates(self, phi):
        """g_c, h_c, g_r, dpsi/dphi, v . u and the unit vectors w, v of the derivation."""
        H, K, C, Q, N = self.points(phi)
        w = ((C[0] - H[0]) / self.l_c, (C[1] - H[1]) / self.l_c)
        v = ((Q[0] - N[0]) / self.l_r, (Q[1] - N[1]) / self.l_r)
        u, _ = self.axis()
        g_c = -_dot(w, _turn(H))
        h_c = _dot(w, _turn(_sub(C, K)))
        g_r = _dot(v, _turn(_sub(Q, K)))
        turn = -g_c / self._safe(h_c)
        return g_c, h_c, g_r, turn, _dot(v, u), w, v

    def nut_velocity(self, phi):
        _, _, g_r, turn, vu, _, _ = self.rates(phi)
        return g_r * turn / self._safe(vu)

    # --- clearance chain -------------------------------------------------------------
    def joints(self, phi, M_h, pin=None):
        g_c, _, g_r, turn, _, w, v = self.rates(phi)
        s = self.sensitivity_axial(phi)
        chain = [
            od.Joint("A screw bearings", "A", sensitivity=s),
            od.Joint("B screw/nut", "B", sensitivity=s),
            od.Joint("O output shaft", "O", angular=True),
        ]
        if pin is None:
            return chain
        S_c = -1.0 / self._safe(g_c)  # coupler tension per unit hinge moment
        S_r = -1.0 / self._safe(g_r * turn)  # rod tension per unit hinge moment
        S_k = m.sqrt((S_c * w[0] + S_r * v[0]) ** 2 + (S_c * w[1] + S_r * v[1]) ** 2)
        rod, coupler, pivot = M_h * S_r, M_h * S_c, M_h * S_k
        return [
            *chain,
            od.Joint("rod pin (nut)", sensitivity=S_r, force=rod, pin=pin),
            od.Joint("rod pin (rocker)", sensitivity=S_r, force=rod, pin=pin),
            od.Joint("rocker pivot", sensitivity=S_k, force=pivot, pin=pin),
            od.Joint("coupler pin (rocker)", sensitivity=S_c, force=coupler, pin=pin),
            od.Joint("coupler pin (horn)", sensitivity=S_c, force=coupler, pin=pin),
        ]

    # --- rows ------------------------------------------------------------------------
    def assembly_rows(self, phi):  # the solver stays where both square roots are real
        *_, four_bar, rod = self.solve_chain(phi)
        return [
            od.Rows("four_bar_reach", four_bar, 0.05, None, "", "sin^2 of the angle at H, K to C"),
            od.Rows("rod_reach", rod, 0.25, None, "", "cos^2 of the rod's inclination"),
        ]

    def transmission_cosines(self, phi):
        """Cosines of the transmission angles: coupler to horn at H (between H -> O and
        H -> C), rod to rocker arm at Q (between Q -> K and Q -> N)."""
        H, K, C, Q, N = self.points(phi)
        at_H = -_dot(H, _sub(C, H)) / (self.R * self.l_c)
        at_Q = _dot(_sub(K, Q), _sub(N, Q)) / (self.r_q * self.l_r)
        return at_H, at_Q

    def requirement_rows(self, name, value, phi):
        if name == "transmission_angle":  # a band: value.min, value.max (rad) or None
            lower = None if value.max is None else float(np.cos(value.max))
            upper = None if value.min is None else float(np.cos(value.min))
            at_H, at_Q = self.transmission_cosines(phi)
            return [
                od.Rows(
                    f"{name}_{where}",
                    cosine,
                    lower,
                    upper,
                    "",
                    f"transmission angle {text} (its cosine)",
                    display=degrees_of_cosine,
                    display_unit="deg",
                )
                for where, text, cosine in (
                    ("horn", "coupler to horn", at_H),
                    ("rocker", "rod to rocker arm", at_Q),
                )
            ]
        if name == "rod_inclination_max":  # a value (rad)
            Q = self.points(phi)[3]
            _, n = self.axis()
            sine = (_dot(n, Q) - self.e) / self.l_r
            bound = float(np.sin(value))
            return [
                od.Rows(
                    name,
                    sine,
                    -bound,
                    bound,
                    "",
                    "rod inclination to the screw axis (its sine)",
                    display=degrees_of_sine,
                    display_unit="deg",
                )
            ]
        return super().requirement_rows(name, value, phi)

    # --- size, sketch, benchmark -----------------------------------------------------
    def size(self):
        return self.R + self.l_c + self.r_c + self.r_q + self.l_r

    def sketch(self, phi):
        H, K, C, Q, N = (tuple(float(c) for c in p) for p in self.points(float(phi)))
        u, _ = self.axis()
        u = (float(u[0]), float(u[1]))
        start = (N[0] - 20.0 * u[0], N[1] - 20.0 * u[1])
        reach = _dot(u, _sub(Q, N))
        end = (N[0] + reach * u[0], N[1] + reach * u[1])
        links = [[(0.0, 0.0), H], [H, C], [C, K, Q], [Q, N]]
        return od.Sketch(links=links, pivots=[(0.0, 0.0), K], slider=N, axis=(start, end))

    @classmethod
    def bench_template(cls):
        variables = {k: {"lower": lo, "upper": hi} for k, (lo, hi) in BOUNDS.items()}
        return {**variables, "p": None}, {
            "transmission_angle": {"min": "45 deg", "max": "135 deg"},
            "rod_inclination_max": "35 deg",
        }


od.register_mechanism(DoubleRocker, replace=True)

#: Bounds of the free variables: the rocker's pivot anywhere in the bay around the horn,
#: its arms at least 30 deg apart, the screw mounted at any inclination from straight
#: down (-90 deg) to pointing back (180 deg) and at any offset. (The neutral horn angle
#: is fixed: with it free, turning the whole linkage about O would leave every quantity
#: unchanged, a valley of optima.)
BOUNDS = {
    "R": ("40 mm", "90 mm"),
    "l_c": ("80 mm", "160 mm"),
    "r_c": ("30 mm", "70 mm"),
    "r_q": ("30 mm", "70 mm"),
    "gamma": ("30 deg", "330 deg"),
    "l_r": ("100 mm", "200 mm"),
    "k_x": ("-150 mm", "170 mm"),
    "k_y": ("-200 mm", "180 mm"),
    "e": ("-200 mm", "260 mm"),
    "beta": ("-90 deg", "180 deg"),
}

#: Fixed values of the other variables (problem-file quantities).
FIXED = {
    "phi0": "0 deg",
}


def problem(objective: str = "backlash") -> dict:
    """The test problem: least worst-case backlash (or ripple) of the double rocker, with
    eleven free variables (the ten of :data:`BOUNDS` and the pin's d).

    Its landscape is multimodal: each configuration (rod arm turned either way from the
    coupler arm, rocker pivot above or below the horn's axis) has its own optimum, for the
    backlash 0.11452, 0.11586, 0.11927 and 0.12107 deg, and more local optima lie inside
    them. ``double_rocker_optimum.json`` holds the global optimum of each objective found
    by the independent reference (``double_rocker_reference.py``)."""
    if objective not in ("backlash", "ripple"):
        raise ValueError(f"objective {objective!r}: use 'backlash' or 'ripple'")
    return {
        "name": f"double_rocker_min_{objective}",
        "description": "screw-driven double rocker, multimodal test problem",
        "mechanism": "double_rocker",
        "variables": {
            **{k: {"lower": lo, "upper": hi} for k, (lo, hi) in BOUNDS.items()},
            **FIXED,
            "p": "5 mm",
            "i_a": 2,
            "d": {"lower": "4 mm", "upper": "30 mm"},
            "pin_length_ratio": 1.5,
        },
        "requirements": {
            "deflection": {"min": "-25 deg", "max": "25 deg", "points": 21},
            "hinge_moment": "300 N*m",
            "mean_ratio": {"min": 120, "max": 180},
            "nut_travel_max": "100 mm",
            "transmission_angle": {"min": "45 deg", "max": "135 deg"},
            "rod_inclination_max": "35 deg",
            "pin_bearing_pressure_max": "100 MPa",
            "pin_shear_stress_max": "200 MPa",
            "fit": "H7/g6",
            "fit_clearance": "max",
        },
        "clearances": {"A": "0.005 mm", "B": "0.01 mm", "O": "0.005 deg"},
        "materials": {"pin": {"E": "2.1e5 MPa", "nu": 0.3}},
        "objective": {"minimize": objective},
    }
