"""Every failure names its cause (issue 21, classes 4 and 7).

- An infeasible problem of every formulation (NLP, catalogue, GP, robust, a fixed design)
  gives the violated requirements by name and amount, the best point found and the
  smallest relaxation of each conflicting requirement, in the default summary, in
  ``--json`` and through ``od.solve``; ``pareto`` on one ends with exit 1 naming them.
- Inputs that cannot be right are refused before any work, naming the field: a duty-cycle
  step outside the stroke, a roller screw from a ball-screw catalogue, an off-catalogue
  d0, a nut offset beyond the shaft, 400-digit integers, a NUL in a name, a 1e-300 mm
  length, an HSL linear solver that is not installed, interference fits.

Each case runs through the command line in the default mode and with ``--json`` (in this
process, through ``optdesign.cli.main``) and through the Python API where it applies.
Expected relaxations come from hand bounds: over a stroke of pi/3 with i_a = 2, a mean
ratio of at least 200 and a lead of at least 2 mm need a nut travel of at least
200 (pi/3) 2 / (2 pi 2) = 33.3 mm (travel = mean ratio x stroke x p / (2 pi i_a)).
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

import optdesign as od
from optdesign.cli import main
from optdesign.errors import InfeasibleRequirementsError, OptDesignError

ROOT = Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "problems"
#: The nut travel a mean ratio >= 200 needs with p >= 2 mm over +-30 deg, i_a = 2 (mm).
TRAVEL_NEEDED = 200 * (math.pi / 3) * 2 / (2 * math.pi * 2)
FAST = ["--starts", "1", "--no-ranges"]


def _text(name: str, *changes: tuple[str, str], extra: str = "") -> str:
    text = (PROBLEMS / f"{name}.toml").read_text()
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text + extra


def _run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "internal error" not in err and "Traceback" not in err + out, err[-2000:]
    return code, out, err


TIGHT = ('nut_travel_max = "110 mm"', 'nut_travel_max = "5 mm"')
COARSE = ("points = 61", "points = 13")
INFEASIBLE = {
    # name: (problem text, formulation, hand bounds of the needed nut travel (mm))
    "nlp": (_text("cs_min_backlash", TIGHT, COARSE), "nlp", (TRAVEL_NEEDED, None)),
    "catalogue": (
        _text("cs_min_backlash_catalogue", TIGHT, COARSE),
        "catalogue",
        (TRAVEL_NEEDED, None),
    ),
    # the fork travels 2 R tan 30 deg >= 2 x 30 mm x tan 30 deg = 34.64 mm
    "gp": (_text("fork_min_backlash", TIGHT, COARSE), "gp", (60 * math.tan(math.pi / 6), None)),
    "robust": (
        _text("cs_min_backlash_robust", TIGHT, COARSE, ("samples = 32", "samples = 4")),
        "robust",
        (TRAVEL_NEEDED, None),
    ),
}

FIXED = """
name = "fixed"
mechanism = "crank_slider"
[variables]
R = "60 mm"
l = "120 mm"
n = "40 mm"
p = "5 mm"
phi0 = "0 rad"
d = "8 mm"
i_a = 2
pin_length_ratio = 1.5
[requirements]
deflection = { min = "-30 deg", max = "30 deg", points = 13 }
hinge_moment = "500 N*m"
[objective]
minimize = "backlash"
"""


def _needed(relaxations, name: str) -> float | None:
    match = [r for r in relaxations if r["name"] == name]
    assert match, relaxations
    return match[0]["needed"]["value"]


@pytest.mark.parametrize("kind", list(INFEASIBLE))
def test_infeasible_problem_of_every_formulation_names_its_cause(tmp_path, capsys, kind):
    text, formulation, (lo, hi) = INFEASIBLE[kind]
    path = tmp_path / f"{kind}.toml"
    path.write_text(text)
    hi = hi or 1.02 * lo
    # --json: the violated requirements by name and amount, the best point, the relaxation
    code, out, _ = _run(capsys, "solve", path, "--json", *FAST)
    doc = json.loads(out)
    assert code == 1 and doc["status"] == "infeasible"
    assert doc["formulation"].startswith(formulation)
    violated = {v["name"]: v for v in doc["violated"]}
    assert violated["nut_travel"]["violation"]["value"] > 0
    assert violated["nut_travel"]["limit"] == {"value": 5.0, "unit": "mm"}
    assert doc["design"] and all(v["value"] is not None for v in doc["design"].values())
    needed = _needed(doc["diagnosis"]["relaxations"], "nut_travel")
    # the hand bound is the continuous stroke's; the mean ratio over the 13 grid angles
    # lets the exact minimum (a phase-1 solve, no bisection above it) lie 0.6 % below it
    assert 0.99 * lo <= needed <= hi, needed
    assert doc["diagnosis"]["basis"]
    # the default mode: the same, as text, and the files (report.html of the best point)
    out_dir = tmp_path / "out"
    code, out, _ = _run(capsys, "solve", path, "--out", out_dir, "--no-plot", *FAST)
    assert code == 1
    assert re.search(r"nut travel \(nut_travel\) = [0-9.]+ mm, max 5 mm: exceeded by", out)
    line = next(x for x in out.splitlines() if "(nut_travel): max 5 mm ->" in x)
    assert float(re.search(r"-> ([0-9.]+) mm", line).group(1)) == pytest.approx(needed, rel=1e-3)
    assert "computed on" in out and (out_dir / "report.html").exists()
    # the API: the same diagnosis, typed
    result = od.solve(path, starts=1, ranges=False)
    assert not result.success and result.design
    relax = {r.name: r for r in result.diagnosis.relaxations}
    assert relax["nut_travel"].upper and 0.99 * lo <= relax["nut_travel"].needed <= hi
    # and od.solve(diagnose=False) skips it
    assert od.solve(path, starts=1, ranges=False, diagnose=False).diagnosis is None


def test_a_catalogue_relaxation_is_enough(tmp_path):
    """The relaxation found at catalogue items makes the catalogue problem feasible."""
    text = INFEASIBLE["catalogue"][0]
    result = od.solve(od.load(tomllib.loads(text)), starts=1, ranges=False)
    needed = {r.name: r.needed for r in result.diagnosis.relaxations}["nut_travel"]
    relaxed = text.replace('nut_travel_max = "5 mm"', f'nut_travel_max = "{needed * 1.001} mm"')
    path = tmp_path / "relaxed.toml"
    path.write_text(relaxed)
    assert od.solve(path, starts=1, ranges=False).success


def test_a_catalogue_relaxation_is_sought_from_the_problems_start_too(tmp_path):
    """With a nut travel of 1 mm the search's best point sits at a dead point (its backlash
    is not a number), and the continuous relaxation started there alone reported every
    requirement "relaxing it alone gave no feasible design". Started from the problem's
    own start too, as the continuous diagnosis is, the travel is relaxed to what the mean
    ratio forces: the nut moves mean(v) x stroke with v = ratio p / (2 pi i_a), at least
    200 x 2 mm x 60 deg / (2 pi x 2) = 33.33 mm at the 2 mm lead it names; and the relaxed
    file solves."""
    text = (ROOT / "problems" / "cs_min_backlash_catalogue.toml").read_text()
    shipped = 'nut_travel_max = "110 mm"'
    tight = text.replace(shipped, 'nut_travel_max = "1 mm"')
    result = od.solve(od.load(tomllib.loads(tight)), ranges=False)
    assert result.status == "infeasible"
    travel = {r.name: r for r in result.diagnosis.relaxations}["nut_travel"]
    assert "p = 2 mm" in travel.at
    assert travel.needed == pytest.approx(200 * 2.0 * math.radians(60) / (4 * math.pi), rel=5e-3)
    relaxed = text.replace(shipped, f'nut_travel_max = "{travel.needed * 1.001} mm"')
    path = tmp_path / "relaxed.toml"
    path.write_text(relaxed)
    assert od.solve(path, starts=1, ranges=False).success


def test_fixed_design_is_checked_not_optimised(tmp_path, capsys):
    """No free variable: the design is checked (formulation "fixed"); infeasible, the
    exact relaxation is its own value (the crank-slider with n < R cos 30 deg travels
    2 R sin 30 deg = R = 60 mm)."""
    path = tmp_path / "fixed.toml"
    path.write_text(FIXED)
    code, out, _ = _run(capsys, "solve", path, "--json")
    doc = json.loads(out)
    assert code == 0 and doc["status"] == "optimal" and doc["formulation"] == "fixed"
    assert doc["verified"] is True and doc["objective"]["value"] > 0
    code, out, _ = _run(capsys, "solve", path, "--out", tmp_path / "o1")
    assert code == 0 and "fixed design checked" in out
    tight = path.with_name("tight.toml")
    tight.write_text(
        FIXED.replace(
            'hinge_moment = "500 N*m"', 'hinge_moment = "500 N*m"\nnut_travel_max = "50 mm"'
        )
    )
    code, out, _ = _run(capsys, "solve", tight, "--json")
    doc = json.loads(out)
    assert code == 1 and doc["status"] == "infeasible"
    assert _needed(doc["diagnosis"]["relaxations"], "nut_travel") == pytest.approx(60.0, rel=1e-9)
    code, out, _ = _run(capsys, "solve", tight, "--out", tmp_path / "o2")
    assert code == 1 and "(nut_travel): max 50 mm -> 60 mm" in out
    assert "the fixed design does not meet" in out
    result = od.solve(tight)
    assert result.formulation == "fixed" and result.violated
    # a front needs a free variable: refused before the output folder is made
    code, out, err = _run(
        capsys, "pareto", path, "--objectives", "backlash,size", "--out", tmp_path / "p"
    )
    assert code == 2 and "variables: no free variable" in err
    assert not (tmp_path / "p").exists()
    with pytest.raises(OptDesignError, match="no free variable"):
        od.pareto(od.load(path), ["backlash", "size"], points=3)


@pytest.mark.parametrize("kind", ["nlp", "catalogue"])
def test_pareto_on_an_infeasible_problem_names_the_violated_requirements(tmp_path, capsys, kind):
    path = tmp_path / f"{kind}.toml"
    path.write_text(INFEASIBLE[kind][0])
    argv = ["pareto", path, "--objectives", "backlash,size", "--points", "3", "--workers", "1"]
    code, _out, err = _run(capsys, *argv, "--starts", "1", "--out", tmp_path / "p")
    assert code == 1
    assert "anchor backlash: no feasible design" in err
    assert re.search(r"nut travel \(nut_travel\) = [0-9.]+ mm, max 5 mm: exceeded by", err)
    assert "KeyError" not in err
    with pytest.raises(InfeasibleRequirementsError, match=r"nut_travel.*exceeded by"):
        od.pareto(od.load(path), ["backlash", "size"], points=3, starts=1)


def test_nsga2_front_with_no_feasible_design_names_what_it_violates(tmp_path, capsys):
    path = tmp_path / "nlp.toml"
    path.write_text(INFEASIBLE["nlp"][0])
    argv = ["pareto", path, "--objectives", "backlash,size", "--method", "nsga2"]
    code, _out, err = _run(
        capsys, *argv, "--pop", "8", "--generations", "3", "--out", tmp_path / "p"
    )
    assert code == 1 and "nsga2: no feasible design" in err and "exceeded by" in err


# --- inputs refused before any work --------------------------------------------------------
FIN = "fin_actuator"
CS = "cs_min_backlash"
BIG = "9" * 400
REFUSED = {
    # name: (base, changes, extra text, words the message must hold)
    "duty step outside the stroke": (
        FIN,
        [('deflection = "15 deg", hinge_moment', 'deflection = "50 deg", hinge_moment')],
        "",
        ["requirements.duty_cycle[1].deflection", "outside the stroke"],
    ),
    "roller screw from a ball-screw catalogue": (
        FIN,
        [('kind = "ball"', 'kind = "roller"')],
        "",
        ["screw.kind", "ball screws only"],
    ),
    "fixed d0 off the catalogue": (
        FIN,
        [('d0 = { catalogue = "HIWIN", lower = "12 mm", upper = "25 mm" }', 'd0 = "13 mm"')],
        "",
        ["variables.d0", "no screw with d0 = 13 mm"],
    ),
    "d0 bounds holding no pair with the leads": (
        FIN,
        [
            ('d0 = { catalogue = "HIWIN", lower = "12 mm", upper = "25 mm" }', 'd0 = "14 mm"'),
            (
                'p = { catalogue = "HIWIN", lower = "2 mm", upper = "10 mm" }',
                'p = { catalogue = "HIWIN", lower = "2 mm", upper = "5 mm" }',
            ),
        ],
        "",
        ["variables.d0", "no screw with d0 = 14 mm, p in [2, 5] mm"],
    ),
    "continuous d0 with a catalogue screw": (
        FIN,
        [
            (
                'd0 = { catalogue = "HIWIN", lower = "12 mm", upper = "25 mm" }',
                'd0 = { lower = "12 mm", upper = "25 mm" }',
            )
        ],
        "",
        ["variables.d0", "continuous"],
    ),
    "catalogue lead without d0": (
        FIN,
        [('d0 = { catalogue = "HIWIN", lower = "12 mm", upper = "25 mm" }', "")],
        "",
        ["variables.d0", "needs d0"],
    ),
    "a reference pin of 0 mm": (
        CS,
        [],
        '\n[reference]\nR = "80 mm"\nl = "120 mm"\nn = "60 mm"\np = "5 mm"\nphi0 = "0.1 rad"\nd = "0 mm"\n',
        ["reference.d", "must be positive"],
    ),
    "a tolerance wider than its variable": (
        "cs_min_backlash_robust",
        [('R = "0.05 mm"', 'R = "20 mm"')],
        "",
        ["tolerances.R", "negative"],
    ),
    "a screw section without d0": (
        CS,
        [],
        '\n[screw]\nkind = "ball"\n',
        ["variables.d0", "needs the screw's diameter"],
    ),
    "nut offset beyond the shaft": (
        FIN,
        [('nut_offset = "40 mm"', 'nut_offset = "400 mm"')],
        "",
        ["screw.nut_offset", "not shorter than screw.length"],
    ),
    "screw length 1e-300 mm": (
        FIN,
        [('length = "300 mm" ', 'length = "1e-300 mm" ')],
        "",
        ["screw.length", "out of range (a nonzero magnitude below 1e-12 mm)"],
    ),
    "bearing stiffness 1e-300 N/um": (
        FIN,
        [('bearing_stiffness = "400 N/um"', 'bearing_stiffness = "1e-300 N/um"')],
        "",
        ["screw.bearing_stiffness", "out of range"],
    ),
    "duty time share 1e300": (
        FIN,
        [("time = 0.6", "time = 1e300")],
        "",
        ["requirements.duty_cycle[0].time", "out of range"],
    ),
    "static safety 1e300": (
        FIN,
        [("static_safety_min = 1.5", "static_safety_min = 1e300")],
        "",
        ["requirements.static_safety_min", "out of range (magnitude above 1e+15)"],
    ),
    "a string for a switch": (
        FIN,
        [("critical_speed = true", 'critical_speed = "yes"')],
        "",
        ["critical_speed", "expected true or false"],
    ),
    "400-digit gear ratio": (
        CS,
        [("i_a = 2", f"i_a = {BIG}")],
        "",
        ["variables.i_a", "out of range"],
    ),
    "400-digit start": (
        CS,
        [
            (
                'R = { lower = "30 mm", upper = "120 mm" }',
                f'R = {{ lower = "30 mm", upper = "120 mm", start = {BIG} }}',
            )
        ],
        "",
        ["variables.R.start", "out of range"],
    ),
    "400-digit seed": (CS, [], f"\n[solver]\nseed = {BIG}\n", ["solver.seed", "out of range"]),
    "400-digit catalogue value": (
        CS,
        [('d = { lower = "4 mm", upper = "30 mm" }', f"d = {{ values = [6, {BIG}] }}")],
        "",
        ["variables.d.values[1]", "out of range"],
    ),
    "400-digit Ipopt option": (
        CS,
        [],
        f"\n[solver]\nipopt = {{ max_iter = {BIG} }}\n",
        ["solver.ipopt.max_iter", "out of range"],
    ),
    "5000-digit integer": (
        CS,
        [],
        f"\nzz = {'9' * 5000}\n",
        ["objective.zz: a number of 5000 digits is out of range"],
    ),
    "negative seed": (CS, [], "\n[solver]\nseed = -1\n", ["solver.seed"]),
    "seed above 32 bits": (CS, [], f"\n[solver]\nseed = {2**32}\n", ["solver.seed"]),
    "NUL in the name": (
        CS,
        [('name = "cs_min_backlash"', 'name = "a\\u0000b"')],
        "",
        ["name", "NUL"],
    ),
    "NUL in a requirement": (
        CS,
        [('hinge_moment = "500 N*m"', 'hinge_moment = "500\\u0000 N*m"')],
        "",
        ["requirements.hinge_moment", "NUL"],
    ),
    "HSL linear solver not installed": (
        CS,
        [],
        '\n[solver]\nipopt = { linear_solver = "ma97" }\n',
        ["solver.ipopt.linear_solver", "'ma97'", "available: ", "mumps"],
    ),
    "an Ipopt tolerance that is not finite": (
        CS,
        [],
        "\n[solver]\nipopt = { tol = nan }\n",
        ["solver.ipopt.tol", "nan is not a finite number"],
    ),
    "an Ipopt tolerance of 1e400": (
        CS,
        [],
        "\n[solver]\nipopt = { tol = 1e400 }\n",
        ["solver.ipopt.tol", "inf is not a finite number"],
    ),
    "an Ipopt integer beyond 32 bits": (
        CS,
        [],
        f"\n[solver]\nipopt = {{ max_iter = {2**40} }}\n",
        ["solver.ipopt.max_iter", "outside Ipopt's integers"],
    ),
    "a library to load": (
        CS,
        [],
        '\n[solver]\nipopt = { hsllib = "/tmp/libx.so" }\n',
        ["solver.ipopt.hsllib", "library"],
    ),
    "interference fit from the tables": (
        "cs_min_backlash_catalogue",
        [('fit = "H7/g6"', 'fit = "H7/s6"\nfit_values = "table"')],
        "",
        ["requirements.fit", "H7/s6", "interference"],
    ),
    "R7/s6 from the tables": (
        "cs_min_backlash_catalogue",
        [('fit = "H7/g6"', 'fit = "R7/s6"')],
        "",
        ["requirements.fit", "R7/s6", "interference"],
    ),
    "tolerances on a catalogue problem": (
        "cs_min_backlash_catalogue",
        [],
        '\n[tolerances]\nR = "0.05 mm"\n',
        ["tolerances", "catalogue values"],
    ),
    "a table-only fit on a continuous pin": (
        CS,
        [('fit = "H7/g6"', 'fit = "D10/s6"')],
        "",
        ["requirements.fit", "not supported with smooth values", "fit_values"],
    ),
    "a transition fit's smallest clearance": (
        CS,
        [('fit_clearance = "max"', 'fit_clearance = "min"'), ('fit = "H7/g6"', 'fit = "H7/k6"')],
        "",
        ["requirements.fit", "smallest clearance", "interference"],
    ),
}


@pytest.mark.parametrize("case", list(REFUSED))
def test_inputs_that_cannot_be_right_are_refused_before_any_work(tmp_path, capsys, case):
    base, changes, extra, words = REFUSED[case]
    path = tmp_path / "p.toml"
    path.write_text(_text(base, *changes, extra=extra))
    out_dir = tmp_path / "out"
    for mode in (["--json"], ["--out", str(out_dir)]):
        code, out, err = _run(capsys, "solve", path, *mode, *FAST)
        assert code == 2, (case, mode, out[-500:], err)
        for word in words:
            assert word in err, (case, word, err)
        assert len(err.strip().splitlines()) == 1
    assert not out_dir.exists()  # refused before the output folder is made
    if case.startswith("5000"):
        return  # a file's syntax: the API takes a parsed dict
    with pytest.raises(OptDesignError, match=re.escape(words[0].split("[")[0])):
        od.solve(path, starts=1, ranges=False)


def test_documented_table_fits_are_accepted():
    """R/S and r/s letters exist as ISO 286-2 table values: D10/s6 is a clearance fit
    (3..59 um at 4 to 6 mm); its clearance on the solver path is the table's (a
    parameter per catalogue item), which the NumPy check confirms."""
    from optdesign.fits import clearance

    data = tomllib.loads(
        _text("cs_min_backlash_catalogue", ('fit = "H7/g6"', 'fit = "D10/s6"'), COARSE)
    )
    result = od.solve(od.load(data), starts=1, ranges=False)
    assert result.success and result.verified
    d = result.design["d"]
    assert d in (3, 4, 5, 6, 8, 10, 12, 16, 20, 25)  # ISO 2338
    # the printed table: D10 over 3 up to 6 mm is +30/+78 um, s6 +19/+27 um
    assert 1e3 * clearance("D10/s6", 5.0, "max") == pytest.approx(78 - 19)
    assert 1e3 * clearance("D10/s6", d, "max") > 0
    # the solver's objective (parameter path) equals the independent NumPy value (table)
    assert result.objective == pytest.approx(result.objectives["backlash"], rel=1e-6)


def test_available_linear_solvers_come_from_ipopt_itself():
    from optdesign.solvers.casadi_nlp import available_linear_solvers, runtime_library

    assert runtime_library("linear_solver", "ma97") == "libhsl.so"
    assert runtime_library("linear_solver", "pardiso") == "libpardiso.so"
    assert runtime_library("linear_solver", "mumps") is None
    available = available_linear_solvers()
    assert "mumps" in available and "custom" not in available


# --- edge values in every field of the drive sections (tests/drive_corpus.py) ----------
def _refusal(case, path: Path) -> str | None:
    """The API's refusal of a corpus case before any solve (None: accepted)."""
    from optdesign.studies.solve import plan_solve

    path.write_text(case.text)
    try:
        plan_solve(od.load(path))
    except OptDesignError as exc:
        return str(exc)
    return None


def test_drive_corpus_refusals_name_the_field(tmp_path):
    """Every edge value the loader refuses names the field (or its table); a sample of
    them through the command line, in both output modes, is one line with exit 2."""
    from drive_corpus import drive_cases, run

    refused = []
    for k, case in enumerate(drive_cases()):
        message = _refusal(case, tmp_path / f"c{k}.toml")
        if message is not None:
            assert any(n in message for n in case.names), (case.name, message)
            refused.append(case)
    assert len(refused) >= 700
    for k, case in enumerate(refused[::40]):
        for json_mode in (True, False):
            v = run(case, tmp_path / f"cli{k}-{json_mode}", json_mode)
            assert (v.code, v.verdict) == (2, "refused"), v


@pytest.mark.slow
@pytest.mark.parametrize("json_mode", [True, False], ids=["json", "text"])
def test_drive_corpus_every_case_ends_cleanly(tmp_path, json_mode):
    """Every case of the corpus - solved when accepted - ends refused, infeasible with
    the violated requirements named, or a success with a finite objective."""
    from collections import Counter

    from drive_corpus import CLEAN, drive_cases, run

    verdicts = [run(c, tmp_path / f"c{k}", json_mode) for k, c in enumerate(drive_cases())]
    print(Counter(v.verdict for v in verdicts))
    bad = [v for v in verdicts if v.verdict not in CLEAN]
    assert not bad, "\n".join(f"{v.name}: {v.verdict} ({v.code}): {v.message}" for v in bad[:20])


def test_a_model_undefined_at_the_midpoint_prints_no_warning():
    """A hinge moment that crushes every pin (Hertz's sqrt(D^2/4 - k F) of a negative at
    the midpoint design, where the NLP takes its scales) builds its NLP without a
    RuntimeWarning on stderr (the solve then reports the requirements it violates)."""
    import warnings

    from optdesign.programs.nlp import build_nlp, typical

    data = tomllib.loads(_text(CS, ('hinge_moment = "500 N*m"', 'hinge_moment = "1e12 N*m"')))
    problem = od.load(data)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert typical([math.nan, math.nan]) == 1.0 and typical([math.nan, -3.0]) == 3.0
        nlp = build_nlp(problem)
    assert nlp.g_names


def test_a_solve_that_stops_early_is_not_called_infeasible(tmp_path, capsys):
    """Ipopt stopped at its start (max_iter = 0): the diagnosis finds that the requirement
    the start violates needs no change - a design meeting every requirement exists - and says the solve
    missed it, instead of calling the requirements conflicting."""
    path = tmp_path / "early.toml"
    path.write_text(_text(CS, COARSE, extra="\n[solver]\nipopt = { max_iter = 0 }\n"))
    code, out, _ = _run(capsys, "solve", path, "--json", *FAST)
    doc = json.loads(out)
    assert code == 1 and doc["status"] == "max_iterations"
    assert "a design meeting every requirement as written exists" in doc["diagnosis"]["note"]
    # the one start (the best of its sample) violates the transmission angle; relaxing it
    # finds a design that needs no change at all
    relax = {r["name"]: r for r in doc["diagnosis"]["relaxations"]}
    assert set(relax) == {"transmission_angle"}
    assert relax["transmission_angle"]["needed"] == relax["transmission_angle"]["limit"]
    code, out, _ = _run(capsys, "solve", path, "--out", tmp_path / "o", "--no-plot", *FAST)
    assert code == 1 and "no feasible design found (the solver stopped: max_iterations)" in out
    assert "conflict within the bounds" not in out
    result = od.solve(path, starts=1, ranges=False)
    assert "the solve missed it" in result.diagnosis.note


def test_a_solution_stays_within_its_bounds():
    """Ipopt relaxes its bounds by ~1e-8 of the scaled variable: over a span of 1e12 mm a
    design came back 1e4 mm below its lower bound (a negative length); the design read
    from the solution is held within the declared bounds. (The arm: a pin diameter that
    large is refused, outside the pin model's range, docs/validity.md.)"""
    from optdesign.formulations.nlp.solve import formulation_for

    data = tomllib.loads(
        _text(
            CS,
            (
                'R = { lower = "30 mm", upper = "120 mm" }',
                'R = { lower = "30 mm", upper = "1e12 mm" }',
            ),
        )
    )
    problem = od.load(data)
    nlp = formulation_for(problem)
    z = np.full(nlp.z.numel(), -1e-8)
    x = nlp.x_from_z(z)
    assert np.array_equal(x, problem.lower())
    assert np.array_equal(nlp.x_from_z(np.full(nlp.z.numel(), 1 + 1e-8)), problem.upper())


def test_report_of_a_design_with_overflowing_quantities(tmp_path, capsys, monkeypatch):
    """A nut of 1e-11 N/um: the design's stiffness quantities overflow to inf; the
    default mode still writes report.html (a non-finite number becomes null in its data)
    instead of 'internal error: Out of range float values are not JSON compliant'. Such
    a nut is outside the stiffness chain's range of validity and refused when read
    (docs/validity.md); the report's handling is checked with that range lifted."""
    from drive_corpus import _set, bases
    from hostile_corpus import dumps

    from optdesign.models.validity import Validity
    from optdesign.problem import spec_drive
    from optdesign.reports.html_page import to_json

    assert to_json({"x": [1.0, math.inf, math.nan]}) == '{"x": [1.0, null, null]}'
    data, _ = bases()["cont"]
    path = tmp_path / "soft.toml"
    path.write_text(dumps(_set(data, ("screw", "nut_stiffness"), "1e-11 N/um")))
    code, _, err = _run(capsys, "solve", path, "--json", *FAST)
    assert code == 2 and "screw.nut_stiffness: 1e-08 N/mm is outside [1 N/mm" in err
    lifted = Validity("test.stiffness", "test", "stiffness", 0.0, None, "N/mm", "lifted")
    monkeypatch.setattr(spec_drive, "MEMBER_STIFFNESS", lifted)
    out_dir = tmp_path / "out"
    # (the stiffness requirement fails: the diagnosis, another test's subject, is skipped)
    fast = [*FAST, "--no-diagnosis"]
    code, out, _ = _run(capsys, "solve", path, "--out", out_dir, "--no-plot", *fast)
    assert code in (0, 1) and (out_dir / "report.html").exists()
    code, out, _ = _run(capsys, "solve", path, "--json", *fast)
    assert code in (0, 1) and json.loads(out)["status"]
