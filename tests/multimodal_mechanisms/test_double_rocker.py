"""The double rocker plug-in (``double_rocker.py``) against its independent model
(``double_rocker_reference.py``) at random designs: positions (and both against scipy
root finding), the ratio, the clearance sensitivities, the joints' forces, the backlash
and the ripple; the problem loads; the recorded reference optimum
(``double_rocker_optimum.json``) holds on both models, and is found again by the
reference's differential evolution (marked slow, and skipped unless ``-m slow`` is
given, so that the plain ``pytest tests/multimodal_mechanisms/test_double_rocker.py``
stays fast)."""

from __future__ import annotations

import itertools
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

import optdesign as od

HERE = Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))

from multimodal_mechanisms import double_rocker as plugin  # noqa: E402
from multimodal_mechanisms import double_rocker_reference as ref  # noqa: E402
from multimodal_mechanisms import first_passing  # noqa: E402

OPTIMUM = HERE / "double_rocker_optimum.json"
SPEC = ref.default_spec("backlash")
PROBLEM = od.load(plugin.problem("backlash"))
#: Pins of the plug-in's chain and the member whose force and sensitivity they share.
PINS = {
    "rod pin (nut)": "rod",
    "rod pin (rocker)": "rod",
    "rocker pivot": "pivot",
    "coupler pin (rocker)": "coupler",
    "coupler pin (horn)": "coupler",
}
REL = 1e-7


def random_designs(n: int, seed: int) -> list[dict[str, float]]:
    """Designs drawn uniformly in the problem's bounds that assemble over the stroke with
    the four-bar and the rod away from their toggles, the ratio >= 1 and both
    transmission angles within 25...155 deg (near a dead point the independent model's
    finite differences lose their digits)."""
    rng = np.random.default_rng(seed)
    X = rng.uniform(SPEC.lower, SPEC.upper, (20000, len(SPEC.free)))

    def passes(chunk: np.ndarray) -> np.ndarray:
        v = {k: np.asarray(val, dtype=float) for k, val in SPEC.fixed.items()}
        v.update({name: chunk[:, j : j + 1] for j, name in enumerate(SPEC.free)})
        rows = ref.constraint_rows(SPEC, ref.model(SPEC, v))
        ok = np.ones(len(chunk), dtype=bool)
        for key in ("four_bar_reach", "rod_reach", "ratio_positive"):
            ok &= np.all(rows[key] >= 0.0, axis=-1)
        for key in ("horn", "rocker"):
            for side in ("min", "max"):
                ok &= np.all(rows[f"transmission_{key}_{side}"] >= -np.radians(20.0), axis=-1)
        return ok

    picked = first_passing(X, passes, n, chunk=2000)
    assert len(picked) == n, f"only {len(picked)} such designs in 20000 draws"
    return [SPEC.design(X[i]) for i in picked]


DESIGNS = random_designs(6, seed=2024)


def mechanism(design):
    names = plugin.DoubleRocker.variable_table()
    return plugin.DoubleRocker({k: v for k, v in design.items() if k in names})


def rel_err(a, b):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))


def root_found_chain(design, phi):
    """H, C, Q, N by scipy root finding: the rocker angle from |C(psi) - H| = l_c on the
    branch with C left of H -> K, the nut from |Q - N(x)| = l_r behind Q."""
    d = design
    a = d["phi0"] + phi
    H = np.array([d["R"] * math.cos(a), d["R"] * math.sin(a)])
    K = np.array([d["k_x"], d["k_y"]])

    def C_of(psi):
        return K + d["r_c"] * np.array([math.cos(psi), math.sin(psi)])

    def gap(psi):
        return np.linalg.norm(C_of(psi) - H) - d["l_c"]

    grid = np.linspace(0.0, 2 * math.pi, 721) + 1e-3
    roots = [
        brentq(gap, lo, hi, xtol=1e-15)
        for lo, hi in itertools.pairwise(grid)
        if gap(lo) * gap(hi) < 0
    ]
    KH, psi = K - H, None
    for r in roots:
        CH = C_of(r) - H
        if KH[0] * CH[1] - KH[1] * CH[0] > 0:
            psi = r
    C = C_of(psi)
    g = psi + d["gamma"]
    Q = K + d["r_q"] * np.array([math.cos(g), math.sin(g)])
    u = np.array([math.cos(d["beta"]), math.sin(d["beta"])])
    n = np.array([-u[1], u[0]])

    def nut_gap(x):
        return np.linalg.norm(Q - (d["e"] * n + x * u)) - d["l_r"]

    along = float(Q @ u)
    x = brentq(nut_gap, along - d["l_r"] - 1.0, along, xtol=1e-14)
    return H, C, Q, d["e"] * n + x * u, x


def test_the_problem_loads_with_six_or_more_free_variables_and_both_objectives():
    for objective in ("backlash", "ripple"):
        problem = od.load(plugin.problem(objective))
        free = [v.name for v in problem.free]
        assert len(free) >= 6 and {"d", "e", "beta"} <= set(free)
        assert problem.objective_names[0] == objective
        assert problem.mechanism_name == "double_rocker"
    with pytest.raises(ValueError, match="objective"):
        plugin.problem("size")
    assert "double_rocker" in od.registered_mechanisms()
    # registered with replace=True: importing the module again is harmless
    od.register_mechanism(plugin.DoubleRocker, replace=True)


def test_positions_against_the_independent_model_and_root_finding():
    for design in DESIGNS[:3]:
        mech = mechanism(design)
        for phi in (SPEC.phi[0], 0.1, SPEC.phi[-1]):
            H, K, C, Q, N, x, _, _ = ref.chain(design, phi)
            mine = mech.points(phi)
            for theirs, ours in zip((H, K, C, Q, N), mine, strict=True):
                assert np.allclose(np.asarray(ours, dtype=float), theirs, rtol=0, atol=1e-9)
            assert float(mech.nut_position(phi)) == pytest.approx(float(x), abs=1e-9)
            Hr, Cr, Qr, Nr, xr = root_found_chain(design, phi)
            for theirs, ours in zip((Hr, Cr, Qr, Nr), (H, C, Q, N), strict=True):
                assert np.allclose(ours, theirs, rtol=0, atol=1e-8)
            assert float(x) == pytest.approx(xr, abs=1e-8)


def test_ratio_sensitivities_and_forces_against_the_independent_model():
    pin = od.PinJoint(8.0, 12.0, "H7/g6")
    M_h = SPEC.hinge_moment
    phi = SPEC.phi
    for design in DESIGNS:
        mech = mechanism(design)
        q = ref.model(SPEC, design)
        # the ratio: closed form of the plug-in vs central differences of the position,
        # and vs the framework's automatic derivative of the plug-in's own position
        assert rel_err(mech.ratio(phi), q["ratio"]) < REL
        assert rel_err(mech.nut_velocity(phi), od.Mechanism.nut_velocity(mech, phi)) < 1e-10
        # the nut force by virtual work vs the rod force's axial component (statics)
        assert rel_err(np.abs(mech.nut_force(phi, M_h)), q["nut_force"]) < REL
        joints = {j.name: j for j in mech.joints(phi, M_h, pin)}
        for name, member in PINS.items():
            joint = joints[name]
            assert joint.pin is pin
            # sensitivities: virtual work vs perturbed lengths / pivot, re-solved
            assert rel_err(np.abs(joint.sensitivity), q["sensitivities"][member]) < REL
            # forces: virtual work vs the statics of the horn and the rocker
            assert rel_err(np.abs(joint.force), q["forces"][member]) < REL
        axial = joints["A screw bearings"].sensitivity
        assert rel_err(np.abs(axial), q["sensitivities"]["axial"]) < REL
        assert rel_err(mech.pin_force(phi, M_h), q["pin_force"]) < REL


def test_backlash_ripple_and_requirements_against_the_independent_model():
    ripple_problem = od.load(plugin.problem("ripple"))
    for design in DESIGNS:
        x = np.array([design[v.name] for v in PROBLEM.free])
        framework = PROBLEM.evaluate(x)
        mine = ref.evaluate(design, "backlash", SPEC)
        assert framework.objectives["backlash"] == pytest.approx(mine["backlash"], rel=REL)
        assert framework.objectives["ripple"] == pytest.approx(mine["ripple"], rel=REL)
        assert ripple_problem.evaluate(x).objectives["ripple"] == pytest.approx(
            mine["ripple"], rel=REL
        )
        # per joint: the framework's chain (fixed clearances A, B, O included) vs the
        # independent sum
        q = PROBLEM.quantities(design)
        per_joint = q.backlash.per_joint
        independent = ref.model(SPEC, design)
        for name in PINS:
            assert rel_err(per_joint[name], independent["backlash_per_joint"][name]) < REL
        for name, key in (("A screw bearings", "A"), ("B screw/nut", "B"), ("O output shaft", "O")):
            assert rel_err(per_joint[name], independent["backlash_per_joint"][key]) < REL
        # the requirements' quantities
        c = framework.constraints
        assert c["mean_ratio"].values[0] == pytest.approx(np.mean(independent["ratio"]), rel=REL)
        x_nut = independent["x"]
        assert c["nut_travel"].values[0] == pytest.approx(x_nut[-1] - x_nut[0], rel=REL)
        for row, angle in (
            ("transmission_angle_horn", "mu_H"),
            ("transmission_angle_rocker", "mu_Q"),
        ):
            shown = plugin.degrees_of_cosine(c[row].values)
            assert np.allclose(shown, np.degrees(independent[angle]), rtol=0, atol=1e-6)
        shown = plugin.degrees_of_sine(np.abs(c["rod_inclination_max"].values))
        assert np.allclose(shown, np.degrees(np.abs(independent["inclination"])), atol=1e-6)


def test_sketch_and_bench_template():
    design = DESIGNS[0]
    sketch = mechanism(design).sketch(0.1)
    assert isinstance(sketch, od.Sketch) and len(sketch.links) == 4
    assert sketch.pivots[1] == pytest.approx((design["k_x"], design["k_y"]))
    variables, requirements = plugin.DoubleRocker.bench_template()
    assert "p" in variables and variables["p"] is None
    assert "transmission_angle" in requirements


def _recorded():
    return json.loads(OPTIMUM.read_text())


def test_the_recorded_optimum_holds_on_both_models():
    record = _recorded()
    for objective, entry in record["optima"].items():
        problem = od.load(plugin.problem(objective))
        design = entry["design"]
        x = np.array([design[v.name] for v in problem.free])
        framework = problem.evaluate(x)
        assert framework.violation <= 1e-6
        assert framework.objectives[objective] == pytest.approx(entry["value"], rel=1e-7)
        mine = ref.evaluate(design, objective)
        assert mine["feasible"]
        assert mine["objective"] == pytest.approx(entry["value"], rel=1e-7)


@pytest.mark.slow  # differential evolution from the recorded seed (minutes each)
@pytest.mark.parametrize("objective", ["backlash", "ripple"])
def test_the_reference_optimum_is_found_again(objective, request):
    if "slow" not in (request.config.getoption("markexpr") or ""):
        pytest.skip("minutes of differential evolution: run with -m slow")
    entry = _recorded()["optima"][objective]
    seed = entry["seeds"][0]
    design, value = ref.reference_optimum(objective, seed)
    assert value == pytest.approx(entry["value"], rel=1e-6)
    assert ref.evaluate(design, objective)["feasible"]
