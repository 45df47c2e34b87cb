"""A mechanism of your own with four pins - a bell crank: the nut pushes a pushrod onto
one arm of a bell crank whose other arm drives the horn through a second rod. Written
from docs/mechanisms.md with public names only; run it as a script.

Output axis O at the origin; the horn pin H = R (sin a, cos a), a = phi0 + phi. The crank
turns about K = (k_x, k_y): its rod arm ends at P2 (|P2 - K| = r2, |P2 - H| = l2, the
branch on the right of K -> H), its push arm at P1, turned gamma from the rod arm
(|P1 - K| = r1). The nut pin N slides on the screw axis y = e, behind P1: |P1 - N| = l1.

Hand derivation (virtual work; u1, u2 the unit vectors N -> P1 and H -> P2):
  g2 = -u2 . dH/dphi      rod length rate as the horn turns, crank held (mm/rad)
  h2 = u2 . dP2/dpsi      rod length rate as the crank turns, horn held
  g1 = u1 . dP1/dpsi      pushrod length rate as the crank turns, nut held
  dpsi/dphi = -g2 / h2,   dx/dphi = (g1 / u1_x) dpsi/dphi
  rod force F2 = M_h / g2, pushrod force F1 = M_h / (g1 dpsi/dphi);
  a clearance delta in a rod's pin turns the horn by delta * F / M_h: S2 = 1/g2, S1 = 1/(g1
  dpsi/dphi) (the nut holds the chain).
"""

import numpy as np

import optdesign as od
from optdesign import math as m

LENGTH, ANGLE = "length", "angle"


def _dot(u, v):
    return u[0] * v[0] + u[1] * v[1]


def _turn(v):  # v turned by +90 deg: the velocity of a point at v about the pivot
    return (-v[1], v[0])


@od.register_mechanism
class BellCrank(od.Mechanism):
    name = "bell_crank"
    title = "bell crank"
    variables = {
        "R": od.VariableInfo(LENGTH, "horn radius"),
        "l2": od.VariableInfo(LENGTH, "rod length (crank to horn)"),
        "r2": od.VariableInfo(LENGTH, "crank's rod arm"),
        "r1": od.VariableInfo(LENGTH, "crank's push arm"),
        "l1": od.VariableInfo(LENGTH, "pushrod length (nut to crank)"),
        "k_x": od.VariableInfo(LENGTH, "crank pivot abscissa", positive=False),
        "k_y": od.VariableInfo(LENGTH, "crank pivot ordinate", positive=False),
        "e": od.VariableInfo(LENGTH, "screw axis ordinate", positive=False),
        "gamma": od.VariableInfo(ANGLE, "angle from rod arm to push arm", default=np.pi / 2),
        "phi0": od.VariableInfo(ANGLE, "neutral horn angle", positive=False, default=np.pi / 2),
    }
    requirements = {
        "transmission_angle": od.RequirementInfo(
            "band", ANGLE, "angle between horn and rod at the horn pin", valid=(0.0, np.pi)
        ),
    }
    pin_shear_planes = 2
    size_description = "sum of the links R + l2 + r2 + r1 + l1"
    bench_families = {"bell_crank_backlash": ("backlash",)}

    def points(self, phi):
        """H, K, P2, P1, N: each a pair (x, y) in mm."""
        return self.solve_chain(phi)[:5]

    def solve_chain(self, phi):
        """The points and the two reaches: sin^2 of the crank's angle at K between K -> H
        and K -> P2 (0: the rod and the arm in line), cos^2 of the pushrod's inclination."""
        a = self.phi0 + phi
        H = (self.R * m.sin(a), self.R * m.cos(a))
        D = (H[0] - self.k_x, H[1] - self.k_y)
        d2 = _dot(D, D)
        along = (self.r2**2 - self.l2**2 + d2) / (2.0 * d2)  # K -> P2 along D, over |D|
        rod_reach = 1.0 - along**2 * d2 / self.r2**2
        across = self.r2 / m.sqrt(d2) * m.sqrt_domain(rod_reach)  # and across D, over |D|
        T = _turn(D)
        P2 = (self.k_x + along * D[0] - across * T[0], self.k_y + along * D[1] - across * T[1])
        c, s, q = m.cos(self.gamma), m.sin(self.gamma), self.r1 / self.r2
        v = (P2[0] - self.k_x, P2[1] - self.k_y)
        P1 = (self.k_x + q * (c * v[0] - s * v[1]), self.k_y + q * (s * v[0] + c * v[1]))
        push_reach = 1.0 - ((P1[1] - self.e) / self.l1) ** 2
        N = (P1[0] - self.l1 * m.sqrt_domain(push_reach), self.e + 0.0 * phi)
        return H, (self.k_x, self.k_y), P2, P1, N, rod_reach, push_reach

    def assembly_rows(self, phi):  # the solver stays where both square roots are real
        _, _, _, _, _, rod, push = self.solve_chain(phi)
        return [
            od.Rows("rod_reach", rod, 0.05, None, "", "sin^2 of the crank's angle to the rod"),
            od.Rows("push_reach", push, 0.25, None, "", "cos^2 of the pushrod's inclination"),
        ]

    def nut_position(self, phi):
        return self.points(phi)[4][0]

    def rates(self, phi):
        """g1, g2, dpsi/dphi of the hand derivation above."""
        a = self.phi0 + phi
        H, K, P2, P1, N = self.points(phi)
        u2 = ((P2[0] - H[0]) / self.l2, (P2[1] - H[1]) / self.l2)
        u1 = ((P1[0] - N[0]) / self.l1, (P1[1] - N[1]) / self.l1)
        g2 = -_dot(u2, (self.R * m.cos(a), -self.R * m.sin(a)))
        h2 = _dot(u2, _turn((P2[0] - K[0], P2[1] - K[1])))
        g1 = _dot(u1, _turn((P1[0] - K[0], P1[1] - K[1])))
        return g1, g2, -g2 / h2

    def joints(self, phi, M_h, pin=None):
        g1, g2, turn = self.rates(phi)
        s = self.sensitivity_axial(phi)
        F1, F2 = M_h / (g1 * turn), M_h / g2
        chain = [
            od.Joint("A screw bearings", "A", sensitivity=s),
            od.Joint("B screw/nut", "B", sensitivity=s),
            od.Joint("O output shaft", "O", angular=True),
        ]
        if pin is None:
            return chain
        return [
            *chain,
            od.Joint("pushrod pin (nut)", sensitivity=1 / (g1 * turn), force=F1, pin=pin),
            od.Joint("pushrod pin (crank)", sensitivity=1 / (g1 * turn), force=F1, pin=pin),
            od.Joint("rod pin (crank)", sensitivity=1 / g2, force=F2, pin=pin),
            od.Joint("rod pin (horn)", sensitivity=1 / g2, force=F2, pin=pin),
        ]

    def requirement_rows(self, name, value, phi):  # value: a band, value.min / value.max
        H, _, P2, _, _ = self.points(phi)
        to_O, to_P2 = (-H[0], -H[1]), (P2[0] - H[0], P2[1] - H[1])
        mu = m.arctan2(to_P2[0] * to_O[1] - to_P2[1] * to_O[0], _dot(to_O, to_P2))
        rows = od.Rows(name, mu, value.min, value.max, "rad", "horn to rod", display_unit="deg")
        return [rows]

    def size(self):
        return self.R + self.l2 + self.r2 + self.r1 + self.l1

    def sketch(self, phi):
        H, K, P2, P1, N = (tuple(float(c) for c in p) for p in self.points(float(phi)))
        axis = ((N[0] - 20.0, N[1]), (P1[0], N[1]))
        links = [[(0.0, 0.0), H], [H, P2], [P2, K, P1], [P1, N]]
        return od.Sketch(links=links, pivots=[(0.0, 0.0), K], slider=N, axis=axis)

    @classmethod
    def bench_template(cls):
        variables = {k: {"lower": f"{lo} mm", "upper": f"{hi} mm"} for k, lo, hi in BOXES}
        return {**variables, "p": None}, {"transmission_angle": {"min": "50 deg", "max": "130 deg"}}


#: Bounds of the lengths (mm), around the neutral layout: the horn along +x, the rod up,
#: the crank's rod arm to the left and its push arm down, the pushrod along the screw.
BOXES = (
    ("R", 40, 90),
    ("l2", 90, 160),
    ("r2", 35, 70),
    ("r1", 35, 70),
    ("l1", 100, 200),
    ("k_x", 90, 170),
    ("k_y", 90, 160),
    ("e", 40, 120),
)

PROBLEM = {
    "name": "bell_crank_min_backlash",
    "mechanism": "bell_crank",
    "variables": {
        **{k: {"lower": f"{lo} mm", "upper": f"{hi} mm"} for k, lo, hi in BOXES},
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
        "transmission_angle": {"min": "50 deg", "max": "130 deg"},
        "pin_bearing_pressure_max": "100 MPa",
        "fit": "H7/g6",
    },
    "objective": {"minimize": "backlash"},
}


def main(out=None, workers=1):
    problem = od.load(PROBLEM)
    result = od.solve(problem, workers=workers)
    front = od.pareto(problem, ["size", "backlash"], points=6, out=out, workers=workers)
    print(result.summary(), front.summary(), sep="\n\n")
    return result, front


if __name__ == "__main__":
    main()
