"""Classes 9 (the Python API checks less than the CLI) and 10 (a bug in a user's
mechanism or function must be reported naming the user's file and line)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from hostile_classes.common import PROBLEMS, ROOT, base, solving
from hostile_classes.model import SUCCESS, Case, either, refuse

RIPPLE = base("cs_min_ripple")
BACKLASH = base("cs_min_backlash")
CATALOGUE = base("cs_min_backlash_catalogue")


_solve = solving


def _pareto(objectives: Any = ("ripple", "size"), points: Any = 3, **kw: Any):
    def api(ctx: Any) -> Any:
        import optdesign as od

        kw.setdefault("workers", 1)
        if kw.get("out") == "@OUT@":
            kw["out"] = ctx.out
        if kw.get("out") == "@FILE_IN_CWD@":
            kw["out"] = ctx.cwd / "sentinel.txt"
        objs = list(objectives) if isinstance(objectives, tuple) else objectives
        return od.pareto(od.load(ctx.data()), objs, points=points, **kw)

    return api


def _bench(**kw: Any):
    def api(ctx: Any) -> Any:
        import optdesign as od

        kw.setdefault("problems", [od.load(ctx.data())])
        kw.setdefault("solvers", ["ipopt-exact"])
        kw.setdefault("out", ctx.out)
        if kw.get("problems") == "@PATH@":
            kw["problems"] = str(PROBLEMS / "cs_min_ripple.toml")
        return od.bench(**kw)

    return api


def _load(value: Any):
    def api(ctx: Any) -> Any:
        import optdesign as od

        arg = value(ctx) if callable(value) else value
        return od.load(arg)

    return api


def _problem(step):
    """Load the case's problem, apply ``step(problem, ctx)``, return what it returns (or
    the problem)."""

    def api(ctx: Any) -> Any:
        import optdesign as od

        problem = od.load(ctx.data())
        got = step(problem, ctx)
        return problem if got is None else got

    return api


def class9() -> list[Case]:
    c: list[Case] = []
    solve_args = [
        ("starts=0", {"starts": 0}, "starts"),
        ("starts=-1", {"starts": -1}, "starts"),
        ("starts=10**9", {"starts": 10**9}, "starts"),
        ("starts=2.5", {"starts": 2.5}, "starts"),
        ("starts=True", {"starts": True}, "starts"),
        ("starts='3'", {"starts": "3"}, "starts"),
        ("workers=0", {"workers": 0, "starts": 1}, "workers"),
        ("workers=-1", {"workers": -1, "starts": 1}, "workers"),
        ("workers=10**6", {"workers": 10**6, "starts": 1}, "workers"),
        ("workers=2.5", {"workers": 2.5, "starts": 1}, "workers"),
        ("workers=True", {"workers": True, "starts": 1}, "workers"),
        ("agree=-1", {"agree": -1, "starts": 2}, "agree"),
        ("agree=2.5", {"agree": 2.5, "starts": 2}, "agree"),
        ("agree=10**9", {"agree": 10**9, "starts": 2}, "agree"),
        ("seed=-1", {"seed": -1, "starts": 2}, "seed"),
        ("seed=2**64", {"seed": 2**64, "starts": 2}, "seed"),
        ("seed=1.5", {"seed": 1.5, "starts": 2}, "seed"),
        ("formulation nosuch", {"formulation": "nosuch", "starts": 1}, "nosuch"),
        ("formulation=5", {"formulation": 5, "starts": 1}, "formulation"),
        ("objective nosuch", {"objective": "nosuch", "starts": 1}, "nosuch"),
        ("objective=5", {"objective": 5, "starts": 1}, "objective"),
        ("solver nosuch", {"solver": "nosuch", "starts": 1}, "nosuch"),
        ("options unknown", {"options": {"nosuch_option": 1}, "starts": 1}, "nosuch_option"),
        ("options wrong type", {"options": {"max_iter": "many"}, "starts": 1}, "max_iter"),
        ("options a string", {"options": "tol=1", "starts": 1}, "options"),
        ("gp on a non-GP", {"formulation": "gp", "starts": 1}, "gp"),
        (
            "objective lock_force without a lock",
            {"objective": "lock_force", "starts": 1},
            "lock_force",
        ),
    ]
    fast = {"starts=0", "starts=10**9", "workers=0", "agree=-1"}
    for what, kw, name in solve_args:
        text = BACKLASH if what.startswith("objective lock") else RIPPLE
        c.append(Case(f"9:solve {what}", "9", refuse(name), text=text, api=_solve(**kw), fast=what in fast))  # fmt: skip
    pareto_args = [
        ("points=2.5", {"points": 2.5}, "points"),
        ("points=0", {"points": 0}, "points"),
        ("points=1", {"points": 1}, "points"),
        ("points=10**9", {"points": 10**9}, "points"),
        ("points=True", {"points": True}, "points"),
        ("points='5'", {"points": "5"}, "points"),
        ("objectives a string", {"objectives": "ripple,size"}, "objectives"),
        ("one objective", {"objectives": ("ripple",)}, "objectives"),
        ("repeated objective", {"objectives": ("ripple", "ripple")}, "objectives"),
        ("unknown objective", {"objectives": ("ripple", "nosuch")}, "nosuch"),
        ("method nosuch", {"method": "nosuch"}, "nosuch"),
        ("workers=0", {"workers": 0}, "workers"),
        ("resume without out", {"resume": True}, "resume"),
        ("unknown option", {"foo": 1}, "foo"),
        ("deterministic='yes'", {"deterministic": "yes"}, "deterministic"),
        ("starts=0", {"starts": 0}, "starts"),
        ("seed=-1", {"seed": -1}, "seed"),
        ("out is a file", {"out": "@FILE_IN_CWD@"}, "sentinel.txt"),
        ("nsga2 pop_size=0", {"method": "nsga2", "pop_size": 0}, "pop_size"),
        ("nsga2 generations=0", {"method": "nsga2", "generations": 0}, "generations"),
    ]
    for what, kw, name in pareto_args:
        kw = dict(kw)
        objs = kw.pop("objectives", ("ripple", "size"))
        points = kw.pop("points", 3)
        # a comma string of objectives is read as the command line reads --objectives
        expect = either(name) if what == "objectives a string" else refuse(name)
        c.append(Case(f"9:pareto {what}", "9", expect, text=RIPPLE, api=_pareto(objs, points, **kw), fast=what == "points=2.5"))  # fmt: skip
    bench_args = [
        ("solvers nosuch", {"solvers": ["nosuch"]}, "nosuch"),
        ("time_limit=0", {"time_limit": 0}, "time_limit"),
        ("time_limit=nan", {"time_limit": float("nan")}, "time_limit"),
        ("time_limit=-1", {"time_limit": -1}, "time_limit"),
        ("workers=0", {"workers": 0}, "workers"),
        ("suite nosuch", {"problems": None, "suite": "nosuch"}, "nosuch"),
        ("problems a path string", {"problems": "@PATH@"}, "problems"),
        ("solvers a string", {"solvers": "ipopt-exact"}, "solvers"),
        ("problems empty", {"problems": []}, "problems"),
        ("resume without out", {"resume": True, "out": None}, "resume"),
    ]
    for what, kw, name in bench_args:
        # a comma string of configurations is read as the command line reads --solvers
        expect = either(name) if what == "solvers a string" else refuse(name)
        c.append(Case(f"9:bench {what}", "9", expect, text=RIPPLE, api=_bench(**kw), timeout=120))  # fmt: skip
    c += [
        Case("9:load 5", "9", refuse("problem"), api=_load(5)),
        Case("9:load None", "9", refuse("problem"), api=_load(None)),
        Case("9:load a list", "9", refuse("problem"), api=_load(["a"])),
        Case("9:load bytes", "9", refuse("problem"), api=_load(b'name = "x"')),
        Case("9:load a folder", "9", refuse("folder"), api=_load(lambda ctx: ctx.outside)),
        Case("9:load a dict with only the mechanism", "9", refuse("name", "variables", "requirements", "objective"), api=_load({"mechanism": "crank_slider"})),
        Case("9:load variables a list", "9", refuse("variables"), text=RIPPLE, api=_load(lambda ctx: {**ctx.data(), "variables": []})),
        Case("9:load requirements a string", "9", refuse("requirements"), text=RIPPLE, api=_load(lambda ctx: {**ctx.data(), "requirements": "x"})),
    ]  # fmt: skip
    c += _problem_methods()
    return c


def _problem_methods() -> list[Case]:
    def add_objective(name: Any, fn: Any = lambda q: q.R, **kw: Any):
        return _problem(lambda p, ctx: p.add_objective(name, fn, **kw) and None)

    def add_constraint(name: Any, fn: Any = lambda q: q.R, **kw: Any):
        return _problem(lambda p, ctx: p.add_constraint(name, fn, **kw) and None)

    def method(name: str, *args: Any):
        return _problem(lambda p, ctx: getattr(p, name)(*args))

    return [
        Case("9:add_objective backlash replaces the built-in", "9", refuse("backlash"), text=BACKLASH, api=add_objective("backlash"), fast=True),
        Case("9:add_objective ripple replaces the built-in", "9", refuse("ripple"), text=BACKLASH, api=add_objective("ripple")),
        Case("9:add_objective empty name", "9", refuse("name"), text=BACKLASH, api=add_objective("")),
        Case("9:add_objective name 5", "9", refuse("name"), text=BACKLASH, api=add_objective(5)),
        Case("9:add_objective not callable", "9", refuse("peak_thing"), text=BACKLASH, api=add_objective("peak_thing", "q.R")),
        Case("9:add_objective kind nosuch", "9", refuse("kind"), text=BACKLASH, api=add_objective("peak_thing", kind="nosuch")),
        Case("9:add_constraint empty name", "9", refuse("name"), text=BACKLASH, api=add_constraint("", upper=1), fast=True),
        Case("9:add_constraint name 5", "9", refuse("name"), text=BACKLASH, api=add_constraint(5, upper=1)),
        Case("9:add_constraint name None", "9", refuse("name"), text=BACKLASH, api=add_constraint(None, upper=1)),
        Case("9:add_constraint no bound", "9", refuse("arm_cap"), text=BACKLASH, api=add_constraint("arm_cap", unit="mm")),
        Case("9:add_constraint lower above upper", "9", refuse("arm_cap"), text=BACKLASH, api=add_constraint("arm_cap", lower=50, upper=40, unit="mm")),
        Case("9:add_constraint over nosuch", "9", refuse("over"), text=BACKLASH, api=add_constraint("arm_cap", upper=40, unit="mm", over="nosuch")),
        Case("9:add_constraint unit furlong", "9", refuse("unit", "furlong"), text=BACKLASH, api=add_constraint("arm_cap", upper="40 mm", unit="furlongs_per_fortnight")),
        Case("9:add_constraint a built-in requirement's name", "9", refuse("nut_travel"), text=BACKLASH, api=add_constraint("nut_travel", upper=40, unit="mm")),
        Case("9:add_constraint not callable", "9", refuse("arm_cap"), text=BACKLASH, api=add_constraint("arm_cap", 42, upper=40, unit="mm")),
        Case("9:set_requirement nosuch", "9", refuse("nosuch"), text=BACKLASH, api=method("set_requirement", "nosuch", 1)),
        Case("9:set_requirement negative moment", "9", refuse("hinge_moment"), text=BACKLASH, api=method("set_requirement", "hinge_moment", "-5 N*m")),
        Case("9:set_objective none", "9", refuse("objective", "minimize"), text=BACKLASH, api=method("set_objective")),
        Case("9:set_objective nosuch", "9", refuse("nosuch"), text=BACKLASH, api=method("set_objective", "nosuch")),
        Case("9:a valid dict in internal units", "9", SUCCESS, text=RIPPLE, api=_solve(starts=1), fast=True),
    ]  # fmt: skip


# --- user files: functions and mechanisms -------------------------------------------------------
class UserFile:
    """A user's module: its source, its name, and the line of the marked statement."""

    def __init__(self, name: str, source: str, marker: str = "# BUG"):
        self.name = name
        self.source = source
        lines = source.splitlines()
        hits = [k + 1 for k, ln in enumerate(lines) if marker in ln]
        self.line = hits[0] if hits else 0

    def files(self) -> dict[str, str]:
        return {f"{self.name}.py": self.source}

    def names(self) -> tuple[str, ...]:
        """How a message may point at the marked line."""
        f, n = f"{self.name}.py", self.line
        return (f"{f}:{n}", f'{f}", line {n}', f"{f}, line {n}", f"{f} line {n}")


_FN = """\
import optdesign as od
from optdesign import math as m


def peak_thing(q):
    {body}
"""


def _user_fn(k: int, body: str) -> UserFile:
    return UserFile(f"userfn_{k}", _FN.format(body=body))


def _user_objective(uf: UserFile, declare_kind: str | None = "max"):
    def api(ctx: Any) -> Any:
        import optdesign as od

        mod = ctx.module(uf.name)
        problem = od.load(ctx.data())
        problem.add_objective("peak_thing", mod.peak_thing, kind=declare_kind)
        return od.solve(problem, objective="peak_thing", starts=1, ranges=False)

    return api


def _user_constraint(uf: UserFile):
    def api(ctx: Any) -> Any:
        import optdesign as od

        mod = ctx.module(uf.name)
        problem = od.load(ctx.data())
        problem.add_constraint("peak_cap", mod.peak_thing, upper=1e9)
        return od.solve(problem, starts=1, ranges=False)

    return api


_MECH = """\
import math

import numpy as np

import optdesign as od
from optdesign import math as m


@od.register_mechanism
class {cls}(od.Mechanism):
    name = "{key}"
    variables = {variables}
    pin_joints = ("crank pin",)  # on the nut's line of action
{extra}
    def nut_position(self, phi):
        {body}
"""

_VARIABLES = (
    '{"R": od.VariableInfo("length", "crank radius"), '
    '"phi0": od.VariableInfo("angle", "neutral angle", positive=False, default=0.0)}'
)
OK_BODY = "return self.R * m.sin(self.phi0 + phi)"


def _mech(
    k: int,
    body: str = OK_BODY,
    extra: str = "",
    variables: str = _VARIABLES,
    key: str | None = None,
) -> UserFile:
    src = _MECH.format(
        cls=f"UserMech{k}",
        key=key if key is not None else f"user_mech_{k}",
        variables=variables,
        extra=extra,
        body=body,
    )
    return UserFile(f"usermech_{k}", src)


def yoke_problem(key: str) -> dict[str, Any]:
    """The Scotch-yoke problem of examples/custom_mechanism.py (read, not imported: the
    example registers its own mechanism) for the mechanism ``key``."""
    import ast

    tree = ast.parse((ROOT / "examples" / "custom_mechanism.py").read_text())
    node = next(
        n.value
        for n in tree.body
        if isinstance(n, ast.Assign) and getattr(n.targets[0], "id", "") == "PROBLEM"
    )
    data = ast.literal_eval(node)
    return {**data, "name": f"{key}_min_backlash", "mechanism": key}


def _mech_api(uf: UserFile, key: str, plot: bool = False, objective: str = "backlash"):
    def api(ctx: Any) -> Any:
        import optdesign as od

        ctx.module(uf.name)
        data = yoke_problem(key)
        data["objective"] = {"minimize": objective}
        result = od.solve(od.load(data), starts=1, ranges=False)
        if plot:  # what draws the linkage: the report's sketches (and front.plot())
            from optdesign.reports.html import solve_report

            result.plot()
            solve_report(result)
        return result

    return api


def _entry_point(uf: UserFile, key: str):
    """A setup: the user's module and a dist-info registering it as plug-in ``key``."""

    def setup(root: Path) -> None:
        cwd = root / "cwd"
        dist = cwd / f"{uf.name}-1.0.dist-info"
        dist.mkdir()
        (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {uf.name}\nVersion: 1.0\n")
        (dist / "entry_points.txt").write_text(
            f"[optdesign.mechanisms]\n{key} = {uf.name}:UserMech{uf.name.rsplit('_', 1)[1]}\n"
        )

    return setup


def class10() -> list[Case]:
    c: list[Case] = []
    bugs = [
        (
            "self.undefined_thing in nut_position",
            "return self.R * m.sin(self.phi0 + phi) * self.undefined_thing  # BUG",
        ),
        ("ZeroDivisionError in nut_position", "return self.R * m.sin(phi) + 1 / 0  # BUG"),
        ("NameError in nut_position", "return self.R * m.sin(phi) + undefined_global  # BUG"),
        ("TypeError in nut_position", "return self.R * m.sin(phi, 2)  # BUG"),
        ("KeyError in nut_position", "return self.R * m.sin(phi) * {}['gain']  # BUG"),
        ("math.sin on a symbol", "return self.R * math.sin(self.phi0 + phi)  # BUG"),
        ("returns None", "return None  # BUG"),
        ("returns a string", "return 'abc'  # BUG"),
        ("returns a list", "return [self.R, self.R]  # BUG"),
        ("raises ValueError", "raise ValueError('the user says no')  # BUG"),
    ]
    for k, (what, body) in enumerate(bugs):
        uf = _mech(k, body)
        c.append(Case(f"10:{what}", "10", refuse(*uf.names()), api=_mech_api(uf, f"user_mech_{k}"), fresh=True, fast=k == 0, files=uf.files()))  # fmt: skip
    k0 = len(bugs)
    uf = _mech(k0, "raise od.InputError('phi', 'the user refuses this angle')")
    c.append(Case("10:raises the user's own InputError", "10", refuse("the user refuses this angle"), api=_mech_api(uf, f"user_mech_{k0}"), fresh=True, files=uf.files()))  # fmt: skip
    extras = [
        (
            "a bug in sketch",
            "    def sketch(self, phi):\n        return self.undefined_sketch  # BUG\n",
            True,
            "backlash",
        ),
        (
            "a bug in joints",
            "    def joints(self, phi, M_h, pin=None):\n        raise RuntimeError('joints broke')  # BUG\n",
            False,
            "backlash",
        ),
        (
            "a bug in size",
            "    def size(self):\n        return self.R + self.missing_length  # BUG\n",
            False,
            "size",
        ),
        (
            "a bug in __init__",
            "    def __init__(self, *a, **kw):\n        super().__init__(*a, **kw)\n        self.setup_thing()  # BUG\n",
            False,
            "backlash",
        ),
    ]
    for j, (what, extra, plot, objective) in enumerate(extras):
        k = k0 + 1 + j
        uf = _mech(k, extra=extra)
        c.append(Case(f"10:{what}", "10", refuse(*uf.names()), api=_mech_api(uf, f"user_mech_{k}", plot, objective), fresh=True, files=uf.files()))  # fmt: skip
    k = k0 + 1 + len(extras)
    declared = [
        (
            "a variable of dimension lengthh",
            {"variables": '{"R": od.VariableInfo("lengthh", "crank radius")}'},
            ("lengthh",),
        ),
        ("variables a list", {"variables": '["R"]'}, ("variables",)),
        ("an empty name", {"key": ""}, ("name", "mechanism")),
        ("the name of a built-in", {"key": "crank_slider"}, ("crank_slider",)),
        ("a name with a path", {"key": "../evil"}, ("name", "mechanism")),
    ]
    for j, (what, kw, names) in enumerate(declared):
        uf = _mech(k + j, **kw)
        # a key with a path is harmless unless it becomes one: refused, or a verified result
        expect = either(*names) if "path" in what else refuse(*names)
        c.append(Case(f"10:{what}", "10", expect, api=_mech_api(uf, kw.get("key") or f"user_mech_{k + j}"), fresh=True, files=uf.files()))  # fmt: skip
    k += len(declared)
    uf = UserFile(f"usermech_{k}", _MECH.format(cls=f"UserMech{k}", key=f"user_mech_{k}", variables=_VARIABLES, extra="", body=OK_BODY).replace("    def nut_position(self, phi):\n        " + OK_BODY + "\n", "    pass\n"))  # fmt: skip
    c.append(Case("10:no nut_position", "10", refuse("nut_position"), api=_mech_api(uf, f"user_mech_{k}"), fresh=True, files=uf.files()))  # fmt: skip
    k += 1
    uf = _mech(k, "return self.R * m.sin(phi) * float('nan')  # BUG")
    c.append(Case("10:nut_position NaN", "10", either("nut_position", f"{uf.name}.py", "NaN", "not finite"), api=_mech_api(uf, f"user_mech_{k}"), fresh=True, files=uf.files()))  # fmt: skip
    k += 1

    def not_a_mechanism(ctx: Any) -> Any:
        import optdesign as od

        class NotAMechanism:
            name = "not_a_mechanism"

        return od.register_mechanism(NotAMechanism)

    c.append(Case("10:register a class that is not a Mechanism", "10", refuse("Mechanism"), api=not_a_mechanism, fresh=True))  # fmt: skip
    # The command line, with the mechanism a plug-in found through its entry point.
    for what, body in [
        (
            "self.undefined_thing",
            "return self.R * m.sin(self.phi0 + phi) * self.undefined_thing  # BUG",
        ),
        ("ZeroDivisionError", "return self.R * m.sin(phi) + 1 / 0  # BUG"),
        ("returns None", "return None  # BUG"),
    ]:
        uf = _mech(k, body)
        key = f"user_mech_{k}"
        text = _toml(yoke_problem(key))
        c.append(Case(f"10:CLI plug-in {what}", "10", refuse(*uf.names()), argv=["solve", "@FILE@", "--starts", "1", "--no-ranges"], text=text, setup=_entry_point(uf, key), files=uf.files(), fresh=True, pythonpath=True, fast=what == "self.undefined_thing"))  # fmt: skip
        k += 1
    # User functions: objectives and constraints.
    fns = [
        ("objective raising ZeroDivisionError", "return 1 / 0 * q.R  # BUG", "objective", refuse),
        (
            "objective raising AttributeError",
            "return q.no_such_quantity  # BUG",
            "objective",
            refuse,
        ),
        ("objective returning NaN", "return q.R * float('nan')  # BUG", "objective", refuse),
        ("objective returning None", "return None  # BUG", "objective", refuse),
        ("objective returning a string", "return 'small'  # BUG", "objective", refuse),
        ("objective returning inf", "return q.R * float('inf')  # BUG", "objective", refuse),
        ("constraint raising ZeroDivisionError", "return 1 / 0 * q.R  # BUG", "constraint", refuse),
        ("constraint returning NaN", "return q.R * float('nan')  # BUG", "constraint", refuse),
    ]
    for j, (what, body, kind, exp) in enumerate(fns):
        uf = _user_fn(j, body)
        names = (
            (*uf.names(), "peak_thing", "peak_cap")
            if "NaN" in what or "None" in what or "string" in what or "inf" in what
            else uf.names()
        )
        api = _user_objective(uf) if kind == "objective" else _user_constraint(uf)
        c.append(Case(f"10:{what}", "10" if "raising" in what else "9", exp(*names), text=RIPPLE, api=api, fast=j == 0, files=uf.files()))  # fmt: skip
    uf = _user_fn(len(fns), "return 1 / 0 * q.R  # BUG")
    c.append(Case("10:objective raising while its kind is inferred", "10", refuse(*uf.names()), text=RIPPLE, api=_user_objective(uf, None), files=uf.files()))  # fmt: skip
    return c


def _toml(data: dict[str, Any]) -> str:
    from hostile_corpus import dumps

    return dumps(data)


def cases() -> list[Case]:
    return [*class9(), *class10()]
