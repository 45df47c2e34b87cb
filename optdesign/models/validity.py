"""Ranges of validity of the models: the record every model declares its own in.

Each model module states, next to its equations, the range where they hold: the physical
bounds of its inputs and the bounds its assumptions put on what it computes (a small-angle
map of joint clearances holds for small angles, Hertz's half-space for a contact strip
narrow against the radius, ...). It declares them once, as a tuple ``VALIDITY`` of
:class:`Validity` records, and explains each bound in its docstring's *Validity* section.
The problem layer reads the records: a problem-file value outside its range is refused
when the file is read (:mod:`optdesign.problem.spec`), and a design whose quantities leave
a model's range is not a verified result (:mod:`optdesign.problem.validity`).
:func:`optdesign.models.validity_registry.declared_ranges` collects every record.

The material constants that several models share (an elastic modulus, a Poisson's ratio)
are declared here, once, and listed by each model that uses them.

Validity
--------
Young's modulus E : 1e2 ... 1.2e6 MPa
    The contact and flexibility models are linear elasticity of a solid: from soft
    engineering polymers (PTFE 400-600 MPa, polyethylene 200-1000, rubbers below 100)
    to diamond (1.05-1.2e6 MPa), the stiffest solid known. Below 100 MPa a "pin" is
    rubber, whose strains under a joint's load leave linear elasticity; above 1.2e6 MPa
    is no material.
Poisson's ratio nu : 0 < nu < 0.5
    An isotropic, stable, compressible solid (engineering materials 0.1-0.45).

Units: the internal ones (mm, N, MPa, rad; backlash in deg, as the models compute it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Where a range is checked: ``"file"`` (a problem-file value, refused when read),
#: ``"design"`` (a quantity of a design, by the independent check of a result),
#: ``"call"`` (the model's own functions refuse an argument outside it), ``"documented"``
#: (a model outside the design problems: reproductions and studies; stated, not checked).
CHECKED_AT = ("file", "design", "call", "documented")


@dataclass(frozen=True)
class Validity:
    """The range of one quantity where a model holds.

    Parameters
    ----------
    name
        Unique key, ``"<module>.<quantity>"`` (e.g. ``"clearance.backlash"``).
    model
        The model, as messages name it (``"small-angle clearance"``).
    quantity
        What is bounded (``"worst-case backlash"``).
    lower, upper
        The range in ``unit`` (None: unbounded on that side); inclusive unless
        ``open_lower`` / ``open_upper``.
    unit
        Unit of the bounds and of the values checked (internal units; ``""`` for a
        plain number).
    why
        One sentence: the assumption that puts the bound there (messages quote it; the
        model's docstring has the argument in full).
    shown_unit, scale
        Unit of messages and ``value * scale`` in it (an angle held in rad is shown in
        deg); default the unit itself.
    checked
        Where the range is enforced (:data:`CHECKED_AT`).
    """

    name: str
    model: str
    quantity: str
    lower: float | None
    upper: float | None
    unit: str
    why: str
    shown_unit: str | None = None
    scale: float = 1.0
    open_lower: bool = False
    open_upper: bool = False
    checked: tuple[str, ...] = ("design",)

    def __post_init__(self):
        if not self.why.strip():
            raise ValueError(f"validity {self.name}: say why the range is where it is")
        if any(c not in CHECKED_AT for c in self.checked):
            raise ValueError(f"validity {self.name}: checked must be among {CHECKED_AT}")
        if self.lower is not None and self.upper is not None and not self.lower <= self.upper:
            raise ValueError(f"validity {self.name}: lower {self.lower} above upper {self.upper}")

    # --- the test ----------------------------------------------------------------------
    def contains(self, value) -> np.ndarray:
        """True where ``value`` (a number or an array, in ``unit``) lies in the range;
        NaN never does."""
        v = np.asarray(value, dtype=float)
        ok = ~np.isnan(v)
        if self.lower is not None:
            ok &= (v > self.lower) if self.open_lower else (v >= self.lower)
        if self.upper is not None:
            ok &= (v < self.upper) if self.open_upper else (v <= self.upper)
        return ok

    def excess(self, value) -> np.ndarray:
        """How far ``value`` lies outside, relative to the bound it crosses (0 inside,
        inf for NaN): what ranks the worst of several values."""
        v = np.asarray(value, dtype=float)
        out = np.zeros_like(v)
        with np.errstate(all="ignore"):
            if self.lower is not None:
                out = np.maximum(out, (self.lower - v) / max(abs(self.lower), 1.0))
            if self.upper is not None:
                out = np.maximum(out, (v - self.upper) / max(abs(self.upper), 1.0))
        out = np.where(self.contains(v), 0.0, np.maximum(out, np.finfo(float).tiny))
        return np.where(np.isnan(v), np.inf, out)

    # --- words -------------------------------------------------------------------------
    @property
    def display_unit(self) -> str:
        return self.unit if self.shown_unit is None else self.shown_unit

    def shown(self, value: float) -> str:
        """``value`` (in ``unit``) as messages write it: ``"5 deg"``, ``"0.2"``."""
        v = float(value) * self.scale
        text = "nan" if math.isnan(v) else f"{v:.6g}"
        return f"{text} {self.display_unit}".rstrip()

    def range_text(self) -> str:
        """``"[100 MPa, 1.2e+06 MPa]"``, ``"(0, 100]"``, ``"<= 5 deg"``, ``">= 0.2"``."""
        if self.lower is not None and self.upper is not None:
            left = "(" if self.open_lower else "["
            right = ")" if self.open_upper else "]"
            return f"{left}{self.shown(self.lower)}, {self.shown(self.upper)}{right}"
        if self.upper is not None:
            return f"{'<' if self.open_upper else '<='} {self.shown(self.upper)}"
        if self.lower is not None:
            return f"{'>' if self.open_lower else '>='} {self.shown(self.lower)}"
        return "any value"

    def outside_text(self, value: float) -> str:
        """``"12.9e+06 deg > 5 deg"``: a value outside and the bound it crosses."""
        v = float(value)
        if math.isnan(v):
            return f"nan (not a number; the range is {self.range_text()})"
        if self.lower is not None and not self.contains(v) and v <= self.lower:
            return f"{self.shown(v)} {'<=' if self.open_lower else '<'} {self.shown(self.lower)}"
        if self.upper is not None:
            return f"{self.shown(v)} {'>=' if self.open_upper else '>'} {self.shown(self.upper)}"
        return f"{self.shown(v)} outside {self.range_text()}"

    def refusal(self, value: float) -> str:
        """The reason a file value outside the range is refused: ``"1e+06 mm is outside
        [0 mm, 1 mm] (small-angle clearance: ...)"``."""
        return f"{self.shown(value)} is outside {self.range_text()} ({self.model}: {self.why})"


# --- material constants shared by the contact and flexibility models -----------------------
ELASTIC_MODULUS = Validity(
    "material.elastic_modulus",
    "linear elasticity",
    "Young's modulus",
    1.0e2,
    1.2e6,
    "MPa",
    "from soft polymers (about 100 MPa) to diamond (1.2e6 MPa), the stiffest solid known",
    checked=("file",),
)
POISSON_RATIO = Validity(
    "material.poisson_ratio",
    "linear elasticity",
    "Poisson's ratio",
    0.0,
    0.5,
    "",
    "an isotropic solid that is stable and compressible has 0 < nu < 0.5 "
    "(engineering materials 0.1-0.45)",
    open_lower=True,
    open_upper=True,
    checked=("file", "call"),
)

#: Records of the shared material constants.
VALIDITY: tuple[Validity, ...] = (ELASTIC_MODULUS, POISSON_RATIO)
