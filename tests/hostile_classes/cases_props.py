"""Class 11: properties a correct result must have, checked against computations that do
not go through the solver - the kind of check that catches a plausible one-line bug in
the formulations, the joints, the pivoting screw, the ISO tables, the relaxation, the
catalogue search, the fronts or the units (issue 21's seeded bugs).

Each case solves through the API; its check compares the result with: every feasible
point of a Sobol sample of the box (evaluated on the NumPy path: the optimum may not be
worse), the same problem written in other units, a tighter or looser requirement
(monotone), the geometry solved by bisection and differentiated by central differences,
the smallest relaxation applied, the catalogue enumerated, the GP's dual certificate.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from hostile_classes.common import base, solving, sub
from hostile_classes.model import SUCCESS, Case

RIPPLE = base("cs_min_ripple")
BACKLASH = base("cs_min_backlash")
CATALOGUE = base("cs_min_backlash_catalogue")
FORK = base("fork_min_backlash")
PIVOT = base("pivot_min_backlash")
DRIVE = base("drive_continuous")


def _solve(**kw: Any):
    kw.setdefault("starts", 4)
    return solving(**kw)


def _tol(a: float, b: float, rel: float = 1e-5) -> bool:
    return abs(a - b) <= rel * max(1.0, abs(a), abs(b))


def beats_samples(n: int = 512):
    """No feasible point of a Sobol sample of the box beats the optimum (discrete
    variables snapped to their catalogue)."""

    def check(result: Any, ctx: Any) -> list[str]:
        from scipy.stats import qmc

        problem = result.problem_object
        lo, hi = problem.lower(), problem.upper()
        X = qmc.Sobol(len(lo), seed=11).random(n) * (hi - lo) + lo
        for k, v in enumerate(problem.free):
            if v.values is not None:
                vals = np.array([c for c in v.values if v.lower - 1e-9 <= c <= v.upper + 1e-9])
                X[:, k] = vals[np.abs(X[:, k : k + 1] - vals[None, :]).argmin(axis=1)]
        ev = problem.evaluate(X)
        ok = np.asarray(ev.violation) <= 1e-9
        if not ok.any():
            return []
        obj = np.asarray(ev.objectives[result.objective_name], dtype=float)[ok]
        best = float(np.nanmin(obj))
        if best < result.objective - 1e-6 * max(1.0, abs(best)):
            return [
                f"a feasible sample has {result.objective_name} {best:.8g} < optimum {result.objective:.8g}"
            ]
        return []

    return check


def same_in_other_units(edits: list[tuple[str, str]], text: str):
    """The problem written in other units has the same optimum."""

    def check(result: Any, ctx: Any) -> list[str]:
        import tomllib

        import optdesign as od

        other = text
        for old, new in edits:
            other = sub(other, old, new)
        again = od.solve(od.load(tomllib.loads(other)), starts=4, ranges=False)
        if not again.success or not _tol(again.objective, result.objective):
            return [
                f"in other units the optimum is {again.objective!r} ({again.status}), here {result.objective!r}"
            ]
        return []

    return check


def monotone(old: str, new: str, text: str, direction: int):
    """A requirement made tighter (direction +1: the optimum may not improve) or looser
    (-1: it may not worsen)."""

    def check(result: Any, ctx: Any) -> list[str]:
        import tomllib

        import optdesign as od

        again = od.solve(od.load(tomllib.loads(sub(text, old, new))), starts=4, ranges=False)
        if not again.success:
            return [] if direction > 0 else [f"a looser requirement made it {again.status}"]
        diff = (again.objective - result.objective) * direction
        if diff < -1e-6 * max(1.0, abs(result.objective)):
            return [f"{new!r}: optimum {again.objective:.8g} against {result.objective:.8g}"]
        return []

    return check


def clearance_counts(key: str):
    """A clearance of joint ``key`` adds backlash: at the optimum design, the worst-case
    backlash with ``key`` = 0.01 mm exceeds the one without it."""

    def check(result: Any, ctx: Any) -> list[str]:
        import tomllib

        import optdesign as od

        data = ctx.data()
        x = np.array([result.design[v.name] for v in result.problem_object.free])
        values = []
        for c in (0.0, 0.01):
            data["clearances"] = {key: f"{c} mm"}
            p = od.load(tomllib.loads(_dumps(data)))
            values.append(float(p.evaluate(x).objectives["backlash"]))
        if not values[1] > values[0] * (1 + 1e-9):
            return [
                f"clearance {key} = 0.01 mm leaves the backlash at {values[1]:.8g} (0: {values[0]:.8g})"
            ]
        return []

    return check


def _dumps(data: dict[str, Any]) -> str:
    from hostile_corpus import dumps

    return dumps(data)


def crank_slider_ripple(result: Any, ctx: Any) -> list[str]:
    """The ripple of the optimum from the loop solved by bisection and differentiated by
    central differences (no model of the package)."""
    from independent_physics import cs_loop

    d = result.design
    phi = np.linspace(-math.pi / 6, math.pi / 6, 61)
    h = 1e-6

    def m_of(f: float) -> float:
        return cs_loop(f, d["R"], d["l"], d["n"], d["phi0"])[1][0]

    ratio = np.array(
        [abs(2 * math.pi * d["i_a"] * (m_of(f + h) - m_of(f - h)) / (2 * h) / d["p"]) for f in phi]
    )
    ripple = (ratio.max() - ratio.min()) / (ratio.max() + ratio.min())
    if not _tol(ripple, result.objective, 1e-4):
        return [f"ripple by the loop {ripple:.8g}, reported {result.objective:.8g}"]
    return []


def pivot_dead_length(result: Any, ctx: Any) -> list[str]:
    """The pivoting screw's shortest length minus its whole stroke, from the geometry."""
    d = result.design
    phi = np.linspace(-math.pi / 6, math.pi / 6, 61)
    a = d["phi0"] + phi
    L = np.hypot(d["R"] * np.sin(a) - d["a_T"], d["R"] * np.cos(a) - d["b_T"])
    dead = L.min() - abs(L[-1] - L[0])
    if dead < 60.0 - 1e-4:
        return [f"dead length by the geometry {dead:.6g} mm < 60 mm required"]
    return []


def relaxation_works():
    """The smallest relaxation of an infeasible problem, applied, makes it feasible."""

    def api(ctx: Any) -> Any:
        import optdesign as od
        from optdesign.formulations.nlp.relaxation import relaxations

        problem = od.load(ctx.data())
        result = od.solve(problem, starts=2, ranges=False)
        assert not result.success, "the base case must be infeasible"
        relax = [r for r in relaxations(problem, result) if r.name == "nut_travel" and r.needed]
        assert relax, f"no relaxation of nut_travel: {relaxations(problem, result)}"
        needed = relax[0].needed
        problem.set_requirement("nut_travel_max", needed * (1 + 1e-4) + 1e-6)
        fixed = od.solve(problem, starts=2, ranges=False)
        if fixed.success:
            other = od.load(ctx.data())
            other.set_requirement("nut_travel_max", needed * 0.97)
            tighter = od.solve(other, starts=4, ranges=False)
            if tighter.success:
                raise AssertionError(
                    f"3 % less than the 'smallest' relaxation {needed:.6g} mm is feasible"
                )
        return fixed

    return api


def catalogue_bounds(result: Any, ctx: Any) -> list[str]:
    """The continuous relaxation's bound is a lower bound of the catalogue optimum."""
    if result.bound is None:
        return ["the catalogue result carries no bound"]
    if result.bound > result.objective * (1 + 1e-6):
        return [f"bound {result.bound:.8g} above the optimum {result.objective:.8g}"]
    return []


def catalogue_enumerated(result: Any, ctx: Any) -> list[str]:
    """The catalogue optimum equals the best of the continuous solves with every pin
    diameter of the catalogue fixed (the lead stays a catalogue variable)."""
    import tomllib

    import optdesign as od

    data = ctx.data()
    data["requirements"]["fit_values"] = "table"  # a fixed d defaults to the smooth values
    best = math.inf
    for d in (4, 5, 6, 8, 10, 12, 16, 20, 25):
        data["variables"]["d"] = f"{d} mm"
        r = od.solve(od.load(tomllib.loads(_dumps(data))), starts=2, ranges=False)
        if r.success:
            best = min(best, r.objective)
    if not _tol(best, result.objective, 1e-5):
        return [f"enumerated optimum {best:.8g}, branch and bound {result.objective:.8g}"]
    return []


def gp_certificate(result: Any, ctx: Any) -> list[str]:
    import tomllib

    import optdesign as od

    out = []
    cert = result.certificate
    if cert is None:
        out.append("no certificate from the GP")
    elif cert.lower_bound > result.objective * (1 + 1e-6):
        out.append(
            f"certificate bound {cert.lower_bound:.8g} above the optimum {result.objective:.8g}"
        )
    nlp = od.solve(od.load(tomllib.loads(ctx.text())), formulation="nlp", starts=4, ranges=False)
    if not nlp.success or not _tol(nlp.objective, result.objective, 1e-4):
        out.append(f"NLP optimum {nlp.objective!r} against the GP's {result.objective!r}")
    return out


def front_ends(objectives: list[str]):
    """A front's ends are the single-objective optima."""

    def api(ctx: Any) -> Any:
        import optdesign as od

        problem = od.load(ctx.data())
        front = od.pareto(problem, objectives, points=5, workers=1, out=ctx.out, starts=4)
        for k in objectives:
            single = od.solve(problem, objective=k, starts=8, ranges=False)
            best = min(p.objectives[k] for p in front.points)
            if not _tol(single.objective, best, 1e-4):
                raise AssertionError(
                    f"front's best {k} {best:.8g}, single-objective optimum {single.objective:.8g}"
                )
        return front

    return api


def user_bound(result: Any, ctx: Any) -> list[str]:
    """A user constraint with a bound far from 1 (9 kN on the nut force) holds at the
    optimum, recomputed from the design's quantities."""
    problem = result.problem_object
    q = problem.quantities({k: result.design[k] for k in result.design})
    force = float(np.max(np.abs(np.asarray(q.nut_force, dtype=float))))
    if force > 9000 * (1 + 1e-6):
        return [f"nut force {force:.6g} N above the 9 kN bound"]
    return []


def _with_user_bound(ctx: Any) -> Any:
    import optdesign as od

    problem = od.load(ctx.data())
    problem.add_constraint(
        "nut_force_cap", lambda q: od.math.fabs(q.nut_force), upper="9 kN", unit="N"
    )
    return od.solve(problem, starts=4, ranges=False)


def rss_below_worst(result: Any, ctx: Any) -> list[str]:
    o = result.objectives
    if "backlash_rss" in o and o["backlash_rss"] > o["backlash"] * (1 + 1e-9):
        return [f"backlash_rss {o['backlash_rss']:.8g} above the worst case {o['backlash']:.8g}"]
    return []


def cases() -> list[Case]:
    mm_to_m = [
        ('R = { lower = "30 mm", upper = "120 mm" }', 'R = { lower = "0.03 m", upper = "0.12 m" }'),
        ('l = { lower = "40 mm", upper = "200 mm" }', 'l = { lower = "4 cm", upper = "20 cm" }'),
        (
            'phi0 = { lower = "-0.6 rad", upper = "0.6 rad" }',
            'phi0 = { lower = "-34.37746770784939 deg", upper = "34.37746770784939 deg" }',
        ),
        ('hinge_moment = "500 N*m"', 'hinge_moment = "0.5 kN*m"'),
        ('"100 MPa"', '"100 N*mm^-2"'),
        ('"200 MPa"', '"2e8 Pa"'),
        ('nut_travel_max = "110 mm"', 'nut_travel_max = "0.11 m"'),
    ]
    c = [
        Case("11:cs_min_backlash optimum beats every feasible sample", "11", SUCCESS, text=BACKLASH, api=_solve(), check=beats_samples(), fast=True),
        Case("11:cs_min_ripple optimum beats every feasible sample", "11", SUCCESS, text=RIPPLE, api=_solve(), check=beats_samples()),
        Case("11:fork optimum beats every feasible sample", "11", SUCCESS, text=FORK, api=_solve(), check=beats_samples()),
        Case("11:pivot optimum beats every feasible sample", "11", SUCCESS, text=PIVOT, api=_solve(), check=beats_samples()),
        Case("11:catalogue optimum beats every feasible sample", "11", SUCCESS, text=CATALOGUE, api=_solve(), check=beats_samples()),
        Case("11:drive optimum beats every feasible sample", "11", SUCCESS, text=DRIVE, api=_solve(), check=beats_samples()),
        Case("11:same optimum in other units", "11", SUCCESS, text=BACKLASH, api=_solve(), check=same_in_other_units(mm_to_m, BACKLASH)),
        Case("11:same ripple optimum in other units", "11", SUCCESS, text=RIPPLE, api=_solve(), check=same_in_other_units(mm_to_m[:4] + mm_to_m[6:], RIPPLE)),
        Case("11:a tighter travel never improves backlash", "11", SUCCESS, text=BACKLASH, api=_solve(), check=monotone('nut_travel_max = "110 mm"', 'nut_travel_max = "95 mm"', BACKLASH, +1)),
        Case("11:a looser ratio band never worsens ripple", "11", SUCCESS, text=RIPPLE, api=_solve(), check=monotone("min = 200, max = 260", "min = 190, max = 270", RIPPLE, -1)),
        Case("11:a tighter fit never worsens backlash", "11", SUCCESS, text=BACKLASH, api=_solve(), check=monotone('fit = "H7/g6"', 'fit = "H7/h6"', BACKLASH, -1)),
        Case("11:a stiffer lock limit never improves backlash", "11", SUCCESS, text=DRIVE, api=_solve(), check=monotone('force_max = "30 N"', 'force_max = "20 N"', DRIVE, +1)),
        Case("11:clearance B (screw/nut) adds backlash", "11", SUCCESS, text=BACKLASH, api=_solve(), check=clearance_counts("B"), fast=True),
        Case("11:clearance A (bearings) adds backlash", "11", SUCCESS, text=BACKLASH, api=_solve(), check=clearance_counts("A")),
        Case("11:clearance C (nut slide) adds backlash", "11", SUCCESS, text=BACKLASH, api=_solve(), check=clearance_counts("C")),
        Case("11:crank-slider ripple by the loop", "11", SUCCESS, text=RIPPLE, api=_solve(), check=crank_slider_ripple),
        Case("11:pivoting screw dead length by the geometry", "11", SUCCESS, text=PIVOT, api=_solve(), check=pivot_dead_length),
        Case("11:the smallest relaxation makes it feasible", "11", SUCCESS, text=sub(BACKLASH, 'nut_travel_max = "110 mm"', 'nut_travel_max = "25 mm"'), api=relaxation_works()),
        Case("11:catalogue bounds below the optimum", "11", SUCCESS, text=CATALOGUE, api=_solve(), check=catalogue_bounds),
        Case("11:catalogue optimum equals the enumeration", "11", SUCCESS, text=CATALOGUE, api=_solve(), check=catalogue_enumerated, timeout=400),
        Case("11:GP certificate and the NLP agree", "11", SUCCESS, text=FORK, api=_solve(starts=1), check=gp_certificate),
        Case("11:front ends are the single-objective optima", "11", SUCCESS, text=RIPPLE, api=front_ends(["ripple", "size"]), timeout=300),
        Case("11:a user bound of 9 kN holds", "11", SUCCESS, text=BACKLASH, api=_with_user_bound, check=user_bound),
        Case("11:RSS backlash below the worst case", "11", SUCCESS, text=BACKLASH, api=_solve(), check=rss_below_worst),
    ]  # fmt: skip
    return c
