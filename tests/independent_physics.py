"""Physics computed without the code under test, shared by the tests that check the models
against it: the fork's nut position from the geometry alone, central differences, the
crank-slider's loop solved by bisection, the fork problem's data. The tests themselves
live with their modules (mechanisms/test_fork.py, mechanisms/test_crank_slider.py,
models/test_loads.py, studies/test_solve.py, studies/pareto/test_pareto.py)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"


# --- fork geometry, phi0 != 0 ----------------------------------------------------------------
def _fork_pin_x(R: float, a: float) -> float:
    """Nut position from the geometry alone: the arm is the ray from O at angle a from the
    normal to the pin's line (direction (sin a, cos a)); the pin is where it meets y = R."""
    t = R / math.cos(a)  # ray parameter at y = R
    return t * math.sin(a)


def _fd(f, x: float, h: float = 1e-6) -> float:
    return (f(x + h) - f(x - h)) / (2 * h)


def cs_loop(phi, R=90.0, l=80.0, n=50.0, phi0=0.2):
    """Arm pin B and nut pin C = (m, n) of the crank-slider at deflection ``phi``: B at
    angle phi0 + phi from the normal to the screw's line, C on that line at distance n
    from O, on the near side of B, with |BC| = l by bisection on m in [Bx - l, Bx] (no
    closed form taken from the model)."""
    a = phi0 + phi
    Bx, By = R * math.sin(a), R * math.cos(a)
    lo, hi = Bx - l, Bx
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if (mid - Bx) ** 2 + (n - By) ** 2 > l**2:
            lo = mid
        else:
            hi = mid
    return (Bx, By), (0.5 * (lo + hi), n)


def _fork_data(**requirements) -> dict:
    data = tomllib.loads((PROBLEMS / "fork_min_backlash.toml").read_text())
    data["requirements"].update(requirements)
    return data
