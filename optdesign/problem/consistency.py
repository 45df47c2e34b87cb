"""Checks across fields of a problem, before any work: inputs the schema accepts one field
at a time but that together leave a model undefined (NaN, a division by zero, an empty
catalogue box) or make it answer another question than the one asked (a duty-cycle step
the stroke never reaches, a roller screw priced from a ball-screw catalogue).

:func:`check_problem` runs when a :class:`~optdesign.problem.design_problem.
DesignProblem` is built or changed (files and dicts alike) and raises a
:class:`~optdesign.errors.ProblemError` naming the field and the reason. What it refuses:

- ``requirements.duty_cycle[k].deflection`` outside ``requirements.deflection``: the
  life model would evaluate the linkage where the stroke never goes (extrapolated, or
  where it does not assemble);
- ``[screw] catalogue`` with a ``kind`` the catalogue does not sell (HIWIN: ball screws);
- a ``[screw]`` section without ``d0`` (its efficiency needs the mean diameter); a
  catalogue screw whose ``d0`` or ``p`` is missing, continuous, given ``values`` the
  catalogue does not list, or whose declared values (fixed, or the bounds of
  ``catalogue = ...``) hold no pair of the catalogue;
- ``screw.nut_offset`` not shorter than ``screw.length`` (the nut outside the shaft);
- a ``[reference]`` value of a positive variable (a length, a lead) that is not positive
  or outside the range of validity of the models it feeds (the pin's), or a
  ``[tolerances]`` band that can take one below zero;
- a pin fit the chosen ISO 286 values cannot evaluate (``fit_values``), at a pin diameter
  outside the tables, or whose clearance is negative (an interference: a pin joint needs a
  clearance, and the backlash model would subtract it);
- ``pin_contact = "huth"`` without ``[materials.lug]`` (Huth's model needs the lug's
  thicknesses);
- a ``[loop]`` without the ``[motor]``, ``[load]`` and ``[screw]`` it closes around, or
  whose closed loop is unstable at every grid angle of the problem's start design
  (:func:`optdesign.problem.loop.check_loop`);
- a plain number of the file (a factor, a share of time) with a nonzero magnitude below
  :data:`~optdesign.units.MIN_MAGNITUDE` or above :data:`~optdesign.units.MAX_MAGNITUDE`
  (quantities with units are checked when they are read).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from optdesign.errors import InputError, ProblemError
from optdesign.units import MAX_MAGNITUDE, MIN_MAGNITUDE

#: Screw kinds each catalogue sells.
CATALOGUE_KINDS: dict[str, tuple[str, ...]] = {"HIWIN": ("ball",)}

#: Relative slack of the stroke a duty-cycle step may sit on (its ends, written in
#: another unit, round to a few ulps outside).
STROKE_SLACK = 1e-9


def check_problem(problem: Any) -> None:
    """Raise :class:`ProblemError` naming the first field that leaves ``problem``'s model
    undefined or answering another question (see the module docstring)."""
    spec = problem.spec
    data = spec.model_dump(mode="python", exclude={"variables", "solver"})
    _magnitudes(data, "")  # variables: read by optdesign.units; solver: Ipopt's own checks
    _duty_cycle(spec.requirements)
    _reference(problem)
    _tolerances(problem)
    if spec.screw is not None:
        _screw(problem, spec.screw)
    _fit(problem)
    _lug(problem)
    if spec.loop is not None:
        from optdesign.problem.loop import check_loop

        check_loop(problem)


def _magnitudes(data: Any, path: str) -> None:
    """Plain numbers of the validated spec within the accepted magnitudes."""
    if isinstance(data, dict):
        for key, value in data.items():
            _magnitudes(value, f"{path}.{key}" if path else str(key))
    elif isinstance(data, list | tuple):
        for k, value in enumerate(data):
            _magnitudes(value, f"{path}[{k}]")
    elif isinstance(data, float) and math.isfinite(data):
        size = abs(data)
        if size > MAX_MAGNITUDE or (0.0 < size < MIN_MAGNITUDE):
            raise ProblemError(
                f"{path}: {data:g} is out of range (nonzero magnitudes from "
                f"{MIN_MAGNITUDE:g} to {MAX_MAGNITUDE:g})"
            )


def _duty_cycle(req: Any) -> None:
    steps = req.duty_cycle or []
    lo, hi = req.deflection.min, req.deflection.max
    slack = STROKE_SLACK * max(1.0, abs(lo), abs(hi))
    for k, step in enumerate(steps):
        if not lo - slack <= step.deflection <= hi + slack:
            raise ProblemError(
                f"requirements.duty_cycle[{k}].deflection: {math.degrees(step.deflection):g} "
                f"deg lies outside the stroke (requirements.deflection, "
                f"{math.degrees(lo):g} to {math.degrees(hi):g} deg)"
            )


def _reference(problem: Any) -> None:
    """A reference design's values where the models are defined (a pin of 0 mm is not)."""
    from optdesign.problem.variables import UNITS, variable_table

    reference = problem.spec.reference
    if reference is None:
        return
    table = variable_table(problem.mechanism)
    for name, value in reference.values().items():
        info = table.get(name)
        if info is not None and info.positive and not value > 0:
            unit = UNITS[info.dimension]
            raise ProblemError(f"reference.{name}: must be positive, got {value:g} {unit}".rstrip())
        valid = getattr(info, "valid", None)  # the models' range (a pin of 5 km is none)
        if valid is not None and not valid.contains(value):
            raise ProblemError(f"reference.{name}: {valid.refusal(value)}")


def _tolerances(problem: Any) -> None:
    """A tolerance leaves a positive variable positive in every sample: uniform within
    +-band, normal (sigma = band/3) within +-2 band (6 sigma)."""
    from optdesign.problem.variables import UNITS, variable_table

    tolerances = problem.spec.tolerances
    if tolerances is None:
        return
    table = variable_table(problem.mechanism)
    for name, t in tolerances.variables().items():
        info, var = table.get(name), problem.by_name.get(name)
        if info is None or var is None or not info.positive:
            continue
        smallest = var.lower if var.free else var.value
        reach = t.band if t.distribution == "uniform" else 2.0 * t.band
        if not reach < smallest:
            unit = UNITS[info.dimension]
            raise ProblemError(
                f"tolerances.{name}: a {t.distribution} band of {t.band:g} {unit} reaches "
                f"{reach:g} {unit} from {name}'s smallest value {smallest:g} {unit}: a "
                f"sample would make {name} negative (a tolerance is a small deviation)"
            )


def _screw(problem: Any, screw: Any) -> None:
    if screw.nut_offset is not None and screw.length is not None:
        if not screw.nut_offset < screw.length:
            raise ProblemError(
                f"screw.nut_offset: {screw.nut_offset:g} mm is not shorter than screw.length "
                f"({screw.length:g} mm): the nut would sit outside the shaft"
            )
    if screw.catalogue is None:
        if "d0" not in problem.by_name:
            raise ProblemError(
                "variables.d0: a [screw] section needs the screw's diameter d0 (its "
                "efficiency follows from the lead and the mean diameter): declare d0, or a "
                'catalogue screw ([screw] catalogue = "HIWIN")'
            )
        return
    kinds = CATALOGUE_KINDS.get(screw.catalogue, ())
    if kinds and screw.kind not in kinds:
        raise ProblemError(
            f"screw.kind: {screw.kind!r}, but screw.catalogue {screw.catalogue!r} lists "
            f"{' and '.join(kinds)} screws only (its load ratings and nut stiffness are theirs)"
        )
    box = {}
    for name in ("d0", "p"):
        var = problem.by_name.get(name)
        if var is None:
            raise ProblemError(
                f"variables.{name}: a catalogue screw ([screw] catalogue = "
                f'"{screw.catalogue}") needs {name}, fixed or '
                f'{{ catalogue = "{screw.catalogue}", lower = ..., upper = ... }}'
            )
        if var.free and not var.discrete:
            raise ProblemError(
                f"variables.{name}: continuous, but the screw comes from catalogue "
                f'{screw.catalogue!r}: write {name} = {{ catalogue = "{screw.catalogue}", '
                "lower = ..., upper = ... }, or a fixed catalogue value"
            )
        if var.free:
            _catalogue_values(screw, name, var.values)
        box[name] = (var.value, var.value) if not var.free else (var.lower, var.upper)
    from optdesign.problem.drive import box_has_item

    if not box_has_item(problem, box):
        shown = ", ".join(
            f"{k} = {a:g} mm" if a == b else f"{k} in [{a:g}, {b:g}] mm"
            for k, (a, b) in box.items()
        )
        raise ProblemError(
            f"variables.d0: catalogue {screw.catalogue!r} has no screw with {shown} (its "
            "(d0, p) pairs: see optdesign/data/ball_screws.csv)"
        )


def _catalogue_values(screw: Any, name: str, values: Any) -> None:
    """Each of a catalogue screw's ``values`` of ``name`` (``d0`` or ``p``, mm) is one its
    catalogue lists: an item lookup of another value finds no screw, and every
    combination with it would fail as if more starts could find one."""
    from optdesign.problem.drive import catalogue_values

    listed = catalogue_values(screw.catalogue, name, screw.nut)
    keys = {float(np.round(v, 9)) for v in listed}  # as the item lookup rounds
    off = [v for v in values if float(np.round(v, 9)) not in keys]
    if off:
        nut = f" with {screw.nut} nuts" if screw.nut else ""
        raise ProblemError(
            f"variables.{name}: catalogue {screw.catalogue!r} lists no {name} of "
            f"{', '.join(f'{v:g}' for v in off)} mm (its {name} values{nut}: "
            f"{', '.join(f'{v:g}' for v in listed)} mm); write {name} = "
            f'{{ catalogue = "{screw.catalogue}", lower = ..., upper = ... }}, or values it '
            "lists"
        )


def _fit(problem: Any) -> None:
    """The pin fit can be evaluated at every pin diameter the problem allows, and leaves
    a clearance (not an interference) there."""
    from optdesign.models.fit_formulas import Fit
    from optdesign.problem.drive import fit_values

    d = problem.by_name.get("d")
    if d is None:
        return
    req = problem.spec.requirements
    values = fit_values(problem)
    try:
        fit = Fit.parse(req.fit, "requirements.fit", values=values)
    except InputError as exc:
        hint = ""
        if values == "smooth":
            hint = (
                '; table values (fit_values = "table") need the pin diameter fixed or from '
                'a catalogue (d = { catalogue = "ISO 2338", ... })'
            )
        raise ProblemError(f"{exc}{hint}") from None
    if values == "table" and d.free and not d.discrete:
        raise ProblemError(
            "requirements.fit_values: table values need pin diameters from a catalogue "
            '(d = { catalogue = "ISO 2338", ... }) or a fixed d; use "smooth" for a '
            "continuous d"
        )
    if d.discrete:
        diameters = np.array(d.values, dtype=float)
    elif d.free:  # the smooth formulas over the bounds
        diameters = np.geomspace(d.lower, d.upper, 64)
    else:
        diameters = np.array([d.value])
    which = [req.fit_clearance]
    tolerances = problem.spec.tolerances
    if tolerances is not None and tolerances.fit == "uniform":
        which = ["min", "max"]  # robust design draws between them
    for side in dict.fromkeys(which):
        try:
            c = np.asarray(fit.clearance(diameters, side, values), dtype=float)
        except InputError as exc:
            raise ProblemError(f"variables.d: {exc.reason} (fit {fit}, {values} values)") from None
        # the conforming contact model needs a clearance (a radial gap), eq. 11 allows 0
        bad = np.flatnonzero(~(c > 0.0 if req.pin_contact == "conforming" else c >= 0.0))
        if bad.size:
            k = int(bad[0])
            word = "largest" if side == "max" else "smallest"
            what = "an interference" if c[k] < 0 else "no gap, which pin_contact conforming needs"
            raise ProblemError(
                f"requirements.fit: {fit} has a {word} clearance of {1e3 * c[k]:.3g} um at "
                f"d = {diameters[k]:g} mm ({what}): a pin joint needs a clearance; choose a "
                "clearance fit (e.g. H7/g6)"
                + (' or fit_clearance = "max"' if side == "min" else "")
            )


def _lug(problem: Any) -> None:
    spec = problem.spec
    if spec.requirements.pin_contact == "huth" and spec.materials.lug is None:
        raise ProblemError(
            'materials.lug: pin_contact "huth" needs the lug around the pin: give '
            "[materials.lug] cheek_thickness (and thickness, E where they differ from the "
            "pin's loaded length and modulus)"
        )
