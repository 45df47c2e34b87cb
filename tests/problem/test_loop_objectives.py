"""optdesign/problem/loop_objectives.py: the objective ``sensitivity_peak`` against
python-control's sensitivity function of the same loop at the same frequencies, its
bound on the exact peak over them (hypothesis), an NLP minimising it against a scan;
``limit_cycle_amplitude`` on an NSGA-II front against the harmonic balance of each point
computed alone, computed only when read, and refused by every formulation that needs a
smooth form, through the API and on the command line."""

from __future__ import annotations

import itertools
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from cli_refusal import command_line_refusal
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from loop_problems import assert_no_scan_point_beats, small_loop_problem

import optdesign as od
from optdesign.models import loop_linear as ll
from optdesign.models.loop_backlash import limit_cycles
from optdesign.problem import loop_margins
from optdesign.problem.loop import drive_plants_of, loop_angles
from optdesign.problem.loop_margins import CYCLE_POINTS, SOFT_MIN_POWER

ct = pytest.importorskip("control")

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"
#: fin_actuator_loop's optimum (16 mm pins, docs/loop.md).
LOOP_OPTIMUM = {"R": 105.5714658, "l": 59.7942416, "n": 102.0869895, "phi0": 0.2292040,
                "d0": 25.0, "p": 5.0, "d": 16.0}  # fmt: skip
NOT_SMOOTH = "needs a smooth form of objective 'limit_cycle_amplitude'"


def _data() -> dict:
    return tomllib.loads((PROBLEMS / "fin_actuator_loop.toml").read_text())


@pytest.fixture(scope="module")
def problem():
    return od.load(PROBLEMS / "fin_actuator_loop.toml")


def _small_problem(**sections) -> od.DesignProblem:
    return small_loop_problem("sensitivity_peak", **sections)


@pytest.fixture(scope="module")
def small():
    return _small_problem()


def _open_loop(plant, loop):
    """L(s) of the fin-feedback loop, built with python-control's algebra from the plant's
    numbers (docs/loop.md, "The linear loop"), not from optdesign's polynomials."""
    s = ct.tf("s")
    J1 = plant.motor_inertia * plant.ratio**2
    chain = plant.damping * s + plant.stiffness
    D1 = J1 * s**2 + chain
    D2 = plant.fin_inertia * s**2 + plant.fin_damping * s + chain + plant.hinge_spring
    fin = plant.ratio * chain / (D1 * D2 - chain * chain)  # phi / T
    controller = loop.kp + loop.kd * s + (loop.ki / s if loop.ki else 0)
    assert loop.feedback == "fin"
    return controller / (loop.current_lag * s + 1) * fin


def _frequencies(problem, q) -> list[np.ndarray]:
    """The margins' 14 frequencies (rad/s) at each loop angle: seven half an octave apart
    from f_ref / 2 to 4 f_ref, seven about the drive's mode, w_r (1 + 0.02 j)."""
    spec = problem.spec
    f_ref = spec.requirements.bandwidth_min or spec.loop.bandwidth
    fixed = 2 * math.pi * f_ref * 2.0 ** (np.arange(-2, 5) / 2)
    w_r = np.sqrt(np.asarray(q.two_mass_frequency_squared).ravel()[loop_angles(problem)])
    return [np.concatenate([fixed, w * (1 + 0.02 * np.arange(-3, 4))]) for w in w_r]


def test_the_sensitivity_peak_is_python_controls_peak_on_the_same_frequencies(problem):
    """At fin_actuator_loop's optimum, each loop angle's value is at least python-control's
    largest |S(jw)| = |1 / (1 + L(jw))| on the margins' 14 frequencies, and above it by
    less than the soft minimum's slack n^(1/2p), n = 14, p = 64 (2.1 %); the objective
    is the largest over the angles, 1.4643, and 0.25 % below python-control's exact
    peak over every w, 1 / (its stability margin): the dip falls between two
    frequencies, as for the margin rows."""
    x = np.array([LOOP_OPTIMUM[v.name] for v in problem.free])
    ex = problem.expressions(problem.design_dict(x))
    q = ex.quantities
    idx = loop_angles(problem)
    values = np.ravel(ex.objectives["sensitivity_peak"].expr)
    assert np.count_nonzero(values) == len(idx) == 7  # 0 where no loop row sits
    plants, loop = drive_plants_of(q, idx)[0]
    slack = 14 ** (1 / (2 * SOFT_MIN_POWER))
    exact_peaks = []
    for value, plant, w in zip(values[idx], plants, _frequencies(problem, q), strict=True):
        L = _open_loop(plant, loop)
        S = ct.feedback(1, L)
        peak = float(np.max(np.abs(S(1j * w))))
        assert peak <= value <= peak * slack
        exact_peaks.append(1.0 / ct.stability_margins(L)[2])
    objective = problem.evaluate(x).objectives["sensitivity_peak"]
    assert objective == pytest.approx(values.max(), rel=1e-12)
    assert objective == pytest.approx(1.4643, abs=1e-4)
    assert objective / max(exact_peaks) == pytest.approx(0.9975, abs=5e-4)


def test_the_sensitivity_peak_is_the_same_expression_on_both_paths(small):
    """The solver's expression of the offset n, evaluated at n = 120 mm, is the NumPy
    path's value at every grid angle (the independent check compares like with like)."""
    import casadi as ca

    z = ca.SX.sym("z")
    sym = small.expressions(small.design_dict([z]), guarded=True)
    f = ca.Function("f", [z], [sym.objectives["sensitivity_peak"].expr])
    numeric = small.expressions(small.design_dict(np.array([120.0])))
    expected = np.ravel(numeric.objectives["sensitivity_peak"].expr)
    np.testing.assert_allclose(f(120.0).full().ravel(), expected, rtol=1e-9)
    assert np.count_nonzero(expected) == 2


@settings(
    max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(n=st.floats(0.0, 150.0), R=st.floats(90.0, 110.0))
def test_the_sensitivity_peak_is_never_below_the_exact_peak_on_its_frequencies(small, n, R):
    """At any design whose drive is a plant, each loop angle's value is at least the exact
    largest 1 / |1 + L| on the 14 frequencies (the soft minimum never exceeds the least
    |1 + L|), and at most the slack n^(1/2p) above it."""
    design = small.design_dict(np.array([n]))
    design["R"] = R
    ex = small.expressions(design)
    q = ex.quantities
    idx = loop_angles(small)
    drive = drive_plants_of(q, idx, strict=False)[0]
    assume(drive is not None)
    plants, loop = drive
    values = np.ravel(ex.objectives["sensitivity_peak"].expr)[idx]
    for value, plant, w in zip(values, plants, _frequencies(small, q), strict=True):
        L, _ = ll.frequency_response(plant, loop, w)
        exact = 1.0 / np.abs(1.0 + L).min()
        assert value >= exact * (1 - 1e-12)
        assert value <= exact * 14 ** (1 / (2 * SOFT_MIN_POWER)) * (1 + 1e-12)


def test_the_nlp_minimising_the_sensitivity_peak_beats_a_scan_of_its_free_variable(small):
    """The NLP's optimum (n = 133.11 mm, Ms = 1.40608) is verified, and no design of a
    200-point scan of n that meets every requirement has a smaller value."""
    result = od.solve(small, starts=1, ranges=False, diagnose=False, sensitivities=False)
    assert result.status == "optimal" and result.verified
    assert_no_scan_point_beats(small, result, "sensitivity_peak")
    assert result.objective == pytest.approx(1.40608, abs=1e-5)


# --- limit_cycle_amplitude ------------------------------------------------------------------
def _front_problem() -> od.DesignProblem:
    """fin_actuator_loop with its linkage at the optimum but n and phi0 free near it, the
    screw fixed, the pins free, and without the requirements that make its feasible set a
    thin sheet (mean ratio, lock, DN) or bound the objectives (resonance margin, cycle)."""
    data = _data()
    variables = data["variables"]
    variables["R"] = f"{LOOP_OPTIMUM['R']} mm"
    variables["l"] = f"{LOOP_OPTIMUM['l']} mm"
    variables["phi0"] = {"lower": "0.2 rad", "upper": "0.26 rad"}
    variables["n"] = {"lower": "98 mm", "upper": "106 mm"}
    variables["d0"], variables["p"] = "25 mm", "5 mm"
    for name in ("resonance_margin_min", "limit_cycle_amplitude_max", "mean_ratio", "lock"):
        del data["requirements"][name]
    del data["requirements"]["dn_max"]
    return od.load(data)


def test_an_nsga2_front_of_the_limit_cycle_holds_each_points_harmonic_balance():
    """A tiny NSGA-II front of backlash against limit_cycle_amplitude: every point is
    verified, and its amplitude is the largest stable cycle (deg) over the loop's angles
    of its design's loop, computed here with limit_cycles alone."""
    problem = _front_problem()
    front = od.pareto(
        problem,
        "backlash,limit_cycle_amplitude",
        method="nsga2",
        pop_size=10,
        generations=4,
        progress=False,
    )
    # which points a 10 x 4 NSGA-II keeps depends on pymoo's release (two with 0.6.2,
    # four with 0.6.1); what holds for any: a trade-off, each point on the harmonic balance
    values = sorted(
        (p.objectives["backlash"], p.objectives["limit_cycle_amplitude"]) for p in front.points
    )
    assert len(values) >= 1
    for (b0, a0), (b1, a1) in itertools.pairwise(values):
        assert b1 >= b0 and a1 <= a0  # mutually non-dominated: more backlash, less cycle
    for point in front.points:
        assert point.verified
        x = np.array([point.design[v.name] for v in problem.free])
        q = problem.quantities(problem.design_dict(x))
        plants, loop = drive_plants_of(q, loop_angles(problem))[0]
        cycles = [limit_cycles(p, loop, CYCLE_POINTS).largest_stable_fin_amplitude for p in plants]
        amplitude = point.objectives["limit_cycle_amplitude"]
        assert amplitude == pytest.approx(math.degrees(max(cycles)), rel=1e-12)
        assert amplitude > 0


def test_a_population_computes_the_limit_cycle_only_when_it_is_read(small, monkeypatch):
    """Without the requirement limit_cycle_amplitude_max, evaluating a population and
    reading another objective runs no harmonic balance; reading the amplitude runs one
    per design and loop angle."""
    calls = []

    def counted(plant, loop, points):
        calls.append(plant)
        return limit_cycles(plant, loop, points)

    monkeypatch.setattr(loop_margins, "limit_cycles", counted)
    loop_margins._largest_cycle.cache_clear()
    ev = small.evaluate(np.array([[120.0], [130.0], [140.0]]))
    assert np.all(np.isfinite(ev.objectives["sensitivity_peak"]))
    assert calls == []
    assert np.all(ev.objectives["limit_cycle_amplitude"] >= 0)
    assert len(calls) == 3 * 2
    loop_margins._largest_cycle.cache_clear()


@pytest.mark.parametrize(
    ("formulation", "who"),
    [
        ("auto", "every formulation"),
        ("nlp", "the NLP"),
        ("gp", "a GP"),
        ("robust", "robust design (an NLP per sample)"),
    ],
)
def test_every_smooth_formulation_refuses_the_limit_cycle_saying_what_to_use(formulation, who):
    """Refused before any work, naming the objective, why, and what to use instead."""
    robust = _small_problem(tolerances={"n": "0.05 mm"})
    with pytest.raises(od.OptDesignError) as err:
        od.solve(robust, formulation, objective="limit_cycle_amplitude")
    message = str(err.value)
    assert f"{who} needs a smooth form of objective 'limit_cycle_amplitude'" in message
    assert "root of the harmonic balance" in message
    assert "method='nsga2'" in message and "limit_cycle_amplitude_max" in message


def test_the_catalogue_search_and_its_front_refuse_the_limit_cycle(problem, tmp_path):
    with pytest.raises(od.OptDesignError, match="the catalogue search .* " + NOT_SMOOTH):
        od.solve(problem, "catalogue", objective="limit_cycle_amplitude")
    out = tmp_path / "out"
    with pytest.raises(od.OptDesignError) as err:
        od.pareto(problem, "backlash,limit_cycle_amplitude", out=out, progress=False)
    assert getattr(err.value, "field", None) == "objectives"
    assert "'epsilon-catalogue' (it solves NLPs) " + NOT_SMOOTH in str(err.value)
    assert not out.exists()


@pytest.mark.parametrize("json_mode", [False, True], ids=["text", "json"])
def test_the_command_line_refuses_the_limit_cycle_as_an_nlps_objective(json_mode, tmp_path):
    data = _data()
    data["objective"] = {"minimize": "limit_cycle_amplitude"}
    message = command_line_refusal(data, tmp_path, json_mode)
    assert "every formulation " + NOT_SMOOTH in message
    assert not (tmp_path / "out").exists()


def test_the_pareto_command_refuses_the_limit_cycle_with_a_solving_method(tmp_path):
    message = command_line_refusal(
        _data(),
        tmp_path,
        False,
        ["pareto", "--objectives", "backlash,limit_cycle_amplitude", "--workers", "1"],
    )
    assert "--objectives: the front method 'epsilon-catalogue'" in message
    assert NOT_SMOOTH in message
    assert not (tmp_path / "out").exists()
