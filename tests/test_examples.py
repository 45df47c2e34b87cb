"""The examples run as users run them, with public names only."""

from __future__ import annotations

import ast
import runpy
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
EXAMPLE = EXAMPLES / "custom_mechanism.py"


@pytest.mark.parametrize(
    "name",
    ["custom_mechanism.py", "bell_crank.py", "fin_actuator_sweep.py", "fin_actuator_loop_front.py"],
)
def test_examples_use_only_public_names(name):
    tree = ast.parse((EXAMPLES / name).read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            assert not (node.module or "").split(".")[-1].startswith("_")
            assert all(not a.name.startswith("_") for a in node.names)
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
            if node.value.id in ("od", "m"):
                assert not node.attr.startswith("_"), node.attr


def test_scotch_yoke_example_is_short():
    assert len(EXAMPLE.read_text().splitlines()) <= 60


def test_custom_mechanism_solves_fronts_and_benches(tmp_path):
    module = runpy.run_path(str(EXAMPLE), run_name="example")
    result, front, report = module["main"](tmp_path)
    assert result.status == "optimal" and result.verified
    assert result.mechanism == "scotch_yoke"
    # a Scotch yoke under the fork's requirements is pinned by the same two limits: nut
    # travel 2 R sin 30 deg <= 110 mm and the pin pressure at the stroke's ends
    assert result.design["R"] == pytest.approx(110.0, rel=1e-7)
    assert {r.name.split("[")[0] for r in result.active} >= {"nut_travel", "pin_bearing_pressure"}
    # the front's ends are the anchors' optima: the smallest yoke, and the backlash optimum
    F = front.F
    assert len(F) == 8
    # (to the anchors' slack of 1e-7 relative, which keeps a tie-break feasible)
    assert F[0, 0] == pytest.approx(front.anchors["size"]["size"], rel=2e-7)
    assert F[-1, 1] == pytest.approx(result.objective, rel=2e-7)
    # the user's constraint reached the front too
    assert all(p.design["R"] >= F[0, 0] * (1 - 1e-9) for p in front.points)
    rows = {r.config: r for r in report.rows}
    assert rows["ipopt-exact"].success and rows["slsqp-exact"].success
    assert rows["ipopt-exact"].objective == pytest.approx(result.objective, rel=1e-6)


def test_the_fin_actuator_sweep_example_states_a_valid_sweep():
    """examples/fin_actuator_sweep.py (minutes to run: its chart is in docs/) names a
    problem and parameters od.sweep takes: the lock of 60 N, both axes of the right
    dimension, 7 x 3 points."""
    import optdesign as od
    from optdesign.studies.sweep_grid import parameter_dimension

    module = runpy.run_path(str(EXAMPLES / "fin_actuator_sweep.py"), run_name="example")
    problem = od.load(module["strong_lock_actuator"]())
    assert problem.spec.requirements.lock.force_max == pytest.approx(60.0)  # N
    dims = {path: parameter_dimension(problem, path) for path in module["VARY"]}
    assert dims == {
        "requirements.hinge_moment": "moment",
        "requirements.deflection_rate": "angular_speed",
    }
    assert [spec[2] for spec in module["VARY"].values()] == [7, 3]


def test_the_loop_front_example_moves_the_placed_bandwidth_with_the_required_one():
    """examples/fin_actuator_loop_front.py (minutes to run: its table and figure are in
    docs/loop.md) sweeps the required bandwidth with the loop's placed bandwidth linked,
    and analyses each point on the problem with both moved."""
    import optdesign as od
    from optdesign.studies.sweep_grid import sweep_axes

    module = runpy.run_path(str(EXAMPLES / "fin_actuator_loop_front.py"), run_name="example")
    problem = od.load(module["PROBLEM"])
    (axis,) = sweep_axes(problem, module["VARY"], module["LINKED"])
    assert axis.linked == ("loop.bandwidth",) and axis.values[0] == 6.0 and len(axis.values) == 11
    at = module["point_problem"](problem, 9.5)
    assert at.spec.loop.bandwidth == at.spec.requirements.bandwidth_min == 9.5  # Hz
