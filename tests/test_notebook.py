"""What a notebook user sees: figures made outside pyplot's state (shown once, none left
open), no text drawn over other text, the od.math hint where CasADi refuses Python's
builtins, the wording of a front's table, and a closed stdout pipe that ends quietly."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from matplotlib.figure import Figure

import optdesign as od
from optdesign.user_code import UserCodeError

ROOT = Path(__file__).resolve().parent.parent
PROBLEM = ROOT / "problems" / "cs_min_backlash.toml"


@pytest.fixture(scope="module")
def solved():
    problem = od.load(PROBLEM)
    result = od.solve(problem, starts=2, ranges=False)
    front = od.pareto(problem, ["backlash", "size"], points=3, workers=1, starts=1)
    return result, front


def _pyplot_figures() -> list[int]:
    import matplotlib.pyplot as plt

    return plt.get_fignums()


def test_public_figures_are_no_pyplot_figures(solved):
    """A notebook's inline back-end draws every figure pyplot holds, and the cell's value
    once more: a figure made through pyplot showed twice. None is made through it now."""
    import matplotlib.pyplot as plt

    from optdesign.display.profiles import plot_profiles

    plt.close("all")
    result, front = solved
    taus = np.logspace(0, 2, 5)
    rho = np.array([[0.2, 0.5, 1.0, 1.0, 1.0], [0.0, 0.5, 0.5, 1.0, 1.0]])
    for make in (
        result.plot,
        front.plot,
        lambda: plot_profiles({"time": (taus, rho), "gap": (taus, rho)}, ["a", "b"]),
    ):
        fig = make()
        assert isinstance(fig, Figure)
        assert _pyplot_figures() == []
        assert fig.canvas.manager is None  # no window, no inline display of its own


def _renderer(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()  # runs the figure's layout, as a notebook's display does
    return canvas.get_renderer()


def test_what_limits_footer_clears_the_axis_labels(solved):
    """The "what limits the design" footer sits below every axis' label and tick labels,
    in the figure as returned (a notebook lays it out without save_figure)."""
    result, _ = solved
    fig = result.plot()
    renderer = _renderer(fig)
    footer = fig._supxlabel
    assert footer.get_text().startswith("what limits the design:")
    box = footer.get_window_extent(renderer)
    assert box.y0 >= 0.0  # inside the figure
    for ax in fig.axes:
        axis = ax.xaxis.get_tightbbox(renderer)  # ticks, tick labels and the label
        assert ax.xaxis.label.get_text() == "deflection phi (deg)"
        assert not box.overlaps(axis), (box, axis)
        assert box.y1 < axis.y0


def test_front_sketches_do_not_overlap(solved):
    """The sketches' titles and x-labels of the front figure do not run into each other."""
    _, front = solved
    fig = front.plot()
    renderer = _renderer(fig)
    boxes = []
    for ax in fig.axes:
        boxes += [t.get_window_extent(renderer) for t in (ax.title, ax.xaxis.label)]
        boxes = [b for b in boxes if b.width > 0]
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            assert not a.overlaps(b), (a, b)


def _builtins_case(kind: str):
    if kind == "max":
        return lambda q: max(q.nut_force)
    if kind == "min":
        return lambda q: -min(q.nut_force)
    if kind == "sum":
        return lambda q: sum(q.nut_force)
    return lambda q: [2.0 * f for f in q.nut_force][-1]  # a loop over the stroke


@pytest.mark.parametrize("kind", ["max", "min", "sum", "loop"])
@pytest.mark.parametrize("role", ["objective", "constraint"])
def test_python_builtins_on_casadi_get_the_od_math_hint(kind, role):
    problem = od.load(PROBLEM)
    fn = _builtins_case(kind)
    if role == "objective":
        problem.add_objective("peak", fn, unit="N")  # fine on NumPy arrays
        kwargs = {"objective": "peak"}
    else:
        problem.add_constraint("peak", fn, upper="50 kN", unit="N")
        kwargs = {}
    with pytest.raises(UserCodeError) as caught:
        od.solve(problem, starts=1, ranges=False, **kwargs)
    text = str(caught.value)
    code = fn.__code__
    assert text.startswith(f"{role} 'peak': its function <lambda>")
    assert f"at {code.co_filename}:{code.co_firstlineno}," in text
    assert "while building the solver's model" in text
    assert "od.math.grid_max / grid_min / grid_sum" in text
    assert "not Python's max, min, sum or a loop" in text


def test_abs_of_a_quantity_on_the_solvers_path():
    """Python's abs works on CasADi expressions where CasADi defines it (3.8.2): no
    refusal, the same run as fabs (the peak force is not smooth: the solve's status is
    whatever fabs gives too). Where it does not (3.6.1, the oldest allowed), the refusal
    points at od.math.fabs."""
    problem = od.load(PROBLEM)
    problem.add_objective("peak", lambda q: od.math.grid_max(abs(q.nut_force)), unit="N")
    problem.add_objective("peak2", lambda q: od.math.grid_max(od.math.fabs(q.nut_force)), unit="N")
    if not hasattr(ca.SX, "__abs__"):
        with pytest.raises(UserCodeError) as caught:
            od.solve(problem, objective="peak", starts=1, ranges=False)
        text = str(caught.value)
        assert "bad operand type for abs()" in text and text.endswith("use od.math.fabs")
        return
    a = od.solve(problem, objective="peak", starts=1, ranges=False)
    b = od.solve(problem, objective="peak2", starts=1, ranges=False)
    assert a.status == b.status
    assert a.objective == pytest.approx(b.objective, rel=1e-9)
    assert a.objective > 1000.0  # N: a hinge moment of hundreds of N*m on a ~100 mm arm


@pytest.mark.parametrize(
    ("step", "text"),
    [
        (1, "all shown"),
        (2, "every 2nd shown"),
        (3, "every 3rd shown"),
        (4, "every 4th shown"),
        (11, "every 11th shown"),
        (12, "every 12th shown"),
        (13, "every 13th shown"),
        (21, "every 21st shown"),
        (22, "every 22nd shown"),
        (112, "every 112th shown"),
    ],
)
def test_front_table_says_which_points_it_shows(step, text):
    from optdesign.reports.front_text import _shown

    assert _shown(step) == text


def test_small_front_summary_says_all_shown(solved):
    _, front = solved
    text = front.summary()
    assert f"front ({len(front.points)} points, all shown):" in text
    assert "1th" not in text


def test_a_closed_stdout_pipe_ends_quietly(tmp_path):
    """`optdesign solve ... | head -1`: the reader is gone before the summary is printed;
    the command still writes its files and exits 0 with no "[Errno 32]" message."""
    read, write = os.pipe()
    options = ["--starts", "1", "--no-ranges", "--out"]
    os.close(read)  # the reader went away: every write to the pipe fails with EPIPE
    out = tmp_path / "out"
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "optdesign", "solve", str(PROBLEM), *options, str(out)],
            stdout=write,
            stderr=subprocess.PIPE,
            text=True,
            timeout=300,
            cwd=ROOT,
        )
    finally:
        os.close(write)
    assert proc.returncode == 0, proc.stderr
    assert "Broken pipe" not in proc.stderr and "Errno" not in proc.stderr
    assert proc.stderr == ""
    assert (out / "result.json").is_file() and (out / "report.html").is_file()
