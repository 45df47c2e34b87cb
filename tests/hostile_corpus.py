"""A hostile-input corpus for the command line (issue 13): generated mutations of the
shipped problem files, hand-written files and bad command lines.

Every case must end with exit code 2 (bad input) or, where stated, 1 (infeasible, with
the violated requirements named), one message naming the field, no traceback, no
internal error and no hang. :func:`run_cases` runs a batch in one process through
``optdesign.cli.main`` (output captured, a time limit per case); ``python
tests/hostile_corpus.py`` prints the counts.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import signal
import sys
import time
import tomllib
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"
#: A solve that gets past the checks must be cheap: one start, no ranges, no files.
SOLVE = ["--json", "--starts", "1", "--no-ranges"]
#: Bad values tried per leaf of a shipped file.
PER_LEAF = 3
#: Seconds a case may take before it counts as a hang.
CASE_TIMEOUT = 20


@dataclass
class Case:
    """One hostile input.

    ``argv`` may hold ``{file}`` (the case's problem file, written from ``text``) and
    ``{tmp}`` (the case's own folder). ``codes``: accepted exit codes; ``names``: a
    string the message must contain (the field), any of several.
    """

    name: str
    argv: list[str]
    text: str | bytes | None = None
    codes: tuple[int, ...] = (2,)
    names: tuple[str, ...] = ()
    setup: str = ""  # "readonly": {tmp}/ro is a read-only folder; "outfile": {tmp}/f exists


@dataclass
class Outcome:
    name: str
    code: int | str
    message: str
    seconds: float
    verdict: str = ""  # "refused" (clean), or what went wrong
    detail: dict[str, Any] = field(default_factory=dict)


# --- a minimal TOML writer (tomli_w is not a dependency) ---------------------------------
def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, _Raw):
        return v.text
    raise TypeError(type(v))


class _Raw:
    """Text written as is (TOML that no Python value produces, e.g. 1e400)."""

    def __init__(self, text: str):
        self.text = text


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() else json.dumps(k)


def dumps(data: dict[str, Any]) -> str:
    """TOML text of ``data``: scalars at the top, then one table per section."""
    lines = [f"{_key(k)} = {_value(v)}" for k, v in data.items() if not isinstance(v, dict)]

    def table(prefix: str, d: dict[str, Any]) -> None:
        lines.append(f"\n[{prefix}]")
        subs = []
        for k, v in d.items():
            if isinstance(v, dict) and any(isinstance(x, dict) for x in v.values()):
                subs.append((k, v))
            else:
                lines.append(f"{_key(k)} = {_value(v)}")
        for k, v in subs:
            table(f"{prefix}.{_key(k)}", v)

    for k, v in data.items():
        if isinstance(v, dict):
            table(_key(k), v)
    return "\n".join(lines) + "\n"


# --- generated mutations of the shipped files --------------------------------------------
#: Free text, where any string is valid.
_FREE_TEXT = {"name", "description", "label"}
#: Values no field accepts (a number field, a quantity, a name or a table).
_BAD_VALUES: dict[str, Any] = {
    "nan": float("nan"),
    "inf": float("inf"),
    "-inf": float("-inf"),
    "1e400": _Raw('"1e400 mm"'),
    "bool": True,
    "list": [1, [2, [3]]],
    "table": {"x": 1},
    "arith": "10**10**10 mm",
    "junk": "abc def",
    "empty": "",
    "nul": "1\u0000 mm",
}


def _leaves(d: dict[str, Any], path: tuple[str, ...] = ()):
    for k, v in d.items():
        here = (*path, k)
        if isinstance(v, dict):
            yield from _leaves(v, here)
        else:
            yield here, v


def _set(data: dict[str, Any], path: tuple[str, ...], value: Any, delete: bool = False):
    import copy

    new = copy.deepcopy(data)
    d = new
    for k in path[:-1]:
        d = d[k]
    if delete:
        del d[path[-1]]
    else:
        d[path[-1]] = value
    return new


def _rename(data: dict[str, Any], path: tuple[str, ...], new_key: str):
    import copy

    new = copy.deepcopy(data)
    d = new
    for k in path[:-1]:
        d = d[k]
    d[new_key] = d.pop(path[-1])
    return new


def _typo(key: str) -> str:
    # Two neighbouring letters swapped (or a letter doubled): the nearest name is the key.
    if len(key) >= 4 and key[1] != key[2]:
        return key[0] + key[2] + key[1] + key[3:]
    return key + key[-1]


#: Required keys whose absence must be named.
_REQUIRED = [("mechanism",), ("variables",), ("requirements",), ("objective",)]
_REQUIRED_REQ = [("requirements", "deflection"), ("requirements", "hinge_moment")]


def generated_cases() -> list[Case]:
    """Mutations of every shipped problem file: each leaf given each bad value, each key
    misspelt, an unknown key in each table, each required key removed."""
    cases: list[Case] = []
    for path in sorted(PROBLEMS.glob("*.toml")):
        data = tomllib.loads(path.read_text())
        stem = path.stem
        for leaf, _ in _leaves(data):
            if leaf[-1] in _FREE_TEXT or leaf[0] == "name":
                continue
            names = (leaf[-1],)
            labels = list(_BAD_VALUES)
            # A few bad values per leaf, rotating over the leaves (every value is used on
            # every file; all of them on every leaf would only repeat the same checks).
            k = sum(map(ord, ".".join(leaf) + stem))
            for label in (labels[(k + j * 4) % len(labels)] for j in range(PER_LEAF)):
                bad = _BAD_VALUES[label]
                if label == "bool" and isinstance(_, bool):
                    bad = "yes"  # a bool field: a string instead
                cases.append(
                    Case(
                        f"{stem}:{'.'.join(leaf)}={label}",
                        ["solve", "{file}", *SOLVE],
                        dumps(_set(data, leaf, bad)),
                        names=names,
                    )
                )
        tables = [()] + [p for p, v in _walk_tables(data)]
        for table in tables:
            target = data
            for k in table:
                target = target[k]
            if table and table[0] == "variables" and len(table) == 1:
                names = ("bogus_key",)
            else:
                names = ("bogus_key",)
            cases.append(
                Case(
                    f"{stem}:{'.'.join(table) or '<top>'}.bogus_key",
                    ["solve", "{file}", *SOLVE],
                    dumps(_set(data, (*table, "bogus_key"), 1)),
                    names=names,
                )
            )
        for key_path, _ in _leaves(data):
            if key_path[-1] in ("name", "description") and len(key_path) == 1:
                continue  # optional top-level text: a misspelt one is still refused below
            if key_path[0] in ("variables",) and len(key_path) > 2:
                continue  # lower/upper typos: the table of allowed keys is small
            typo = _typo(key_path[-1])
            cases.append(
                Case(
                    f"{stem}:typo {'.'.join(key_path)}->{typo}",
                    ["solve", "{file}", *SOLVE],
                    dumps(_rename(data, key_path, typo)),
                    names=(typo,),
                )
            )
        for req in [*_REQUIRED, *_REQUIRED_REQ]:
            cases.append(
                Case(
                    f"{stem}:missing {'.'.join(req)}",
                    ["solve", "{file}", *SOLVE],
                    dumps(_set(data, req, None, delete=True)),
                    names=(req[-1],),
                )
            )
    return cases


def _walk_tables(d: dict[str, Any], path: tuple[str, ...] = ()):
    for k, v in d.items():
        if isinstance(v, dict) and not (path and path[0] == "variables"):
            yield (*path, k), v
            yield from _walk_tables(v, (*path, k))


# --- hand-written files -------------------------------------------------------------------
def _base() -> str:
    return (PROBLEMS / "cs_min_backlash.toml").read_text()


def _sub(old: str, new: str) -> str:
    text = _base()
    assert old in text, old
    return text.replace(old, new, 1)


_MOMENT = 'hinge_moment = "500 N*m"'
_DEFL = 'deflection = { min = "-30 deg", max = "30 deg", points = 61 }'
_R = 'R = { lower = "30 mm", upper = "120 mm" }'


def handwritten_cases() -> list[Case]:
    """Physically meaningless, malformed and oversized files, one class each."""
    s = ["solve", "{file}", *SOLVE]
    # fmt: off
    files: list[tuple[str, str | bytes, tuple[str, ...], tuple[int, ...]]] = [
        ('negative moment', _sub(_MOMENT, 'hinge_moment = "-500 N*m"'), ('hinge_moment',), (2,)),
        ('zero moment', _sub(_MOMENT, 'hinge_moment = "0 N*m"'), ('hinge_moment',), (2,)),
        ('bare moment', _sub(_MOMENT, 'hinge_moment = 300'), ('"300 N*m"',), (2,)),
        ('bare length', _sub(_R, 'R = { lower = 30, upper = "120 mm" }'), ('R.lower',), (2,)),
        ('bare angle', _sub(_DEFL, 'deflection = { min = -0.5, max = 0.5 }'), ('deflection',), (2,)),
        ('moment as length', _sub(_MOMENT, 'hinge_moment = "500 mm"'), ('hinge_moment',), (2,)),
        ('moment N-s', _sub(_MOMENT, 'hinge_moment = "500 N*s"'), ('hinge_moment',), (2,)),
        ('deflection in percent', _sub(_DEFL, 'deflection = { min = "-30 percent", max = "30 percent" }'), ('deflection',), (2,)),
        ('deflection in mm', _sub(_DEFL, 'deflection = { min = "-30 mm", max = "30 mm" }'), ('deflection',), (2,)),
        ('deflection reversed', _sub(_DEFL, 'deflection = { min = "30 deg", max = "-30 deg" }'), ('deflection',), (2,)),
        ('deflection over a turn', _sub(_DEFL, 'deflection = { min = "-300 deg", max = "300 deg" }'), ('deflection',), (2,)),
        ('deflection points 2', _sub(_DEFL, 'deflection = { min = "-30 deg", max = "30 deg", points = 2 }'), ('points',), (2,)),
        ('deflection points 1e8', _sub(_DEFL, 'deflection = { min = "-30 deg", max = "30 deg", points = 100000000 }'), ('points',), (2,)),
        ('rod inclination 200 deg', _sub('rod_inclination_max = "30 deg"', 'rod_inclination_max = "200 deg"'), ('rod_inclination_max',), (2,)),
        ('rod inclination negative', _sub('rod_inclination_max = "30 deg"', 'rod_inclination_max = "-10 deg"'), ('rod_inclination_max',), (2,)),
        ('transmission angle 200 deg', _sub('max = "140 deg" }', 'max = "200 deg" }'), ('transmission_angle',), (2,)),
        ('transmission angle in percent', _sub('min = "40 deg", max = "140 deg"', 'min = "40 percent", max = "140 deg"'), ('transmission_angle',), (2,)),
        ('negative shear limit', _sub('"200 MPa"', '"-200 MPa"'), ('pin_shear_stress_max',), (2,)),
        ('negative pressure limit', _sub('"100 MPa"', '"-100 MPa"'), ('pin_bearing_pressure_max',), (2,)),
        ('negative nut travel', _sub('"110 mm"', '"-110 mm"'), ('nut_travel_max',), (2,)),
        ('negative ratio band', _sub('min = 200, max = 260', 'min = -260, max = -200'), ('mean_ratio',), (2,)),
        ('ratio band reversed', _sub('min = 200, max = 260', 'min = 260, max = 200'), ('mean_ratio',), (2,)),
        ('ratio nan', _sub('min = 200, max = 260', 'min = nan, max = 260'), ('mean_ratio',), (2,)),
        ('efficiency negative', _sub(_MOMENT, _MOMENT + '\neta_screw = -0.5'), ('eta_screw',), (2,)),
        ('efficiency above one', _sub(_MOMENT, _MOMENT + '\neta_screw = 1.5'), ('eta_screw',), (2,)),
        ('efficiency zero', _sub(_MOMENT, _MOMENT + '\neta_gear = 0'), ('eta_gear',), (2,)),
        ('efficiency nan', _sub(_MOMENT, _MOMENT + '\neta_gear = nan'), ('eta_gear',), (2,)),
        ('lock negative back efficiency', _sub(_MOMENT, _MOMENT + '\nlock = { kind = "pin", radius = "10 mm", eta_screw_back = -0.3 }'), ('eta_screw_back',), (2,)),
        ('shear planes true', _sub('pin_shear_planes = 2', 'pin_shear_planes = true'), ('pin_shear_planes',), (2,)),
        ('shear planes 3', _sub('pin_shear_planes = 2', 'pin_shear_planes = 3'), ('pin_shear_planes',), (2,)),
        ('E negative', _sub('E = "2.1e5 MPa"', 'E = "-2.1e5 MPa"'), ('E',), (2,)),
        ('nu 0.5', _sub('nu = 0.3', 'nu = 0.5'), ('nu',), (2,)),
        ('R nan', _sub(_R, 'R = { lower = "30 mm", upper = nan }'), ('R.upper',), (2,)),
        ('R 1e308', _sub(_R, 'R = { lower = "30 mm", upper = "1e308 mm" }'), ('R.upper',), (2,)),
        ('R 1e400', _sub(_R, 'R = { lower = "30 mm", upper = "1e400 mm" }'), ('R.upper',), (2,)),
        ('R power tower', _sub(_R, 'R = { lower = "30 mm", upper = "10**10**10 mm" }'), ('R.upper',), (2,)),
        ('R long unit', _sub(_R, 'R = { lower = "30 mm", upper = "1 ' + 'mm*' * 60 + 'mm" }'), ('R.upper',), (2,)),
        ('R nested parentheses', _sub(_R, 'R = { lower = "30 mm", upper = "1 ((((((mm))))))" }'), ('R.upper',), (2,)),
        ('R negative', _sub(_R, 'R = { lower = "-30 mm", upper = "120 mm" }'), ('R.lower',), (2,)),
        ('R reversed', _sub(_R, 'R = { lower = "120 mm", upper = "30 mm" }'), ('variables.R',), (2,)),
        ('R start outside', _sub(_R, 'R = { lower = "30 mm", upper = "120 mm", start = "500 mm" }'), ('R.start',), (2,)),
        ('R one bound', _sub(_R, 'R = { lower = "30 mm" }'), ('R.upper',), (2,)),
        ('R in deg', _sub(_R, 'R = { lower = "30 deg", upper = "120 deg" }'), ('R.lower',), (2,)),
        ('R unknown key', _sub(_R, 'R = { lower = "30 mm", upper = "120 mm", uper = "1 mm" }'), ('R.uper',), (2,)),
        ('R values empty', _sub(_R, 'R = { values = [] }'), ('R.values',), (2,)),
        ('R catalogue list', _sub(_R, 'R = { catalogue = [1, 2] }'), ('R.catalogue',), (2,)),
        ('R catalogue unknown', _sub(_R, 'R = { catalogue = "ISO 9999" }'), ('R.catalogue',), (2,)),
        ('unknown variable', _sub(_R, _R + '\nRR = "5 mm"'), ('RR',), (2,)),
        ('i_a negative', _sub('i_a = 2', 'i_a = -2'), ('i_a',), (2,)),
        ('phi0 in mm', _sub('phi0 = { lower = "-0.6 rad", upper = "0.6 rad" }', 'phi0 = { lower = "-0.6 mm", upper = "0.6 mm" }'), ('phi0',), (2,)),
        ('unknown reference key', _base() + '\n[reference]\nlabel = "x"\nRR = "50 mm"\n', ('reference.RR',), (2,)),
        ('reference in wrong unit', _base() + '\n[reference]\nR = "50 deg"\n', ('reference.R',), (2,)),
        ('misspelt requirement', _sub('nut_travel_max', 'max_nut_travel'), ('nut_travel_max',), (2,)),
        ('misspelt section', _sub('[objective]', '[objectiv]'), ('objective',), (2,)),
        ('unknown section', _base() + '\n[extras]\nx = 1\n', ('extras',), (2,)),
        ('minimize empty', _sub('minimize = "backlash"', 'minimize = []'), ('minimize',), (2,)),
        ('minimize unknown', _sub('minimize = "backlash"', 'minimize = "backlsh"'), ('backlsh',), (2,)),
        ('minimize number', _sub('minimize = "backlash"', 'minimize = 3'), ('minimize',), (2,)),
        ('unknown fit', _sub('fit = "H7/g6"', 'fit = "H7/zz9"'), ('fit',), (2,)),
        ('fit not a fit', _sub('fit = "H7/g6"', 'fit = "loose"'), ('fit',), (2,)),
        ('fit clearance bogus', _sub('fit_clearance = "max"', 'fit_clearance = "mid"'), ('fit_clearance',), (2,)),
        ('unknown mechanism', _sub('mechanism = "crank_slider"', 'mechanism = "crank_slidr"'), ('mechanism',), (2,)),
        ('mechanism number', _sub('mechanism = "crank_slider"', 'mechanism = 5'), ('mechanism',), (2,)),
        ('ipopt unknown option', _base() + '\n[solver]\nipopt = { print_levl = 5 }\n', ('print_levl',), (2,)),
        ('ipopt wrong type', _base() + '\n[solver]\nipopt = { print_level = "loud" }\n', ('print_level',), (2,)),
        ('ipopt out of range', _base() + '\n[solver]\nipopt = { print_level = 99 }\n', ('print_level',), (2,)),
        ('ipopt bad choice', _base() + '\n[solver]\nipopt = { mu_strategy = "bogus" }\n', ('mu_strategy',), (2,)),
        ('ipopt table value', _base() + '\n[solver]\nipopt = { tol = { a = 1 } }\n', ('tol',), (2,)),
        ('solver starts zero', _base() + '\n[solver]\nstarts = 0\n', ('starts',), (2,)),
        ('solver starts huge', _base() + '\n[solver]\nstarts = 100000000\n', ('starts',), (2,)),
        ('tolerance of unknown variable', _base() + '\n[tolerances]\nZ = "0.1 mm"\n', ('Z',), (2,)),
        ('tolerance negative', _base() + '\n[tolerances]\nR = "-0.1 mm"\n', ('band',), (2,)),
        ('tolerance samples 0', _base() + '\n[tolerances]\nsamples = 0\nR = "0.1 mm"\n', ('samples',), (2,)),
        ('clearance negative', _base() + '\n[clearances]\nA = "-0.01 mm"\n', ('A',), (2,)),
        ('clearance unknown joint', _base() + '\n[clearances]\nQ = "0.01 mm"\n', ('Q',), (2,)),
        ('screw friction 1', _base() + '\n[screw]\nfriction = 1.0\n', ('friction',), (2,)),
        ('screw unknown kind', _base() + '\n[screw]\nkind = "magic"\n', ('kind',), (2,)),
        ('screw nut without catalogue', _base() + '\n[screw]\nnut = "FSI"\n', ('nut',), (2,)),
        ('life without duty cycle', _sub(_MOMENT, _MOMENT + '\nlife_min = "1000 h"'), ('life_min',), (2,)),
        ('duty step negative moment', _sub(_MOMENT, _MOMENT + '\ndeflection_rate = "60 deg/s"\nduty_cycle = [{ deflection = "0 deg", hinge_moment = "-5 N*m", time = 1 }]'), ('hinge_moment',), (2,)),
        ('name a table', _sub('name = "cs_min_backlash"', 'name = { a = 1 }'), ('name',), (2,)),
        ('nested arrays', _sub('[objective]', 'junk = ' + '[' * 500 + ']' * 500 + '\n[objective]'), ('nested',), (2,)),
        ('nested tables', _sub('[objective]', 'junk = ' + '{ a = ' * 300 + '1' + ' }' * 300 + '\n[objective]'), ('nested',), (2,)),
        ('not TOML', 'this is not = = toml', ('TOML',), (2,)),
        ('empty file', '', ('mechanism',), (2,)),
        ('binary', b'\x00\x01\x02\xff\xfe garbage', ('not a text file',), (2,)),
        ('latin-1', _base().encode('utf-8') + '\n# café\n'.encode('latin-1'), ('UTF-8',), (2,)),
        ('utf-16', _base().encode('utf-16'), ('text file',), (2,)),
        ('too large', '# ' + 'x' * 1100000 + '\n' + _base(), ('too large',), (2,)),
        ('duplicate key', _sub(_MOMENT, _MOMENT + '\n' + _MOMENT), ('TOML',), (2,)),
        ('infeasible travel', _sub('"110 mm"', '"1 mm"'), ('nut_travel',), (1,)),
    ]
    # fmt: on
    pivot = (PROBLEMS / "pivot_min_backlash.toml").read_text()
    assert 'dead_length = "60 mm"' in pivot
    files += [
        ("dead length negative", pivot.replace('dead_length = "60 mm"', 'dead_length = "-60 mm"'), ("dead_length",), (2,)),
        ("infeasible ratio band", _sub("min = 200, max = 260", "min = 2000, max = 2100"), ("mean_ratio",), (1,)),
        ("infeasible pin pressure", _sub('"100 MPa"', '"0.01 MPa"'), ("pin_bearing_pressure",), (1,)),
        ("assembly margin 2", _sub(_MOMENT, _MOMENT + "\nassembly_margin_min = 2"), ("assembly_margin_min",), (2,)),
    ]  # fmt: skip
    cases = [Case(f"file:{n}", s, t, codes=c, names=k) for n, t, k, c in files]
    return cases


def command_line_cases() -> list[Case]:
    """Bad command lines (argparse refusals name the option)."""
    ok = str(PROBLEMS / "cs_min_backlash.toml")
    two = str(PROBLEMS / "cs_min_ripple.toml")
    # fmt: off
    lines: list[tuple[str, list[str], tuple[str, ...], str]] = [
        ('no command', [], ('command',), ''),
        ('unknown command', ['optimise', ok], ('optimise',), ''),
        ('solve no file', ['solve'], ('file',), ''),
        ('solve missing file', ['solve', '{tmp}/nope.toml'], ('nope.toml',), ''),
        ('solve folder', ['solve', '{tmp}'], ('folder',), ''),
        ('solve /dev/null', ['solve', '/dev/null'], ('regular file',), ''),
        ('solve /dev/zero', ['solve', '/dev/zero'], ('regular file',), ''),
        ('starts 0', ['solve', ok, '--starts', '0'], ('--starts',), ''),
        ('starts -2', ['solve', ok, '--starts', '-2'], ('--starts',), ''),
        ('starts x', ['solve', ok, '--starts', 'x'], ('--starts',), ''),
        ('starts 1e9', ['solve', ok, '--starts', '1000000000'], ('--starts',), ''),
        ('workers 0', ['solve', ok, '--workers', '0'], ('--workers',), ''),
        ('workers -1', ['solve', ok, '--workers', '-1'], ('--workers',), ''),
        ('workers 1e5', ['solve', ok, '--workers', '100000'], ('--workers',), ''),
        ('seed -1', ['solve', ok, '--seed', '-1'], ('--seed',), ''),
        ('seed 2^64', ['solve', ok, '--seed', str(2 ** 64)], ('--seed',), ''),
        ('solver nosuch', ['solve', ok, '--solver', 'nosuch', *SOLVE], ('nosuch', 'ipopt'), ''),
        ('formulation nosuch', ['solve', ok, '--formulation', 'nosuch', *SOLVE], ('nosuch',), ''),
        ('objective nosuch', ['solve', ok, '--objective', 'nosuch', *SOLVE], ('nosuch',), ''),
        ('unknown option', ['solve', ok, '--startz', '3'], ('--startz',), ''),
        ('out is a file', ['solve', ok, '--out', '{tmp}/f', '--starts', '1'], ('f',), 'outfile'),
        ('out read-only', ['solve', ok, '--out', '{tmp}/ro/x', '--starts', '1'], ('ro',), 'readonly'),
        ('pareto points 0', ['pareto', two, '--objectives', 'ripple,backlash', '--points', '0'], ('--points',), ''),
        ('pareto points 1e7', ['pareto', two, '--objectives', 'ripple,backlash', '--points', '10000000'], ('--points',), ''),
        ('pareto one objective', ['pareto', two, '--objectives', 'ripple', '--out', '{tmp}/p'], ('objectives',), ''),
        ('pareto unknown objective', ['pareto', two, '--objectives', 'ripple,nosuch', '--out', '{tmp}/p'], ('nosuch',), ''),
        ('pareto unknown method', ['pareto', two, '--objectives', 'ripple,backlash', '--method', 'nosuch', '--out', '{tmp}/p'], ('nosuch',), ''),
        ('pareto workers 0', ['pareto', two, '--objectives', 'ripple,backlash', '--workers', '0'], ('--workers',), ''),
        ('pareto pop 0', ['pareto', two, '--objectives', 'ripple,backlash', '--pop', '0'], ('--pop',), ''),
        ('pareto out is a file', ['pareto', two, '--objectives', 'ripple,backlash', '--out', '{tmp}/f'], ('f',), 'outfile'),
        ('pareto resume without out', ['pareto', two, '--objectives', 'ripple,size', '--resume'], ('--resume',), ''),
        ('pareto resume and overwrite', ['pareto', two, '--objectives', 'ripple,size', '--resume', '--overwrite', '--out', '{tmp}/p'], ('--overwrite',), ''),
        ('bench workers 0', ['bench', '--workers', '0'], ('--workers',), ''),
        ('bench time limit nan', ['bench', '--time-limit', 'nan'], ('--time-limit',), ''),
        ('bench time limit -1', ['bench', '--time-limit', '-1'], ('--time-limit',), ''),
        ('bench suite nosuch', ['bench', '--suite', 'nosuch'], ('--suite',), ''),
        ('bench solvers nosuch', ['bench', '--solvers', 'nosuch', '--out', '{tmp}/b'], ('nosuch',), ''),
        ('bench out is a file', ['bench', '--suite', 'quick', '--out', '{tmp}/f'], ('f',), 'outfile'),
        ('out under a file', ['solve', ok, '--out', '{tmp}/f/sub', '--starts', '1'], ('f',), 'outfile'),
        ('reproduce out is a file', ['reproduce', 'duan2017', '--out', '{tmp}/f'], ('f',), 'outfile'),
        ('reproduce nosuch', ['reproduce', 'nosuch'], ('nosuch',), ''),
    ]
    # fmt: on
    resume = [
        "pareto",
        two,
        "--objectives",
        "ripple,size",
        "--points",
        "5",
        "--resume",
        "--out",
        "{tmp}/p",
        "--workers",
        "1",
    ]
    lines += [
        (f"pareto resume {kind}", resume, ("epsilon.jsonl",), f"store-{kind}")
        for kind in ("binary", "empty", "foreign")
    ]
    if os.geteuid() == 0:  # root writes into a read-only folder: the case tests nothing
        lines = [line for line in lines if line[3] != "readonly"]
    return [Case(f"argv:{n}", a, None, names=k, setup=st) for n, a, k, st in lines]


def all_cases() -> list[Case]:
    return generated_cases() + handwritten_cases() + command_line_cases()


# --- running -------------------------------------------------------------------------------
class _Hang(BaseException):
    """Raised by the alarm: a case ran past CASE_TIMEOUT (not an Exception, so that no
    handler of the code under test swallows it)."""


def _on_alarm(signum, frame):
    raise _Hang


def _prepare(case: Case, tmp: Path) -> list[str]:
    tmp.mkdir(parents=True, exist_ok=True)
    if case.text is not None:
        data = case.text.encode("utf-8") if isinstance(case.text, str) else case.text
        (tmp / "problem.toml").write_bytes(data)
    if case.setup == "outfile":
        (tmp / "f").write_text("not a folder\n")
    if case.setup.startswith("store-"):
        (tmp / "p").mkdir(exist_ok=True)
        store = {
            "store-binary": bytes(range(256)) * 8,
            "store-empty": b"",
            "store-foreign": b'{"kind": "something else", "id": 1}\n{"x": 1}\n',
        }[case.setup]
        (tmp / "p" / "epsilon.jsonl").write_bytes(store)
    if case.setup == "readonly":
        (tmp / "ro").mkdir(exist_ok=True)
        (tmp / "ro").chmod(0o555)
    return [
        a.replace("{file}", str(tmp / "problem.toml")).replace("{tmp}", str(tmp)) for a in case.argv
    ]


def judge(case: Case, code: Any, out: str, err: str, seconds: float) -> Outcome:
    """The verdict of one case: ``refused`` when it ended as it should."""
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    message = lines[-1] if lines else ""
    o = Outcome(case.name, code, message[:400], round(seconds, 3))
    if code == "hang":
        o.verdict = "hang"
    elif "Traceback (most recent call last)" in err or "Traceback" in out:
        o.verdict = "traceback"
    elif "internal error" in err:
        o.verdict = "internal error"
    elif code == 0:
        o.verdict = "wrong success"
    elif code not in case.codes:
        o.verdict = f"exit {code}, expected {case.codes}"
    elif case.names and not any(n.lower() in (err + out).lower() for n in case.names):
        o.verdict = f"message does not name {case.names}"
    else:
        o.verdict = "refused"
    o.detail = {"stderr_lines": len(lines)}
    return o


def run_main(argv: list[str], timeout: int = CASE_TIMEOUT) -> tuple[Any, str, str, float]:
    """Run ``optdesign.cli.main(argv)`` in this process with its output captured and a
    time limit: (exit code, or "hang" / "exception"; stdout; stderr; seconds)."""
    from optdesign.cli import main

    out, err = io.StringIO(), io.StringIO()
    t0 = time.perf_counter()
    old = signal.signal(signal.SIGALRM, _on_alarm)
    signal.alarm(timeout)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code: Any = main(argv)
            except SystemExit as exc:  # argparse
                code = exc.code if isinstance(exc.code, int) else 2
            except _Hang:
                code = "hang"
            except BaseException:
                import traceback

                traceback.print_exc(file=err)
                code = "exception"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    return code, out.getvalue(), err.getvalue(), time.perf_counter() - t0


def run_case(case: Case, tmp: Path) -> Outcome:
    """Run one case in this process through ``optdesign.cli.main``."""
    argv = _prepare(case, tmp)
    try:
        code, out, err, seconds = run_main(argv)
    finally:
        if case.setup == "readonly":
            (tmp / "ro").chmod(0o755)
    return judge(case, code, out, err, seconds)


def run_cases(cases: list[Case], tmp: Path) -> list[Outcome]:
    return [run_case(c, tmp / f"c{k}") for k, c in enumerate(cases)]


def counts(outcomes: list[Outcome]) -> dict[str, int]:
    """Tried, refused cleanly, tracebacks, hangs, wrong successes, other failures."""
    c = {"tried": len(outcomes), "refused": 0, "tracebacks": 0, "hangs": 0, "wrong_successes": 0}
    c["internal_errors"] = c["other"] = 0
    for o in outcomes:
        key = {
            "refused": "refused",
            "traceback": "tracebacks",
            "hang": "hangs",
            "wrong success": "wrong_successes",
            "internal error": "internal_errors",
        }.get(o.verdict, "other")
        c[key] += 1
    return c


def main(argv: list[str] | None = None) -> int:
    """``python tests/hostile_corpus.py OUT.json [TMP]``: run every case, write the
    outcomes, print the counts."""
    import tempfile

    argv = sys.argv[1:] if argv is None else argv
    target = Path(argv[0]) if argv else None
    with tempfile.TemporaryDirectory() as tmp:
        outcomes = run_cases(all_cases(), Path(argv[1]) if len(argv) > 1 else Path(tmp))
    summary = counts(outcomes)
    if target is not None:
        target.write_text(
            json.dumps({"counts": summary, "outcomes": [asdict(o) for o in outcomes]}, indent=1)
        )
    print(json.dumps(summary), file=sys.__stdout__)
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())
