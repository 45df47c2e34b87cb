"""Classes 5 (units of the wrong dimension) and 6 (outputs that break or inject)."""

from __future__ import annotations

import io
import math
import re
from typing import Any

from hostile_classes import workspace
from hostile_classes.common import (
    SOLVE,
    SOLVE_OUT,
    add,
    api_load,
    base,
    file_case,
    sub,
    toml_str,
    value_check,
)
from hostile_classes.model import SUCCESS, Case, either, refuse

RIPPLE = base("cs_min_ripple")
BACKLASH = base("cs_min_backlash")
DRIVE = base("drive_continuous")
FIN = base("fin_actuator")
DUAN = base("duan2017_redesign")

MOMENT = 'hinge_moment = "500 N*m"'
DEFL = 'deflection = { min = "-30 deg", max = "30 deg", points = 61 }'
RATE = 'deflection_rate = "120 deg/s"'
STIFF = 'stiffness_min = "600 kN*m/rad"'
DEG = math.pi / 180


def class5() -> list[Case]:
    c: list[Case] = []
    wrong = [
        # a moment given as a moment per angle, or times an angle (radians are not 1)
        (BACKLASH, MOMENT, 'hinge_moment = "500 N*m/deg"', "hinge_moment"),
        (BACKLASH, MOMENT, 'hinge_moment = "500 N*m/rad"', "hinge_moment"),
        (BACKLASH, MOMENT, 'hinge_moment = "500 N*m*rad"', "hinge_moment"),
        (BACKLASH, MOMENT, 'hinge_moment = "500 N*m*deg"', "hinge_moment"),
        (BACKLASH, MOMENT, 'hinge_moment = "500 N*m/turn"', "hinge_moment"),
        (BACKLASH, MOMENT, 'hinge_moment = "500 N*m/arcmin"', "hinge_moment"),
        (BACKLASH, MOMENT, 'hinge_moment = "500 N*m/sr"', "hinge_moment"),
        # an angle given as an angle squared, per angle, per time, a solid angle
        (BACKLASH, DEFL, DEFL.replace('"-30 deg"', '"-30 deg^2"'), "deflection"),
        (BACKLASH, DEFL, DEFL.replace('"-30 deg"', '"-0.5 rad/rad"'), "deflection"),
        (BACKLASH, DEFL, DEFL.replace('"-30 deg"', '"-30 deg*rad"'), "deflection"),
        (BACKLASH, DEFL, DEFL.replace('"-30 deg"', '"-30 deg/s"'), "deflection"),
        (BACKLASH, DEFL, DEFL.replace('"-30 deg"', '"-0.1 sr"'), "deflection"),
        (BACKLASH, 'rod_inclination_max = "30 deg"', 'rod_inclination_max = "30 deg/rad"', "rod_inclination_max"),
        (BACKLASH, 'max = "140 deg" }', 'max = "140 deg*deg" }', "transmission_angle"),
        (BACKLASH, 'lower = "-0.6 rad"', 'lower = "-0.6 rad/s"', "phi0"),
        # lengths, pressures and limits carrying an angle
        (BACKLASH, 'R = { lower = "30 mm"', 'R = { lower = "30 mm*rad"', "R"),
        (BACKLASH, 'R = { lower = "30 mm"', 'R = { lower = "30 mm/deg"', "R"),
        (BACKLASH, '"100 MPa"', '"100 MPa*rad"', "pin_bearing_pressure_max"),
        (BACKLASH, '"110 mm"', '"110 mm/rad"', "nut_travel_max"),
        (BACKLASH, MOMENT, MOMENT + '\nbacklash_max = "0.1 deg/rad"', "backlash_max"),
        (BACKLASH, MOMENT, MOMENT + '\nbacklash_max = "0.1 mm"', "backlash_max"),
        (BACKLASH, MOMENT, MOMENT + '\nmotor_torque_max = "5 N*m/rad"', "motor_torque_max"),
        (BACKLASH, "[materials.pin]", '[clearances]\nO = "0.01 mm"\n\n[materials.pin]', "O"),
        (BACKLASH, "[materials.pin]", '[clearances]\nA = "0.01 deg"\n\n[materials.pin]', "A"),
        (BACKLASH, "[materials.pin]", '[clearances]\nO = "0.01 deg*rad"\n\n[materials.pin]', "O"),
        # the drive: a rotational stiffness needs a moment per angle, a rate an angle per time
        (DRIVE, STIFF, 'stiffness_min = "600 kN*m"', "stiffness_min"),
        (DRIVE, STIFF, 'stiffness_min = "600 kN*m/s"', "stiffness_min"),
        (DRIVE, STIFF, 'stiffness_min = "600 kN*m/rad^2"', "stiffness_min"),
        (DRIVE, STIFF, 'stiffness_min = "600 kN*m*rad"', "stiffness_min"),
        (DRIVE, STIFF, 'stiffness_min = "600 kN/mm"', "stiffness_min"),
        (DRIVE, RATE, 'deflection_rate = "1 Hz"', "deflection_rate"),
        (DRIVE, RATE, 'deflection_rate = "120 1/s"', "deflection_rate"),
        (DRIVE, RATE, 'deflection_rate = "120 s^-1"', "deflection_rate"),
        (DRIVE, RATE, 'deflection_rate = "120 rad/s/rad"', "deflection_rate"),
        (DRIVE, RATE, 'deflection_rate = "120 deg"', "deflection_rate"),
        (DRIVE, RATE, 'deflection_rate = "120 deg/s^2"', "deflection_rate"),
        (DRIVE, RATE, 'deflection_rate = "120 mm/s"', "deflection_rate"),
        (DRIVE, 'bearing_stiffness = "400 N/um"', 'bearing_stiffness = "400 N/um/rad"', "bearing_stiffness"),
        (DRIVE, 'bearing_stiffness = "400 N/um"', 'bearing_stiffness = "400 N*m/rad"', "bearing_stiffness"),
        (DRIVE, 'nut_stiffness = "270 N/um"', 'nut_stiffness = "270 N/rad"', "nut_stiffness"),
        (DRIVE, 'radius = "20 mm"', 'radius = "20 mm*rad"', "radius"),
        (DRIVE, 'force_max = "30 N"', 'force_max = "30 N/rad"', "force_max"),
        (DRIVE, 'force_max = "30 N"', 'force_max = "30 N*m"', "force_max"),
        (DRIVE, 'length = "300 mm"', 'length = "300 mm*rad"', "length"),
        (FIN, 'life_min = "200 h"', 'life_min = "200 h/rad"', "life_min"),
        (FIN, 'life_min = "200 h"', 'life_min = "1e6 rev"', "life_min"),
        (FIN, 'life_min = "200 h"', 'life_min = "200 Hz"', "life_min"),
        (FIN, 'hinge_moment = "150 N*m"', 'hinge_moment = "150 N*m/deg"', "hinge_moment"),
        (FIN, '{ deflection = "0 deg"', '{ deflection = "0 mm"', "deflection"),
    ]  # fmt: skip
    fast = {'stiffness_min = "600 kN*m"'}
    for text, old, new, field in wrong:
        fresh = [q for q in re.findall(r'"[^"]*"', new) if q not in old]
        what = f"{field} {fresh[0]}"
        c.append(file_case("5", what, sub(text, old, new), refuse(field), fast=new in fast))
    # Quantities of the right dimension, in other units: loaded with the right value.
    right = [
        (BACKLASH, MOMENT, 'hinge_moment = "368.781 lbf*ft"', "requirements.hinge_moment", 5e5, 1e-5),
        (BACKLASH, MOMENT, 'hinge_moment = "50000 N*cm"', "requirements.hinge_moment", 5e5, 1e-9),
        (BACKLASH, MOMENT, 'hinge_moment = "0.5 kN*m"', "requirements.hinge_moment", 5e5, 1e-9),
        (BACKLASH, '"100 MPa"', '"100 N*mm^-2"', "requirements.pin_bearing_pressure_max", 100.0, 1e-9),
        (BACKLASH, '"100 MPa"', '"1e8 Pa"', "requirements.pin_bearing_pressure_max", 100.0, 1e-9),
        (BACKLASH, '"100 MPa"', '"0.1 GPa"', "requirements.pin_bearing_pressure_max", 100.0, 1e-9),
        (BACKLASH, '"110 mm"', '"0.11 m"', "requirements.nut_travel_max", 110.0, 1e-9),
        (BACKLASH, '"110 mm"', '"110000 um"', "requirements.nut_travel_max", 110.0, 1e-9),
        (BACKLASH, '"110 mm"', '"110 m*mm/m"', "requirements.nut_travel_max", 110.0, 1e-9),
        (BACKLASH, DEFL, DEFL.replace('"-30 deg"', '"-1800 arcmin"'), "requirements.deflection.min", -30 * DEG, 1e-9),
        (BACKLASH, DEFL, DEFL.replace('"-30 deg"', '"-0.0833333333333 turn"'), "requirements.deflection.min", -30 * DEG, 1e-9),
        (DRIVE, STIFF, 'stiffness_min = "10.471975511966 kN*m/deg"', "requirements.stiffness_min", 6e8, 1e-9),
        (DRIVE, STIFF, 'stiffness_min = "600000 N*m/rad"', "requirements.stiffness_min", 6e8, 1e-9),
        (DRIVE, STIFF, 'stiffness_min = "6e8 N*mm/rad"', "requirements.stiffness_min", 6e8, 1e-9),
        (DRIVE, RATE, 'deflection_rate = "2.0943951023932 rad/s"', "requirements.deflection_rate", 120 * DEG, 1e-9),
        (DRIVE, RATE, 'deflection_rate = "7200 deg/min"', "requirements.deflection_rate", 120 * DEG, 1e-9),
        (DRIVE, RATE, 'deflection_rate = "20 rpm"', "requirements.deflection_rate", 120 * DEG, 1e-9),
        (DRIVE, 'bearing_stiffness = "400 N/um"', 'bearing_stiffness = "4e8 N/m"', "screw.bearing_stiffness", 4e5, 1e-9),
        (DRIVE, 'bearing_stiffness = "400 N/um"', 'bearing_stiffness = "400 kN/mm"', "screw.bearing_stiffness", 4e5, 1e-9),
        (FIN, 'hinge_moment = "150 N*m"', 'hinge_moment = "0.15 kN*m"', "requirements.duty_cycle.0.hinge_moment", 1.5e5, 1e-9),
        (FIN, 'life_min = "200 h"', 'life_min = "720000 s"', "requirements.life_min", 200.0, 1e-9),
    ]  # fmt: skip
    for text, old, new, path, value, rel in right:
        what = new.strip()
        expect = either("deflection_rate") if "rpm" in new else SUCCESS
        c.append(
            Case(f"5:{what} is read right", "5", expect, text=sub(text, old, new), api=api_load, check=value_check(path, value, rel), fast="kN*m/deg" in new)
        )  # fmt: skip
    c += _api_units()
    return c


def _api_units() -> list[Case]:
    """The same dimensions through the Python API: a pint quantity, set_requirement,
    add_constraint's bounds."""

    def quantity(ctx: Any) -> Any:
        import optdesign as od

        data = ctx.data()
        data["requirements"]["hinge_moment"] = od.units.registry().Quantity(500, "N*m/deg")
        return od.load(data)

    def set_req(value: str, name: str = "hinge_moment"):
        def run(ctx: Any) -> Any:
            import optdesign as od

            problem = od.load(ctx.data())
            problem.set_requirement(name, value)
            return problem

        return run

    def constraint(bound: str, unit: str):
        def run(ctx: Any) -> Any:
            import optdesign as od

            problem = od.load(ctx.data())
            problem.add_constraint("nut_force_cap", lambda q: q.nut_force, upper=bound, unit=unit)
            return problem

        return run

    return [
        Case("5:API pint quantity N*m/deg", "5", refuse("hinge_moment"), text=BACKLASH, api=quantity),
        Case("5:API set_requirement N*m/deg", "5", refuse("hinge_moment"), text=BACKLASH, api=set_req("500 N*m/deg"), fast=True),
        Case("5:API set_requirement stiffness kN*m", "5", refuse("stiffness_min"), text=DRIVE, api=set_req("600 kN*m", "stiffness_min")),
        Case("5:API set_requirement rate Hz", "5", refuse("deflection_rate"), text=DRIVE, api=set_req("2 Hz", "deflection_rate")),
        Case("5:API constraint bound kN*m/deg for N", "5", refuse("nut_force_cap"), text=BACKLASH, api=constraint("3 kN*m/deg", "N")),
        Case("5:API constraint bound deg for mm", "5", refuse("nut_force_cap"), text=BACKLASH, api=constraint("3 deg", "mm")),
        Case("5:API constraint bound rad for a plain number", "5", refuse("nut_force_cap"), text=BACKLASH, api=constraint("0.5 rad", "")),
    ]  # fmt: skip


# --- class 6 -----------------------------------------------------------------------------------
PAYLOADS = {
    "html comment": "<!--",
    "script end": "</script><script>alert(1)</script>",
    "comment and script": "<!--<script>",
    "attribute quote": '"><img src=x onerror=alert(1)>',
    "quoted attribute": 'x" onmouseover="alert(1)',
    "mathtext frac": "$\\frac{$",
    "mathtext dollars": "$$ $x$ $",
    "backslashes": "a\\b\\\\c\\n",
    "csv formula": "=cmd|' /C calc'!A0",
    "csv plus": "+SUM(1;2)",
    "csv at": "@SUM(1)",
    "ANSI colour": "\x1b[31mred\x1b[0m",
    "ANSI clear screen": "\x1b[2J\x1b[H",
    "OSC title": "\x1b]0;pwned\x07",
    "C1 CSI": "\x9b31m",
    "newline": "first\nsecond",
    "carriage return": "visible\rhidden",
    "line separators": "a\u2028b\u2029c",
    "bidi override": "\u202eevil",
    "backspace": "abc\x08\x08\x08xyz",
    "delete": "a\x7fb",
    "template braces": "{{7*7}} ${HOME} %s%n",
    "ampersand entities": "&lt;&amp;&#x3c;",
    "emoji": "fin 🚀 ✓",
    "tab": "a\tb",
}


def _named(text: str, old: str, field: str, payload: str) -> str:
    return sub(text, old, f"{field} = {toml_str(payload)}")


def _outputs_check(payload: str, quote: bool):
    """An API result's summary, plot, page and JSON: safe for the payload."""

    def check(value: Any, ctx: Any) -> list[str]:
        import matplotlib

        matplotlib.use("Agg")
        from optdesign.reports.html import solve_report
        from optdesign.reports.result_json import result_json

        out = workspace.terminal_problems(value.summary().encode(), payload)
        fig = value.plot()
        fig.savefig(io.BytesIO(), format="png")
        out += workspace.check_report(solve_report(value), quote)
        workspace._strict_json(result_json(value))
        return out

    return check


def _front_outputs(payload: str, quote: bool):
    def check(value: Any, ctx: Any) -> list[str]:
        from optdesign.reports.html import front_report

        problem = value.problem_object
        out = workspace.terminal_problems(value.summary().encode(), payload)
        value.plot().savefig(io.BytesIO(), format="png")
        out += workspace.check_report(front_report(problem, [value]), quote)
        return out

    return check


def class6() -> list[Case]:
    c: list[Case] = []
    name = 'name = "cs_min_ripple"'
    fast = {"html comment", "mathtext frac", "ANSI colour"}
    for what, payload in PAYLOADS.items():
        quote = '"' in payload
        text = _named(RIPPLE, name, "name", payload)
        c.append(
            file_case(
                "6", f"name {what}", text, SUCCESS, argv=SOLVE_OUT, payload=payload,
                quote_check=quote, check=_outputs_check(payload, quote), fast=what in fast,
            )
        )  # fmt: skip
    for what in ("ANSI colour", "newline", "OSC title", "carriage return"):
        payload = PAYLOADS[what]
        text = _named(RIPPLE, name, "name", payload)
        c.append(file_case("6", f"name {what}, default output folder", text, either("name:"), argv=SOLVE, api=None, payload=payload))  # fmt: skip
    desc = (
        'description = "Crank-slider linkage that keeps the reduction ratio flattest over +-30 deg"'
    )
    for what in (
        "html comment",
        "script end",
        "mathtext frac",
        "ANSI colour",
        "newline",
        "quoted attribute",
    ):
        payload = PAYLOADS[what]
        quote = '"' in payload
        c.append(
            file_case("6", f"description {what}", _named(RIPPLE, desc, "description", payload), SUCCESS, argv=SOLVE_OUT, payload=payload, quote_check=quote, check=_outputs_check(payload, quote))
        )  # fmt: skip
    for what in ("html comment", "mathtext frac", "ANSI colour", "quoted attribute"):
        payload = PAYLOADS[what]
        quote = '"' in payload
        c.append(
            file_case("6", f"reference label {what}", _named(DUAN, 'label = "Duan 2017"', "label", payload), SUCCESS, argv=SOLVE_OUT, payload=payload, quote_check=quote, check=_outputs_check(payload, quote))
        )  # fmt: skip
    pareto = ["pareto", "@FILE@", "--objectives", "ripple,size", "--points", "3", "--workers", "1", "--no-progress", "--out", "@OUT@"]  # fmt: skip
    for what in ("html comment", "mathtext frac", "ANSI colour", "quoted attribute", "script end"):
        payload = PAYLOADS[what]
        quote = '"' in payload

        def api(ctx: Any) -> Any:
            import optdesign as od

            return od.pareto(
                od.load(ctx.data()), ["ripple", "size"], points=3, workers=1, out=ctx.out
            )

        c.append(
            Case(f"6:pareto name {what}", "6", SUCCESS, argv=pareto, text=_named(RIPPLE, name, "name", payload), json=False, api=api, payload=payload, quote_check=quote, check=_front_outputs(payload, quote))
        )  # fmt: skip
    # Refusals that echo the hostile text: the message must not print it raw.
    echo = [
        ("minimize", lambda p: sub(RIPPLE, 'minimize = "ripple"', f"minimize = {toml_str(p)}"), ("minimize", "objective")),
        ("unknown requirement key", lambda p: add(RIPPLE, "requirements", f"{toml_str(p)} = 1"), ("requirements",)),
        ("mechanism", lambda p: sub(RIPPLE, 'mechanism = "crank_slider"', f"mechanism = {toml_str(p)}"), ("mechanism",)),
        ("fit", lambda p: sub(RIPPLE, 'fit = "H7/g6"', f"fit = {toml_str(p)}"), ("fit",)),
        ("variable name", lambda p: add(RIPPLE, "variables", f'{toml_str(p)} = "5 mm"'), ("variables",)),
        ("unit", lambda p: sub(RIPPLE, MOMENT, f"hinge_moment = {toml_str('500 ' + p)}"), ("hinge_moment",)),
        ("ipopt option", lambda p: RIPPLE + f"\n[solver]\nipopt = {{ {toml_str(p)} = 1 }}\n", ("ipopt",)),
    ]  # fmt: skip
    for what, make, names in echo:
        for pname in ("ANSI clear screen", "newline", "bidi override"):
            payload = PAYLOADS[pname]
            c.append(file_case("6", f"echo {pname} in {what}", make(payload), refuse(*names), payload=payload, fast=(what, pname) == ("minimize", "ANSI clear screen")))  # fmt: skip
    for pname in ("ANSI clear screen", "newline"):
        payload = PAYLOADS[pname]
        c.append(Case(f"6:echo {pname} in --objective", "6", refuse("--objective", "objective"), argv=["solve", "@FILE@", "--objective", payload, "--starts", "1"], text=RIPPLE, payload=payload))  # fmt: skip
        c.append(Case(f"6:echo {pname} in --objectives", "6", refuse("--objectives", "objectives"), argv=[*pareto[:3], "ripple," + payload, *pareto[4:]], text=RIPPLE, json=False, payload=payload))  # fmt: skip
    c += _csv_cases()
    return c


def _csv_cases() -> list[Case]:
    """User objective and constraint names in front.csv (written as the CLI writes it)."""

    def run(objective: str, constraint: str):
        def api(ctx: Any) -> Any:
            import optdesign as od
            from optdesign.reports.front_files import write_front_csv, write_front_json
            from optdesign.reports.html import front_report

            problem = od.load(ctx.data())
            problem.add_objective(objective, lambda q: q.R + q.l + q.n, unit="mm", kind="scalar")
            # binding at the front's size end: its name shows in the active column
            problem.add_constraint(
                constraint, lambda q: q.R, lower="35 mm", unit="mm", over="design"
            )
            front = od.pareto(problem, ["ripple", objective], points=3, workers=1, out=ctx.out)
            write_front_csv(front, problem, ctx.out / "front.csv")
            write_front_json([front], ctx.out / "front.json", problem=problem.name)
            (ctx.out / "report.html").write_text(front_report(problem, [front]), encoding="utf-8")
            return front

        return api

    rows = [
        ("formula objective", '=HYPERLINK("http://x","y")', "r_min"),
        ("formula constraint", "linkage_sum", "=cmd|' /C calc'!A0"),
        ("plus and at", "+SUM(1)", "@SUM(2)"),
        ("comma and quote", 'a,"b', "c,d"),
        ("newline in names", "a\nb", "c\rd"),
    ]
    return [
        Case(
            f"6:front.csv {what}",
            "6",
            # names are identifiers since issue 21 (class 9): a refusal naming the
            # argument is right; a name that passes must be neutralised in the CSV
            either("add_objective.name", "add_constraint.name"),
            text=RIPPLE,
            api=run(obj, con),
            payload=obj,
            fast=what == "formula objective",
        )
        for what, obj, con in rows
    ]


def cases() -> list[Case]:
    return [*class5(), *class6()]
