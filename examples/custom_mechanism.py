"""A mechanism of your own - a Scotch yoke: the output crank's pin slides in a slot of the
nut - written with public names only, gets what the built-ins get (multistart and the
independent check, an exact-ended Pareto front, a benchmark). Run it as a script."""

import optdesign as od
from optdesign import math as m


@od.register_mechanism
class ScotchYoke(od.Mechanism):
    name = "scotch_yoke"
    variables = {
        "R": od.VariableInfo("length", "crank radius"),
        "phi0": od.VariableInfo("angle", "neutral angle", positive=False, default=0.0),
    }
    pin_joints = ("crank pin in the yoke's slot",)  # on the screw's line, the nut's force
    size_description = "crank radius R"  # the default size: the sum of the lengths

    def nut_position(self, phi):  # the nut follows the pin: x = R sin(phi0 + phi)
        return self.R * m.sin(self.phi0 + phi)

    def sketch(self, phi):  # crank O-B, the yoke's slot through B, the nut on the axis
        x, y = float(self.R * m.sin(self.phi0 + phi)), float(self.R * m.cos(self.phi0 + phi))
        return od.Sketch(links=[[(0, 0), (x, y)], [(x, 0), (x, y)]], pivots=[(0, 0)], slider=(x, 0))


PROBLEM = {
    "name": "yoke_min_backlash",
    "mechanism": "scotch_yoke",
    "variables": {
        "R": {"lower": "30 mm", "upper": "120 mm"},
        "p": {"lower": "2 mm", "upper": "10 mm"},
        "phi0": {"lower": "-10 deg", "upper": "10 deg"},
        "d": {"lower": "4 mm", "upper": "30 mm"},
        "i_a": 2,
        "pin_length_ratio": 1.5,
    },
    "requirements": {
        "deflection": {"min": "-30 deg", "max": "30 deg", "points": 31},
        "hinge_moment": "500 N*m",
        "mean_ratio": {"min": 200, "max": 260},
        "nut_travel_max": "110 mm",
        "pin_bearing_pressure_max": "100 MPa",
    },
    "objective": {"minimize": "backlash"},
}


def main(out=None):
    problem = od.load(PROBLEM)
    problem.add_constraint("nut_force", lambda q: q.nut_force, upper="25 kN", unit="N")
    result = od.solve(problem)
    front = od.pareto(problem, ["size", "backlash"], points=8, out=out)
    report = od.bench(problems=[problem], solvers=["ipopt-exact", "slsqp-exact", "de"])
    print(result.summary(), front.summary(), report.summary(), sep="\n\n")
    return result, front, report


if __name__ == "__main__":
    main()
