"""Schema of a problem file, validated with pydantic; every quantity may carry a unit.

The generic part (:class:`ProblemSpec`) holds what every mechanism shares: the stroke, the
hinge moment, the drive and pin requirements, the objective, the solver settings. The
mechanism-specific part is *derived from the mechanism plug-in* by :func:`spec_model`:
its requirements (e.g. a crank-slider's transmission angle), the keys of its fixed
clearances, the variables a tolerance or a reference design may name. Quantities are
converted to the internal units (mm, N, MPa, N*mm, rad) on load by
:func:`optdesign.units.to_internal`, which counts the angle as a dimension of its own (a
moment carries none, a rotational stiffness is a moment per angle). Plain numbers
(efficiencies, ratios, factors) are :data:`Dimensionless`: bare, or in percent
(``"90 %"`` is 0.9); an angle there is refused.

The field types are in :mod:`optdesign.problem.spec_types`, the drive's tables in
:mod:`optdesign.problem.spec_drive`, the requirements in
:mod:`optdesign.problem.spec_requirements`; every name is imported from here as before.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BeforeValidator,
    Field,
    create_model,
    field_validator,
    model_validator,
)

from optdesign.argument_checks import MAX_SEED, MAX_STARTS
from optdesign.problem.spec_drive import (  # noqa: F401 - the names of optdesign.problem.spec
    DutyStep,
    Lug,
    Material,
    Materials,
    MotorLock,
    Screw,
    ScrewSizing,
)
from optdesign.problem.spec_loop import Loop
from optdesign.problem.spec_motor import Load, Motion, Motor
from optdesign.problem.spec_requirements import (
    Requirements,
)
from optdesign.problem.spec_types import (  # noqa: F401 - the names of optdesign.problem.spec
    BAND_TYPES,
    POSITIVE_REQUIREMENTS,
    QUANTITY_TYPES,
    Angle,
    AngleBand,
    AngularSpeed,
    Band,
    Deflection,
    Dimensionless,
    Force,
    Length,
    LengthBand,
    Moment,
    Pressure,
    RotationalStiffness,
    Stiffness,
    Time,
    _Model,
    in_range,
)


class Objective(_Model):
    """Objective(s) to minimise; several for Pareto fronts. Names are checked against the
    problem's objective catalogue (built-in and user-added) when the problem is built."""

    minimize: list[str] = Field(min_length=1, max_length=10)

    @model_validator(mode="before")
    @classmethod
    def _listify(cls, data):
        if isinstance(data, dict) and isinstance(data.get("minimize"), str):
            data = dict(data, minimize=[data["minimize"]])
        return data


class SolverOptions(_Model):
    """Defaults of ``optdesign solve`` for this problem (the CLI may override them)."""

    # the caps of the API's and the command line's arguments (optdesign.validation)
    #: The most starts of the global search (None: chosen from the number of free
    #: variables, :func:`optdesign.search.global_phase.default_max_starts`).
    starts: int | None = Field(None, ge=1, le=MAX_STARTS)
    seed: int = Field(0, ge=0, le=MAX_SEED)
    #: The global search stops when the odds of a better optimum say so and at least this
    #: many starts reached the best value (0: the odds never stop it, every start runs).
    agree: int = Field(3, ge=0, le=MAX_STARTS)
    ipopt: dict[str, Any] = Field(default_factory=dict)

    @field_validator("ipopt")
    @classmethod
    def _no_files(cls, value: dict[str, Any]) -> dict[str, Any]:
        # A problem file comes from anyone: an option that writes or reads a file
        # (output_file) or loads code (hsllib) is refused on load, before any solve.
        from optdesign.safe_io import file_option_problem

        found = file_option_problem(value, "ipopt")
        if found:
            where, reason = found
            raise ValueError(f"{where.removeprefix('ipopt.')}: refused: it {reason}")
        return value


def _band_table(data: Any) -> Any:
    # ``R = "0.05 mm"`` is short for ``R = { band = "0.05 mm" }``.
    return {"band": data} if isinstance(data, str | int | float) else data


class _Tolerance(_Model):
    distribution: Literal["normal", "uniform"] = "normal"

    @model_validator(mode="after")
    def _non_negative(self):
        if self.band < 0:  # type: ignore[attr-defined]
            raise ValueError(f"band must be >= 0, got {self.band}")  # type: ignore[attr-defined]
        return self


class LengthTolerance(_Tolerance):
    """Manufacturing tolerance +-band of a length: uniform on [-band, band] or normal with
    sigma = band/3 (a process capability Cp = 1)."""

    band: Length


class AngleTolerance(_Tolerance):
    """Manufacturing tolerance +-band of an angle (see :class:`LengthTolerance`)."""

    band: Angle


TOLERANCE_TYPES: dict[str, Any] = {
    "length": Annotated[LengthTolerance, BeforeValidator(_band_table)],
    "angle": Annotated[AngleTolerance, BeforeValidator(_band_table)],
}


class Tolerances(_Model):
    """Manufacturing scatter of a design, for robust design (formulations/robust.py).

    Any length or angle variable may get a tolerance (fields derived per mechanism).
    ``fit = "uniform"`` draws each pin joint's fit clearance uniformly between the fit's
    smallest and largest clearance (``"fixed"``: the requirement's ``fit_clearance``).
    ``samples`` and ``seed`` fix the sample-average approximation; ``risk`` is the
    minimised statistic of the objective over the samples: ``"cvar"`` (mean of the worst
    1 - alpha) or ``"mean_std"`` (mean + k std).
    """

    fit: Literal["fixed", "uniform"] = "fixed"
    samples: int = Field(32, ge=1, le=2000)
    seed: int = Field(0, ge=0, le=MAX_SEED)
    risk: Literal["cvar", "mean_std"] = "cvar"
    alpha: Dimensionless = Field(0.9, ge=0.0, lt=1.0)
    k: Dimensionless = Field(2.0, ge=0.0)

    @model_validator(mode="after")
    def _names_a_tolerance(self):
        # A section that scatters nothing would make robust design draw no sample at all.
        if self.variables() or self.fit != "fixed":
            return self
        hint = (
            'give a variable\'s band (e.g. R = "0.05 mm") or fit = "uniform", '
            "or leave the table out"
        )
        given = sorted(self.model_fields_set)
        if not given:
            raise ValueError(f"the table is empty: it names no tolerance; {hint}")
        raise ValueError(f"names no tolerance, only settings ({', '.join(given)}); {hint}")

    def variables(self) -> dict[str, Any]:
        """Variable name -> tolerance, for the variables that have one."""
        own = set(Tolerances.model_fields)
        return {k: v for k, v in self if k not in own and v is not None}


class Reference(_Model):
    """A design to compare with (e.g. a paper's): a label and variable values (fields
    derived per mechanism)."""

    label: str = "reference"

    def values(self) -> dict[str, float]:
        """Variable name -> value (internal units) for the variables given."""
        return {k: v for k, v in self if k != "label" and v is not None}


class ProblemSpec(_Model):
    """A whole problem file (generic part; :func:`spec_model` derives the one of a
    mechanism)."""

    name: str
    description: str = ""
    mechanism: str
    variables: dict[str, Any]
    requirements: Requirements
    materials: Materials = Materials()
    clearances: _Model | None = None
    objective: Objective
    solver: SolverOptions = SolverOptions()
    tolerances: Tolerances | None = None
    reference: Reference | None = None
    screw: Screw | None = None
    motor: Motor | None = None
    load: Load | None = None
    motion: Motion | None = None
    loop: Loop | None = None


def _requirement_field(info) -> tuple[Any, Any]:
    """Pydantic field (type, default) of a mechanism-specific requirement."""
    if info.kind == "band":
        typ: Any = BAND_TYPES[info.dimension]
    elif info.kind == "value":
        typ = QUANTITY_TYPES[info.dimension]
    else:
        raise ValueError(f"requirement kind {info.kind!r}: use 'band' or 'value'")
    if getattr(info, "valid", None) is not None:
        typ = Annotated[typ, AfterValidator(_in_range(info.valid, info.dimension))]
    if info.default is None:
        return (typ | None, Field(None, description=info.description))
    return (typ, Field(info.default, description=info.description))


def _in_range(valid: tuple[float, float], dimension: str):
    """Validator: a value (or a band's min and max) within ``valid`` (inclusive)."""
    lo, hi = valid
    deg = dimension == "angle"

    def shown(v: float) -> str:
        return f"{math.degrees(v):g} deg" if deg else f"{v:g}"

    def check(value: Any) -> Any:
        values = [value] if isinstance(value, int | float) else [value.min, value.max]
        for v in values:
            if v is not None and not lo <= v <= hi:
                raise ValueError(f"{shown(v)} is outside [{shown(lo)}, {shown(hi)}]")
        return value

    return check


def _clearance_type(dimension: str) -> Any:
    """The type of a fixed clearance of ``dimension``: a quantity held to the clearance
    chain's range of validity (a play of micrometres, not a metre; an angle within the
    small-angle limit), :mod:`optdesign.models.clearance`."""
    from optdesign.models.clearance import FIXED_CLEARANCE_ANGLE, FIXED_CLEARANCE_LENGTH

    record = {"length": FIXED_CLEARANCE_LENGTH, "angle": FIXED_CLEARANCE_ANGLE}.get(dimension)
    typ = QUANTITY_TYPES[dimension]
    return typ if record is None else Annotated[typ, AfterValidator(in_range(record))]


@cache
def spec_model(mechanism_cls: type) -> type[ProblemSpec]:
    """The problem-file model of one mechanism class (cached per class).

    Its ``requirements`` gain the mechanism's :attr:`~Mechanism.requirements`;
    ``clearances`` takes the keys of its fixed clearances; ``tolerances`` and
    ``reference`` accept its variables and the framework's (drive, pin).
    """
    from optdesign.problem.variables import variable_table

    name = mechanism_cls.__name__
    req_fields = {k: _requirement_field(v) for k, v in mechanism_cls.requirements.items()}
    Req = create_model(f"{name}Requirements", __base__=Requirements, **req_fields)
    cl_fields: dict[str, Any] = {
        key: (_clearance_type(dim), Field(0.0, ge=0.0, description=desc))
        for key, (dim, desc) in mechanism_cls.fixed_clearances.items()
    }
    Cl = create_model(f"{name}Clearances", __base__=_Model, **cl_fields)
    table = variable_table(mechanism_cls)
    tol_fields = {
        k: (TOLERANCE_TYPES[v.dimension] | None, None)
        for k, v in table.items()
        if v.dimension in TOLERANCE_TYPES
    }
    Tol = create_model(f"{name}Tolerances", __base__=Tolerances, **tol_fields)
    ref_fields = {k: (QUANTITY_TYPES[v.dimension] | None, None) for k, v in table.items()}
    Ref = create_model(f"{name}Reference", __base__=Reference, **ref_fields)
    return create_model(
        f"{name}ProblemSpec",
        __base__=ProblemSpec,
        requirements=(Req, ...),
        clearances=(Cl, Cl()),
        tolerances=(Tol | None, None),
        reference=(Ref | None, None),
    )
