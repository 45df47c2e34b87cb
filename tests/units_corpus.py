"""Quantities of the wrong dimension (issue 21, class 5): a corpus of problem-file values
and API calls, each either refused (naming the field) or accepted with a stated value.

Angles are a dimension of their own: a moment per angle is not a moment, an angle per
time is not a frequency. Every case runs through the problem-file path (the loader the
CLI uses, and the CLI itself in both output modes: :func:`run_cli`) and through the
Python API (a dict to ``od.load``; ``add_constraint``, ``set_requirement``, pint
quantities). ``python tests/units_corpus.py`` prints how many wrong-dimension inputs
each path accepts (0 expected) and every right input whose value differs from the one
stated here.
"""

from __future__ import annotations

import contextlib
import copy
import io
import math
import sys
import tomllib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"
DEG = math.pi / 180.0


@dataclass(frozen=True)
class FieldCase:
    """A value written at ``path`` of the shipped problem ``problem``.

    ``expect``: None when the value must be refused (the message naming ``field``, the
    path's last key); otherwise the value it must be read as, in internal units.
    """

    name: str
    problem: str
    path: tuple[Any, ...]
    value: Any
    expect: float | None = None

    @property
    def field(self) -> str:
        return str(self.path[-1] if not isinstance(self.path[-1], int) else self.path[-2])


_FIN = "fin_actuator"
_REQ = "requirements"
_DUTY = ((_REQ, "duty_cycle", 0, "hinge_moment"), (_REQ, "duty_cycle", 0, "deflection"))

#: Values of the wrong dimension: each must be refused on every path.
WRONG: list[FieldCase] = [
    # a moment carries no angle
    FieldCase("moment per angle", _FIN, (_REQ, "hinge_moment"), "500 N*m/deg"),
    FieldCase("moment per radian", _FIN, (_REQ, "hinge_moment"), "500 N*m/rad"),
    FieldCase("moment times angle", _FIN, (_REQ, "hinge_moment"), "500 N*m*rad"),
    FieldCase("moment per angle, power", _FIN, (_REQ, "hinge_moment"), "500 N*m*deg^-1"),
    FieldCase("moment per turn", _FIN, (_REQ, "hinge_moment"), "500 N*m/turn"),
    FieldCase("motor torque per angle", _FIN, (_REQ, "motor_torque_max"), "2 N*m/rad"),
    FieldCase("duty moment per angle", _FIN, _DUTY[0], "150 N*m/deg"),
    # a rotational stiffness is a moment per angle, exactly
    FieldCase("stiffness without angle", _FIN, (_REQ, "stiffness_min"), "600 kN*m"),
    FieldCase("stiffness times angle", _FIN, (_REQ, "stiffness_min"), "600 kN*m*deg"),
    FieldCase("stiffness per angle squared", _FIN, (_REQ, "stiffness_min"), "600 kN*m/deg^2"),
    FieldCase("stiffness as energy", _FIN, (_REQ, "stiffness_min"), "600 kJ"),
    # an angular speed is an angle per time, exactly
    FieldCase("rate in hertz", _FIN, (_REQ, "deflection_rate"), "1 Hz"),
    FieldCase("rate per minute", _FIN, (_REQ, "deflection_rate"), "60 1/min"),
    FieldCase("rate per second", _FIN, (_REQ, "deflection_rate"), "2 1/s"),
    FieldCase("rate, angle squared", _FIN, (_REQ, "deflection_rate"), "120 deg^2/s"),
    FieldCase("rate, rpm times angle", _FIN, (_REQ, "deflection_rate"), "20 rpm*rad"),
    FieldCase("rate, per angle", _FIN, (_REQ, "deflection_rate"), "2 1/(s*rad)"),
    # a length, force, pressure or time carries no angle
    FieldCase("travel times angle", _FIN, (_REQ, "nut_travel_max"), "110 mm*rad"),
    FieldCase("bound times angle", _FIN, ("variables", "R", "upper"), "30 mm*rad"),
    FieldCase("bound per angle", _FIN, ("variables", "R", "lower"), "30 mm/deg"),
    FieldCase("screw length in mm deg", _FIN, ("screw", "length"), "300 mm*deg"),
    FieldCase("nut offset per turn", _FIN, ("screw", "nut_offset"), "40 mm/turn"),
    FieldCase("linear stiffness per angle", _FIN, ("screw", "bearing_stiffness"), "400 N/um/rad"),
    FieldCase("lock force times angle", _FIN, (_REQ, "lock", "force_max"), "30 N*rad"),
    FieldCase("lock radius per angle", _FIN, (_REQ, "lock", "radius"), "20 mm/rad"),
    FieldCase("pressure per angle", _FIN, (_REQ, "pin_bearing_pressure_max"), "100 MPa/deg"),
    FieldCase("modulus times angle", _FIN, ("materials", "pin", "E"), "2.1e5 MPa*rad"),
    FieldCase("life times angle", _FIN, (_REQ, "life_min"), "200 h*rad"),
    FieldCase("life per turn", _FIN, (_REQ, "life_min"), "200 h/turn"),
    FieldCase(
        "tolerance times angle", "cs_min_backlash_robust", ("tolerances", "R"), "0.05 mm*deg"
    ),
    FieldCase("reference per angle", "duan2017_redesign", ("reference", "R"), "90 mm/rad"),
    FieldCase("clearance times angle", _FIN, ("clearances", "A"), "0.01 mm*rad"),
    # an angle carries angle^1, exactly
    FieldCase("deflection squared", _FIN, (_REQ, "deflection", "max"), "30 deg^2"),
    FieldCase("deflection per angle", _FIN, (_REQ, "deflection", "min"), "-30 1/deg"),
    FieldCase("deflection ratio", _FIN, (_REQ, "deflection", "min"), "-30 deg/rad"),
    FieldCase("backlash in percent", _FIN, (_REQ, "backlash_max"), "5 %"),
    FieldCase("inclination steradian", _FIN, (_REQ, "rod_inclination_max"), "0.5 sr"),
    FieldCase("angle clearance in mm", _FIN, ("clearances", "O"), "0.01 mm"),
    FieldCase("duty deflection per time", _FIN, _DUTY[1], "0 deg/s"),
    # a plain number carries no angle
    FieldCase("gear ratio in degrees", _FIN, ("variables", "i_a"), "2 rad"),
    FieldCase("efficiency in degrees", _FIN, (_REQ, "efficiency_min"), "30 deg"),
    FieldCase("gear efficiency per angle", _FIN, ("screw", "gear_efficiency"), "0.96 1/rad"),
    FieldCase("ripple in degrees", "duan2017_redesign", (_REQ, "ripple_max"), "0.1 deg"),
]

#: Values of the right dimension, with what they must be read as.
RIGHT: list[FieldCase] = [
    FieldCase("rate in deg/s", _FIN, (_REQ, "deflection_rate"), "120 deg/s", 120 * DEG),
    FieldCase("rate in rpm", _FIN, (_REQ, "deflection_rate"), "20 rpm", 20 * 2 * math.pi / 60),
    FieldCase("rate in rad/s", _FIN, (_REQ, "deflection_rate"), "2 rad/s", 2.0),
    FieldCase("rate in turn/min", _FIN, (_REQ, "deflection_rate"), "20 turn/min", 2 * math.pi / 3),
    FieldCase("rate in rev/s", _FIN, (_REQ, "deflection_rate"), "0.25 rev/s", math.pi / 2),
    FieldCase("rate, power", _FIN, (_REQ, "deflection_rate"), "120 deg*s^-1", 120 * DEG),
    FieldCase("stiffness per rad", _FIN, (_REQ, "stiffness_min"), "600 kN*m/rad", 6e8),
    FieldCase("stiffness per deg", _FIN, (_REQ, "stiffness_min"), "10 kN*m/deg", 1e7 / DEG),
    FieldCase("stiffness, power", _FIN, (_REQ, "stiffness_min"), "600 kN*m*rad^-1", 6e8),
    FieldCase(
        "stiffness per arcmin", _FIN, (_REQ, "stiffness_min"), "1 N*m/arcmin", 1e3 * 10800 / math.pi
    ),
    FieldCase("moment", _FIN, (_REQ, "hinge_moment"), "500 N*m", 5e5),
    FieldCase("moment, angles cancel", _FIN, (_REQ, "hinge_moment"), "500 N*m*deg/deg", 5e5),
    FieldCase("linear stiffness", _FIN, ("screw", "bearing_stiffness"), "400 N/um", 4e5),
    FieldCase("life", _FIN, (_REQ, "life_min"), "200 h", 200.0),
    FieldCase("bound in metres", _FIN, ("variables", "R", "upper"), "0.12 m", 120.0),
    FieldCase("backlash in arcmin", _FIN, (_REQ, "backlash_max"), "1 arcmin", DEG / 60),
    FieldCase("deflection in turns", _FIN, (_REQ, "deflection", "max"), "0.1 turn", 0.2 * math.pi),
    FieldCase("deflection in rad", _FIN, (_REQ, "deflection", "max"), "0.5 rad", 0.5),
    FieldCase("deflection in grad", _FIN, (_REQ, "deflection", "max"), "20 grad", math.pi / 10),
    FieldCase("phase in mrad", _FIN, ("variables", "phi0", "upper"), "600 mrad", 0.6),
    FieldCase("efficiency in percent", _FIN, (_REQ, "efficiency_min"), "90 %", 0.9),
    FieldCase("gear efficiency in percent", _FIN, ("screw", "gear_efficiency"), "96 %", 0.96),
    FieldCase("ripple in percent", "duan2017_redesign", (_REQ, "ripple_max"), "10 %", 0.1),
    FieldCase("gear ratio", _FIN, ("variables", "i_a"), "2", 2.0),
    FieldCase("angle clearance", _FIN, ("clearances", "O"), "0.01 deg", 0.01 * DEG),
]


def problem_data(name: str) -> dict[str, Any]:
    """The parsed TOML of the shipped problem ``name``."""
    return tomllib.loads((PROBLEMS / f"{name}.toml").read_text())


def with_value(case: FieldCase) -> dict[str, Any]:
    """The case's problem dict with its value written at its path."""
    data = copy.deepcopy(problem_data(case.problem))
    d: Any = data
    for key in case.path[:-1]:
        if isinstance(d, dict) and key not in d:
            d[key] = {}
        d = d[key]
    d[case.path[-1]] = case.value
    return data


def read_back(problem: Any, path: tuple[Any, ...]) -> float:
    """The value a loaded problem holds at ``path`` (internal units)."""
    if path[0] == "variables":
        var = next(v for v in problem.variables if v.name == path[1])
        value = getattr(var, path[2]) if len(path) > 2 else None
        return float(var.value if value is None else value)  # equal bounds: a fixed value
    obj: Any = problem.spec
    for key in path:
        obj = obj[key] if isinstance(key, int) else getattr(obj, key)
    return float(getattr(obj, "band", obj))  # a tolerance given as a string is its band


@dataclass
class Outcome:
    """What a path made of a case: ``value`` when accepted, ``message`` when refused."""

    value: float | None = None
    message: str = ""

    @property
    def accepted(self) -> bool:
        return self.value is not None


def load_file(case: FieldCase, tmp: Path) -> Outcome:
    """The case through the problem-file loader (what ``optdesign solve FILE`` runs)."""
    from hostile_corpus import dumps

    from optdesign.errors import OptDesignError
    from optdesign.problem.load import load_problem

    path = tmp / f"{case.problem}.toml"
    path.write_text(dumps(with_value(case)))
    try:
        problem = load_problem(path)
    except OptDesignError as exc:
        return Outcome(message=str(exc))
    return Outcome(value=read_back(problem, case.path))


def load_dict(case: FieldCase) -> Outcome:
    """The case through the Python API (a dict given to ``od.load``)."""
    import optdesign as od

    try:
        problem = od.load(with_value(case))
    except od.OptDesignError as exc:
        return Outcome(message=str(exc))
    return Outcome(value=read_back(problem, case.path))


def run_cli(case: FieldCase, tmp: Path, json_mode: bool) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``optdesign solve FILE [--json]`` on the case."""
    from hostile_corpus import dumps

    from optdesign.cli import main

    path = tmp / f"{case.problem}.toml"
    path.write_text(dumps(with_value(case)))
    argv = ["solve", str(path), "--out", str(tmp / "out"), "--starts", "1", "--no-ranges"]
    argv += ["--no-report", "--json"] if json_mode else ["--no-report"]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


# --- API calls ---------------------------------------------------------------------------
@dataclass(frozen=True)
class ApiCase:
    """A call of the API with a quantity; ``expect`` None: refused naming ``field``."""

    name: str
    call: Callable[[], float]
    field: str
    expect: float | None = None


def _constraint(value: Any, unit: str, side: str = "upper") -> Callable[[], float]:
    def call() -> float:
        import optdesign as od

        problem = od.load(PROBLEMS / "cs_min_backlash.toml")
        info = problem.add_constraint("c", lambda q: q.nut_force, unit=unit, **{side: value})
        return float(getattr(info, side))

    return call


def _requirement(name: str, value: Any) -> Callable[[], float]:
    def call() -> float:
        import optdesign as od

        problem = od.load(PROBLEMS / f"{_FIN}.toml")
        problem.set_requirement(name, value)
        return float(getattr(problem.spec.requirements, name))

    return call


def _pint(text: str, dimension: str) -> Callable[[], float]:
    def call() -> float:
        import pint

        from optdesign.units import to_internal

        ureg = pint.UnitRegistry()  # a user's own registry
        return to_internal(ureg.Quantity(text), dimension, "q")

    return call


API_WRONG: list[ApiCase] = [
    ApiCase("constraint force times angle", _constraint("3 kN*rad", "N"), "add_constraint.upper"),
    ApiCase("constraint force per angle", _constraint("3 kN/deg", "N"), "add_constraint.upper"),
    ApiCase("constraint angle for a ratio", _constraint("0.1 deg", ""), "add_constraint.upper"),
    ApiCase(
        "constraint moment for stiffness",
        _constraint("5 N*m", "N*mm/rad", "lower"),
        "add_constraint.lower",
    ),
    ApiCase(
        "constraint frequency for a rate", _constraint("1 Hz", "rad/s"), "add_constraint.upper"
    ),
    ApiCase(
        "requirement moment per angle",
        _requirement("hinge_moment", "500 N*m/deg"),
        "requirements.hinge_moment",
    ),
    ApiCase(
        "requirement stiffness as moment",
        _requirement("stiffness_min", "600 kN*m"),
        "requirements.stiffness_min",
    ),
    ApiCase(
        "requirement rate in hertz",
        _requirement("deflection_rate", "1 Hz"),
        "requirements.deflection_rate",
    ),
    ApiCase("pint moment per angle", _pint("500 N*m/deg", "moment"), "q"),
    ApiCase("pint rate in hertz", _pint("1 Hz", "angular_speed"), "q"),
    ApiCase("pint stiffness as moment", _pint("600 kN*m", "rotational_stiffness"), "q"),
    ApiCase("pint angle for a ratio", _pint("30 deg", "dimensionless"), "q"),
]

API_RIGHT: list[ApiCase] = [
    ApiCase("constraint force", _constraint("3 kN", "N"), "add_constraint.upper", 3000.0),
    ApiCase("constraint angle", _constraint("30 deg", "rad"), "add_constraint.upper", 30 * DEG),
    ApiCase(
        "constraint stiffness",
        _constraint("5 N*m/deg", "N*mm/rad", "lower"),
        "add_constraint.lower",
        5e3 / DEG,
    ),
    ApiCase(
        "constraint rate", _constraint("20 rpm", "rad/s"), "add_constraint.upper", 2 * math.pi / 3
    ),
    ApiCase("constraint ratio in percent", _constraint("5 %", ""), "add_constraint.upper", 0.05),
    ApiCase("constraint bare number", _constraint(7.5, "N*mm/rad"), "add_constraint.upper", 7.5),
    ApiCase(
        "requirement rate in rpm",
        _requirement("deflection_rate", "20 rpm"),
        "deflection_rate",
        2 * math.pi / 3,
    ),
    ApiCase("pint moment", _pint("500 N*m", "moment"), "q", 5e5),
    ApiCase("pint rate in rpm", _pint("20 rpm", "angular_speed"), "q", 2 * math.pi / 3),
    ApiCase("pint stiffness", _pint("600 kN*m/rad", "rotational_stiffness"), "q", 6e8),
]


def run_api(case: ApiCase) -> Outcome:
    from optdesign.errors import OptDesignError

    try:
        return Outcome(value=case.call())
    except OptDesignError as exc:
        return Outcome(message=str(exc))


def main() -> int:
    """Print, per path, how many wrong-dimension inputs were accepted and every right
    input read as another value (or refused)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        file_wrong = {c.name: load_file(c, Path(tmp)) for c in WRONG}
        file_right = {c.name: load_file(c, Path(tmp)) for c in RIGHT}
    dict_wrong = {c.name: load_dict(c) for c in WRONG}
    dict_right = {c.name: load_dict(c) for c in RIGHT}
    api_wrong = {c.name: run_api(c) for c in API_WRONG}
    api_right = {c.name: run_api(c) for c in API_RIGHT}

    def misread(cases, outcomes) -> list[str]:
        out = []
        for c in cases:
            o = outcomes[c.name]
            if not o.accepted or not math.isclose(o.value, c.expect, rel_tol=1e-12):
                got = f"{o.value:.12g}" if o.accepted else o.message[:160]
                out.append(f"  {c.name}: expected {c.expect:.12g}, got {got}")
        return out

    for label, cases, wrong, right_cases, right in (
        ("file", WRONG, file_wrong, RIGHT, file_right),
        ("dict", WRONG, dict_wrong, RIGHT, dict_right),
        ("api", API_WRONG, api_wrong, API_RIGHT, api_right),
    ):
        accepted = [c.name for c in cases if wrong[c.name].accepted]
        print(f"{label}: wrong dimension accepted {len(accepted)}/{len(cases)}")
        for name in accepted:
            print(f"  accepted: {name} -> {wrong[name].value:g}")
        off = misread(right_cases, right)
        print(f"{label}: right dimension refused or misread {len(off)}/{len(right_cases)}")
        for line in off:
            print(line)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    sys.exit(main())
