"""A hypothesis fuzz of problem dicts through ``od.load`` / ``od.solve``.

Each draw takes a shipped problem (as the dict a script passes to ``od.load``) and
replaces, deletes or adds one to three fields (mostly one) with hostile values (non-finite and huge
numbers, 400-digit integers, booleans, tables and lists where a number goes, quantities
of the wrong dimension, control characters, paths). Each draw must end as a clear
refusal (an OptDesignError naming a field it touched, or a failed result naming the
violated requirements) or a verified result: nothing else. Derandomised: the same draws
on every run.
"""

from __future__ import annotations

import copy
import json
import math
import re
import signal
import time
import tomllib
from pathlib import Path
from typing import Any

from hostile_classes.common import base

SHIPPED = (
    "cs_min_ripple",
    "cs_min_backlash",
    "fork_min_backlash",
    "pivot_min_backlash",
    "drive_continuous",
)
UNITS = ("mm", "m", "deg", "rad", "N*m", "N*m/deg", "kN*m", "kN*m/rad", "deg/s", "Hz", "MPa", "N/um", "h", "s", "percent", "")  # fmt: skip
HOSTILE: tuple[Any, ...] = (
    math.nan, math.inf, -math.inf, 0, -1, 0.0, -0.0, 1e-300, 1e300, 10**400, -(10**400),
    2**63, True, False, "", "abc", "1 mm", "500 N*m/deg", "1 Hz", "600 kN*m", "30 deg",
    "1e-300 mm", "1e400 mm", "10**10 mm", "\x1b[2J", "../x", "<!--", "a\u0000b", [], {},
    [1, [2]], {"a": 1}, {"min": "1 deg"}, ["1 mm", "2 mm"], "H7/s6", "R7/s6", "ma97",
)  # fmt: skip
NEW_KEYS = ("bogus", "\x1b[31m", "", "../x", "lock", "duty_cycle", "stiffness_min", "deflection_rate", "life_min", "values", "catalogue", "start", "output_file")  # fmt: skip
_ORDER = {"requirements": 0, "screw": 1, "variables": 2, "materials": 3, "objective": 4}
#: Seconds one draw may take.
DRAW_TIMEOUT = 90


def bases() -> dict[str, dict[str, Any]]:
    return {name: tomllib.loads(base(name)) for name in SHIPPED}


def _leaves(d: Any, path: tuple = ()) -> list[tuple]:
    """Paths of the scalar values, and of the tables two levels down (a variable's bounds:
    replacing them fixes the variable, or breaks it)."""
    out = []
    items = d.items() if isinstance(d, dict) else enumerate(d) if isinstance(d, list) else []
    for k, v in items:
        here = (*path, k)
        if isinstance(v, dict | list):
            if len(here) == 2:
                out.append(here)
            out += _leaves(v, here)
        else:
            out.append(here)
    return out


_QUANTITY = re.compile(r"^\s*([-+]?[0-9.eE+-]+)\s*(.*)$")
#: Factors and values that keep a field's unit but not its sense.
_EXTREMES = (0.0, -1.0, 1e-300, 1e300, 1e-12, 1e12, math.nan, math.inf, -math.inf)


def _near(original: Any):
    """Values of the original's kind (the same unit) at magnitudes that make no sense."""
    from hypothesis import strategies as st

    plausible = st.sampled_from((0.1, 0.5, 0.9, 1.1, 2.0, 10.0))
    factors = st.one_of(
        plausible, plausible, st.sampled_from(_EXTREMES), st.floats(allow_nan=False, width=32)
    )
    if isinstance(original, bool):
        return st.sampled_from((1, 0, "true", "yes"))
    if isinstance(original, int | float):
        x = float(original) if abs(original) < 1e300 else 1.0  # an earlier draw's 10**400
        return st.one_of(
            factors.map(lambda f: x * f if f not in (0.0, 1e-300, 1e300) else f),
            st.sampled_from((10**400, -(10**400), 2**63, -1)),
        )
    m = _QUANTITY.match(original) if isinstance(original, str) else None
    if m is None:
        return st.sampled_from(HOSTILE)
    x, unit = float(m.group(1)), m.group(2)
    return factors.map(lambda f: f"{x * f if f not in (0.0, 1e-300, 1e300) else f!r} {unit}")


def _tables(d: dict[str, Any], path: tuple = ()) -> list[tuple]:
    out = [path]
    for k, v in d.items():
        if isinstance(v, dict):
            out += _tables(v, (*path, k))
    return out


def _at(d: Any, path: tuple) -> Any:
    for k in path:
        d = d[k]
    return d


def strategy():
    """Draws of (shipped problem, mutated dict, what was done, the field names touched)."""
    from hypothesis import strategies as st

    originals = bases()
    numbers = st.one_of(
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(min_value=-(10**30), max_value=10**30),
    )
    quantities = st.builds(lambda x, u: f"{x} {u}", numbers, st.sampled_from(UNITS))
    values = st.one_of(st.sampled_from(HOSTILE), numbers, quantities, st.text(max_size=12))

    @st.composite
    def draw(draw_: Any) -> tuple[str, dict[str, Any], list[str], set[str]]:
        name = draw_(st.sampled_from(SHIPPED))
        data = copy.deepcopy(originals[name])
        done: list[str] = []
        names: set[str] = set()
        for _ in range(draw_(st.sampled_from((1, 1, 2, 3)))):
            op = draw_(st.sampled_from(("replace", "replace", "delete", "add")))
            if op == "add":
                table = draw_(st.sampled_from(_tables(data)))
                key = draw_(st.sampled_from(NEW_KEYS))
                value = draw_(values)
                _at(data, table)[key] = value
                path = (*table, key)
                if not key and table:  # an empty key: the message names its table
                    names.add(str(table[-1]))
            else:
                # the drive and the requirements first: hypothesis prefers early items,
                # and the top-level name or mechanism would end most draws at the loader
                leaves = sorted(_leaves(data), key=lambda p: _ORDER.get(str(p[0]), 9))
                if not leaves:
                    continue
                path = draw_(st.sampled_from(leaves))
                parent = _at(data, path[:-1])
                if op == "delete":
                    del parent[path[-1]]
                else:
                    near = _near(parent[path[-1]])
                    value = draw_(st.one_of(near, near, values))
                    parent[path[-1]] = value
            done.append(
                f"{op} {'.'.join(map(str, path))}"
                + (f" = {value!r}"[:80] if op != "delete" else "")
            )
            # the field a message must name: the last key of the path (a list's key for
            # an item of it)
            keys = [p for p in path if not isinstance(p, int)]
            if keys:
                names.add(str(keys[-1]))
            if len(keys) >= 3:  # a band's min, a bound: naming the band or variable will do
                names.add(str(keys[-2]))
        return name, data, done, names

    return draw()


class _Hang(BaseException):
    pass


def _alarm(signum, frame):
    raise _Hang


def judge_draw(data: dict[str, Any], names: set[str]) -> tuple[str, str]:
    """(verdict, message) of one draw: od.load, then od.solve (one start) if it loads."""
    import optdesign as od
    from hostile_classes.verify import failure_text, result_problems
    from optdesign.errors import OptDesignError

    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(DRAW_TIMEOUT)
    try:
        try:
            result = od.solve(od.load(data), starts=1, ranges=False)
        except _Hang:
            return "hang", f"still running after {DRAW_TIMEOUT} s"
        except OptDesignError as exc:
            msg = str(exc)
            low = msg.lower()
            named = any(n and n.lower() in low for n in names)
            return ("refused" if named else "unclear_refusal"), msg[:300]
        except Exception as exc:
            return "internal_error", f"{type(exc).__name__}: {exc}"[:300]
        if not result.success:
            text = failure_text(result)
            return ("refused" if result.violated else "unclear_refusal"), text[:300]
        problems = result_problems(result)
        return ("wrong_success", "; ".join(problems)[:300]) if problems else ("verified", "")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def run_in_child(examples: int, home: str) -> list[dict[str, Any]]:
    """Run ``examples`` derandomised draws (in the corpus server); one outcome per draw.
    ``home``: hypothesis's own folder (not the working directory, which is checked)."""
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis.configuration import set_hypothesis_home_dir

    set_hypothesis_home_dir(home)

    outcomes: list[dict[str, Any]] = []

    @settings(
        max_examples=examples,
        derandomize=True,
        database=None,
        deadline=None,
        phases=[Phase.generate],
        suppress_health_check=list(HealthCheck),
    )
    @given(strategy())
    def body(drawn: tuple[str, dict[str, Any], list[str], set[str]]) -> None:
        name, data, done, names = drawn
        t0 = time.perf_counter()
        verdict, message = judge_draw(data, names)
        outcomes.append(
            {
                "case": f"fuzz:{len(outcomes):03d} {name}: {'; '.join(done)}"[:300],
                "mode": "api",
                "verdict": verdict,
                "seconds": round(time.perf_counter() - t0, 3),
                "message": message,
            }
        )

    body()
    return outcomes


def run_fuzz(server: Any, root: Path, examples: int) -> list[Any]:
    """The fuzz through the corpus server (a crash or a hang costs the batch, not the
    runner); its working directory checked like a case's."""
    from hostile_classes import workspace
    from hostile_classes.model import Outcome

    if root.exists():
        import shutil

        shutil.rmtree(root)
    workspace.prepare(root, None)
    folders = [root / "out"]
    before = workspace.snapshot(root, folders)
    req = {
        "fuzz": examples,
        "home": str(root.parent / f"{root.name}-hypothesis"),
        "root": str(root),
        "stdout": str(root.parent / f"{root.name}.out"),
        "stderr": str(root.parent / f"{root.name}.err"),
        "timeout": DRAW_TIMEOUT * examples,
    }
    raw = server.execute(req, DRAW_TIMEOUT * examples)
    out = []
    for d in raw.get("outcomes", []):
        out.append(
            Outcome(d["case"], "fuzz", "api", d["verdict"], d["seconds"], None, d["message"], [])
        )
    if "crash" in raw or raw.get("hang"):
        what = "crash" if "crash" in raw else "hang"
        out.append(
            Outcome(
                "fuzz:batch",
                "fuzz",
                "api",
                what,
                raw.get("seconds", 0.0),
                None,
                json.dumps(raw)[:300],
                [],
            )
        )
    touched = workspace.changes(before, workspace.snapshot(root, folders))
    if touched:
        out.append(
            Outcome(
                "fuzz:files", "fuzz", "api", "files_touched", 0.0, None, "; ".join(touched[:5]), []
            )
        )
    return out
