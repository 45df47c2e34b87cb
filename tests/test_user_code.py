"""A bug in a user's own code is reported as such (issue 21, classes 9 and 10).

A user's objective or constraint function, or a user's mechanism, that raises or returns
what no formulation can use gives an error naming the function (or the mechanism class
and method), what optdesign was doing, and the user's own file and line, with the
original exception chained; the command line prints it as one line, and with
``OPTDESIGN_DEBUG=1`` its traceback reaches the user's line. The mechanisms below are
written in this module (as in a script) and in a temporary file (as in a notebook).
"""

from __future__ import annotations

import math
import pickle
import textwrap
from pathlib import Path

import numpy as np
import pytest
from test_api import yoke_data

import optdesign as od
from optdesign import math as m
from optdesign.cli import main
from optdesign.errors import InputError, OptDesignError
from optdesign.user_code import UserCodeError

ROOT = Path(__file__).resolve().parents[1]
BACKLASH = ROOT / "problems" / "cs_min_backlash.toml"
HERE = str(Path(__file__).resolve())


def line_of(fn, offset: int = 1) -> str:
    """``file:line`` of the line ``offset`` lines below ``fn``'s ``def``."""
    code = getattr(fn, "__code__", fn)
    return f"{code.co_filename}:{code.co_firstlineno + offset}"


# --- user mechanisms, one bug each ------------------------------------------------------
class _Yoke(od.Mechanism):
    variables = {"R": od.VariableInfo("length", "crank radius")}  # noqa: RUF012
    pin_joints = ("crank pin",)  # on the nut's line of action


class AttrBug(_Yoke):
    name = "t21_attr"

    def nut_position(self, phi):
        return self.ratio_of_arms * m.sin(phi)  # no such variable


class PropertyBug(_Yoke):
    name = "t21_property"

    @property
    def arm(self):
        return self.R * self.undefined_scale  # an AttributeError inside a property

    def nut_position(self, phi):
        return self.arm * m.sin(phi)


class ZeroBug(_Yoke):
    name = "t21_zero"

    def nut_position(self, phi):
        teeth = 0
        gain = 1 / teeth
        return gain * self.R * m.sin(phi)


class NaNBug(_Yoke):
    name = "t21_nan"

    def nut_position(self, phi):
        return self.R * m.sin(phi) * math.nan


class TextBug(_Yoke):
    name = "t21_text"

    def nut_position(self, phi):
        return "R sin(phi)"


class SymbolicBug(_Yoke):
    name = "t21_symbolic"

    def nut_position(self, phi):
        if self.R > 50:  # a CasADi symbol has no truth value
            return self.R * m.sin(phi)
        return 50 * m.sin(phi)


class SketchBug(_Yoke):
    name = "t21_sketch"

    def nut_position(self, phi):
        return self.R * m.sin(phi)

    def sketch(self, phi):
        return self.undefined_drawing  # used only where the linkage is drawn


for _cls in (AttrBug, PropertyBug, ZeroBug, NaNBug, TextBug, SymbolicBug, SketchBug):
    od.register_mechanism(_cls, replace=True)


def yoke_file(tmp_path: Path, mechanism: str) -> Path:
    path = tmp_path / f"{mechanism}.toml"
    path.write_text(
        textwrap.dedent(
            f"""
            name = "y"
            mechanism = "{mechanism}"
            [variables]
            R = {{ lower = "30 mm", upper = "120 mm" }}
            p = "5 mm"
            i_a = 2
            [requirements]
            deflection = {{ min = "-30 deg", max = "30 deg", points = 21 }}
            hinge_moment = "500 N*m"
            nut_travel_max = "100 mm"
            [objective]
            minimize = "motor_torque"
            """
        )
    )
    return path


MECHANISM_BUGS = [
    (
        AttrBug,
        line_of(AttrBug.nut_position),
        "AttrBug.nut_position raised AttributeError: AttrBug has no attribute "
        "'ratio_of_arms' (its variables: R, p, i_a)",
    ),
    (
        PropertyBug,
        line_of(PropertyBug.arm.fget, 2),  # the first line is the decorator's
        "PropertyBug.arm raised AttributeError: PropertyBug has no attribute 'undefined_scale'",
    ),
    (ZeroBug, line_of(ZeroBug.nut_position, 2), "ZeroBug.nut_position raised ZeroDivisionError"),
    (
        TextBug,
        line_of(TextBug.nut_position),  # the line of its return
        f"TextBug.nut_position (defined at {line_of(TextBug.nut_position, 0)}) returned a str "
        "('R sin(phi)') at {where}",
    ),
    (
        SymbolicBug,
        line_of(SymbolicBug.nut_position),
        "SymbolicBug.nut_position raised RuntimeError",
    ),
]


@pytest.mark.parametrize(
    ("cls", "where", "what"), MECHANISM_BUGS, ids=lambda x: getattr(x, "__name__", "")
)
def test_a_user_mechanism_bug_names_its_class_method_file_and_line_when_loaded(cls, where, what):
    with pytest.raises(UserCodeError) as caught:
        od.load(yoke_data(cls.name))
    text = str(caught.value)
    assert text.startswith(
        f"mechanism {cls.name!r} (class {__name__}.{cls.__qualname__} at {HERE}:"
    )
    assert what.format(where=where) in text
    assert where in text
    assert "no quantity or variable" not in text and "internal error" not in text
    assert caught.value.location is not None and str(caught.value.location) == where
    if cls is SymbolicBug:  # only CasADi's symbols see it: the hint says what to write
        assert "while differentiating it (CasADi)" in text and "od.math.where" in text
    else:
        assert "while loading the problem" in text
        assert caught.value.__cause__ is not None or cls is TextBug


def test_a_user_mechanism_bug_when_solving_a_problem_loaded_before_the_bug():
    # the problem is loaded with a working method, which is then broken (a notebook
    # cell edited and re-run): the solve names the method and the line
    class Late(_Yoke):
        name = "t21_late"

        def nut_position(self, phi):
            return self.R * m.sin(phi)

    od.register_mechanism(Late, replace=True)
    problem = od.load(yoke_data("t21_late"))

    def broken(self, phi):
        return self.R * m.sin(phi) * self.undefined_gain

    Late.nut_position = broken
    from optdesign.mechanisms.base import _DERIVATIVES

    _DERIVATIVES.clear()
    with pytest.raises(UserCodeError) as caught:
        od.solve(problem, starts=1, ranges=False)
    text = str(caught.value)
    assert "broken raised AttributeError: Late has no attribute 'undefined_gain'" in text
    assert f"at {line_of(broken)}" in text
    assert "while building the solver's model" in text or "while differentiating" in text
    assert isinstance(caught.value.__cause__, AttributeError)


def test_a_user_mechanism_that_returns_nan_is_never_a_verified_result():
    result = od.solve(od.load(yoke_data("t21_nan")), starts=1, ranges=False)
    assert not result.success and not result.verified
    assert "objective 'motor_torque' is NaN at this design" in result.notes
    rows = {r.name: r for r in result.violated}
    assert np.isnan(rows["ratio_positive[phi=+30.0deg]"].value)


@pytest.mark.parametrize("mode", ["default", "json"])
def test_the_command_line_reports_a_nan_mechanism_as_no_design(mode, tmp_path, capsys):
    import json

    out = tmp_path / "out"
    argv = ["solve", str(yoke_file(tmp_path, "t21_nan")), "--starts", "1", "--no-ranges"]
    argv += ["--json"] if mode == "json" else ["--out", str(out)]
    assert main(argv) == 1
    captured = capsys.readouterr()
    assert "internal error" not in captured.err and "Traceback" not in captured.err
    if mode == "json":
        doc = json.loads(captured.out)
        assert doc["status"] == "failed" and not doc["verified"]
        assert "objective 'motor_torque' is NaN at this design" in doc["notes"]
        assert any(v["side"] == "number" for v in doc["violated"])
    else:
        assert "objective 'motor_torque' is NaN at this design" in captured.out
        assert "is not a number (NaN)" in captured.out
        assert (out / "result.json").is_file() and (out / "report.html").is_file()


def test_a_user_mechanism_written_in_a_notebook_file(tmp_path):
    cell = tmp_path / "notebook_cell.py"
    cell.write_text(
        textwrap.dedent(
            """
            import optdesign as od
            from optdesign import math as m

            @od.register_mechanism
            class CellYoke(od.Mechanism):
                name = "t21_cell"
                variables = {"R": od.VariableInfo("length", "crank radius")}
                pin_joints = ("crank pin",)  # on the nut's line of action

                def nut_position(self, phi):
                    return self.R * m.sin(phi) / self.undefined_in_cell
            """
        )
    )
    namespace = {"__name__": "notebook"}
    exec(compile(cell.read_text(), str(cell), "exec"), namespace)  # as a notebook runs it
    with pytest.raises(UserCodeError) as caught:
        od.load(yoke_data("t21_cell"))
    text = str(caught.value)
    assert "mechanism 't21_cell' (class notebook.CellYoke" in text
    assert "CellYoke.nut_position raised AttributeError" in text
    assert f"at {cell}:12," in text


@pytest.mark.parametrize("mode", ["default", "json"])
def test_the_command_line_prints_a_user_mechanism_bug_as_one_line(
    mode, tmp_path, capsys, monkeypatch
):
    monkeypatch.delenv("OPTDESIGN_DEBUG", raising=False)
    file = yoke_file(tmp_path, "t21_attr")
    out = tmp_path / "out"
    argv = ["solve", str(file), "--starts", "1", "--out", str(out)]
    code = main([*argv, "--json"] if mode == "json" else argv)
    captured = capsys.readouterr()
    assert code == 2 and captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("optdesign: error: mechanism 't21_attr' (class ")
    assert f"at {line_of(AttrBug.nut_position)}" in lines[0]
    assert not out.exists()


def test_with_optdesign_debug_the_traceback_reaches_the_users_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("OPTDESIGN_DEBUG", "1")
    code = main(["solve", str(yoke_file(tmp_path, "t21_zero")), "--json", "--starts", "1"])
    err = capsys.readouterr().err
    assert code == 2
    zero = ZeroBug.nut_position.__code__.co_firstlineno + 2
    assert f'File "{HERE}", line {zero}, in nut_position' in err
    assert "ZeroDivisionError: division by zero" in err
    assert err.strip().splitlines()[-1].startswith("optdesign: error: mechanism 't21_zero'")


def test_registering_a_mechanism_checks_its_declarations():
    class NoPosition(od.Mechanism):
        name = "t21_no_position"
        variables = {"R": ("length", "arm")}  # noqa: RUF012
        pin_joints = ("crank pin",)  # on the nut's line of action

    with pytest.raises(OptDesignError, match=r"t21_no_position.*define nut_position\(self, phi\)"):
        od.register_mechanism(NoPosition)

    class BadVariable(_Yoke):
        name = "t21_bad_variable"
        variables = {"R": ("lenght", "arm")}  # noqa: RUF012

        def nut_position(self, phi):
            return self.R * m.sin(phi)

    with pytest.raises(OptDesignError) as caught:
        od.register_mechanism(BadVariable)
    assert "its variables: InputError: dimension: 'lenght' is not one of length" in str(
        caught.value
    )
    assert f"{HERE}:" in str(caught.value)
    with pytest.raises(InputError, match="register_mechanism: 5 is not a Mechanism subclass"):
        od.register_mechanism(5)


# --- user objectives and constraints ----------------------------------------------------
def zero_objective(q):
    return 1.0 / len(q.labels[:0])


def none_objective(q):
    return None


def peak_force(q):
    return max(q.nut_force)  # Python's max: not on CasADi expressions


def unknown_quantity(q):
    return q.nut_forse


@pytest.mark.parametrize(
    ("fn", "kwargs", "expected"),
    [
        (
            zero_objective,
            {},
            "objective 'bad': its function zero_objective (test_user_code.zero_objective) "
            f"raised ZeroDivisionError: float division by zero at {line_of(zero_objective)}, "
            "while trying it at the middle of the bounds",
        ),
        (
            none_objective,
            {},
            "objective 'bad': its function none_objective (test_user_code.none_objective) "
            f"(defined at {line_of(none_objective, 0)}) returned None at "
            f"{line_of(none_objective)} while trying it at the middle of the bounds; return a "
            "number or an expression of q",
        ),
        (
            lambda q: "peak",
            {},
            "returned a str ('peak') at ",
        ),
        (
            lambda q: np.ones(3),
            {"kind": "max"},
            "returned 3 values (expected one value or one per grid angle (61))",
        ),
        (lambda q: q.nut_force, {"kind": "scalar"}, "returned 61 values (expected one value)"),
        (
            unknown_quantity,
            {},
            "raised AttributeError: no quantity or variable 'nut_forse' (variables: ",
        ),
    ],
)
def test_a_user_objective_that_fails_is_refused_when_added(fn, kwargs, expected):
    problem = od.load(BACKLASH)
    with pytest.raises(UserCodeError) as caught:
        problem.add_objective("bad", fn, **kwargs)
    assert expected in str(caught.value)
    assert "bad" not in problem.objectives


def test_pythons_max_in_an_objective_is_refused_at_the_solve_with_the_od_math_hint():
    problem = od.load(BACKLASH)
    problem.add_objective("peak", peak_force, unit="N")  # fine on NumPy arrays
    with pytest.raises(UserCodeError) as caught:
        od.solve(problem, objective="peak", starts=1, ranges=False)
    text = str(caught.value)
    # CasADi 3.8.2 raises TypeError, 3.6.1 a plain Exception: the message names
    # the type that was raised
    cause = caught.value.__cause__
    assert type(cause) in (TypeError, Exception)
    assert text.startswith(
        "objective 'peak': its function peak_force (test_user_code.peak_force) raised "
        f"{type(cause).__name__}: CasADi matrices are not iterable at "
        f"{line_of(peak_force)}, while building the solver's model; "
    )
    assert "od.math.grid_max" in text


def test_a_user_constraint_that_fails_names_its_function():
    problem = od.load(BACKLASH)

    def lever_limit(q):
        return q.R if q.R > 50 else 2 * q.R  # a CasADi symbol has no truth value

    problem.add_constraint("lever", lever_limit, upper="100 mm", unit="mm", over="design")
    with pytest.raises(UserCodeError) as caught:
        od.solve(problem, starts=1, ranges=False)
    text = str(caught.value)
    assert text.startswith("constraint 'lever': its function lever_limit (")
    assert f"at {line_of(lever_limit)}, while building the solver's model" in text
    assert "od.math.where" in text
    with pytest.raises(UserCodeError, match=r"returned 61 values \(expected one value\)"):
        problem.add_constraint("forces", lambda q: q.nut_force, upper=1e4, over="design")


def test_a_nan_objective_at_the_optimum_is_reported_as_such():
    problem = od.load(BACKLASH)

    def efficiency_map(q):
        return q.size * math.nan  # e.g. a table looked up outside its range

    problem.add_objective("efficiency_map", efficiency_map, kind="scalar")
    result = od.solve(problem, starts=1, ranges=False)
    assert not result.verified and not result.success
    note = next(n for n in result.notes if "efficiency_map" in n)
    assert "is NaN at this design: its function efficiency_map" in note
    assert f"defined at {line_of(efficiency_map, 0)}" in note
    assert "NaN" in result.summary()


def test_a_user_error_crosses_process_boundaries():
    problem = od.load(BACKLASH)
    problem.add_objective("peak", peak_force, unit="N")
    with pytest.raises(UserCodeError) as caught:
        od.solve(problem, objective="peak", starts=1, ranges=False)
    back = pickle.loads(pickle.dumps(caught.value))
    assert str(back) == str(caught.value) and back.location == caught.value.location


# --- declarations -----------------------------------------------------------------------
def test_a_builtin_objective_is_replaced_only_on_purpose():
    problem = od.load(BACKLASH)
    with pytest.raises(InputError) as caught:
        problem.add_objective("backlash", lambda q: q.size)
    assert str(caught.value) == (
        "add_objective.name: 'backlash' is a built-in objective of the problem already; pass "
        "replace=True to replace it on purpose, or choose another name"
    )
    builtin = problem.objectives["backlash"]
    assert problem.objectives["backlash"] is builtin  # untouched
    problem.add_objective("size_twice", lambda q: 2 * q.size)
    with pytest.raises(InputError, match="'size_twice' is an objective of the problem already"):
        problem.add_objective("size_twice", lambda q: 3 * q.size)

    def wide(q):
        return m.fabs(q.nut_force)

    info = problem.add_objective("backlash", wide, unit="N", replace=True)
    assert problem.objectives["backlash"] is info and info.fn is wide


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (
            {"name": ""},
            "add_constraint.name: '' is not a name: use letters, digits and underscores",
        ),
        ({"name": 5}, "add_constraint.name: expected a name (a string), got 5"),
        ({"name": "nut force"}, "add_constraint.name: 'nut force' is not a name"),
        ({"name": "x" * 65}, "add_constraint.name: 'xxxxxxxxxxxxxx"),
        ({"name": "a,b"}, "add_constraint.name: 'a,b' is not a name"),
        ({"fn": 3}, "add_constraint.fn: expected a function, got 3"),
        ({"upper": True}, "add_constraint.upper: expected a number or a quantity string, got True"),
        ({"upper": "12 mm"}, "add_constraint.upper: '12 mm' is a length, expected a force ('N')"),
        ({"upper": float("inf")}, "add_constraint.upper: inf is not a finite number"),
        ({"upper": None}, "add_constraint.upper: give a lower or an upper bound (or both)"),
        (
            {"lower": "5 kN", "upper": "3 kN"},
            "add_constraint.lower: 5000 is above the upper bound 3000",
        ),
        (
            {"over": "strok"},
            "add_constraint.over: unknown over 'strok' (did you mean 'stroke'? known: stroke, design)",
        ),
        ({"unit": "Nx"}, "add_constraint.unit: 'Nx' is not a unit (unknown unit 'Nx'"),
        ({"unit": "10**10**10"}, "add_constraint.unit: '10**10**10' is not a unit"),
    ],
)
def test_add_constraint_refuses_bad_declarations(kwargs, message):
    problem = od.load(BACKLASH)
    args = {"name": "nut_force", "fn": lambda q: q.nut_force, "upper": "12 kN", "unit": "N"}
    with pytest.raises(InputError) as caught:
        problem.add_constraint(**{**args, **kwargs})
    assert str(caught.value).startswith(message)
    assert problem.user_constraints == []


def test_add_constraint_refuses_a_second_constraint_of_the_same_name():
    problem = od.load(BACKLASH)
    problem.add_constraint("nut_force", lambda q: q.nut_force, upper="12 kN", unit="N")
    with pytest.raises(
        InputError, match=r"add_constraint\.name: 'nut_force' names a constraint of the problem"
    ):
        problem.add_constraint("nut_force", lambda q: q.nut_force, upper="11 kN", unit="N")
    assert [c.upper for c in problem.user_constraints] == [12_000.0]
    # a requirement's rows, and an objective's limit, are constraints of the problem too
    for taken in ("nut_travel", "transmission_angle", "pin_bearing_pressure"):
        with pytest.raises(InputError, match=rf"add_constraint\.name: '{taken}' names a"):
            problem.add_constraint(taken, lambda q: q.nut_force, upper="11 kN", unit="N")
    # a refusal of another argument names the constraint being declared
    with pytest.raises(InputError) as caught:
        problem.add_constraint("nut_cap", lambda q: q.nut_force, upper="3 deg", unit="N")
    assert str(caught.value) == (
        "add_constraint.upper: '3 deg' is an angle, expected a force ('N') (constraint 'nut_cap')"
    )


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"name": "peak force"}, "add_objective.name: 'peak force' is not a name"),
        ({"kind": "maximum"}, "add_objective.kind: unknown kind 'maximum' (did you mean 'max'?"),
        ({"unit": 5}, "add_objective.unit: expected a string, got 5"),
        ({"display_scale": 0}, "add_objective.display_scale: 0 would show every value as 0"),
        ({"display_scale": float("nan")}, "add_objective.display_scale: nan is outside"),
        ({"replace": "yes"}, "add_objective.replace: 'yes' is not True or False"),
    ],
)
def test_add_objective_refuses_bad_declarations(kwargs, message):
    problem = od.load(BACKLASH)
    args = {"name": "peak", "fn": lambda q: m.fabs(q.nut_force), "unit": "N"}
    with pytest.raises(InputError) as caught:
        problem.add_objective(**{**args, **kwargs})
    assert str(caught.value).startswith(message)


# --- the quantities keep their own errors -----------------------------------------------
def test_an_unknown_quantity_still_says_so_and_an_error_inside_one_is_not_hidden(monkeypatch):
    problem = od.load(BACKLASH)
    q = problem.quantities(problem.design_dict(problem.midpoint()))
    with pytest.raises(AttributeError, match="no quantity or variable 'nut_forse'"):
        q.nut_forse  # noqa: B018
    from optdesign.problem import drive

    def broken(quantities):
        raise AttributeError("the drive lost its lead")

    monkeypatch.setattr(drive, "screw_data", broken)
    q = problem.quantities(problem.design_dict(problem.midpoint()))
    with pytest.raises(AttributeError, match="the drive lost its lead"):
        q.screw  # noqa: B018


def test_a_scalar_user_objective_reduced_over_the_grid_evaluates_a_population():
    """od.math.grid_max of a population gives one value per design: a population of
    any size (the grid's own size too) has each design's own value, as NSGA-II needs."""
    problem = od.load(BACKLASH)
    problem.add_objective("peak", lambda q: m.grid_max(m.fabs(q.nut_force)), unit="N")
    assert problem.objectives["peak"].kind == "scalar"
    rng = np.random.default_rng(5)
    lo, hi = problem.lower(), problem.upper()
    for size in (3, len(problem.phi)):
        X = lo + (hi - lo) * rng.random((size, len(lo)))
        one_by_one = [problem.evaluate(x).objectives["peak"] for x in X]
        assert problem.evaluate(X).objectives["peak"] == pytest.approx(
            one_by_one, rel=1e-12, nan_ok=True
        )


def test_a_user_sketch_bug_names_its_line_where_the_linkage_is_drawn(tmp_path, capsys):
    from optdesign.reports.html import solve_report

    result = od.solve(od.load(yoke_data("t21_sketch")), starts=1, ranges=False)
    assert result.success and result.verified  # the optimisation never draws the linkage
    with pytest.raises(UserCodeError) as caught:
        solve_report(result)  # the report's sketches
    text = str(caught.value)
    assert "SketchBug.sketch raised AttributeError" in text and "while drawing its sketch" in text
    assert str(caught.value.location) == line_of(SketchBug.sketch)
    # the command line keeps the result and says why the page is missing
    path = yoke_file(tmp_path, "t21_sketch")
    out = tmp_path / "out"
    assert main(["solve", str(path), "--starts", "1", "--no-ranges", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "report.html not written: mechanism 't21_sketch'" in printed
    assert (out / "result.json").exists() and not (out / "report.html").exists()


def test_builtins_on_quantities_get_a_hint_and_no_casadi_source_path():
    """max() of two CasADi scalars asks for their truth value: the message says so without
    CasADi's C++ file and line; round() of the stroke's array is named as such."""
    problem = od.load(BACKLASH)

    def larger_end(q):
        return max(q.nut_force[0], q.nut_force[1])

    problem.add_objective("ends", larger_end, unit="N")
    with pytest.raises(UserCodeError) as caught:
        od.solve(problem, objective="ends", starts=1, ranges=False)
    text = str(caught.value)
    assert "Cannot compute the truth value of a CasADi" in text and ".cpp" not in text
    assert f"at {line_of(larger_end)}, while building the solver's model" in text
    assert "od.math.where(cond, a, b) or od.math.fmax / fmin" in text

    def rounded(q):
        return round(q.nut_force)

    with pytest.raises(UserCodeError) as caught:  # tried when declared, on NumPy arrays
        problem.add_objective("rounded", rounded, unit="N")
    assert str(caught.value).endswith(
        "Python's round() does not apply to them, and a rounded value gives the solver no gradient"
    )
