"""A screw-driven knee (toggle) linkage, written from docs/mechanisms.md with public names
only (``optdesign`` and ``optdesign.math``), as a user would write it.

Layout (mm; output axis O at the origin). The horn pin H = R (cos a, sin a), a = phi0 +
phi, turns about O. A coupler of length l_c joins H to the knee pin K; a ground link of
length r_g joins K to the ground pivot G = (g_x, g_y) below the horn. The horn, coupler
and ground link are a four-bar O-H-K-G whose coupler and ground link form the knee; the
knee lies on the left of the line G -> H (the knee bent towards the screw). A pushrod of
length l_n joins K to the nut pin N = (x, e) on the screw axis y = e, the nut on the left
of K. The screw pushes the knee sideways: as the nut moves right (x grows) the knee
straightens, |GH| grows, H rises and the horn turns by +phi. When coupler and ground link
come into line (knee angle 180 deg) the linkage is at its toggle: the ratio dx/dphi grows
without bound (the knee requirement keeps away from it).

Four pins, one of them joining three links: the nut pin N (pushrod eye), the knee pin K
(pressed into the ground link's fork; the pushrod's and the coupler's eyes turn on it:
two running clearances), the horn pin H (coupler eye) and the ground pivot G (ground
link eye). One pin size serves all of them.

Derivation (virtual work; u_c = (K - H)/l_c, u_g = (K - G)/r_g, u_n = (K - N)/l_n the
unit vectors of the three two-force members, dH = dH/dphi = turn(H), turn(v) = (-v_y,
v_x) the velocity of a point at v about a pivot at unit angular speed):

  coupler, knee held (the nut held holds the pushrod and ground link, hence K):
      g_c = -u_c . dH                     rate at which the coupler would lengthen
  ground link turns at w = dpsi/dphi = (u_c . dH) / (u_c . turn(K - G)),
      so dK = w turn(K - G)
  pushrod, nut held (coupler and ground link rigid: K moves on the four-bar):
      g_n = u_n . dK,          dx/dphi = g_n / u_n_x
  ground link, nut held (pushrod and coupler rigid: K turns about N):
      dK' = lam turn(u_n),  lam = (u_c . dH) / (u_c . turn(u_n)),   g_g = u_g . dK'

A clearance delta in a member's joint turns the horn by delta / g (nut held); the
member's force is M_h / g. So the sensitivities are 1/g and the forces M_h/g; the nut
force is M_h / (dx/dphi) (the framework's, from ``nut_velocity``).

Requirements of its own: the transmission angle at the horn pin, the knee angle (its
largest value keeps the toggle away) and the push angle between pushrod and coupler (the
screw pushes across the knee; near 0 or 180 deg the ground link would carry no load and
its pins' backlash would turn through a kink, |S| = 0, that no smooth solver likes).

``problem(objective)`` is the design problem (a dict for ``od.load``) with ten free
variables; ``BOUNDS``, ``FIXED`` and ``REQUIREMENTS`` hold its numbers as plain floats
(internal units, angles of requirements in degrees), so that an independent model
(``knee_reference.py``) reads the same problem without optdesign's unit parser. The
bounds were chosen (tests/multimodal_mechanisms/knee_optimum.json says how) so that the
backlash has two local optima: the global one, a layout with the ground pivot left of the
horn and the screw axis level with the hinge, has a small region of attraction; the
other, with the pivot on the right and the screw axis at its lowest, a large one.
"""

from __future__ import annotations

import math

import numpy as np

import optdesign as od
from optdesign import math as m

LENGTH, ANGLE = "length", "angle"


def _dot(u, v):
    return u[0] * v[0] + u[1] * v[1]


def _cross(u, v):
    return u[0] * v[1] - u[1] * v[0]


def _turn(v):  # v turned by +90 deg
    return (-v[1], v[0])


def degrees_of_cosine(value):
    """The angle (deg) whose cosine a row bounds: how the knee-angle row is read."""
    return np.degrees(np.arccos(np.clip(np.asarray(value, dtype=float), -1.0, 1.0)))


class KneeToggle(od.Mechanism):
    name = "knee_toggle"
    title = "knee (toggle) linkage"
    variables = {  # noqa: RUF012 - a plug-in declares its variables as a plain dict
        "R": od.VariableInfo(LENGTH, "horn radius"),
        "l_c": od.VariableInfo(LENGTH, "coupler length (horn pin to knee)"),
        "r_g": od.VariableInfo(LENGTH, "ground link length (knee to ground pivot)"),
        "g_x": od.VariableInfo(LENGTH, "ground pivot abscissa", positive=False),
        "g_y": od.VariableInfo(LENGTH, "ground pivot ordinate", positive=False),
        "l_n": od.VariableInfo(LENGTH, "pushrod length (nut to knee)"),
        "e": od.VariableInfo(LENGTH, "screw axis ordinate", positive=False),
        "phi0": od.VariableInfo(ANGLE, "neutral horn angle", positive=False, default=0.0),
    }
    requirements = {  # noqa: RUF012 - as variables
        "transmission_angle": od.RequirementInfo(
            "band", ANGLE, "angle between horn and coupler at the horn pin", valid=(0.0, np.pi)
        ),
        "knee_angle": od.RequirementInfo(
            "band",
            ANGLE,
            "angle at the knee between coupler and ground link (180 deg: the toggle)",
            valid=(0.0, np.pi),
        ),
        "push_angle": od.RequirementInfo(
            "band",
            ANGLE,
            "angle at the knee between pushrod and coupler (the push across the knee)",
            valid=(0.0, np.pi),
        ),
    }
    pin_shear_planes = 2
    size_description = "sum of the links R + l_c + r_g + l_n"
    bench_families = {"knee_toggle_backlash": ("backlash",)}  # noqa: RUF012

    # --- positions ------------------------------------------------------------------------
    def solve_chain(self, phi):
        """H, K, N (each a pair (x, y), mm) and the two reaches: sin^2 of the angle at G
        between G -> H and G -> K (0: the knee straight or folded), cos^2 of the pushrod's
        inclination to the screw axis."""
        a = self.phi0 + phi
        H = (self.R * m.cos(a), self.R * m.sin(a))
        D = (H[0] - self.g_x, H[1] - self.g_y)
        d2 = _dot(D, D)
        along = (self.r_g**2 - self.l_c**2 + d2) / (2.0 * d2)  # G -> K along D, over |D|
        reach = 1.0 - along**2 * d2 / self.r_g**2
        across = self.r_g / m.sqrt(d2) * m.sqrt_domain(reach)  # and across D (left), over |D|
        T = _turn(D)
        K = (self.g_x + along * D[0] + across * T[0], self.g_y + along * D[1] + across * T[1])
        push = 1.0 - ((K[1] - self.e) / self.l_n) ** 2
        N = (K[0] - self.l_n * m.sqrt_domain(push), self.e + 0.0 * phi)
        return H, K, N, reach, push

    def points(self, phi):
        """H, K, N: the horn pin, the knee pin and the nut pin (mm)."""
        return self.solve_chain(phi)[:3]

    def nut_position(self, phi):
        return self.points(phi)[2][0]

    def _div(self, x):
        return m.away_from_zero(x) if self.guarded else x

    def rates(self, phi):
        """g_n, g_c, g_g of the derivation and the pushrod's direction cosine u_n_x."""
        H, K, N = self.points(phi)
        G = (self.g_x, self.g_y)
        dH = _turn(H)
        u_c = ((K[0] - H[0]) / self.l_c, (K[1] - H[1]) / self.l_c)
        u_g = ((K[0] - G[0]) / self.r_g, (K[1] - G[1]) / self.r_g)
        u_n = ((K[0] - N[0]) / self.l_n, (K[1] - N[1]) / self.l_n)
        drive = _dot(u_c, dH)
        w = drive / self._div(_dot(u_c, _turn((K[0] - G[0], K[1] - G[1]))))
        g_n = w * _dot(u_n, _turn((K[0] - G[0], K[1] - G[1])))
        g_c = -drive
        lam = drive / self._div(_dot(u_c, _turn(u_n)))
        g_g = lam * _dot(u_g, _turn(u_n))
        return g_n, g_c, g_g, u_n[0]

    def nut_velocity(self, phi):  # closed form: dx/dphi = g_n / u_n_x
        g_n, _, _, u_nx = self.rates(phi)
        return g_n / self._div(u_nx)

    # --- clearance chain --------------------------------------------------------------------
    def joints(self, phi, M_h, pin=None):
        g_n, g_c, g_g, _ = self.rates(phi)
        S_n, S_c, S_g = 1.0 / self._div(g_n), 1.0 / self._div(g_c), 1.0 / self._div(g_g)
        s = self.sensitivity_axial(phi)
        chain = [
            od.Joint("A screw bearings", "A", sensitivity=s),
            od.Joint("B screw/nut", "B", sensitivity=s),
            od.Joint("O output shaft", "O", angular=True),
        ]
        if pin is None:
            return chain
        F_n, F_c, F_g = M_h * S_n, M_h * S_c, M_h * S_g
        return [
            *chain,
            od.Joint("pushrod pin (nut)", sensitivity=S_n, force=F_n, pin=pin),
            od.Joint("knee pin (pushrod eye)", sensitivity=S_n, force=F_n, pin=pin),
            od.Joint("knee pin (coupler eye)", sensitivity=S_c, force=F_c, pin=pin),
            od.Joint("horn pin (coupler eye)", sensitivity=S_c, force=F_c, pin=pin),
            od.Joint("ground pivot (ground link eye)", sensitivity=S_g, force=F_g, pin=pin),
        ]

    # --- requirements -----------------------------------------------------------------------
    def assembly_rows(self, phi):
        _, _, _, reach, push = self.solve_chain(phi)
        return [
            od.Rows("knee_reach", reach, 0.01, None, "", "sin^2 of the ground link's angle to G-H"),
            od.Rows("push_reach", push, 0.25, None, "", "cos^2 of the pushrod's inclination"),
        ]

    def requirement_rows(self, name, value, phi):  # a band: value.min / value.max
        H, K, N = self.points(phi)
        if name == "transmission_angle":
            to_O, to_K = (-H[0], -H[1]), (K[0] - H[0], K[1] - H[1])
            mu = m.arctan2(_cross(to_O, to_K), _dot(to_O, to_K))
            return [
                od.Rows(
                    name, mu, value.min, value.max, "rad", "horn to coupler", display_unit="deg"
                )
            ]
        # the knee and push angles: bounded through their cosines (smooth through 180 deg)
        to_H = (H[0] - K[0], H[1] - K[1])
        if name == "knee_angle":
            other, length, what = (self.g_x - K[0], self.g_y - K[1]), self.r_g, "knee"
        else:
            other, length, what = (N[0] - K[0], N[1] - K[1]), self.l_n, "push"
        cosine = _dot(to_H, other) / (self.l_c * length)
        lower = None if value.max is None else math.cos(value.max)
        upper = None if value.min is None else math.cos(value.min)
        return [
            od.Rows(
                name,
                cosine,
                lower,
                upper,
                "",
                f"cosine of the {what} angle",
                display=degrees_of_cosine,
                display_unit="deg",
            )
        ]

    def size(self):
        return self.R + self.l_c + self.r_g + self.l_n

    def sketch(self, phi):
        H, K, N = (tuple(float(c) for c in p) for p in self.points(float(phi)))
        G = (float(self.g_x), float(self.g_y))
        axis = ((N[0] - 20.0, N[1]), (K[0], N[1]))
        links = [[(0.0, 0.0), H], [H, K], [G, K], [K, N]]
        return od.Sketch(links=links, pivots=[(0.0, 0.0), G], slider=N, axis=axis)

    @classmethod
    def bench_template(cls):
        variables = {
            k: {"lower": f"{lo} mm", "upper": f"{hi} mm"}
            for k, (lo, hi) in BOUNDS.items()
            if k in LINKS
        }
        variables["phi0"] = {"lower": "-0.8 rad", "upper": "1.3 rad"}
        return {**variables, "p": None}, {
            "transmission_angle": {"min": "40 deg", "max": "140 deg"},
            "knee_angle": {"max": "165 deg"},
            "push_angle": {"min": "45 deg", "max": "135 deg"},
        }


od.register_mechanism(KneeToggle, replace=True)  # a re-import (another module path) replaces

#: The mechanism's length variables (mm).
LINKS = ("R", "l_c", "r_g", "g_x", "g_y", "l_n", "e")

#: Bounds of the free variables, internal units (mm; phi0 in rad).
BOUNDS = {
    "R": (40.0, 100.0),
    "l_c": (50.0, 150.0),
    "r_g": (50.0, 150.0),
    "g_x": (-90.0, 200.0),
    "g_y": (-240.0, -80.0),
    "l_n": (60.0, 200.0),
    "e": (-120.0, 200.0),
    "phi0": (-0.8, 1.3),
    "p": (2.0, 10.0),
    "d": (4.0, 30.0),
}

#: Fixed variables.
FIXED = {"i_a": 2.0, "pin_length_ratio": 1.5}

#: The requirements: internal units (N*mm, mm, MPa), angles in degrees (as the file
#: writes them; optdesign converts them to rad).
REQUIREMENTS = {
    "deflection_deg": (-25.0, 25.0, 51),
    "hinge_moment": 300e3,
    "mean_ratio": (120.0, 180.0),
    "nut_travel_max": 100.0,
    "transmission_angle_deg": (40.0, 140.0),
    "knee_angle_max_deg": 165.0,
    "push_angle_deg": (45.0, 135.0),
    "pin_bearing_pressure_max": 100.0,
    "pin_shear_stress_max": 200.0,
    "pin_shear_planes": 2,
    "fit": "H7/g6",
    "E": 2.1e5,
    "nu": 0.3,
}

OBJECTIVES = ("backlash", "ripple")


def _q(value, unit):
    return f"{float(value)!r} {unit}"  # repr: the float read back exactly


def problem(objective: str = "backlash") -> dict:
    """The knee's design problem as a dict for ``od.load``: ten free variables (the seven
    lengths, phi0, the lead p and the pin diameter d), minimising ``objective``
    ("backlash" or "ripple")."""
    if objective not in OBJECTIVES:
        raise ValueError(f"objective {objective!r}: use one of {OBJECTIVES}")
    r = REQUIREMENTS
    variables = {}
    for k, (lo, hi) in BOUNDS.items():
        unit = "rad" if k == "phi0" else "mm"
        variables[k] = {"lower": _q(lo, unit), "upper": _q(hi, unit)}
    variables.update(FIXED)
    lo, hi, points = r["deflection_deg"]
    mu_lo, mu_hi = r["transmission_angle_deg"]
    return {
        "name": f"knee_toggle_min_{objective}",
        "mechanism": "knee_toggle",
        "variables": variables,
        "requirements": {
            "deflection": {"min": _q(lo, "deg"), "max": _q(hi, "deg"), "points": points},
            "hinge_moment": _q(r["hinge_moment"], "N*mm"),
            "mean_ratio": {"min": r["mean_ratio"][0], "max": r["mean_ratio"][1]},
            "nut_travel_max": _q(r["nut_travel_max"], "mm"),
            "transmission_angle": {"min": _q(mu_lo, "deg"), "max": _q(mu_hi, "deg")},
            "knee_angle": {"max": _q(r["knee_angle_max_deg"], "deg")},
            "push_angle": {
                "min": _q(r["push_angle_deg"][0], "deg"),
                "max": _q(r["push_angle_deg"][1], "deg"),
            },
            "pin_bearing_pressure_max": _q(r["pin_bearing_pressure_max"], "MPa"),
            "pin_shear_stress_max": _q(r["pin_shear_stress_max"], "MPa"),
            "pin_shear_planes": r["pin_shear_planes"],
            "fit": r["fit"],
            "fit_clearance": "max",
        },
        "materials": {"pin": {"E": _q(r["E"], "MPa"), "nu": r["nu"]}},
        "objective": {"minimize": objective},
    }
