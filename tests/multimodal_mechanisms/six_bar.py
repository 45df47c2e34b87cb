"""A screw-driven Watt six-bar, written from docs/mechanisms.md with public names only.

The links: the ground (a ternary link: the screw, the rocker's pivot K and the output
axis O), the nut, the pushrod (nut pin N to P1), the ternary rocker (pivot K, arms to P1
and P2), the rod (P2 to the horn pin H) and the horn (H, O). Two loops: the nut drives
the rocker through the pushrod (a slider-rocker four-bar loop: ground, nut, pushrod,
rocker), and the rocker drives the horn through the rod (a four-bar loop: ground,
rocker, rod, horn). The rocker's arms may point anywhere (``gamma``, the angle from the
rod arm to the push arm): on opposite sides of K (a see-saw) or on one side (a lever
pivoted at its end), which is what makes the design landscape multimodal.

Geometry (mm, rad; output axis O at the origin):

- horn pin H = R (cos a, sin a), a = phi0 + phi;
- rocker pivot K = (k_x, k_y); rod arm end P2 = K + r2 (cos psi, sin psi), on the
  branch to the right of the direction K -> H (|P2 - H| = l2: a circle intersection);
- push arm end P1 = K + r1 (cos(psi + gamma), sin(psi + gamma));
- nut pin N = (x, e) on the screw axis y = e, behind P1 (|P1 - N| = l1, x < P1_x): the
  nut position is x.

Virtual work (u1 = (P1 - N)/l1, u2 = (P2 - H)/l2, turn(v) = v turned +90 deg):

  g2 = -u2 . dH/dphi         rate at which the rod lengthens as the horn turns, rocker held
  h2 = u2 . turn(P2 - K)      rate at which it lengthens as the rocker turns, horn held
  g1 = u1 . turn(P1 - K)      rate at which the pushrod lengthens as the rocker turns, nut held
  dpsi/dphi = -g2 / h2,       dx/dphi = (g1 / u1_x) dpsi/dphi
  rod compression F2 = M_h / g2, pushrod compression F1 = M_h / (g1 dpsi/dphi);
  the ground's reaction on the rocker F_K = -(F1 u1 + F2 u2).

A pin carrying the force F (N) turns the output by delta |F| / M_h for a clearance delta
taken up along its load (virtual work with the nut held): the sensitivities are
1/(g1 dpsi/dphi) for both pushrod pins, 1/g2 for both rod pins and |F_K| / M_h for the
rocker's pivot. Five pins, one size.
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


def degrees_of_cosine(c):
    """The angle (deg) whose cosine a row bounds (a row's ``display``)."""
    return np.degrees(np.arccos(np.clip(np.asarray(c, dtype=float), -1.0, 1.0)))


def degrees_of_sine(s):
    """The angle (deg) whose sine a row bounds (a row's ``display``)."""
    return np.degrees(np.arcsin(np.clip(np.asarray(s, dtype=float), -1.0, 1.0)))


class WattSixBar(od.Mechanism):
    name = "watt_six_bar"
    title = "Watt six-bar"
    variables = {  # noqa: RUF012 - a plug-in declares its variables as a plain dict
        "R": od.VariableInfo(LENGTH, "horn radius"),
        "l2": od.VariableInfo(LENGTH, "rod length (rocker to horn)"),
        "r2": od.VariableInfo(LENGTH, "rocker's rod arm"),
        "r1": od.VariableInfo(LENGTH, "rocker's push arm"),
        "l1": od.VariableInfo(LENGTH, "pushrod length (nut to rocker)"),
        "k_x": od.VariableInfo(LENGTH, "rocker pivot abscissa", positive=False),
        "k_y": od.VariableInfo(LENGTH, "rocker pivot ordinate", positive=False),
        "e": od.VariableInfo(LENGTH, "screw axis ordinate", positive=False),
        "gamma": od.VariableInfo(ANGLE, "angle from the rod arm to the push arm", positive=False),
        "phi0": od.VariableInfo(ANGLE, "neutral horn angle", positive=False),
    }
    requirements = {  # noqa: RUF012
        "transmission_angle": od.RequirementInfo(
            "band", ANGLE, "angle between horn and rod at the horn pin", valid=(0.0, np.pi)
        ),
        "rocker_transmission_angle": od.RequirementInfo(
            "band", ANGLE, "angle between rod and rocker arm at the rocker pin", valid=(0.0, np.pi)
        ),
        "pushrod_inclination_max": od.RequirementInfo(
            "value", ANGLE, "largest inclination of the pushrod to the screw", valid=(0.0, 1.5)
        ),
    }
    pin_shear_planes = 2
    size_description = "sum of the links R + l2 + r2 + r1 + l1"
    bench_families = {"watt_six_bar_backlash": ("backlash",)}  # noqa: RUF012

    # --- position ------------------------------------------------------------------------
    def solve_chain(self, phi):
        """H, K, P2, P1, N (pairs (x, y), mm) and the two reaches: sin^2 of the angle at K
        between K -> H and K -> P2 (0: rod and arm in line, the loop at its limit) and
        cos^2 of the pushrod's inclination to the screw."""
        a = self.phi0 + phi
        H = (self.R * m.cos(a), self.R * m.sin(a))
        K = (self.k_x + 0.0 * phi, self.k_y + 0.0 * phi)
        D = (H[0] - K[0], H[1] - K[1])
        d2 = _dot(D, D)
        along = (self.r2**2 - self.l2**2 + d2) / (2.0 * d2)  # K -> P2 along D, over |D|
        rod_reach = 1.0 - along**2 * d2 / self.r2**2
        across = self.r2 / m.sqrt(d2) * m.sqrt_domain(rod_reach)  # across D, over |D|
        T = _turn(D)
        P2 = (K[0] + along * D[0] - across * T[0], K[1] + along * D[1] - across * T[1])
        c, s = m.cos(self.gamma), m.sin(self.gamma)
        q = self.r1 / self.r2
        v = (P2[0] - K[0], P2[1] - K[1])
        P1 = (K[0] + q * (c * v[0] - s * v[1]), K[1] + q * (s * v[0] + c * v[1]))
        rise = (P1[1] - self.e) / self.l1  # sine of the pushrod's inclination
        push_reach = 1.0 - rise**2
        N = (P1[0] - self.l1 * m.sqrt_domain(push_reach), self.e + 0.0 * phi)
        return H, K, P2, P1, N, rod_reach, push_reach

    def points(self, phi):
        """H, K, P2, P1, N: each a pair (x, y) in mm."""
        return self.solve_chain(phi)[:5]

    def nut_position(self, phi):
        return self.solve_chain(phi)[4][0]

    def assembly_rows(self, phi):  # the solver stays where both square roots are real
        *_, rod, push = self.solve_chain(phi)
        return [
            od.Rows("rod_reach", rod, 0.05, None, "", "sin^2 of the rocker's angle to the rod"),
            od.Rows("push_reach", push, 0.25, None, "", "cos^2 of the pushrod's inclination"),
        ]

    # --- rates, forces, clearance chain --------------------------------------------------
    def rates(self, phi):
        """g1, g2, dpsi/dphi and the unit vectors u1, u2 of the module docstring."""
        a = self.phi0 + phi
        H, K, P2, P1, N = self.points(phi)
        u2 = ((P2[0] - H[0]) / self.l2, (P2[1] - H[1]) / self.l2)
        u1 = ((P1[0] - N[0]) / self.l1, (P1[1] - N[1]) / self.l1)
        g2 = -_dot(u2, (-self.R * m.sin(a), self.R * m.cos(a)))
        h2 = _dot(u2, _turn((P2[0] - K[0], P2[1] - K[1])))
        g1 = _dot(u1, _turn((P1[0] - K[0], P1[1] - K[1])))
        return g1, g2, -g2 / h2, u1, u2

    def nut_velocity(self, phi):  # closed form: dx/dphi = (g1 / u1_x) dpsi/dphi
        g1, _, turn, u1, _ = self.rates(phi)
        return g1 * turn / u1[0]

    def pin_loads(self, phi, M_h):
        """(F1, F2, |F_K|): pushrod and rod compressions and the pivot's reaction (N)."""
        g1, g2, turn, u1, u2 = self.rates(phi)
        F1, F2 = M_h / (g1 * turn), M_h / g2
        FK = m.sqrt((F1 * u1[0] + F2 * u2[0]) ** 2 + (F1 * u1[1] + F2 * u2[1]) ** 2)
        return F1, F2, FK

    def joints(self, phi, M_h, pin=None):
        s = self.sensitivity_axial(phi)
        chain = [
            od.Joint("A screw bearings", "A", sensitivity=s),
            od.Joint("B screw/nut", "B", sensitivity=s),
            od.Joint("O output shaft", "O", angular=True),
        ]
        if pin is None:
            return chain
        F1, F2, FK = self.pin_loads(phi, M_h)
        S1, S2, SK = F1 / M_h, F2 / M_h, FK / M_h
        return [
            *chain,
            od.Joint("pushrod pin (nut)", sensitivity=S1, force=F1, pin=pin),
            od.Joint("pushrod pin (rocker)", sensitivity=S1, force=F1, pin=pin),
            od.Joint("rocker pivot K", sensitivity=SK, force=FK, pin=pin),
            od.Joint("rod pin (rocker)", sensitivity=S2, force=F2, pin=pin),
            od.Joint("rod pin (horn)", sensitivity=S2, force=F2, pin=pin),
        ]

    # --- requirements --------------------------------------------------------------------
    def angles(self, phi):
        """Cosines of the transmission angles (at the horn pin: H -> O against H -> P2; at
        the rocker pin: P2 -> K against P2 -> H) and the sine of the pushrod's
        inclination."""
        H, K, P2, P1, _ = self.points(phi)
        to_P2 = (P2[0] - H[0], P2[1] - H[1])
        horn = _dot((-H[0], -H[1]), to_P2) / (self.R * self.l2)
        to_K, to_H = (K[0] - P2[0], K[1] - P2[1]), (-to_P2[0], -to_P2[1])
        rocker = _dot(to_K, to_H) / (self.r2 * self.l2)
        return horn, rocker, (P1[1] - self.e) / self.l1

    def requirement_rows(self, name, value, phi):
        horn, rocker, rise = self.angles(phi)
        if name == "pushrod_inclination_max":
            s = float(np.sin(value))
            return [
                od.Rows(
                    name,
                    rise,
                    -s,
                    s,
                    "",
                    "pushrod's inclination to the screw (its sine bounded)",
                    display=degrees_of_sine,
                    display_unit="deg",
                )
            ]
        cosine = horn if name == "transmission_angle" else rocker
        lower = None if value.max is None else float(np.cos(value.max))
        upper = None if value.min is None else float(np.cos(value.min))
        what = "horn to rod" if name == "transmission_angle" else "rod to rocker arm"
        return [
            od.Rows(
                name,
                cosine,
                lower,
                upper,
                "",
                f"angle {what} (its cosine bounded)",
                display=degrees_of_cosine,
                display_unit="deg",
            )
        ]

    # --- size, sketch, benchmark ---------------------------------------------------------
    def size(self):
        return self.R + self.l2 + self.r2 + self.r1 + self.l1

    def sketch(self, phi):
        H, K, P2, P1, N = (tuple(float(c) for c in p) for p in self.points(float(phi)))
        axis = ((N[0] - 20.0, N[1]), (max(P1[0], N[0]) + 20.0, N[1]))
        links = [[(0.0, 0.0), H], [H, P2], [P2, K, P1], [P1, N]]
        return od.Sketch(links=links, pivots=[(0.0, 0.0), K], slider=N, axis=axis)

    @classmethod
    def bench_template(cls):
        variables = {k: _bounds(k, lo, hi) for k, (lo, hi) in BOUNDS.items() if k != "d"}
        variables.update({k: f"{v:g} mm" for k, v in FIXED.items()})
        requirements = {
            "transmission_angle": {"min": "40 deg", "max": "140 deg"},
            "rocker_transmission_angle": {"min": "40 deg", "max": "140 deg"},
            "pushrod_inclination_max": "30 deg",
        }
        return {**variables, "p": None}, requirements


od.register_mechanism(WattSixBar, replace=True)

#: Bounds of the free variables: mm, and deg for the angles.
BOUNDS = {
    "l2": (60.0, 160.0),
    "r2": (25.0, 70.0),
    "r1": (25.0, 70.0),
    "k_x": (-150.0, 150.0),
    "k_y": (-150.0, 150.0),
    "e": (-150.0, 150.0),
    "gamma": (-180.0, 180.0),
    "phi0": (-180.0, 180.0),
    "d": (3.0, 20.0),
}
ANGLES = ("gamma", "phi0")
#: Fixed variables (mm): the horn radius and the pushrod's length.
FIXED = {"R": 70.0, "l1": 80.0}
#: The backlash the ripple problem allows (with no cap the six-bar reaches a ripple of
#: zero on a continuum of designs).
BACKLASH_MAX = "0.14 deg"


def _bounds(name, lo, hi):
    unit = "deg" if name in ANGLES else "mm"
    return {"lower": f"{lo:g} {unit}", "upper": f"{hi:g} {unit}"}


def problem(objective="backlash"):
    """The problem dict: every variable of :data:`BOUNDS` free (nine, the pin diameter
    ``d`` among them), the horn radius and the pushrod's length (:data:`FIXED`), the
    screw lead and the gear fixed; ``objective`` is ``"backlash"`` (the worst-case
    backlash of the five pins and the fixed clearances) or ``"ripple"`` (the ratio
    ripple, with the backlash capped at :data:`BACKLASH_MAX`)."""
    if objective not in ("backlash", "ripple"):
        raise ValueError(f"objective {objective!r}: use 'backlash' or 'ripple'")
    out = {
        "name": f"watt_six_bar_min_{objective}",
        "mechanism": "watt_six_bar",
        "variables": {
            **{k: _bounds(k, lo, hi) for k, (lo, hi) in BOUNDS.items()},
            **{k: f"{v:g} mm" for k, v in FIXED.items()},
            "p": "5 mm",
            "i_a": 2,
            "pin_length_ratio": 1.5,
        },
        "requirements": {
            "deflection": {"min": "-25 deg", "max": "25 deg", "points": 21},
            "hinge_moment": "300 N*m",
            "mean_ratio": {"min": 120, "max": 160},
            "nut_travel_max": "80 mm",
            "transmission_angle": {"min": "40 deg", "max": "140 deg"},
            "rocker_transmission_angle": {"min": "40 deg", "max": "140 deg"},
            "pushrod_inclination_max": "30 deg",
            "pin_bearing_pressure_max": "100 MPa",
            "pin_shear_stress_max": "200 MPa",
            "fit": "H7/g6",
        },
        "clearances": {"A": "0.005 mm", "B": "0.01 mm", "O": "0.005 deg"},
        "objective": {"minimize": objective},
    }
    if objective == "ripple":
        out["requirements"]["backlash_max"] = BACKLASH_MAX
    return out
