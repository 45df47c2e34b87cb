"""Benchmark instances: random problems generated from (family, seed), user problems, and
the shipped problem files.

Each mechanism plug-in names its families (:attr:`Mechanism.bench_families`: family ->
objectives) and its own variables and requirements (:meth:`Mechanism.bench_template`);
here every family draws the requirements common to all mechanisms (deflection range
20-40 deg, hinge moment, mean-ratio band, nut-travel limit, fit class, catalogue or
continuous screw lead, sized pins) and states the instance as a *problem dict*, the
parsed form of a problem file, so that every instance goes through
:func:`optdesign.problem.problem_from_dict` and its validation exactly like a TOML file.

An instance is reproducible from ``(family, seed)`` alone: the generator is
``numpy.random.default_rng([crc32(family), seed])``. The shipped problem files are a family
of their own (``shipped``, seeds 0..2).
"""

from __future__ import annotations

import copy
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from optdesign.problem import DesignProblem, problem_from_dict

#: Fits drawn for the pin joints (all supported by :class:`optdesign.models.fit_formulas.Fit`).
FITS = ("H7/g6", "H7/f7", "H8/f7", "H7/h6")

#: Catalogue windows of the ISO 3408 leads (mm): three values each, so that enumerating
#: the catalogue costs three continuous solves.
LEAD_WINDOWS = ((2.0, 3.0), (3.0, 5.0), (4.0, 6.0), (5.0, 8.0), (6.0, 10.0))

#: Probability that an instance takes its lead from the catalogue.
P_CATALOGUE = 0.3

#: Shipped problem files (family ``shipped``, seed = index).
SHIPPED = ("cs_min_ripple", "cs_min_backlash", "fork_min_backlash")


def _declared() -> dict[str, tuple[str, tuple[str, ...]]]:
    """family -> (mechanism, objectives) as every registered mechanism declares them."""
    from optdesign.mechanisms.registry import get_mechanism, registered

    out: dict[str, tuple[str, tuple[str, ...]]] = {}
    for name in registered():
        for family, objectives in get_mechanism(name).bench_families.items():
            out[family] = (name, tuple(objectives))
    return out


@dataclass(frozen=True)
class Coverage:
    """Which registered mechanisms the seeded suites cover.

    Attributes
    ----------
    families
        mechanism -> its families (each builds a valid problem).
    skipped
        mechanism -> why it has no instances (no families declared, or the first family
        whose instance its template cannot build, with the error).
    """

    families: dict[str, tuple[str, ...]]
    skipped: dict[str, str]


_COVERAGE: dict[tuple, Coverage] = {}


def coverage() -> Coverage:
    """Every registered mechanism with its families or the reason it has none (no
    mechanism is left out silently); cached per set of registered classes."""
    from optdesign.errors import OptDesignError
    from optdesign.mechanisms.registry import get_mechanism, registered

    classes = {name: get_mechanism(name) for name in registered()}
    key = tuple((name, id(cls)) for name, cls in classes.items())
    if key in _COVERAGE:
        return _COVERAGE[key]
    fams: dict[str, tuple[str, ...]] = {}
    skipped: dict[str, str] = {}
    for name, cls in classes.items():
        if not cls.bench_families:
            skipped[name] = (
                "declares no bench_families (bench its problems with "
                "od.bench(problems=[...]) or optdesign bench --problem FILE, or declare "
                "bench_families and bench_template)"
            )
            continue
        for family in cls.bench_families:
            try:
                problem_from_dict(instance_dict(family, 0), source=f"{family}-000")
            except (OptDesignError, ValueError, TypeError, KeyError) as exc:
                skipped[name] = f"its family {family!r} builds no valid problem: {exc}"
                break
        else:
            fams[name] = tuple(cls.bench_families)
    _COVERAGE[key] = result = Coverage(fams, skipped)
    return result


def families() -> dict[str, tuple[str, tuple[str, ...]]]:
    """family -> (mechanism, objectives), from every registered mechanism whose
    families build valid problems (:func:`coverage` says why the others have none). A
    two-objective family is a Pareto-front instance."""
    covered = coverage().families
    return {f: (mech, obj) for f, (mech, obj) in _declared().items() if mech in covered}


def single_families() -> tuple[str, ...]:
    """Families of single-objective instances."""
    return tuple(f for f, (_, obj) in families().items() if len(obj) == 1)


def front_families() -> tuple[str, ...]:
    """Families of Pareto-front instances."""
    return tuple(f for f, (_, obj) in families().items() if len(obj) > 1)


@dataclass(frozen=True)
class Instance:
    """One benchmark instance.

    Attributes
    ----------
    family, seed
        Identity; :func:`make_instance` rebuilds the same ``data`` from them (family
        ``"user"``: a problem given by the caller, carried in ``given``).
    data
        The problem dict (parsed-TOML form); empty for a user problem.
    given
        The user's problem (family ``"user"``).
    """

    family: str
    seed: int
    data: dict[str, Any]
    given: DesignProblem | None = None

    @property
    def id(self) -> str:
        if self.given is not None:
            return f"user-{self.seed:03d}-{self.given.name}"
        return f"{self.family}-{self.seed:03d}"

    @property
    def objectives(self) -> list[str]:
        if self.given is not None:
            return self.given.objective_names
        obj = self.data["objective"]["minimize"]
        return [obj] if isinstance(obj, str) else list(obj)

    @property
    def is_front(self) -> bool:
        return len(self.objectives) > 1

    @property
    def mechanism(self) -> str:
        return self.given.mechanism_name if self.given is not None else self.data["mechanism"]

    def problem(self) -> DesignProblem:
        """The validated problem (same validation as a problem file)."""
        if self.given is not None:
            return self.given
        return problem_from_dict(copy.deepcopy(self.data), source=self.id)


def user_instances(problems) -> list[Instance]:
    """Instances of the caller's own problems (family ``"user"``)."""
    return [Instance("user", k, {}, p) for k, p in enumerate(problems)]


def _rng(family: str, seed: int) -> np.random.Generator:
    return np.random.default_rng([zlib.crc32(family.encode()), int(seed)])


def instance_dict(family: str, seed: int) -> dict[str, Any]:
    """The problem dict of instance ``(family, seed)``.

    Raises
    ------
    KeyError
        Unknown family.
    """
    if family == "shipped":
        return _shipped(seed)
    fams = _declared()
    if family not in fams:
        raise KeyError(f"unknown instance family {family!r} (known: shipped, {', '.join(fams)})")
    mechanism, objectives = fams[family]
    from optdesign.mechanisms.registry import get_mechanism

    mech = get_mechanism(mechanism)
    rng = _rng(family, seed)
    phi_max = float(rng.uniform(20.0, 40.0))
    points = int(rng.choice([31, 41, 61]))
    hinge = float(rng.uniform(200.0, 800.0))
    centre = float(rng.uniform(160.0, 280.0))
    width = float(rng.uniform(0.15, 0.30)) * centre
    travel = float(rng.uniform(80.0, 140.0))
    fit = str(rng.choice(FITS))
    if rng.random() < P_CATALOGUE:
        lo, hi = LEAD_WINDOWS[int(rng.integers(len(LEAD_WINDOWS)))]
        lead: dict[str, Any] = {"catalogue": "ISO 3408", "lower": f"{lo} mm", "upper": f"{hi} mm"}
    else:
        lead = {"lower": "2 mm", "upper": "10 mm"}
    own_vars, own_reqs = mech.bench_template()
    # The template says where the lead goes (``"p": None``), so the variable order - and
    # with it every instance - is the same as when the families were written by hand.
    variables: dict[str, Any] = {k: (lead if k == "p" else v) for k, v in own_vars.items()}
    variables.setdefault("p", lead)
    variables["i_a"] = 2
    requirements: dict[str, Any] = {
        "deflection": {"min": f"{-phi_max} deg", "max": f"{phi_max} deg", "points": points},
        "hinge_moment": f"{hinge} N*m",
        "mean_ratio": {"min": centre - width / 2, "max": centre + width / 2},
        "nut_travel_max": f"{travel} mm",
        "fit": fit,
        "fit_clearance": "max",
        **own_reqs,
    }
    needs_pin = any(o.startswith("backlash") for o in objectives) or rng.random() < 0.5
    if needs_pin:
        variables["d"] = {"lower": "4 mm", "upper": "30 mm"}
        variables["pin_length_ratio"] = float(rng.choice([1.0, 1.5, 2.0]))
        requirements["pin_bearing_pressure_max"] = f"{float(rng.uniform(60.0, 120.0))} MPa"
        requirements["pin_shear_stress_max"] = "200 MPa"
        requirements["pin_shear_planes"] = mech.pin_shear_planes
    return {
        "name": f"{family}-{seed:03d}",
        "description": f"benchmark instance {family} seed {seed}",
        "mechanism": mechanism,
        "variables": variables,
        "requirements": requirements,
        "materials": {"pin": {"E": "2.1e5 MPa", "nu": 0.3}},
        "objective": {"minimize": list(objectives)},
    }


def _shipped(seed: int) -> dict[str, Any]:
    import tomllib

    if not 0 <= seed < len(SHIPPED):
        raise KeyError(f"shipped instance {seed}: there are {len(SHIPPED)} (0..{len(SHIPPED) - 1})")
    path = problems_dir() / f"{SHIPPED[seed]}.toml"
    data = tomllib.loads(path.read_text())
    data.setdefault("name", SHIPPED[seed])
    return data


def problems_dir() -> Path:
    """The shipped ``problems/`` folder (package data, see :mod:`optdesign.data`)."""
    from optdesign.data import problems_dir as shipped

    return shipped()


def make_instance(family: str, seed: int) -> Instance:
    """Instance ``(family, seed)``."""
    return Instance(family, int(seed), instance_dict(family, seed))


#: The suites :func:`suite` builds.
SUITES = ("default", "quick")


def suite(name: str, fronts: bool = True) -> list[Instance]:
    """The instances of suite ``name``.

    ``default``: the three shipped problems and 14 seeds of each single-objective family
    (101 instances), plus 3 seeds of each front family when ``fronts``; ``quick``: three
    instances covering a crank-slider, a fork with a catalogue lead (a GP) and the
    shipped crank-slider backlash problem, plus one front instance when ``fronts``.
    """
    if name == "default":
        out = [make_instance("shipped", k) for k in range(len(SHIPPED))]
        out += [make_instance(f, s) for f in single_families() for s in range(14)]
        if fronts:
            out += [make_instance(f, s) for f in front_families() for s in range(3)]
        return out
    if name == "quick":
        out = [
            make_instance("cs_ripple", 0),
            make_instance("fork_backlash", QUICK_FORK_SEED),
            make_instance("shipped", 1),
        ]
        if fronts:
            out.append(make_instance("fork_front", 0))
        return out
    raise KeyError(f"unknown suite {name!r} (known: {', '.join(SUITES)})")


#: Seed of the quick suite's fork instance: its lead comes from the catalogue.
QUICK_FORK_SEED = 8
